// SPDX-License-Identifier: GPL-3.0-or-later
// StartGravity (lib/Pipeline/StartGravity.h): the estimator's start-up gravity when the
// board never kept still, and the pipeline starting from it.
#include <gtest/gtest.h>

#include <cmath>

#include "Pipeline.h"
#include "StartGravity.h"
#include "pipeline_test_support.h"

using linalg::Vector3f;

namespace {

using pipeline_test::imu;
using pipeline_test::kLevel;

constexpr float kDt_s = 1.0f / pipeline::kRateHz;
constexpr float kPi = 3.14159265f;

float angle_deg(const Vector3f& a, const Vector3f& b) {
    const float c = a.dot(b) / (sqrtf(a.length_squared() * b.length_squared()));
    return acosf(c > 1.0f ? 1.0f : c) / linalg::kRadPerDeg;
}

// Gravity (earth down, 1 g) seen from a body rolled by roll_rad about its x axis.
Vector3f gravity_rolled(float roll_rad) {
    return Vector3f(0.0f, -9.80665f * sinf(roll_rad), -9.80665f * cosf(roll_rad));
}

// One sample of these values, as the MPU6000 gives it, into g.
void add(pipeline::StartGravity& g, const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    const mpu6000::Sample s = imu(gyro_rad_s, accel_m_s2);
    g.add(s.gyro, s.accel, s.gyro_rad_s_per_count, s.accel_m_s2_per_count, Vector3f(), kDt_s);
}

TEST(StartGravity, NothingYetIsZero) {
    pipeline::StartGravity g;
    EXPECT_EQ(g.count(), 0u);
    EXPECT_TRUE(g.mean_m_s2() == Vector3f());
}

// Rolling at 90 deg/s through the start-up window: the mean is gravity where the board is
// now, not the smear of everywhere it was (the plain mean of the samples is 58 deg off).
TEST(StartGravity, FollowsTheBoardAsItTurns) {
    pipeline::StartGravity g;
    Vector3f plain_sum;
    const float rate_rad_s = 90.0f * linalg::kRadPerDeg;
    float roll_rad = 0.0f;
    for (uint16_t i = 0; i < pipeline::kStartupDeadlineSteps; ++i) {
        roll_rad = rate_rad_s * kDt_s * i;
        add(g, Vector3f(rate_rad_s, 0.0f, 0.0f), gravity_rolled(roll_rad));
        plain_sum += gravity_rolled(roll_rad);
    }
    EXPECT_EQ(g.count(), pipeline::kStartupDeadlineSteps);  // a whole number of folds
    EXPECT_LT(angle_deg(g.mean_m_s2(), gravity_rolled(roll_rad)), 0.5f);
    // Its strength to 2 %: each fold's first-order turn grows the sum by (1 + theta^2 / 2);
    // TRIAD takes the direction alone.
    EXPECT_NEAR(sqrtf(g.mean_m_s2().length_squared()), 9.80665f, 0.2f);
    EXPECT_GT(angle_deg(plain_sum, gravity_rolled(roll_rad)), 45.0f);
}

// A still, level board shaken sideways (a gust's 3 m/s^2 at 1.5 Hz): one sample can be
// 17 deg off; the mean over the window is within a degree.
TEST(StartGravity, AveragesAGustOut) {
    pipeline::StartGravity g;
    for (uint16_t i = 0; i < pipeline::kStartupDeadlineSteps; ++i)
        add(g, Vector3f(), kLevel + Vector3f(0.0f, 3.0f * sinf(2.0f * kPi * 1.5f * kDt_s * i), 0.0f));
    EXPECT_LT(angle_deg(g.mean_m_s2(), kLevel), 1.0f);
}

TEST(StartGravity, RestartForgets) {
    pipeline::StartGravity g;
    for (int i = 0; i < 10; ++i) add(g, Vector3f(), Vector3f(9.8f, 0.0f, 0.0f));
    g.restart();
    for (int i = 0; i < pipeline::StartGravity::kFoldSamples; ++i) add(g, Vector3f(), kLevel);
    EXPECT_EQ(g.count(), (unsigned)pipeline::StartGravity::kFoldSamples);
    EXPECT_LT(angle_deg(g.mean_m_s2(), kLevel), 0.01f);
}

// The known bias comes off the turn: a board still but for a 5 deg/s bias keeps its
// gravity where it is (with the bias taken for a turn it would move 6.5 deg in 1.3 s).
TEST(StartGravity, TheKnownBiasIsNoTurn) {
    pipeline::StartGravity g;
    const Vector3f bias_rad_s(5.0f * linalg::kRadPerDeg, 0.0f, 0.0f);
    const mpu6000::Sample s = imu(bias_rad_s, kLevel + Vector3f(0.0f, 0.0f, 0.0f));
    const Vector3f bias_in_counts = linalg::scaled(s.gyro, s.gyro_rad_s_per_count);
    for (uint16_t i = 0; i < pipeline::kStartupDeadlineSteps; ++i)
        g.add(s.gyro, s.accel, s.gyro_rad_s_per_count, s.accel_m_s2_per_count, bias_in_counts, kDt_s);
    EXPECT_LT(angle_deg(g.mean_m_s2(), kLevel), 0.05f);
}

// The pipeline on a board that never keeps still (level, shaken sideways as in a gust):
// the estimator starts at the deadline from the window's mean, level within a degree;
// from the deadline's one sample it started 6 deg rolled.
TEST(StartGravity, PipelineStartsFromTheMeanWhenNeverStill) {
    pipeline::AttitudePipeline p;
    float first_roll_deg = NAN;
    for (int i = 0; i < 400 && std::isnan(first_roll_deg); ++i) {
        const float side_m_s2 = 3.0f * sinf(2.0f * kPi * 1.5f * kDt_s * i);
        p.on_imu_sample(imu(Vector3f(), kLevel + Vector3f(0.0f, side_m_s2, 0.0f)));
        if (p.output_due()) first_roll_deg = p.angles().roll_deg;
    }
    ASSERT_FALSE(std::isnan(first_roll_deg));
    EXPECT_LT(fabsf(first_roll_deg), 1.0f);
    EXPECT_FALSE(p.estimator().gyro_bias_measured());  // the bias still to find: ki_rp
}

// ... and through the start-up that follows, the gust goes on: the estimator started from
// a mean (Dcm::init's gravity_is_mean) follows it at the steady gain, not the start-up's
// (which rolled it 5.3 deg).
TEST(StartGravity, TheStartUpAfterTheMeanDoesNotFollowTheGust) {
    pipeline::AttitudePipeline p;
    float worst_roll_deg = 0.0f;
    int lines = 0;
    for (int i = 0; i < 1200; ++i) {
        const float side_m_s2 = 3.0f * sinf(2.0f * kPi * 1.5f * kDt_s * i);
        p.on_imu_sample(imu(Vector3f(), kLevel + Vector3f(0.0f, side_m_s2, 0.0f)));
        if (!p.output_due()) continue;
        ++lines;
        worst_roll_deg = fmaxf(worst_roll_deg, fabsf(p.angles().roll_deg));
    }
    ASSERT_GT(lines, 20);
    EXPECT_LT(worst_roll_deg, 2.5f);
}

// A still start is a mean too (the calibration's second): a board picked up and shaken
// right after it (a hand launch) is followed at the steady gain, not the start-up's.
TEST(StartGravity, AStillStartFollowsAShakeAfterItAtTheSteadyGain) {
    pipeline::AttitudePipeline p;
    int i = 0;
    for (; i < 400 && p.phase() != pipeline::Phase::Running; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    ASSERT_EQ(p.phase(), pipeline::Phase::Running);
    float worst_roll_deg = 0.0f;
    for (int j = 0; j < 400; ++j) {  // 2 s of the start-up
        const float side_m_s2 = 3.0f * sinf(2.0f * kPi * 1.5f * kDt_s * j);
        p.on_imu_sample(imu(Vector3f(), kLevel + Vector3f(0.0f, side_m_s2, 0.0f)));
        if (p.output_due()) worst_roll_deg = fmaxf(worst_roll_deg, fabsf(p.angles().roll_deg));
    }
    EXPECT_LT(worst_roll_deg, 2.5f);  // the start-up's gain: 5.4
}

// A restart after an outage starts from the one sample it has: that one may be a shock's
// (20 deg off), and the start-up's fast gain takes most of it back within the second.
TEST(StartGravity, ARestartFromOneSamplePullsItInFast) {
    pipeline::AttitudePipeline p;
    for (int i = 0; i < 400 && p.phase() != pipeline::Phase::Running; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    ASSERT_EQ(p.phase(), pipeline::Phase::Running);
    for (int i = 0; i < 200; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    p.restart_estimator();
    p.on_imu_sample(imu(Vector3f(), gravity_rolled(20.0f * linalg::kRadPerDeg)));
    float roll_deg = NAN;
    for (int i = 0; i < 200; ++i) {  // 1 s
        p.on_imu_sample(imu(Vector3f(), kLevel));
        if (p.output_due()) roll_deg = p.angles().roll_deg;
    }
    ASSERT_FALSE(std::isnan(roll_deg));
    EXPECT_LT(fabsf(roll_deg), 4.0f);  // 2.1 (the steady gain alone: 9.7)
}

// A still start measures the bias: the estimator's gravity integrator starts slow
// (ki_rp_measured_1_s2, DcmSettings.h).
TEST(StartGravity, AStillStartMeasuresTheBias) {
    pipeline::AttitudePipeline p;
    for (int i = 0; i < 400 && p.phase() != pipeline::Phase::Running; ++i) p.on_imu_sample(imu(Vector3f(), kLevel));
    ASSERT_EQ(p.phase(), pipeline::Phase::Running);
    EXPECT_TRUE(p.estimator().gyro_bias_measured());
}

}  // namespace
