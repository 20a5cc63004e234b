// SPDX-License-Identifier: GPL-3.0-or-later
// The AttitudePipeline (lib/Pipeline) as the firmware and the replay tool run it: the
// start-up calibration, the sample checks, the rate-limited warnings (RateLimiter), `cal
// mag`; the events it returns as numbers, and their words (PipelineText).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "Params.h"
#include "Pipeline.h"
#include "PipelineText.h"
#include "pipeline_test_support.h"

using linalg::Vector3f;

namespace {

using pipeline_test::imu;
using pipeline_test::kLevel;
using pipeline_test::LoggedPipeline;

const Vector3f kBias(0.02f, -0.01f, 0.005f);

// North-facing level board: field north and down (dip ~60 deg).
const Vector3f kFieldNorthDown(20.0f, 0.0f, 40.0f);

int count_of(const std::string& text, const std::string& what) {
    int n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

}  // namespace

// ---------------------------------------------------------------------------
// Start-up, checks and commands (moved from test_calibration.cpp).

TEST(Pipeline, StartsAfterOneStillSecondLevelAndNorth) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    p.set_mag_present(true);
    int first_output = -1;
    for (int i = 0; i < 400; ++i) {
        if (i % 3 == 0) p.on_mag_sample(kFieldNorthDown);
        p.on_imu_sample(imu(kBias, kLevel));
        if (p.output_due() && first_output < 0) first_output = i;
    }
    // The step that finished the calibration started the estimator, the next told the
    // bias; the step after those two has a field sample (every third): the first line on
    // the one after it.
    EXPECT_EQ(first_output, calib::kGyroWindow - 1 + 3);
    EXPECT_EQ(p.phase(), pipeline::Phase::Running);
    // The mean of what the sensor gave: kBias in whole counts.
    EXPECT_NEAR(p.settings().cal.gyro_bias_rad_s.x, imu(kBias, kLevel).gyro_rad_s().x, 1e-6f);
    const pipeline::Angles a = p.angles();
    EXPECT_NEAR(a.roll_deg, 0.0f, 0.1f);
    EXPECT_NEAR(a.pitch_deg, 0.0f, 0.1f);
    EXPECT_TRUE(a.heading_deg < 0.5f || a.heading_deg > 359.5f) << a.heading_deg;
    EXPECT_NE(log.find("# gyro bias: "), std::string::npos) << log;
    settings::set_declination_centideg(p.settings(), 250);
    EXPECT_NEAR(p.angles().heading_deg, 2.5f, 0.5f);
    // COMPASS_DEC as a ground station sends it: the heading moves by the float, not by its
    // hundredths of a degree (11.46).
    const float before_deg = p.angles().heading_deg - 2.5f;
    ASSERT_TRUE(params::set(p.settings(), (uint16_t)params::find("COMPASS_DEC"), 0.2f));
    EXPECT_NEAR(p.angles().heading_deg - before_deg, 11.459156f, 2e-4f);
    // The lines' integer heading adds the hundredths.
    EXPECT_EQ(p.angles_centideg().heading_centideg,
              (1146 + dcm::angles_centideg(p.estimator().euler_now_q24(), 0).heading_centideg) % 36000);
}

TEST(Pipeline, RolledAndPitchedBoardFromGravity) {
    // 90 deg roll right: body y points down, the accelerometer reads -g on body y.
    pipeline::AttitudePipeline p;
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), Vector3f(0.0f, -9.80665f, 0.0f)));
    EXPECT_NEAR(p.angles().roll_deg, 90.0f, 0.5f);
    // 30 deg nose up: body x tilts up, specific force along +x is g sin 30.
    pipeline::AttitudePipeline q;
    for (int i = 0; i < 300; ++i) q.on_imu_sample(imu(Vector3f(), Vector3f(4.903f, 0.0f, -8.4926f)));
    EXPECT_NEAR(q.angles().pitch_deg, 30.0f, 0.5f);
}

