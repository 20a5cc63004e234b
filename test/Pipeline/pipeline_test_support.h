// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the pipeline tests: the sample the MPU6000 gives for given values, and a
// pipeline whose events are worded into a string (PipelineText), as the sketch's go to
// the serial line.
#pragma once

#include <string>

#include "Mpu6000.h"
#include "Pipeline.h"
#include "PipelineText.h"

namespace pipeline_test {

const linalg::Vector3f kLevel(0.0f, 0.0f, -9.80665f);

inline void append_to_string(void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }

// The sample the MPU6000 gives for these values (counts of the driver's ranges).
inline mpu6000::Sample imu(const linalg::Vector3f& gyro, const linalg::Vector3f& accel) {
    return mpu6000::sample_from_si(gyro, accel, 25.0f, mpu6000::kGyroRange, mpu6000::kAccelRange);
}

// A pipeline and the text of its events. Its parts point at each other: not copied.
struct LoggedPipeline {
    std::string log;
    const text::Sink sink{&log, append_to_string};
    const pipeline::EventSink events = pipeline_text::events_to(&sink);
    pipeline::AttitudePipeline p{&events};
    LoggedPipeline() = default;
    LoggedPipeline(const LoggedPipeline&) = delete;
    LoggedPipeline& operator=(const LoggedPipeline&) = delete;
};

}  // namespace pipeline_test
