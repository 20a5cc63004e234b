// SPDX-License-Identifier: GPL-3.0-or-later
// The six-position accelerometer fit (lib/Calibration/AccelFit.h): injected offsets and
// scales recovered from six still positions held a few degrees off, the positions
// recognised, a fit without every axis both ways refused.
#include <gtest/gtest.h>

#include <math.h>

#include "AccelFit.h"
#include "BoardFrame.h"

namespace {

using calib::AccelFit;
using calib::AccelPosition;
using linalg::Vector3f;

constexpr float kG = 9.80665f;

// The specific force of a still airframe at roll, pitch (deg): -R^T (0, 0, g).
Vector3f force(float roll_deg, float pitch_deg) {
    const float r = roll_deg * linalg::kRadPerDeg, p = pitch_deg * linalg::kRadPerDeg;
    return Vector3f(kG * sinf(p), -kG * cosf(p) * sinf(r), -kG * cosf(p) * cosf(r));
}

// What the sensor reads: scale .* f + offset (the scenario tool's error model).
Vector3f sensed(const Vector3f& f, const Vector3f& offset, const Vector3f& scale) {
    return Vector3f(scale.x * f.x + offset.x, scale.y * f.y + offset.y, scale.z * f.z + offset.z);
}

// The six positions, each a few degrees off as a hand leaves them.
void six_means(const Vector3f& offset, const Vector3f& scale, Vector3f out[6]) {
    const float rp[6][2] = {{3, -2}, {-88, 4}, {93, -3}, {2, -87}, {-4, 92}, {177, 3}};
    for (int k = 0; k < 6; ++k) out[k] = sensed(force(rp[k][0], rp[k][1]), offset, scale);
}

AccelFit::Quality run(AccelFit& fit) {
    AccelFit::Quality q = AccelFit::Quality::Fitting;
    for (int i = 0; i < 20 && q == AccelFit::Quality::Fitting; ++i) q = fit.step();
    return q;
}

TEST(AccelFit, RecoversInjectedOffsetsAndScales) {
    const Vector3f offset(0.3f, -0.25f, 0.4f), scale(1.02f, 0.98f, 1.015f);
    Vector3f means[6];
    six_means(offset, scale, means);
    AccelFit fit;
    fit.begin(means, kG);
    ASSERT_EQ(run(fit), AccelFit::Quality::Ok);
    EXPECT_NEAR(fit.offset_m_s2().x, 0.3f, 1e-3f);
    EXPECT_NEAR(fit.offset_m_s2().y, -0.25f, 1e-3f);
    EXPECT_NEAR(fit.offset_m_s2().z, 0.4f, 1e-3f);
    // INS_ACCSCAL undoes the sensor's scale: 1 / scale.
    EXPECT_NEAR(fit.scale().x, 1.0f / 1.02f, 1e-4f);
    EXPECT_NEAR(fit.scale().y, 1.0f / 0.98f, 1e-4f);
    EXPECT_NEAR(fit.scale().z, 1.0f / 1.015f, 1e-4f);
    EXPECT_LT(fit.residual_m_s2(), 1e-3f);
}

TEST(AccelFit, AnExactBoardFitsAsTheIdentity) {
    Vector3f means[6];
    six_means(Vector3f(), Vector3f(1, 1, 1), means);
    AccelFit fit;
    fit.begin(means, kG);
    ASSERT_EQ(run(fit), AccelFit::Quality::Ok);
    EXPECT_NEAR(fit.offset_m_s2().length(), 0.0f, 1e-3f);
    EXPECT_NEAR(fit.scale().x, 1.0f, 1e-4f);
}

TEST(AccelFit, PositionsThatMissAnAxisAreRefused) {
    Vector3f means[6];
    for (int k = 0; k < 6; ++k) means[k] = force(2.0f * k, 1.0f);  // always level
    AccelFit fit;
    fit.begin(means, kG);
    const AccelFit::Quality q = run(fit);
    EXPECT_TRUE(q == AccelFit::Quality::Singular || q == AccelFit::Quality::NoConvergence) << (int)q;
}

TEST(AccelFit, OffsetsBeyondArduPilotsRangeAreRefused) {
    Vector3f means[6];
    six_means(Vector3f(4.0f, 0.0f, 0.0f), Vector3f(1, 1, 1), means);
    AccelFit fit;
    fit.begin(means, kG);
    EXPECT_EQ(run(fit), AccelFit::Quality::OutOfRange);
}

TEST(AccelFit, PositionsAreRecognised) {
    EXPECT_TRUE(calib::in_position(AccelPosition::kLevel, force(5, -5)));
    EXPECT_TRUE(calib::in_position(AccelPosition::kLeft, force(-90, 0)));
    EXPECT_TRUE(calib::in_position(AccelPosition::kRight, force(90, 0)));
    EXPECT_TRUE(calib::in_position(AccelPosition::kNoseDown, force(0, -90)));
    EXPECT_TRUE(calib::in_position(AccelPosition::kNoseUp, force(0, 90)));
    EXPECT_TRUE(calib::in_position(AccelPosition::kBack, force(180, 0)));
    EXPECT_FALSE(calib::in_position(AccelPosition::kLeft, force(90, 0)));      // the other side
    EXPECT_FALSE(calib::in_position(AccelPosition::kLevel, force(40, 0)));     // beyond 30 deg
    EXPECT_FALSE(calib::in_position(AccelPosition::kLevel, Vector3f(0, 0, -5.0f)));  // not 1 g: moving
    EXPECT_FALSE(calib::in_position(AccelPosition::kLevel, Vector3f(NAN, 0, -kG)));
}

}  // namespace