TEST(Pipeline, MovingBoardStillStartsBeforeTheDeadline) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    int start = -1;
    for (int i = 0; i < 400 && start < 0; ++i) {
        const float wobble = (i % 20 < 10) ? 0.2f : -0.2f;  // +-11 deg/s
        p.on_imu_sample(imu(Vector3f(0.0f, 0.0f, wobble), kLevel));
        EXPECT_FALSE(p.output_due()) << i;
        if (p.phase() == pipeline::Phase::Running) start = i;
    }
    EXPECT_EQ(start, pipeline::kStartupDeadlineSteps - 1);
    EXPECT_NE(log.find("# calibrating gyro: board moved, retrying"), std::string::npos);
    // The warning goes out on the step after the start (that one carries Dcm::init), the
    // first line on the step after the warning's.
    EXPECT_TRUE(p.starting());
    EXPECT_EQ(log.find("# warn: board not still"), std::string::npos);
    p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_NE(log.find("# warn: board not still"), std::string::npos);
    EXPECT_TRUE(p.starting());
    EXPECT_FALSE(p.output_due());
    p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_FALSE(p.starting());
    EXPECT_TRUE(p.output_due());
    EXPECT_TRUE(p.gyro_calibrating());  // measuring on in the background
}

TEST(Pipeline, TheLinesAfterTheStartKeepTheirRate) {
    // The first line waits out the start's two long steps; the next ones come at the
    // rate from it (not two at once to catch up).
    pipeline::AttitudePipeline p;
    std::vector<int> lines;
    for (int i = 0; i < calib::kGyroWindow + 40; ++i) {
        p.on_imu_sample(imu(kBias, kLevel));
        if (p.output_due()) lines.push_back(i);
    }
    ASSERT_GE(lines.size(), 5u);
    EXPECT_EQ(lines[0], calib::kGyroWindow + 1);
    for (size_t k = 1; k < lines.size(); ++k) EXPECT_EQ(lines[k] - lines[k - 1], 4) << k;  // 50 Hz of 200
}

TEST(Pipeline, OutputRateFollowsTheSetting) {
    pipeline::AttitudePipeline p;
    for (int i = 0; i < calib::kGyroWindow; ++i) p.on_imu_sample(imu(kBias, kLevel));
    for (uint8_t rate : {50, 1, 7, 100}) {
        p.settings().rate_hz = rate;
        int lines = 0;
        for (int i = 0; i < 2000; ++i) {  // 10 s
            p.on_imu_sample(imu(kBias, kLevel));
            if (p.output_due()) ++lines;
        }
        EXPECT_NEAR(lines, rate * 10, 1) << int(rate);
    }
}

TEST(Pipeline, SpikeIsReplacedAndWarnedOnce) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(kBias, kLevel));
    log.clear();
    p.on_imu_sample(imu(Vector3f(30.0f, -30.0f, 30.0f), kLevel * 6.0f));
    p.on_imu_sample(imu(Vector3f(30.0f, -30.0f, 30.0f), kLevel * 6.0f));
    for (int i = 0; i < 10; ++i) p.on_imu_sample(imu(kBias, kLevel));
    EXPECT_EQ(p.spikes(), 2u);
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.2f);  // the spike never reached the estimator
    size_t first = log.find("# warn: MPU6000 spike");
    EXPECT_NE(first, std::string::npos) << log;
    EXPECT_EQ(log.find("# warn: MPU6000 spike", first + 1), std::string::npos) << "rate-limited";
}

TEST(Pipeline, StuckAccelIsNotGravityButGyroIsIntegrated) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));  // past the start-up ramp
    log.clear();
    // 1 s of accel stuck at full scale on every axis (a broken sensor, 28 g): it must
    // not tilt the estimate.
    const float fs = 32767.0f * mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);  // full scale
    mpu6000::Sample clipped = imu(kBias, Vector3f(fs, fs, -fs));
    clipped.accel_saturated = true;
    for (int i = 0; i < 200; ++i) p.on_imu_sample(clipped);
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.05f);
    EXPECT_NEAR(p.angles().pitch_deg, 0.0f, 0.05f);
    EXPECT_NE(log.find("# warn: MPU6000 accel saturated"), std::string::npos) << log;
    // The gyro still counts: 0.5 s at 20 deg/s about x with a stuck accel rolls 10 deg.
    mpu6000::Sample turning = clipped;
    turning.gyro = imu(kBias + Vector3f(20.0f * linalg::kRadPerDeg, 0.0f, 0.0f), Vector3f()).gyro;
    for (int i = 0; i < 100; ++i) p.on_imu_sample(turning);
    EXPECT_NEAR(p.angles().roll_deg, 10.0f, 0.3f);
}

