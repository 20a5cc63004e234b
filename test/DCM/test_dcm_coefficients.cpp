// SPDX-License-Identifier: GPL-3.0-or-later
// DcmCoefficients (lib/DCM/Coefficients.h): what follows from the settings and the
// MPU6000's scales, to the bit where the step relies on it.
#include <gtest/gtest.h>

#include <cmath>

#include "Coefficients.h"
#include "DcmSettings.h"
#include "Mpu6000.h"

namespace {

dcm::DcmCoefficients board_coefficients(const dcm::DcmSettings& s) {
    dcm::DcmCoefficients k;
    k.from_settings(s);
    k.set_scales(s, mpu6000::gyro_rad_s_per_count(mpu6000::kGyroRange),
                 mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange));
    return k;
}

uint16_t q15_of(float x) { return (uint16_t)(x * 32768.0f + 0.5f); }

// The output's lead and the turn's 16-bit factor: each rounded to Q15 while below 2 (a
// lead of 1.5 steps still takes the integer path).
TEST(DcmCoefficients, LeadAndTurnFactorsInQ15BelowTwo) {
    dcm::DcmSettings s = dcm::kDefaultDcmSettings;
    s.output_lead_s = 1.5f * s.step_s;
    const dcm::DcmCoefficients k = board_coefficients(s);
    const float q26_per_unit = k.turn_rad_per_unit() * 67108864.0f;
    ASSERT_GT(q26_per_unit, 0.0f);
    ASSERT_LT(q26_per_unit, 1.99f);
    EXPECT_EQ(k.lead_steps_q15, q15_of(1.5f));
    EXPECT_EQ(k.theta_q26_per_unit_q15, q15_of(q26_per_unit));
    // Two steps or more: the float path (both factors 0).
    s.output_lead_s = 2.5f * s.step_s;
    const dcm::DcmCoefficients beyond = board_coefficients(s);
    EXPECT_EQ(beyond.lead_steps_q15, 0u);
    EXPECT_EQ(beyond.theta_q26_per_unit_q15, 0u);
}

// The limits the sums are compared with, in the board's units: the hold rate, the rest
// test's deviations (a float-form default would be 16 times too fine for the gyro).
TEST(DcmCoefficients, TheLimitsAreInTheBoardsUnits) {
    const dcm::DcmSettings& s = dcm::kDefaultDcmSettings;
    const dcm::DcmCoefficients k = board_coefficients(s);
    const dcm::Limit hold = dcm::limit_of(s.integrator_hold_rate_rad_s * k.units_per_rad_s);
    EXPECT_EQ(k.hold_rate.limit2, hold.limit2);
    EXPECT_EQ(k.hold_rate.shift, hold.shift);
    const dcm::Limit gyro = dcm::limit_of(s.rest_gyro_deviation_rad_s * k.units_per_rad_s);
    EXPECT_EQ(k.rest_gyro_dev.limit2, gyro.limit2);
    EXPECT_EQ(k.rest_gyro_dev.shift, gyro.shift);
    dcm::DcmCoefficients float_form;
    float_form.from_settings(s);
    EXPECT_FALSE(float_form.hold_rate.limit2 == hold.limit2 && float_form.hold_rate.shift == hold.shift);
}

// The float form (from_settings alone: the host's float scales until set_scales) compares
// its sums with the same limits set_scales would give at those scales: the hold rate and
// the rest test's gyro and accelerometer deviations.
TEST(DcmCoefficients, TheFloatFormsLimitsAreSetScalesAtTheFloatScales) {
    const dcm::DcmSettings& s = dcm::kDefaultDcmSettings;
    dcm::DcmCoefficients float_form;
    float_form.from_settings(s);
    dcm::DcmCoefficients scaled;
    scaled.from_settings(s);
    scaled.set_scales(s, dcm::kFloatGyroScale, dcm::kFloatAccelScale);
    ASSERT_EQ(scaled.units_per_rad_s, float_form.units_per_rad_s);
    ASSERT_EQ(scaled.accel_units_per_m_s2, float_form.accel_units_per_m_s2);
    EXPECT_EQ(float_form.hold_rate.limit2, scaled.hold_rate.limit2);
    EXPECT_EQ(float_form.hold_rate.shift, scaled.hold_rate.shift);
    EXPECT_EQ(float_form.rest_gyro_dev.limit2, scaled.rest_gyro_dev.limit2);
    EXPECT_EQ(float_form.rest_gyro_dev.shift, scaled.rest_gyro_dev.shift);
    EXPECT_EQ(float_form.rest_accel_dev.limit2, scaled.rest_accel_dev.limit2);
    EXPECT_EQ(float_form.rest_accel_dev.shift, scaled.rest_accel_dev.shift);
}

// The compass latency in steps, Q12, held within 0..5.9 steps (the wait for the next
// step and the 16-bit turn's range).
TEST(DcmCoefficients, MagLatencyHeldWithinItsSteps) {
    dcm::DcmSettings s = dcm::kDefaultDcmSettings;
    s.mag_latency_s = 10.0f * s.step_s;
    EXPECT_EQ(board_coefficients(s).mag_latency_steps_q12, (int16_t)(5.9f * 4096.0f + 0.5f));
    s.mag_latency_s = -s.step_s;
    EXPECT_EQ(board_coefficients(s).mag_latency_steps_q12, 0);
    s.mag_latency_s = 2.0f * s.step_s;
    EXPECT_EQ(board_coefficients(s).mag_latency_steps_q12, (int16_t)(2.0f * 4096.0f + 0.5f));
}

// The coarse turn is the 16-bit factor's product, to the bit (not the Q30 path's, whose
// rounding differs).
TEST(DcmCoefficients, TheCoarseTurnIsTheQ15FactorsProduct) {
    const dcm::DcmCoefficients k = board_coefficients(dcm::kDefaultDcmSettings);
    ASSERT_NE(k.theta_q26_per_unit_q15, 0u);
    int differs_from_q30_path = 0;
    for (int32_t units = -300000; units <= 300000; units += 997) {
        const linalg::Vector3l u(units, -units / 3, units / 7);
        const linalg::Vector3l coarse = k.theta_q26_coarse(u);
        EXPECT_EQ(coarse.x, dcm::scale_q15(u.x, k.theta_q26_per_unit_q15)) << units;
        EXPECT_EQ(coarse.y, dcm::scale_q15(u.y, k.theta_q26_per_unit_q15)) << units;
        EXPECT_EQ(coarse.z, dcm::scale_q15(u.z, k.theta_q26_per_unit_q15)) << units;
        if (coarse.x != k.theta_q26(u).x) ++differs_from_q30_path;
    }
    EXPECT_GT(differs_from_q30_path, 0);  // the test can tell the two paths apart
}

}  // namespace

// The rest means' low-pass factor per correction, dt / (tau + dt), rounded to Q14.
TEST(DcmCoefficients, RestMeansLowPassFactorRoundedToQ14) {
    const dcm::DcmSettings& s = dcm::kDefaultDcmSettings;
    const dcm::DcmCoefficients k = board_coefficients(s);
    const float dt = dcm::correction_dt_s(s);
    const float alpha = dt / (dcm::kRestMeanTau_s + dt);
    EXPECT_EQ(k.rest_alpha_q14, (int16_t)std::lround(16384.0f * alpha));
}
