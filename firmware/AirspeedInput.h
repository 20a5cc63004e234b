// SPDX-License-Identifier: GPL-3.0-or-later
// The airspeed sensor on A0 (an MPXV7002DP pitot; lib/Pipeline/Airspeed.h converts), for
// the estimator's centripetal correction. Never blocking: each sample reads the
// conversion of A0 started after the previous one (13 ADC clocks at 125 kHz, long done
// 5 ms later) and starts the next (the ADC is shared with the battery's pins: Adc.h). While the gyro calibrates (the board still) the readings are the
// sensor's zero, kept as ARSPD_OFFSET (saved when it moved); a zero far from 2.5 V is no
// sensor, and the configured cruise speed (TRIM_ARSPD_CM) is used instead. A start the gyro
// calibration never found still (it may be flying: no still-air zero to take) uses the
// saved ARSPD_OFFSET, or the cruise speed without one (airspeed::start_zero). Then the mean
// of each kReadings readings is the airspeed.
#pragma once

#include <stdint.h>

namespace airspeed_input {

enum class State : uint8_t { kZero, kSensor, kNone };

// In setup(): the ADC on channel 0 and its first conversion.
void begin();
// Sample task: a reading, and the pipeline's airspeed.
void step();
State state();

}  // namespace airspeed_input
