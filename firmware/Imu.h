// SPDX-License-Identifier: GPL-3.0-or-later
// The MPU6000 as the sketch uses it: bring-up with its messages, the data-ready pacing
// of the 200 Hz loop, the burst read, missed-sample accounting and health.
#pragma once

#include <stdint.h>

#include "Mpu6000.h"
#include "Pipeline.h"
#include "SensorHealth.h"
#include "Text.h"

class Imu {
public:
    static constexpr uint16_t kPeriodUs = 1000000u / mpu6000::kRateHz;  // 5 000

    // constexpr: the static object needs no start-up code.
    constexpr Imu(const mpu6000::SpiDevice& spi, const text::Sink* out) : chip_(spi), out_(out) {}

    // Bring-up (~110 ms); a failure is reported once. True when the chip is configured.
    bool start(uint32_t now_ms);
    // Once a second while the chip is down: says so, tries again; true when it is back
    // (the caller restarts the estimator: the attitude may have changed meanwhile).
    bool retry(uint32_t now_ms);
    bool ok() const { return health_.ok(); }
    // Paced on the timer: data-ready is not seen, the samples may be stale.
    bool pacing_on_timer() const { return timer_pacing_; }

    // True when a new sample is waiting: the INT pin (latched until the burst read);
    // when the pin is silent, the MPU6000's FIFO (polled from 4 ms after the previous
    // sample: no sample is lost to a late poll or to the race of reading INT_STATUS);
    // when neither delivers, the timer (said once).
    bool sample_ready(uint32_t now_us);
    // The burst read of the sample sample_ready() saw at now_us. Counts the samples
    // missed since the previous one (a gap over 1.5 periods), with a rate-limited
    // warning. False (reported once, then retried by retry()) when nobody answered.
    bool read(mpu6000::Sample& out, uint32_t now_us, uint32_t now_ms);
    uint32_t missed_samples() const { return missed_; }
    // Time since the last sample was read (0 before the first).
    uint32_t us_since_sample(uint32_t now_us) const { return have_sample_time_ ? now_us - last_sample_us_ : 0u; }
    // No sample time yet (the first sample, or the first after pacing changed): one may come any moment.
    bool awaiting_sample() const { return !have_sample_time_; }

private:
    mpu6000::Mpu6000 chip_;
    const text::Sink* out_;
    SensorHealth health_;
    uint32_t last_sample_us_ = 0;
    uint32_t missed_ = 0;
    pipeline::RateLimiter warn_missed_{};
    bool have_sample_time_ = false;  // false: the next gap is not counted as missed
    bool int_pin_ok_ = true;         // the INT pin paces the loop (else the FIFO)
    bool from_fifo_ = false;         // the waiting sample is in the FIFO, not the registers
    bool timer_pacing_ = false;
    bool pacing_warned_ = false;
};
