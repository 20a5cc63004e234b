// SPDX-License-Identifier: GPL-3.0-or-later
// What the estimator's step needs that follows from the settings and the sensor's
// scales, worked out once where they change (VQF's coefficients struct): the step
// then does no float division and no trigonometry.
//
// Units of the integer state (the table the other Dcm files refer to):
//   units            the turn sums': gyro counts * 2^kTurnFraction (2^8) per step
//   fine units       the bias estimate: units * 2^8
//   accel units      accel counts * 2^8 (the sums, the low-pass, the rest means)
//   Q30              R's entries and factors in [-2, 2): value * 2^30
//   Q26              a turn in radians * 2^26 (|theta| <= 0.75 rad an axis)
//   Q14 / Q15 / Q12  16-bit factors: value * 2^14, 2^15, 2^12
//   field Q5         a field sample, uT * 2^5 (steps of 0.03 uT, up to 1 000 uT)
#pragma once

#include <stdint.h>

#include "DcmSettings.h"
#include "Fixed.h"

namespace dcm {

// The roll/pitch correction is worked out every this many steps (50 Hz at the
// default 200 Hz step) and applied at every step: it moves at the 3 s pace of
// the accel low-pass, and the work saved is a quarter of the step.
constexpr uint8_t kCorrectionDivider = 4;
// The matrix is turned every this many steps (50 Hz at the 200 Hz step) by the
// rates summed meanwhile (Strapdown). Even: the coning term needs two halves.
constexpr uint8_t kIntegrationSteps = 4;
// Renormalisation every this many integrations (6 Hz): each integration is a
// rotation to 4e-7 (Strapdown), so eight leave R orthonormal to ~3e-6, below
// what a 0.01 deg output shows (1.7e-4).
constexpr uint8_t kRenormaliseEvery = 8;
// The turn of one integration saturates at 0.75 rad an axis (Q26): beyond any gyro
// (2000 deg/s over 20 ms is 0.7 rad), and |theta|^2 < 2 stays within Q30.
constexpr int32_t kMaxTurnAxisQ26 = 50331648L;
// The heading is corrected from the mean of the field samples over at least this
// many steps (12.5 Hz; the HMC5883L's 75 Hz samples in sixes): the correction is
// slow (1/kp_yaw = 10 s; 0.2 s at start-up, 0.4 of the error an update), and the
// mean keeps every sample's information. (A mean at 25 Hz runs the float part twice
// as often for no better heading: the commit that chose 16 steps.)
constexpr uint8_t kHeadingSteps = 16;
// The means the rest test compares the samples against (VQF's 0.5 s).
constexpr float kRestMeanTau_s = 0.5f;
// The accel low-pass's time constant at start (startup_s ramps it to accel_lowpass_s).
constexpr float kStartupAccelTau_s = 0.25f;
// The turn sums hold gyro counts * kTurnScale (2^kTurnFraction): the offset the step
// subtracts is resolved to 1/256 of a count (0.0002 deg/s on the 2000 deg/s range).
constexpr uint8_t kTurnFraction = 8;
constexpr int32_t kTurnScale = 1L << kTurnFraction;
// The float form's units: 2^-14 rad/s (50 rad/s * 2^8 * 4 steps fits in 32 bits)
// and 2^-12 m/s^2.
constexpr float kFloatGyroScale = 1.0f / 16384.0f;
constexpr float kFloatAccelScale = 1.0f / 4096.0f;
constexpr float kFloatUnitsPerRad_s = (float)kTurnScale / kFloatGyroScale;

// A field sample in 16 bits, uT * 2^kFieldQ: steps of 0.03 uT, a third of the
// HMC5883L's finest count and far below its noise (~0.2 uT), up to 1 000 uT (the chip
// reads at most 810). The latency turn and the rotation into earth axes are then 16x16
// products; a matrix entry in 16 bits (Q14) moves the earth-frame field by 6e-5 of its
// strength at most, 0.004 deg of heading.
constexpr uint8_t kFieldQ = 5;
constexpr float kMaxField_uT = 1000.0f;

// A value as Q30 (truncated toward zero), for constants written as their value:
// q30_of(1.0 / 6.0).
constexpr int32_t q30_of(float x) { return (int32_t)(x * 1073741824.0f); }

// A rate or specific-force limit for a squared comparison in 16x16 products: the
// vector shifted right by `shift`, its squared length against limit2.
struct Limit {
    uint32_t limit2;
    uint8_t shift;
};
// A limit L as a shift s and (L / 2^s)^2 with L / 2^s below 2^14: a vector that stays
// within 16 bits after the shift up to twice the limit, and the limit resolved to 2^-13.
Limit limit_of(float value);
// |v| >= the limit, from 16x16 products: an axis beyond 16 bits after the shift is.
bool exceeds(const linalg::Vector3l& v, const Limit& limit);

struct DcmCoefficients {
    // From the settings alone (from_settings).
    float step_s = 0.0f;                 // the fixed step, s
    uint16_t startup_steps = 0;              // startup_s in steps
    float inv_startup_steps = 0;             // 1 / startup_steps
    int32_t accel_alpha_q30 = 0;             // the accel low-pass factor per correction, Q30
    int32_t tilt_turn_q30 = 0;               // kp_rp * the correction interval, Q30
    uint16_t mag_recover_steps = 0;          // mag_recover_s in steps
    uint16_t rest_min_corrections = 0;       // rest_min_s in corrections
    int16_t rest_alpha_q14 = 0;              // the rest means' low-pass factor per correction, Q14 (0.04: 2e-4 rounding)
    int32_t rest_bias_alpha_q30 = 0;         // the bias's step towards the rest mean per correction, Q30
    float startup_accel_alpha = 0;           // the accel low-pass factor at the start of the ramp, per correction
    float mag_new_min_turn_rad = 0;          // how far the board must turn while a new field stays steady, rad
    // From the settings and the sensor's scales (set_scales; the float form's scales
    // until then).
    float gyro_rad_s_per_count = kFloatGyroScale;
    float accel_m_s2_per_count = kFloatAccelScale;
    float accel_units_per_m_s2 = (float)kTurnScale / kFloatAccelScale;  // the accel sums' units
    float units_per_rad_s = kFloatUnitsPerRad_s;                        // the turn sums' units
    Limit hold_rate = {};                     // integrator_hold_rate_rad_s, units
    Limit rest_gyro_dev = {};                 // rest_gyro_deviation_rad_s, units
    Limit rest_accel_dev = {};                // rest_accel_deviation_m_s2, accel units
    int32_t bias_limit_fine = 0;             // bias_limit_rad_s, fine units
    int32_t ki_fine = 0;                     // ki_rp * the correction interval, fine units per rad/s
    int32_t kp_units = 0;                // kp_rp, units per rad/s
    uint32_t min_lp2 = 0;                // (g/2)^2 as correct_tilt's |lp|^2 / 2^30 (lp in accel units)
    uint16_t lead_steps_q15 = 0;         // output_lead_s / step_s, Q15
    uint16_t theta_q26_per_unit_q15 = 0; // Q26 radians per unit, Q15; 0: the float path
    int32_t theta_factor_q30 = 0;        // Q26 radians per unit, Q30; 0: the float path
    int32_t theta_units_limit = 0;       // the units that make kMaxTurnAxisQ26
    int16_t mag_latency_steps_q12 = 0;   // mag_latency_s in steps (below 6), Q12
    int32_t ki_measured_fine = 0;        // ki_rp_measured * the correction interval, fine units per rad/s