TEST(Pipeline, AGyroAtFullScaleOnEveryAxisIsNotIntegrated) {
    // Every axis at the 2000 deg/s full scale (60 rad/s together, beyond any MEMS gyro):
    // a stuck or broken read, which the DCM rejects instead of spinning the attitude.
    pipeline::AttitudePipeline p(nullptr);
    for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));
    const mpu6000::Sample stuck = imu(Vector3f(40.0f, 40.0f, -40.0f), kLevel);
    ASSERT_TRUE(stuck.gyro_saturated);
    for (int i = 0; i < 200; ++i) {
        p.on_imu_sample(stuck);
        // The first kMaxSpikeRun steps the spike guard stands the previous sample in.
        if (i >= pipeline::kMaxSpikeRun) {
            EXPECT_TRUE(p.estimator().status() & dcm::kStatusGyroRejected) << i;
        }
    }
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.1f);
    EXPECT_NEAR(p.angles().pitch_deg, 0.0f, 0.1f);
    // One axis at full scale is a real (if clipped) rotation: integrated (once the spike
    // guard has seen it last longer than a glitch).
    for (int i = 0; i <= pipeline::kMaxSpikeRun; ++i) p.on_imu_sample(imu(Vector3f(40.0f, 0.0f, 0.0f), kLevel));
    EXPECT_FALSE(p.estimator().status() & dcm::kStatusGyroRejected);
}

TEST(Pipeline, BriefOneAxisClippingInAShakeIsStillUsed) {
    // A shake that clips one axis for 40 ms at each swing: the clipped samples are
    // used as they are, so the estimate is the one the same samples give unflagged
    // (withholding the clipped half of each swing would leave the other half: tens of
    // degrees of tilt). The bound: a full-scale square shake's own error, the swing of the
    // first-order low-pass (40 ms of +-fs against its 3 s: +-fs 0.04 / 6) that the
    // estimate follows.
    auto pitch_after_shake = [](bool flagged) {
        pipeline::AttitudePipeline p(nullptr);
        for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));
        const float fs = 32767.0f * mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);  // full scale
        for (int cycle = 0; cycle < 20; ++cycle) {
            for (int i = 0; i < 8; ++i) {  // 40 ms of +x clipped
                mpu6000::Sample s = imu(kBias, Vector3f(fs, 0.0f, -9.80665f));
                s.accel_saturated = flagged;
                p.on_imu_sample(s);
            }
            for (int i = 0; i < 8; ++i) p.on_imu_sample(imu(kBias, Vector3f(-fs + 0.5f, 0.0f, -9.80665f)));
        }
        for (int i = 0; i < 20; ++i) p.on_imu_sample(imu(kBias, kLevel));
        return p.angles().pitch_deg;
    };
    const float clipped = pitch_after_shake(true);
    EXPECT_NEAR(clipped, pitch_after_shake(false), 0.01f);
    const float fs = 32767.0f * mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
    const float swing_deg = std::atan(fs * 0.04f / 6.0f / 9.80665f) / linalg::kRadPerDeg;
    EXPECT_LT(std::fabs(clipped), swing_deg);
}

// A strong vibration whose peaks are one-sided (a fundamental and its second harmonic:
// +20 / -60 m/s^2 at 30 Hz, jumping by several g a sample): every sample is used, so it
// averages out (standing in for the samples that jump beyond 4 g, as a spike rule on the
// accel did, kept its +20 side: 30 deg of tilt).
TEST(Pipeline, StrongOneSidedVibrationAveragesOut) {
    pipeline::AttitudePipeline p(nullptr);
    for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));
    const float w = 2.0f * 3.14159265f * 30.0f;
    for (int i = 0; i < 20 * 200; ++i) {
        const float t = (float)i * 0.005f;
        const float ax = 40.0f * (std::sin(w * t) + 0.5f * std::cos(2.0f * w * t));
        p.on_imu_sample(imu(kBias, Vector3f(ax, 0.0f, -9.80665f)));
    }
    EXPECT_EQ(p.spikes(), 0u);
    EXPECT_LT(std::fabs(p.angles().pitch_deg), 1.0f);
    EXPECT_LT(std::fabs(p.angles().roll_deg), 1.0f);
}

