// SPDX-License-Identifier: GPL-3.0-or-later
// Euler extraction: aerospace Z-Y-X, finite and exact through pitch +-90 deg.
#include <gtest/gtest.h>

#include <cmath>

#include "dcm_test_support.h"

using namespace dcm_test;
using dcm::dcm_from_euler;
using dcm::euler_from_dcm;

static float max_abs_diff(const Matrix3f& a, const Matrix3f& b) {
    const Matrix3f d = a - b;
    const float v[9] = {d.a.x, d.a.y, d.a.z, d.b.x, d.b.y, d.b.z, d.c.x, d.c.y, d.c.z};
    float worst = 0.0f;
    for (float x : v) worst = std::fabs(x) > worst ? std::fabs(x) : worst;
    return worst;
}

static void expect_round_trip(const Matrix3f& r, float tol = 1e-4f) {
    const dcm::EulerAngles e = euler_from_dcm(r);
    ASSERT_TRUE(linalg::is_finite(e.roll_rad) && linalg::is_finite(e.pitch_rad) && linalg::is_finite(e.yaw_rad));
    EXPECT_LT(max_abs_diff(dcm_from_euler(e.roll_rad, e.pitch_rad, e.yaw_rad), r), tol);
}

TEST(Euler, KnownAnglesComeBack) {
    const float d = linalg::kRadPerDeg;
    const dcm::EulerAngles e = euler_from_dcm(dcm_from_euler(10 * d, -20 * d, 135 * d));
    EXPECT_NEAR(e.roll_rad / d, 10.0f, 1e-3f);
    EXPECT_NEAR(e.pitch_rad / d, -20.0f, 1e-3f);
    EXPECT_NEAR(e.yaw_rad / d, 135.0f, 1e-3f);
    // Nose up 30 deg: R31 = -sin(pitch) < 0.
    EXPECT_LT(dcm_from_euler(0, 30 * d, 0).c.x, 0.0f);
    // Right wing down 30 deg: gravity seen on +y in body (down has +y component).
    EXPECT_GT(dcm_from_euler(30 * d, 0, 0).c.y, 0.0f);
}

TEST(Euler, RoundTripForRandomRotations) {
    std::mt19937 rng(1);
    for (int i = 0; i < 10000; ++i) expect_round_trip(random_rotation(rng));
}

TEST(Euler, RoundTripAtAndNearPitch90) {
    const float half_pi = linalg::kPi / 2;
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> angle(-linalg::kPi, linalg::kPi);
    const float offsets[] = {0.0f, 1e-6f, -1e-6f, 1e-5f, 3e-5f, 1e-4f, 1e-3f};
    for (float sign : {1.0f, -1.0f}) {
        for (float off : offsets) {
            for (int i = 0; i < 200; ++i) {
                const Matrix3f r = dcm_from_euler(angle(rng), sign * (half_pi - off), angle(rng));
                expect_round_trip(r);
                EXPECT_NEAR(euler_from_dcm(r).pitch_rad, sign * (half_pi - off), 2e-5f);
            }
        }
    }
}

TEST(Euler, GimbalLockConventionIsRollZero) {
    const float d = linalg::kRadPerDeg;
    // At exactly +90 deg pitch, roll 30 and yaw 50 look like roll 0, yaw 50 - 30.
    const dcm::EulerAngles e = euler_from_dcm(dcm_from_euler(30 * d, 90 * d, 50 * d));
    EXPECT_EQ(e.roll_rad, 0.0f);
    EXPECT_NEAR(e.yaw_rad / d, 20.0f, 0.01f);
    EXPECT_NEAR(e.pitch_rad / d, 90.0f, 0.01f);
}

TEST(Euler, NonFiniteMatrixGivesFiniteAngles) {
    const Matrix3f bad(Vector3f(NAN, 0, 0), Vector3f(0, INFINITY, 0), Vector3f(0, 0, NAN));
    const dcm::EulerAngles e = euler_from_dcm(bad);
    EXPECT_TRUE(linalg::is_finite(e.roll_rad) && linalg::is_finite(e.pitch_rad) && linalg::is_finite(e.yaw_rad));
}

