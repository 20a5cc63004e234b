// SPDX-License-Identifier: GPL-3.0-or-later
// The MS5611 barometer as the sketch uses it: lib/MS5611's sequencer on the shared SPI
// bus (chip select pin 40 = PG1), run by the task table's `baro` loop task between
// samples, so a transfer never delays the MPU6000's; the ground's pressure and
// temperature taken at start-up while the gyro calibrates (GND_ABS_PRESS; GND_TEMP, when
// not 0, stands for the temperature); the height above that ground and the climb rate at
// 10 Hz, from the mean of the pressures read in each tenth of a second. Its faults are
// "# " lines (STATUSTEXT in MAVLink): not found (blank PROM, bad CRC), lost and back,
// stuck, readings rejected.
#pragma once

#include <stdint.h>

#include "Text.h"

namespace baro {

// Above the ground reference (m) and its rate (m/s, up positive): 0 until the ground is
// taken, and held at their last values while the barometer is not healthy.
float height_m();
float climb_m_s();
// The last 10 Hz mean (Pa) and the chip's temperature (degC); 0 before the first.
float pressure_pa();
float temperature_c();
// Converting, not stuck, the ground taken, a pressure accepted within the last 0.5 s.
bool healthy();
// The chip answered with a good PROM at some time (SYS_STATUS's "present").
bool present();

// The loop task: due when the sequencer has work (a conversion to read, a reset's wait
// over, a retry); the run reads it and starts the next, and every 0.1 s the height.
bool due();
void service();

// `baro` and `status`'s barometer line, within console::kPartReply:
//   "# baro ok: P Pa, T C, H m, V m/s, M missed, R rejected" (height above the ground,
//   climb; the state word "absent", "lost", "stuck" or "starting" instead of "ok").
void print_line(const text::Sink* out);
// `status`'s word for it: "ok", "absent", "lost", "stuck", "starting".
text::Flash state_word();

}  // namespace baro