TEST(Pipeline, MagCalibrationCommand) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    p.set_mag_present(true);
    for (int i = 0; i < 250; ++i) p.on_imu_sample(imu(kBias, kLevel));
    p.start_mag_calibration();
    EXPECT_TRUE(p.mag_calibrating());
    // Only turned about z: the check must fail and keep the old calibration (the fit
    // goes a part a step after the 30 s: a few more steps).
    for (int i = 0; i < calib::kMagCalSeconds * 200 + 2 * calib::MagCalibrator::kFitParts; ++i) {
        const float a = (float)i * 0.01f;
        if (i % 3 == 0) p.on_mag_sample(Vector3f(30.0f * cosf(a), 30.0f * sinf(a), 40.0f));
        p.on_imu_sample(imu(kBias, kLevel));
    }
    EXPECT_FALSE(p.mag_calibrating());
    EXPECT_NE(log.find("# error: cal mag failed: not turned every way (coverage "), std::string::npos) << log;
    EXPECT_TRUE(p.settings().cal.mag_scale == Vector3f(1.0f, 1.0f, 1.0f));
    // Defaults keep the gyro bias measured at this start.
    p.restore_defaults();
    // The mean of what the sensor gave: kBias in whole counts.
    EXPECT_NEAR(p.settings().cal.gyro_bias_rad_s.x, imu(kBias, kLevel).gyro_rad_s().x, 1e-6f);
}

// A board turning about down at 1 rad/s with (8, -5, 0) uT of hard iron: the pipeline's
// learner takes pairs; with the IMU in doubt (the firmware pacing on its timer: a frozen
// sensor repeats a stale rate) it takes none, and none across a gyro spike either.
TEST(Pipeline, LearnerTakesNoPairAcrossADoubtfulTurn) {
    const Vector3f field_ef(20.0f, 0.0f, 45.0f), hard_iron(8.0f, -5.0f, 0.0f);
    for (int run = 0; run < 3; ++run) {  // 0: clean, 1: IMU in doubt, 2: a spike every 10 ms
        pipeline::AttitudePipeline p;
        p.set_mag_present(true);
        for (int i = 0; i < 250; ++i) {
            if (i % 3 == 0) p.on_mag_sample(field_ef + hard_iron);
            p.on_imu_sample(imu(kBias, kLevel));
        }
        ASSERT_EQ(p.phase(), pipeline::Phase::Running);
        const float rate_rad_s = 1.0f;
        for (int i = 0; i < 200 * 10; ++i) {
            const float yaw = rate_rad_s * (float)i * 0.005f;  // body field: the earth's turned by -yaw
            const Vector3f body(cosf(yaw) * field_ef.x, -sinf(yaw) * field_ef.x, field_ef.z);
            if (i % 3 == 0) p.on_mag_sample(body + hard_iron);
            if (run == 1) p.imu_doubtful();
            const bool spike = run == 2 && i % 2 == 0;
            p.on_imu_sample(imu(kBias + Vector3f(0.0f, 0.0f, spike ? 20.0f : rate_rad_s), kLevel));
        }
        if (run == 0) {
            EXPECT_GT(p.offset_learner().updates(), 10);
        } else {
            EXPECT_EQ(p.offset_learner().updates(), 0) << "run " << run;
        }
    }
}