    // From the settings alone (the estimator's constructor): an ordinary function, so
    // that the float work is one copy in flash and runs once.
    void from_settings(const DcmSettings& settings);
    // The factors that follow from the scales (rad/s and m/s^2 per count).
    void set_scales(const DcmSettings& settings, float gyro_rad_s_per_count, float accel_m_s2_per_count);
    // ... from the scales in use (set_scales, or the float form's).
    void derive_from_scales(const DcmSettings& settings);
    // Radians per unit of the turn sums.
    float turn_rad_per_unit() const { return gyro_rad_s_per_count * step_s * (1.0f / (float)kTurnScale); }

    // A turn in units (the turn sums) in Q26 radians, each axis saturated at
    // kMaxTurnAxisQ26: beyond any gyro's range over an integration (2000 deg/s for 20 ms
    // is 0.7 rad), and |theta|^2 stays below 2 in Q30. One mul_q30 an axis.
    linalg::Vector3l theta_q26(const linalg::Vector3l& units) const;
    // ... in Q30 (the integration's).
    linalg::Vector3l theta_q30(const linalg::Vector3l& units) const;
    // The same by the 16-bit factor (scale_q15: two 16x16 products an axis, the factor
    // to 1.5e-5 of itself), for a turn used in 16 bits: the compass sample's latency turn
    // and the gravity window's turn per step. Unsaturated: both are a few steps' rates.
    linalg::Vector3l theta_q26_coarse(const linalg::Vector3l& units) const;
    // The float path's theta_q26 (scales whose factor is beyond Q30's 2: the float form).
    linalg::Vector3l theta_q26_in_float(const linalg::Vector3l& units) const;
    int32_t theta_axis_q26(int32_t units) const;
};

// x * c / 2^15 for |x| < 2^31, c < 2^16 (a Q15 factor), rounded toward zero: two 16x16
// multiplies.
FIXED_INLINE int32_t scale_q15(int32_t x, uint16_t c_q15) {
    const uint32_t m = linalg::magnitude(x);
    const uint32_t product = (linalg::mul_u16((uint16_t)(m >> 16), c_q15) << 1) + (linalg::mul_u16((uint16_t)m, c_q15) >> 15);
    return x < 0 ? -(int32_t)product : (int32_t)product;
}

FIXED_INLINE int32_t DcmCoefficients::theta_axis_q26(int32_t units) const {
    if (units > theta_units_limit) units = theta_units_limit;
    if (units < -theta_units_limit) units = -theta_units_limit;
    return linalg::hot::mul_q30(theta_factor_q30, units);
}

FIXED_COLD inline linalg::Vector3l DcmCoefficients::theta_q26(const linalg::Vector3l& units) const {
    if (theta_factor_q30 == 0) return theta_q26_in_float(units);  // scales beyond the integer factor
    return linalg::Vector3l(theta_axis_q26(units.x), theta_axis_q26(units.y), theta_axis_q26(units.z));
}

FIXED_INLINE linalg::Vector3l DcmCoefficients::theta_q30(const linalg::Vector3l& units) const {
    const linalg::Vector3l t_q26 = theta_q26(units);
    return linalg::Vector3l(t_q26.x * 16, t_q26.y * 16, t_q26.z * 16);
}

FIXED_INLINE linalg::Vector3l DcmCoefficients::theta_q26_coarse(const linalg::Vector3l& units) const {
    const uint16_t factor_q15 = theta_q26_per_unit_q15;
    if (factor_q15 == 0) return theta_q26(units);  // scales beyond the 16-bit factor
    return linalg::Vector3l(scale_q15(units.x, factor_q15), scale_q15(units.y, factor_q15), scale_q15(units.z, factor_q15));
}

// v * ratio, rounded toward zero (state carried over to new sensor scales).
linalg::Vector3l rescaled(const linalg::Vector3l& v, float ratio);

// Seconds between two gravity corrections.
inline float correction_dt_s(const DcmSettings& settings) { return settings.step_s * (float)kCorrectionDivider; }

}  // namespace dcm
