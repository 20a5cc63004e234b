// SPDX-License-Identifier: GPL-3.0-or-later
// The HMC5883L as the sketch uses it: bring-up (with the self-test at power-up),
// reads paced by its DRDY pin, the faults the user is told about (silent or stuck
// DRDY, overflow, a compass that stops answering) and health. Its samples go to the
// pipeline; while it is down the pipeline runs yaw on the gyro alone.
#pragma once

#include <stdint.h>

#include "Hmc5883.h"
#include "Pipeline.h"
#include "SensorHealth.h"
#include "Text.h"

class Compass {
public:
    // constexpr: the static object needs no start-up code.
    constexpr Compass(const hmc5883::I2cBus& bus, const text::Sink* out, pipeline::AttitudePipeline& pipe)
        : chip_(bus), out_(out), pipe_(pipe) {}

    // Bring-up; with self_test the datasheet's positive-bias test sets the per-axis
    // scale (power-up only). A failure is reported once. True when it is delivering.
    bool start(bool self_test, uint32_t now_ms);
    // Once a second while it is down (first freeing a bus held low); reports the return.
    void retry(uint32_t now_ms);
    // Every estimator step: reads a new sample when DRDY says so, spaced by at least
    // pipeline::kMagReadMinSteps, and watches for the faults above.
    void service(uint32_t now_ms);
    bool ok() const { return health_.ok(); }

private:
    void failed(text::Flash why, uint32_t now_ms);  // reported once
    void say_gyro_only();

    hmc5883::Hmc5883 chip_;
    const text::Sink* out_;
    pipeline::AttitudePipeline& pipe_;
    SensorHealth health_;
    uint32_t last_read_ms_ = 0, last_ok_ms_ = 0;
    uint32_t last_read_step_ = 0;
    uint8_t failures_ = 0;          // bus failures in a row
    uint8_t drdy_high_reads_ = 0;   // reads after which DRDY stayed high (3: stuck, said)
    bool drdy_warned_ = false;
    bool overflow_warned_ = false;
};