// ---------------------------------------------------------------------------
// Rate-limited warnings are deferred, never dropped (RateLimiter): what a limit holds
// back is told, with its count, once the quiet time is over (moved from
// test_warnings.cpp).

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
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
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
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    log.clear();
    // Accel clipped on one axis for five samples (a shake: the rise over a few samples is
    // no spike), twice 1 s apart: 2 g a sample to 17 g, beyond the 16 g full scale.
    const float rise_g[] = {3.0f,  5.0f,  7.0f,  9.0f,  11.0f, 13.0f, 15.0f, 17.0f, 17.0f, 17.0f,
                            17.0f, 17.0f, 15.0f, 13.0f, 11.0f, 9.0f,  7.0f,  5.0f,  3.0f};
    for (int burst = 0; burst < 2; ++burst) {
        for (const float g : rise_g) p.on_imu_sample(imu(Vector3f(), kLevel * g));
        for (int i = 0; i < 200 - (int)(sizeof rise_g / sizeof rise_g[0]); ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    }
    for (int i = 0; i < 2 * 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    EXPECT_EQ(count_of(log, "# warn: MPU6000 accel saturated"), 2) << log;
    EXPECT_NE(log.find("# warn: MPU6000 accel saturated: 9 more samples"), std::string::npos) << log;
    EXPECT_EQ(p.spikes(), 0u);
}

// The start-up calibration's "board moved" (once a second at most): the restarts in
// between are counted on the next line.
TEST(RateLimiter, BoardMovedCountsTheRestartsBetweenLines) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
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

// ---------------------------------------------------------------------------
// The events as numbers: what the pipeline returns, before any words.

namespace {

using pipeline::EventKind;

struct Recorded {
    std::vector<pipeline::Event> events;
    std::vector<uint32_t> steps;  // the pipeline's step count at each
    std::vector<pipeline::Event> of(EventKind kind) const {
        std::vector<pipeline::Event> r;
        for (const pipeline::Event& e : events)
            if (e.kind == kind) r.push_back(e);
        return r;
    }
};

void record(void* ctx, const pipeline::AttitudePipeline& pipe, const pipeline::Event& e) {
    Recorded& r = *static_cast<Recorded*>(ctx);
    r.events.push_back(e);
    r.steps.push_back(pipe.steps());
}

std::string centi(float v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2f", (double)v);
    return buf;
}

std::string words_of(const pipeline::AttitudePipeline& pipe, const pipeline::Event& e) {
    std::string s;
    const text::Sink sink{&s, pipeline_test::append_to_string};
    pipeline_text::write_event(const_cast<text::Sink*>(&sink), pipe, e);
    return s;
}

}  // namespace

TEST(PipelineEvents, StartTellsCalibrationThenTheBiasOnTheStepAfterTheStart) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline p(&events);
    int start_step = -1;
    for (int i = 0; i < 300; ++i) {
        p.on_imu_sample(imu(kBias, kLevel));
        if (p.phase() == pipeline::Phase::Running && start_step < 0) start_step = (int)p.steps();
    }
    ASSERT_GE(r.events.size(), 2u);
    EXPECT_EQ(r.events[0].kind, EventKind::kGyroCalStart);
    EXPECT_EQ(r.steps[0], 1u);
    EXPECT_EQ(r.events[1].kind, EventKind::kGyroBias);
    EXPECT_EQ(r.steps[1], (uint32_t)start_step + 1);
    EXPECT_EQ(r.events.size(), 2u);  // a still board: nothing else
    EXPECT_NEAR(p.settings().cal.gyro_bias_rad_s.y, imu(kBias, kLevel).gyro_rad_s().y, 1e-6f);
    EXPECT_EQ(words_of(p, r.events[1]), "# gyro bias: 1.16 -0.55 0.30 deg/s\n");  // kBias in whole counts
}

TEST(PipelineEvents, NotStillSaysWhichBiasItStartsWith) {
    for (const bool saved : {false, true}) {
        Recorded r;
        const pipeline::EventSink events{&r, record};
        pipeline::AttitudePipeline p(&events);
        if (saved) p.settings().flags = (uint8_t)(p.settings().flags | settings::kFlagGyroCalibrated);
        for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(0.0f, 0.0f, (i % 20 < 10) ? 0.2f : -0.2f), kLevel));
        const std::vector<pipeline::Event> not_still = r.of(EventKind::kNotStill);
        ASSERT_EQ(not_still.size(), 1u) << saved;
        EXPECT_EQ(not_still[0].code, saved ? 1 : 0);
        EXPECT_EQ(words_of(p, not_still[0]), saved ? "# warn: board not still: starting with the saved gyro bias, measuring on\n"
                                                   : "# warn: board not still: starting with zero gyro bias, measuring on\n");
        // Each "board moved" after the first counts the restarts held back since.
        const std::vector<pipeline::Event> moved = r.of(EventKind::kGyroCalMoved);
        ASSERT_GE(moved.size(), 2u);
        EXPECT_EQ(moved[0].count, 0u);
        EXPECT_GT(moved[1].count, 0u);
    }
}

