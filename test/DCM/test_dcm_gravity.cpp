// SPDX-License-Identifier: GPL-3.0-or-later
// The gravity correction alone (Gravity.h), closed through the strapdown part: a tilt
// the matrix does not know is corrected (sign and pace), a level board gets no
// correction, the integrator learns only when not held.
#include <gtest/gtest.h>

#include <cmath>

#include "Gravity.h"
#include "Strapdown.h"
#include "dcm_test_support.h"

using namespace dcm_test;
using linalg::Vector3l;

namespace {

struct Loop {
    dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GravityCorrection gravity;
    dcm::Strapdown strapdown;
    dcm::GyroBias bias;
    explicit Loop(const Matrix3f& estimate) {
        strapdown.reset(linalg::q30_from_matrix(estimate));
        gravity.reset(linalg::fixed_from_float(-kG * k.accel_units_per_m_s2, 0));
    }
    // `seconds` of a board at rest at `truth` (gyro reads 0): the correction turns R.
    void run(const Matrix3f& truth, float seconds, bool hold_integrator) {
        const Vector3l accel_counts = linalg::fixed_from_vector(accel_for(truth) * (1.0f / dcm::kFloatAccelScale), 0);
        const int windows = (int)std::lround(seconds / (k.step_s * dcm::kCorrectionDivider));
        for (int w = 0; w < windows; ++w) {
            for (int i = 0; i < dcm::kCorrectionDivider; ++i) {
                gravity.add(Vector3l(), accel_counts);
                const Vector3l offset = bias.offset_units(gravity.correction_units());
                strapdown.add_turn(Vector3l(-offset.x, -offset.y, -offset.z));
                strapdown.end_step();
                if (strapdown.pending_steps() == dcm::kIntegrationSteps) strapdown.integrate(k);
            }
            const Vector3l offset = bias.offset_units(gravity.correction_units());
            const dcm::GravityContext c = {dcm::kDefaultDcmSettings, k, strapdown.r(), strapdown.pending_steps(),
                                           offset, bias.sensor_units(), false, 0.0f, 0.0f};
            dcm::WindowMeans means;
            ASSERT_TRUE(gravity.low_pass_window(c, means));
            EXPECT_TRUE(means.whole);
            gravity.correct_tilt(c, hold_integrator, bias);
        }
    }
    Matrix3f estimate() const { return linalg::matrix_from_q30(strapdown.r()); }
};

}  // namespace

TEST(DcmGravity, ALevelBoardGetsNoCorrection) {
    Loop loop(Matrix3f::identity());
    loop.run(Matrix3f::identity(), 2.0f, false);
    EXPECT_EQ(loop.gravity.correction_units().x, 0);
    EXPECT_EQ(loop.gravity.correction_units().y, 0);
    EXPECT_LT(tilt_error_deg(Matrix3f::identity(), loop.estimate()), 1e-3f);
}

// A 10 deg tilt the matrix does not know: the low-pass (3 s) takes its time, the
// correction (kp 1/s) turns R towards it; after 15 s it is within 0.05
// deg, and the heading is not touched.
TEST(DcmGravity, AnUnknownTiltIsCorrected) {
    float first_after_1s = -1.0f;
    for (const Matrix3f& truth : {dcm::dcm_from_euler(10.0f * linalg::kRadPerDeg, 0.0f, 0.0f),
                                  dcm::dcm_from_euler(0.0f, -10.0f * linalg::kRadPerDeg, 0.0f)}) {
        Loop loop(Matrix3f::identity());
        loop.run(truth, 1.0f, true);
        const float after_1s = tilt_error_deg(truth, loop.estimate());
        EXPECT_LT(after_1s, 9.9f);
        EXPECT_GT(after_1s, 1.0f);
        // Roll (a tilt about north) and pitch (about east) at the same pace.
        if (first_after_1s < 0.0f) first_after_1s = after_1s;
        EXPECT_NEAR(after_1s, first_after_1s, 0.02f * first_after_1s);
        loop.run(truth, 14.0f, true);
        EXPECT_LT(tilt_error_deg(truth, loop.estimate()), 0.05f);  // float acos resolves ~0.02 deg
        const dcm::EulerAngles e = dcm::euler_from_dcm(loop.estimate());
        EXPECT_NEAR(e.yaw_rad, 0.0f, 1e-3f);
    }
}

TEST(DcmGravity, TheIntegratorLearnsOnlyWhenNotHeld) {
    const Matrix3f truth = dcm::dcm_from_euler(5.0f * linalg::kRadPerDeg, 0.0f, 0.0f);
    Loop held(Matrix3f::identity());
    held.run(truth, 2.0f, true);
    EXPECT_EQ(held.bias.units().x, 0);
    Loop learning(Matrix3f::identity());
    learning.run(truth, 2.0f, false);
    EXPECT_NE(learning.bias.units().x, 0);
}

