// SPDX-License-Identifier: GPL-3.0-or-later
// The BROAD error metric (sim/ScoreMetric.h) on hand-computed cases.
#include <gtest/gtest.h>

#include <cmath>

#include "ScoreMetric.h"

namespace {

using score::ErrorAngles;
using score::Quat;
using score::deg2rad;
using score::error_angles;
using score::quat_from_euler_deg;
using score::quat_mul;
using score::rad2deg;

Quat axis_angle(double ax, double ay, double az, double angle_deg) {
    const double n = std::sqrt(ax * ax + ay * ay + az * az);
    const double h = 0.5 * deg2rad(angle_deg);
    return Quat{std::cos(h), std::sin(h) * ax / n, std::sin(h) * ay / n, std::sin(h) * az / n};
}

// v' = q v q^-1
void rotate(const Quat& q, const double v[3], double out[3]) {
    const Quat p{0.0, v[0], v[1], v[2]};
    const Quat r = quat_mul(quat_mul(q, p), score::quat_conj(q));
    out[0] = r.x;
    out[1] = r.y;
    out[2] = r.z;
}

const double kTol = 1e-9;

TEST(ScoreMetric, IdenticalOrientationsHaveNoError) {
    const Quat q = quat_from_euler_deg(20.0, -30.0, 100.0);
    const ErrorAngles e = error_angles(q, q);
    EXPECT_NEAR(rad2deg(e.total_rad), 0.0, 1e-6);
    EXPECT_NEAR(rad2deg(e.inclination_rad), 0.0, 1e-6);
    EXPECT_NEAR(rad2deg(e.heading_rad), 0.0, 1e-6);
}

TEST(ScoreMetric, SignOfTheQuaternionDoesNotMatter) {
    const Quat q = quat_from_euler_deg(20.0, -30.0, 100.0);
    const Quat minus_q{-q.w, -q.x, -q.y, -q.z};
    const ErrorAngles e = error_angles(q, minus_q);
    EXPECT_NEAR(rad2deg(e.total_rad), 0.0, 1e-6);
    EXPECT_NEAR(rad2deg(e.heading_rad), 0.0, 1e-6);
}

TEST(ScoreMetric, YawOffsetIsPureHeadingError) {
    // Same roll and pitch, heading 10 deg off: the error is a rotation about the vertical.
    const Quat q_true = quat_from_euler_deg(20.0, -30.0, 100.0);
    const Quat q_est = quat_from_euler_deg(20.0, -30.0, 110.0);
    const ErrorAngles e = error_angles(q_true, q_est);
    EXPECT_NEAR(rad2deg(e.total_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e.heading_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e.inclination_rad), 0.0, 1e-6);
}

TEST(ScoreMetric, TiltIsPureInclinationError) {
    // Level and north, estimated rolled 10 deg.
    const ErrorAngles e = error_angles(quat_from_euler_deg(0, 0, 0), quat_from_euler_deg(10, 0, 0));
    EXPECT_NEAR(rad2deg(e.total_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e.inclination_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e.heading_rad), 0.0, kTol);
    // Any orientation tilted a further 10 deg about a horizontal earth axis (here north-east).
    const Quat q_true = quat_from_euler_deg(-35.0, 50.0, 230.0);
    const Quat q_est = quat_mul(axis_angle(1, 1, 0, 10.0), q_true);
    const ErrorAngles e2 = error_angles(q_true, q_est);
    EXPECT_NEAR(rad2deg(e2.total_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e2.inclination_rad), 10.0, kTol);
    EXPECT_NEAR(rad2deg(e2.heading_rad), 0.0, 1e-6);
}

TEST(ScoreMetric, CombinedErrorSplitsExactly) {
    // e_earth = Rz(30) Rx(20): heading 30, inclination 20 (w^2 + z^2 = cos^2(10 deg)).
    const Quat q_true = quat_from_euler_deg(5.0, 15.0, -60.0);
    const Quat e_earth = quat_mul(axis_angle(0, 0, 1, 30.0), axis_angle(1, 0, 0, 20.0));
    const ErrorAngles e = error_angles(q_true, quat_mul(e_earth, q_true));
    EXPECT_NEAR(rad2deg(e.heading_rad), 30.0, kTol);
    EXPECT_NEAR(rad2deg(e.inclination_rad), 20.0, kTol);
    // total: cos(total/2) = cos(15) cos(10)
    const double expected_total = 2.0 * std::acos(std::cos(deg2rad(15)) * std::cos(deg2rad(10)));
    EXPECT_NEAR(e.total_rad, expected_total, kTol);
}

TEST(ScoreMetric, ErrorAboutTheBodyAxisOfAnUprightBoardIsHeading) {
    // Pitched up 90 deg, the body x axis points up: an error about body x is a heading error.
    const Quat q_true = quat_from_euler_deg(0.0, 90.0, 0.0);
    const Quat q_est = quat_mul(q_true, axis_angle(1, 0, 0, 10.0));
    const ErrorAngles e = error_angles(q_true, q_est);
    EXPECT_NEAR(rad2deg(e.heading_rad), 10.0, 1e-6);
    EXPECT_NEAR(rad2deg(e.inclination_rad), 0.0, 1e-6);
}

TEST(ScoreMetric, EulerAnglesFollowTheAerospaceConvention) {
    const double fwd[3] = {1, 0, 0}, down[3] = {0, 0, 1};
    double v[3];
    // Yaw 90: the nose points east.
    rotate(quat_from_euler_deg(0, 0, 90), fwd, v);
    EXPECT_NEAR(v[0], 0.0, kTol);
    EXPECT_NEAR(v[1], 1.0, kTol);
    // Pitch 30 nose up: the nose points up (negative down), 30 deg above the horizon.
    rotate(quat_from_euler_deg(0, 30, 0), fwd, v);
    EXPECT_NEAR(v[2], -0.5, kTol);
    // Roll 90 right wing down: body down points west (negative east).
    rotate(quat_from_euler_deg(90, 0, 0), down, v);
    EXPECT_NEAR(v[1], -1.0, kTol);
    // Z-Y-X order: yaw applied last (outermost).
    const Quat q = quat_from_euler_deg(10, 20, 30);
    const Quat expected = quat_mul(axis_angle(0, 0, 1, 30),
                                   quat_mul(axis_angle(0, 1, 0, 20), axis_angle(1, 0, 0, 10)));
    EXPECT_NEAR(q.w, expected.w, kTol);
    EXPECT_NEAR(q.x, expected.x, kTol);
    EXPECT_NEAR(q.y, expected.y, kTol);
    EXPECT_NEAR(q.z, expected.z, kTol);
}

TEST(ScoreMetric, RmseAccumulatesRootMeanSquare) {
    score::RmseAccumulator acc;
    EXPECT_EQ(acc.samples(), 0);
    EXPECT_TRUE(std::isnan(acc.total_rmse_deg()));
    acc.add(ErrorAngles{deg2rad(3.0), deg2rad(0.0), deg2rad(3.0)});
    acc.add(ErrorAngles{deg2rad(4.0), deg2rad(4.0), deg2rad(0.0)});
    EXPECT_EQ(acc.samples(), 2);
    EXPECT_NEAR(acc.total_rmse_deg(), std::sqrt((9.0 + 16.0) / 2.0), kTol);
    EXPECT_NEAR(acc.incl_rmse_deg(), std::sqrt(16.0 / 2.0), kTol);
    EXPECT_NEAR(acc.heading_rmse_deg(), std::sqrt(9.0 / 2.0), kTol);
    EXPECT_NEAR(acc.max_total_deg(), 4.0, kTol);
}

}  // namespace