TEST(PipelineEvents, SpikesCarryTheHeldCountAndTheTotal) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline p(&events);
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    const Vector3f spike_gyro(30.0f, -30.0f, 30.0f);
    for (int i = 0; i < 20; ++i) p.on_imu_sample(i % 2 == 0 ? imu(spike_gyro, kLevel * 6.0f) : imu(Vector3f(), kLevel));
    for (int i = 0; i < 3 * 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    const std::vector<pipeline::Event> spikes = r.of(EventKind::kSpike);
    ASSERT_EQ(spikes.size(), 2u);
    EXPECT_EQ(spikes[0].count, 0u);  // the first, at once
    EXPECT_EQ(spikes[0].total, 1u);
    EXPECT_EQ(spikes[1].count, 9u);  // the rest, once the 2 s are over
    EXPECT_EQ(spikes[1].total, 10u);
    EXPECT_EQ(p.spikes(), 10u);
}

TEST(PipelineEvents, AFieldThatIsNotTheEarthsCarriesItsStrength) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline p(&events);
    p.set_mag_present(true);
    for (int i = 0; i < 300; ++i) {
        if (i % 3 == 0) p.on_mag_sample(kFieldNorthDown);
        p.on_imu_sample(imu(kBias, kLevel));
    }
    for (int i = 0; i < 3 * 200; ++i) {
        if (i % 3 == 0) p.on_mag_sample(i < 30 ? Vector3f(300.0f, 0.0f, 0.0f) : kFieldNorthDown);
        p.on_imu_sample(imu(kBias, kLevel));
    }
    const std::vector<pipeline::Event> fields = r.of(EventKind::kMagNotEarth);
    ASSERT_EQ(fields.size(), 2u);
    EXPECT_EQ(fields[0].count, 0u);
    EXPECT_NEAR(fields[0].value, 300.0f, 1e-3f);
    EXPECT_EQ(fields[1].count, 9u);  // the other nine of the first 30 steps' ten
    EXPECT_EQ(words_of(p, fields[0]), "# warn: HMC5883L field 300.00 uT is not the Earth's (10..200): sample dropped\n");
    EXPECT_EQ(words_of(p, fields[1]), "# warn: HMC5883L field not the Earth's: 9 more samples dropped\n");
}

TEST(PipelineEvents, CalMagProgressAndVerdictAreNumbers) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline p(&events);
    p.set_mag_present(true);
    for (int i = 0; i < 250; ++i) p.on_imu_sample(imu(kBias, kLevel));
    p.start_mag_calibration();
    for (int i = 0; i < calib::kMagCalSeconds * 200 + 2 * calib::MagCalibrator::kFitParts; ++i) {
        const float a = (float)i * 0.01f;  // only turned about z
        if (i % 3 == 0) p.on_mag_sample(Vector3f(30.0f * cosf(a), 30.0f * sinf(a), 40.0f));
        p.on_imu_sample(imu(kBias, kLevel));
    }
    ASSERT_EQ(r.of(EventKind::kMagCalStart).size(), 1u);
    const std::vector<pipeline::Event> progress = r.of(EventKind::kMagCalProgress);
    ASSERT_EQ(progress.size(), 5u);
    for (size_t i = 0; i < progress.size(); ++i) {
        EXPECT_EQ(progress[i].count, 25u - 5u * i);  // seconds left
        if (i > 0) {
            EXPECT_GT(progress[i].total, progress[i - 1].total);  // samples so far
        }
    }
    const std::vector<pipeline::Event> done = r.of(EventKind::kMagCalDone);
    ASSERT_EQ(done.size(), 1u);
    EXPECT_EQ(done[0].code, (uint8_t)calib::MagCalibrator::Quality::ThinCoverage);
    EXPECT_EQ(done[0].count, p.mag_calibrator().coverage_pct());
    EXPECT_LT(done[0].count, calib::kMagMinCoveragePct);
    EXPECT_EQ(done[0].total, p.mag_calibrator().count());
    EXPECT_EQ(words_of(p, done[0]), "# error: cal mag failed: not turned every way (coverage " +
                                        std::to_string(done[0].count) + "%, need " +
                                        std::to_string(calib::kMagMinCoveragePct) + "%); calibration unchanged\n");
}