// The integrator learns on the axis of the tilt error: a roll error (about body x, the
// board facing north) moves the x bias, a pitch error the y bias, each far more than the
// other axis.
TEST(DcmGravity, TheIntegratorLearnsOnTheErrorsAxis) {
    Loop roll(Matrix3f::identity());
    roll.run(dcm::dcm_from_euler(5.0f * linalg::kRadPerDeg, 0.0f, 0.0f), 2.0f, false);
    EXPECT_GT(std::abs(roll.bias.units().x), 10 * std::abs(roll.bias.units().y) + 10);
    Loop pitch(Matrix3f::identity());
    pitch.run(dcm::dcm_from_euler(0.0f, 5.0f * linalg::kRadPerDeg, 0.0f), 2.0f, false);
    EXPECT_GT(std::abs(pitch.bias.units().y), 10 * std::abs(pitch.bias.units().x) + 10);
}

TEST(DcmGravity, AnEmptyWindowIsNoWindow) {
    Loop loop(Matrix3f::identity());
    const Vector3l zero = Vector3l();
    const dcm::GravityContext c = {dcm::kDefaultDcmSettings, loop.k, loop.strapdown.r(), 0, zero, zero, false, 0.0f,
                                   0.0f};
    dcm::WindowMeans means;
    EXPECT_FALSE(loop.gravity.low_pass_window(c, means));
}

// A reset puts the low-pass exactly at gravity (earth down) with no correction.
TEST(DcmGravity, AResetStartsAtGravityWithNoCorrection) {
    dcm::GravityCorrection gravity;
    gravity.reset(-123456);
    EXPECT_EQ(gravity.low_pass_ef().x, 0);
    EXPECT_EQ(gravity.low_pass_ef().y, 0);
    EXPECT_EQ(gravity.low_pass_ef().z, -123456);
    EXPECT_EQ(gravity.correction_units().x, 0);
    EXPECT_EQ(gravity.correction_units().y, 0);
    EXPECT_EQ(gravity.correction_units().z, 0);
}

// New sample scales (a new calibration): the low-pass, in accel units, follows the
// accelerometer's ratio either way, and stays as it is when only the gyro's changes.
TEST(DcmGravity, TheLowPassFollowsANewAccelScale) {
    dcm::GravityCorrection gravity;
    gravity.reset(-400000);
    gravity.rescale(1.0f, 0.5f);
    EXPECT_EQ(gravity.low_pass_ef().z, -200000);
    gravity.rescale(1.0f, 2.0f);
    EXPECT_EQ(gravity.low_pass_ef().z, -400000);
    gravity.rescale(2.0f, 1.0f);
    EXPECT_EQ(gravity.low_pass_ef().z, -400000);
}

// The window's means for every length a window can have (1 to 5 samples: a correction
// late by a step takes five): the sums over n, whatever n, to a unit (counts * 2^8).
TEST(DcmGravity, TheWindowsMeansAreTheSumsOverTheirLength) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    const Vector3l gyro_counts(10, -20, 30), accel_counts(100, -200, -4096);
    for (uint8_t n = 1; n <= 5; ++n) {
        dcm::GravityCorrection gravity;
        gravity.reset(-4096 * 256);
        for (uint8_t i = 0; i < n; ++i) gravity.add(gyro_counts, accel_counts);
        const linalg::Matrix3q30 level = linalg::q30_from_matrix(Matrix3f::identity());
        const Vector3l zero = Vector3l();
        dcm::WindowMeans means;
        const dcm::GravityContext c = {dcm::kDefaultDcmSettings, k, level, 0, zero, zero, false, 0.0f, 0.0f};
        ASSERT_TRUE(gravity.low_pass_window(c, means));
        const Vector3l &gyro_mean = means.gyro, &accel_mean = means.accel;
        const bool whole = means.whole;
        EXPECT_NEAR(gyro_mean.x, 10 * 256, 1) << (int)n;
        EXPECT_NEAR(gyro_mean.y, -20 * 256, 1) << (int)n;
        EXPECT_NEAR(gyro_mean.z, 30 * 256, 1) << (int)n;
        EXPECT_NEAR(accel_mean.x, 100 * 256, 1) << (int)n;
        EXPECT_NEAR(accel_mean.z, -4096 * 256, 1) << (int)n;
        EXPECT_EQ(whole, n >= dcm::kCorrectionDivider) << (int)n;
    }
}

// A new gyro scale rescales the correction held between corrections (units per step)
// either way, as the accelerometer's rescales the low-pass.
TEST(DcmGravity, TheHeldCorrectionFollowsANewGyroScale) {
    for (float ratio : {2.0f, 0.5f}) {
        Loop loop(Matrix3f::identity());
        loop.run(dcm::dcm_from_euler(10.0f * linalg::kRadPerDeg, 0.0f, 0.0f), 0.5f, true);
        const Vector3l before = loop.gravity.correction_units();
        ASSERT_NE(before.x, 0);
        loop.gravity.rescale(ratio, 1.0f);
        EXPECT_NEAR(loop.gravity.correction_units().x, before.x * ratio, 1.0) << ratio;
    }
}
