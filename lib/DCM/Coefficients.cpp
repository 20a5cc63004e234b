// SPDX-License-Identifier: GPL-3.0-or-later
#include "Coefficients.h"

namespace dcm {

using linalg::fixed_from_float;

bool exceeds(const linalg::Vector3l& v, const Limit& limit) {
    const int32_t* axis[3] = {&v.x, &v.y, &v.z};
    uint32_t sum = 0;  // three squares below 2^30: no overflow
    for (uint8_t i = 0; i < 3; ++i) {
        int32_t a = *axis[i];
        for (uint8_t k = limit.shift; k > 0; --k) a >>= 1;
        if (a > 32767 || a < -32767) return true;
        sum += (uint32_t)linalg::mul_s16((int16_t)a, (int16_t)a);
    }
    return sum >= limit.limit2;
}

linalg::Vector3l rescaled(const linalg::Vector3l& v, float ratio) { return linalg::fixed_from_vector(v.scaled(ratio), 0); }

Limit limit_of(float value) {
    uint8_t shift = 0;
    for (; value >= 16384.0f && shift < 31; ++shift) value *= 0.5f;  // exact: a power of two
    return Limit{value > 0.0f ? (uint32_t)(value * value) : 0u, shift};
}

// A low-pass's factor per correction for the time constant tau_s: dt / (tau + dt).
static float lowpass_alpha(float tau_s, float dt_s) { return dt_s / (tau_s + dt_s); }

// From the settings alone: each figure in the unit the step compares or multiplies.
FIXED_COLD void DcmCoefficients::from_settings(const DcmSettings& settings) {
    step_s = settings.step_s;
    startup_steps = (uint16_t)(settings.startup_s / settings.step_s);
    inv_startup_steps = settings.step_s / settings.startup_s;
    accel_alpha_q30 = q30_of(lowpass_alpha(settings.accel_lowpass_s, correction_dt_s(settings)));
    tilt_turn_q30 = q30_of(settings.kp_rp_1_s * correction_dt_s(settings));
    mag_recover_steps = (uint16_t)(settings.mag_recover_s / settings.step_s);
    rest_min_corrections = (uint16_t)(settings.rest_min_s / correction_dt_s(settings));
    rest_alpha_q14 = (int16_t)(16384.0f * lowpass_alpha(kRestMeanTau_s, correction_dt_s(settings)) + 0.5f);
    rest_bias_alpha_q30 = settings.rest_bias_s > 0.0f ? q30_of(lowpass_alpha(settings.rest_bias_s, correction_dt_s(settings))) : 0;
    startup_accel_alpha = lowpass_alpha(kStartupAccelTau_s, correction_dt_s(settings));
    mag_new_min_turn_rad = settings.mag_recover_s * settings.mag_new_min_rate_rad_s;
    // For the float form's scales until set_scales.
    hold_rate = limit_of(settings.integrator_hold_rate_rad_s * kFloatUnitsPerRad_s);
    rest_gyro_dev = limit_of(settings.rest_gyro_deviation_rad_s * kFloatUnitsPerRad_s);
    rest_accel_dev = limit_of(settings.rest_accel_deviation_m_s2 * ((float)kTurnScale / kFloatAccelScale));
    bias_limit_fine = (int32_t)(settings.bias_limit_rad_s * kFloatUnitsPerRad_s * (float)kTurnScale);
    ki_fine = (int32_t)(settings.ki_rp_1_s2 * correction_dt_s(settings) * kFloatUnitsPerRad_s * (float)kTurnScale);
    ki_measured_fine =
        (int32_t)(settings.ki_rp_measured_1_s2 * correction_dt_s(settings) * kFloatUnitsPerRad_s * (float)kTurnScale);
}

void DcmCoefficients::set_scales(const DcmSettings& settings, float gyro_scale, float accel_scale) {
    gyro_rad_s_per_count = gyro_scale;
    accel_m_s2_per_count = accel_scale;
    units_per_rad_s = (float)kTurnScale / gyro_scale;
    accel_units_per_m_s2 = (float)kTurnScale / accel_scale;
    derive_from_scales(settings);
}

// The output's two factors in Q15 (0: beyond 2, the float path), the lead in steps and
// Q26 radians per unit; the compass latency; the turn's factor; the limits and gains in
// the sums' units.
void DcmCoefficients::derive_from_scales(const DcmSettings& settings) {
    const float lead_steps = settings.output_lead_s / settings.step_s;
    const float q26_per_unit = turn_rad_per_unit() * 67108864.0f;  // 2^26
    const bool fits = lead_steps >= 0.0f && lead_steps < 1.99f && q26_per_unit > 0.0f && q26_per_unit < 1.99f;
    lead_steps_q15 = fits ? (uint16_t)(lead_steps * 32768.0f + 0.5f) : 0;
    theta_q26_per_unit_q15 = fits ? (uint16_t)(q26_per_unit * 32768.0f + 0.5f) : 0;
    // The compass sample's latency in steps, Q12 (with the wait of up to kMaxMagAgeSteps,
    // below 8 steps in 16 bits: 30 ms at most at 200 Hz).
    const float latency_steps = linalg::constrain(settings.mag_latency_s / settings.step_s, 0.0f, 5.9f);
    mag_latency_steps_q12 = (int16_t)(latency_steps * 4096.0f + 0.5f);
    // The turn's factor: Q26 radians per unit in Q30 (mul_q30's factor; a 2000 deg/s
    // gyro's 1.40, the float form's 0.08), below 2 for any gyro of 4000 deg/s or less.
    const bool integer_path = q26_per_unit > 0.0f && q26_per_unit < 1.99f;
    theta_factor_q30 = integer_path ? fixed_from_float(q26_per_unit, linalg::kQ30) : 0;
    const float limit_units = integer_path ? (float)kMaxTurnAxisQ26 / q26_per_unit : 0.0f;
    theta_units_limit = limit_units < 2.0e9f ? (int32_t)limit_units : 2000000000L;
    // The limits in the units of the sums they are compared with.
    hold_rate = limit_of(settings.integrator_hold_rate_rad_s * units_per_rad_s);
    rest_gyro_dev = limit_of(settings.rest_gyro_deviation_rad_s * units_per_rad_s);
    rest_accel_dev = limit_of(settings.rest_accel_deviation_m_s2 * accel_units_per_m_s2);
    bias_limit_fine = fixed_from_float(settings.bias_limit_rad_s * units_per_rad_s * (float)kTurnScale, 0);
    ki_fine = fixed_from_float(settings.ki_rp_1_s2 * correction_dt_s(settings) * units_per_rad_s * (float)kTurnScale, 0);
    ki_measured_fine =
        fixed_from_float(settings.ki_rp_measured_1_s2 * correction_dt_s(settings) * units_per_rad_s * (float)kTurnScale, 0);
    kp_units = fixed_from_float(settings.kp_rp_1_s * units_per_rad_s, 0);
    // |lp| = g/2 in correct_tilt's |lp|^2 / 2^30 (lp in accel units).
    const float half_g_units = 0.5f * kGravity_m_s2 * accel_units_per_m_s2;
    min_lp2 = (uint32_t)(half_g_units * half_g_units * (1.0f / 1073741824.0f));
}

linalg::Vector3l DcmCoefficients::theta_q26_in_float(const linalg::Vector3l& units) const {
    const linalg::Vector3f t = units.scaled(turn_rad_per_unit() * 67108864.0f);
    const float limit = (float)kMaxTurnAxisQ26;
    return linalg::fixed_from_vector(linalg::Vector3f(linalg::constrain(t.x, -limit, limit), linalg::constrain(t.y, -limit, limit),
                                                      linalg::constrain(t.z, -limit, limit)),
                                     0);
}

}  // namespace dcm