TEST(PipelineEvents, CalMagWithoutACompassIsRefused) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline p(&events);
    for (int i = 0; i < 250; ++i) p.on_imu_sample(imu(kBias, kLevel));
    r.events.clear();
    p.start_mag_calibration();
    EXPECT_FALSE(p.mag_calibrating());
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0].kind, EventKind::kMagCalNoCompass);
    EXPECT_EQ(words_of(p, r.events[0]), "# error: cal mag: HMC5883L absent\n");
}

TEST(PipelineEvents, NoSinkIsSilentAndTheSameEstimate) {
    Recorded r;
    const pipeline::EventSink events{&r, record};
    pipeline::AttitudePipeline told(&events), silent(nullptr);
    for (int i = 0; i < 400; ++i) {
        const mpu6000::Sample s = imu(i % 50 == 0 ? Vector3f(30.0f, 0.0f, 0.0f) : kBias, kLevel);
        told.on_imu_sample(s);
        silent.on_imu_sample(s);
    }
    EXPECT_FALSE(r.events.empty());
    const pipeline::AnglesCentideg a = told.angles_centideg(), b = silent.angles_centideg();
    EXPECT_EQ(a.roll_centideg, b.roll_centideg);
    EXPECT_EQ(a.pitch_centideg, b.pitch_centideg);
    EXPECT_EQ(a.heading_centideg, b.heading_centideg);
}

// ---------------------------------------------------------------------------
// The words (PipelineText): one "# " line an event; the `status` lines.

TEST(PipelineText, EachEventIsOneLine) {
    const pipeline::AttitudePipeline p;
    for (uint8_t k = 0; k <= (uint8_t)EventKind::kMagCalDone; ++k) {
        for (const uint16_t count : {0, 3}) {
            const std::string s = words_of(p, pipeline::Event{(EventKind)k, 0, count, 7, 42.0f});
            ASSERT_GE(s.size(), 3u) << int(k);
            EXPECT_EQ(s.compare(0, 2, "# "), 0) << s;
            EXPECT_EQ(s.find('\n'), s.size() - 1) << s;
        }
    }
    // The counted forms: the first at once, then "N more".
    const struct {
        pipeline::Event event;
        std::string line;
    } kLines[] = {
        {{EventKind::kSpike, 0, 3, 7, 0.0f}, "# warn: MPU6000 spike: 3 more samples replaced (7 so far)\n"},
        {{EventKind::kSpike, 0, 0, 1, 0.0f}, "# warn: MPU6000 spike: previous sample used instead (1 so far)\n"},
        {{EventKind::kGyroSaturated, 0, 0, 0, 0.0f}, "# warn: MPU6000 gyro saturated (beyond 2000 deg/s)\n"},
        {{EventKind::kAccelSaturated, 0, 4, 0, 0.0f}, "# warn: MPU6000 accel saturated: 4 more samples\n"},
        {{EventKind::kGyroCalMoved, 0, 0, 0, 0.0f}, "# calibrating gyro: board moved, retrying\n"},
        {{EventKind::kGyroCalMoved, 0, 12, 0, 0.0f}, "# calibrating gyro: board moved 12 more times, retrying\n"},
        {{EventKind::kMagCalProgress, 0, 15, 929, 0.0f}, "# cal mag: 15 s left, keep turning (929 samples)\n"},
        {{EventKind::kMagCalDone, (uint8_t)calib::MagCalibrator::Quality::PoorFit, 90, 2000, 3.5f},
         "# error: cal mag failed: residual 3.50 uT, over " + centi(calib::kMagMaxResidual_uT) +
             " (field changed while turning?); calibration unchanged\n"},
    };
    for (const auto& l : kLines) EXPECT_EQ(words_of(p, l.event), l.line);
}

