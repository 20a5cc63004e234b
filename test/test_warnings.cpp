// SPDX-License-Identifier: GPL-3.0-or-later
// Rate-limited warnings are deferred, never dropped (lib/Pipeline RateLimiter): what a
// limit holds back is told, with its count, once the quiet time is over.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "Pipeline.h"
#include "PipelineText.h"

namespace {

using linalg::Vector3f;

void sink_write(void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }

mpu6000::Sample imu(const Vector3f& gyro, const Vector3f& accel) { return mpu6000::sample_from_si(gyro, accel, 25.0f); }
const Vector3f kLevel(0.0f, 0.0f, -9.80665f);

int count_of(const std::string& text, const std::string& what) {
    int n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(RateLimiter, HeldEventsAreCountedAndToldOnceTheIntervalIsOver) {
    pipeline::RateLimiter r{};
    EXPECT_TRUE(r.allow(100, 10));
    EXPECT_EQ(r.deferred(105, 10), 0);  // nothing held
    EXPECT_FALSE(r.allow(101, 10));
    EXPECT_FALSE(r.allow(108, 10));
    EXPECT_EQ(r.deferred(109, 10), 0);  // the interval is not over
    EXPECT_EQ(r.deferred(110, 10), 2);
    EXPECT_EQ(r.deferred(200, 10), 0);  // told once
    // The deferred line started a new interval: an event right after it is held too.
    EXPECT_FALSE(r.allow(112, 10));
    EXPECT_EQ(r.deferred(119, 10), 0);
    EXPECT_EQ(r.deferred(120, 10), 1);
    // After a quiet interval, the next event is said at once.
    EXPECT_TRUE(r.allow(131, 10));
    // While some are held, the next one after the interval joins them: one line for all.
    EXPECT_FALSE(r.allow(135, 10));
    EXPECT_FALSE(r.allow(141, 10));
    EXPECT_EQ(r.deferred(141, 10), 2);
}

TEST(RateLimiter, HeldCountSaturates) {
    pipeline::RateLimiter r{};
    EXPECT_TRUE(r.allow(0, 10));
    for (uint32_t i = 0; i < 70000; ++i) r.allow(1, 10);
    EXPECT_EQ(r.deferred(11, 10), 0xFFFF);
}

// Two bursts of ten spikes 1 s apart: the first spike at once, the other nineteen in one
// line when the 2 s are over; every spike is in a line.
TEST(RateLimiter, TwoSpikeBurstsOneSecondApartAreBothReported) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    const pipeline::EventSink events = pipeline_text::events_to(&sink);
    pipeline::AttitudePipeline p(&events);
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    ASSERT_EQ(p.phase(), pipeline::Phase::Running);
    log.clear();
    const Vector3f spike_gyro(30.0f, -30.0f, 30.0f);
    for (int burst = 0; burst < 2; ++burst) {
        for (int i = 0; i < 20; ++i)  // a spike every other sample
            p.on_imu_sample(i % 2 == 0 ? imu(spike_gyro, kLevel * 6.0f) : imu(Vector3f(), kLevel));
        for (int i = 0; i < 180; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));  // 1 s a burst
    }
    EXPECT_EQ(p.spikes(), 20u);
    EXPECT_EQ(count_of(log, "# warn: MPU6000 spike"), 1) << log;  // within the 2 s: held
    for (int i = 0; i < 2 * 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_EQ(count_of(log, "# warn: MPU6000 spike"), 2) << log;
    EXPECT_NE(log.find("# warn: MPU6000 spike: previous sample used instead (1 so far)"), std::string::npos) << log;
    EXPECT_NE(log.find("# warn: MPU6000 spike: 19 more samples replaced (20 so far)"), std::string::npos) << log;
    // Nothing more to tell: quiet from then on.
    for (int i = 0; i < 5 * 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_EQ(count_of(log, "# warn: MPU6000 spike"), 2) << log;
}

TEST(RateLimiter, HeldSaturationWarningsAreTold) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    const pipeline::EventSink events = pipeline_text::events_to(&sink);
    pipeline::AttitudePipeline p(&events);
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    log.clear();
    // Accel clipped on one axis for five samples (a shake: the rise over a few samples is
    // no spike), twice 1 s apart.
    const float rise_g[] = {3.0f, 5.0f, 7.0f, 9.0f, 9.0f, 9.0f, 9.0f, 9.0f, 7.0f, 5.0f, 3.0f};
    for (int burst = 0; burst < 2; ++burst) {
        for (const float g : rise_g) p.on_imu_sample(imu(Vector3f(), kLevel * g));
        for (int i = 0; i < 189; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    }
    for (int i = 0; i < 2 * 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_EQ(count_of(log, "# warn: MPU6000 accel saturated"), 2) << log;
    EXPECT_NE(log.find("# warn: MPU6000 accel saturated: 9 more samples"), std::string::npos) << log;
    EXPECT_EQ(p.spikes(), 0u);
}

// The start-up calibration's "board moved" (once a second at most): the restarts in
// between are counted on the next line.
TEST(RateLimiter, BoardMovedCountsTheRestartsBetweenLines) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    const pipeline::EventSink events = pipeline_text::events_to(&sink);
    pipeline::AttitudePipeline p(&events);
    for (int i = 0; i < 230; ++i) {
        const float wobble = (i % 2 == 0) ? 1.0f : -1.0f;  // restarts again and again
        p.on_imu_sample(imu(Vector3f(0.0f, 0.0f, wobble), kLevel));
    }
    EXPECT_EQ(count_of(log, "# calibrating gyro: board moved, retrying"), 1) << log;
    EXPECT_EQ(count_of(log, "# calibrating gyro: board moved"), 2) << log;  // 230 steps: two lines
    const size_t more = log.find(" more times, retrying");
    ASSERT_NE(more, std::string::npos) << log;
    EXPECT_GT(std::atoi(log.c_str() + log.rfind("board moved ", more) + 12), 1) << log;
}

}  // namespace