TEST(Heading, WrapsIntoZeroTo360WithDeclination) {
    const float d = linalg::kRadPerDeg;
    EXPECT_NEAR(dcm::heading_deg(-90 * d, 0.0f), 270.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(175 * d, 10.0f), 185.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(-5 * d, 10.0f), 5.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(5 * d, -10.0f), 355.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(0.0f, 3.5f), 3.5f, 1e-6f);
    const float h = dcm::heading_deg(-1e-9f, 0.0f);
    EXPECT_TRUE(h >= 0.0f && h < 360.0f);
    EXPECT_EQ(dcm::heading_deg(NAN, 0.0f), 0.0f);
    const float big = dcm::heading_deg(1e30f, 0.0f);
    EXPECT_TRUE(big >= 0.0f && big < 360.0f);
}

// A yaw a hair below 0 makes h = 360 - 1e-9, which a float rounds to 360 exactly: still
// inside [0, 360), as 0.
TEST(EulerHeading, AYawAHairBelowZeroIsNorthNot360) {
    const float h = dcm::heading_deg(-1e-9f, 0.0f);
    EXPECT_GE(h, 0.0f);
    EXPECT_LT(h, 360.0f);
    EXPECT_EQ(h, 0.0f);
}

// Beyond the documented ranges (yaw -pi..pi, declination -180..180) a sum within
// (-720, 720) still folds into 0..360 (Euler.h): a 190 deg declination at a 3 rad yaw
// (h = 361.9) gives 1.9, -190 at -3 rad gives 358.1; further out, 0. Found by make
// mutate (without the `h >= 360` fold no test inside the ranges told), which also found
// Euler.h promising 0 there: the comment now says what the code does.
TEST(EulerHeading, BeyondTheDocumentedRangesFoldsWithin720ElseZero) {
    const float yaw_deg = 3.0f * linalg::kDegPerRad;
    EXPECT_NEAR(dcm::heading_deg(3.0f, 190.0f), yaw_deg + 190.0f - 360.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(-3.0f, -190.0f), 720.0f - yaw_deg - 190.0f, 1e-3f);
    EXPECT_EQ(dcm::heading_deg(0.0f, 800.0f), 0.0f);
    EXPECT_EQ(dcm::heading_deg(0.0f, -800.0f), 0.0f);
    // Just beyond -720: two folds leave it a hair below 0: 0, not -0.5.
    EXPECT_EQ(dcm::heading_deg(0.0f, -720.5f), 0.0f);
}

// A yaw of exactly 180 deg is +pi on both sides of the gimbal lock: away from it from
// R21 = 0, R11 < 0; at it (pitch +90, roll folded into yaw) from R12 = 0, R22 < 0.
TEST(EulerQ24, YawOf180DegIsPlusPiAtTheGimbalLockAsAwayFromIt) {
    const int32_t one = 1073741824, pi_q24 = (int32_t)std::lround(3.14159265358979 * 16777216.0);
    // Level, facing south: R11 = -1, R21 = 0, R31 = 0, R12 = 0, R22 = -1, R32 = 0, R33 = 1.
    const dcm::EulerQ24 level = dcm::euler_q24_from_q30(-one, 0, 0, -one, 0, 0, one);
    EXPECT_NEAR(level.yaw_q24, pi_q24, 2);
    // Nose straight up, facing south: R11 = R21 = 0, R31 = -1, R12 = 0, R22 = -1, R32 = R33 = 0.
    const dcm::EulerQ24 up = dcm::euler_q24_from_q30(0, 0, 0, -one, -one, 0, 0);
    EXPECT_NEAR(up.yaw_q24, pi_q24, 2);
    EXPECT_EQ(up.roll_q24, 0);
}