TEST(PipelineText, StatusLinesWordTheBiasAndTheCompass) {
    pipeline::AttitudePipeline p;
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(kBias, kLevel));
    std::string s;
    const text::Sink sink{&s, pipeline_test::append_to_string};
    pipeline_text::write_bias_status(&sink, p);
    EXPECT_EQ(s, "# gyro bias 1.16 -0.55 0.30 deg/s, temperature 25.00 C\n");  // kBias in whole counts
    s.clear();
    pipeline_text::write_compass_status(&sink, p);
    EXPECT_EQ(s, "# compass: cal none, learned offset 0.00 0.00 0.00 uT (0 updates)\n");
    p.settings().flags = (uint8_t)(p.settings().flags | settings::kFlagMagCalibrated);
    p.settings().cal.mag_learned_uT = Vector3f(1.5f, -2.25f, 0.0f);
    s.clear();
    pipeline_text::write_compass_status(&sink, p);
    EXPECT_EQ(s, "# compass: cal yes, learned offset 1.50 -2.25 0.00 uT (0 updates)\n");
}

// A start that is never still (a restart in the air), then a steady turn: 20 deg of bank at
// 18 m/s, 11 deg/s about the body's y and z and the accelerometer along z at 1.06 g, what
// the still test accepts. The turn is not taken as the bias: the one in use stays, and the
// board says so. A still second near the bias in use after such a start is taken.
TEST(PipelineEvents, ACalibrationAfterAMovingStartIsNotATurn) {
    const float bank = 20.0f * linalg::kPi / 180.0f;
    const float yaw_rate = 9.80665f * std::tan(bank) / 18.0f;
    const Vector3f turn(0.0f, yaw_rate * std::sin(bank), yaw_rate * std::cos(bank));
    const Vector3f turn_accel(0.0f, 0.0f, -9.80665f / std::cos(bank));
    const Vector3f saved(0.01f, -0.02f, 0.015f);
    for (const bool in_turn : {true, false}) {
        Recorded r;
        const pipeline::EventSink events{&r, record};
        pipeline::AttitudePipeline p(&events);
        p.settings().flags = (uint8_t)(p.settings().flags | settings::kFlagGyroCalibrated);
        p.settings().cal.gyro_bias_rad_s = saved;
        for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(saved + Vector3f(0.0f, 0.0f, (i % 20 < 10) ? 0.2f : -0.2f), kLevel));
        ASSERT_EQ(r.of(EventKind::kNotStill).size(), 1u);
        ASSERT_TRUE(p.gyro_calibrating()) << "measuring on";
        const Vector3f still = saved + Vector3f(0.01f, 0.0f, -0.01f);  // 0.8 deg/s off: a bias that moved
        for (int i = 0; i < 400; ++i) p.on_imu_sample(in_turn ? imu(saved + turn, turn_accel) : imu(still, kLevel));
        EXPECT_FALSE(p.gyro_calibrating());
        const std::vector<pipeline::Event> refused = r.of(EventKind::kGyroBiasRefused);
        if (in_turn) {
            ASSERT_EQ(refused.size(), 1u);
            EXPECT_NEAR(refused[0].value, turn.length() * linalg::kDegPerRad, 0.2f);
            EXPECT_NEAR((p.settings().cal.gyro_bias_rad_s - saved).length(), 0.0f, 1e-6f) << "the saved bias kept";
            EXPECT_EQ(words_of(p, refused[0]).rfind("# warn: gyro calibration in motion (a steady turn?): 11.", 0), 0u)
                << words_of(p, refused[0]);
            EXPECT_NE(words_of(p, refused[0]).find("not taken; keeping the saved gyro bias"), std::string::npos);
        } else {
            EXPECT_TRUE(refused.empty());
            EXPECT_NEAR((p.settings().cal.gyro_bias_rad_s - still).length(), 0.0f, 2e-3f) << "taken";
        }
    }
}
