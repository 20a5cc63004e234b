// SPDX-License-Identifier: GPL-3.0-or-later
#include "Gravity.h"

namespace dcm {

using linalg::Vector3l;

namespace {

// 1/n in Q30 for the window's samples (n = 1..5: a correction late by a step takes
// five), as code (a table would take RAM on the AVR).
int32_t inverse_q30(uint8_t n) {
    switch (n) {
        case 1: return linalg::q30_ratio(1, 1);
        case 2: return linalg::q30_ratio(1, 2);
        case 3: return linalg::q30_ratio(1, 3);
        case 4: return linalg::q30_ratio(1, 4);
        case 5: return linalg::q30_ratio(1, 5);
        default: return linalg::fixed_from_float(1.0f / (float)n, linalg::kQ30);
    }
}

// A sum's mean: v / n, by two bit shifts in the usual case (n = 4), else by 1/n in Q30.
// Forced inline: called, its vector argument had to be stored in correct_gravity's deep
// frame and the result read back from it.
FIXED_INLINE Vector3l per(const Vector3l& v, uint8_t n, int32_t inverse_q30) {
    if (n == 4) return Vector3l(v.x >> 2, v.y >> 2, v.z >> 2);
    return Vector3l(linalg::mul_q30(inverse_q30, v.x), linalg::mul_q30(inverse_q30, v.y), linalg::mul_q30(inverse_q30, v.z));
}

// v * 2^8 by byte shifts (a multiply may become avr-gcc's 32x32 routine).
Vector3l times_256(const Vector3l& v) {
    return Vector3l((int32_t)((uint32_t)v.x << 8), (int32_t)((uint32_t)v.y << 8), (int32_t)((uint32_t)v.z << 8));
}

}  // namespace

void GravityCorrection::reset(int32_t down_accel_units) {
    lp_ef_ = Vector3l(0, 0, down_accel_units);
    correction_units_ = Vector3l();
    clear_window();
}

void GravityCorrection::clear_window() {
    gyro_sum_ = Vector3l();
    accel_sum_ = Vector3l();
    accel_sum_of_sums_ = Vector3l();
    window_samples_ = 0;
}

void GravityCorrection::rescale(float gyro_ratio, float accel_ratio) {
    if (gyro_ratio != 1.0f) correction_units_ = rescaled(correction_units_, gyro_ratio);
    if (accel_ratio != 1.0f) lp_ef_ = rescaled(lp_ef_, accel_ratio);
}

bool GravityCorrection::low_pass_window(const GravityContext& c, WindowMeans& means, bool feed_low_pass) {
    if (window_samples_ == 0) return false;
    const DcmCoefficients& k = c.k;
    const linalg::Matrix3q30& r = c.r;
    using linalg::hot::mul_q14;
    using linalg::mul_q30;
    using linalg::q14_of;
    const uint8_t n = window_samples_;
    const int32_t inv_n = inverse_q30(n);
    // The means (units, accel counts * 2^8; |sums| < 2^18 counts): the gyro's less the
    // calibrated bias.
    const Vector3l gyro_raw_mean = per(times_256(gyro_sum_), n, inv_n);
    const Vector3l accel_sum = times_256(accel_sum_);
    means.gyro = gyro_raw_mean - c.sensor_bias_units;
    means.accel = per(accel_sum, n, inv_n);
    // Sample j of the window meets the matrix of the step before it, R_(j-1) =
    // R (I - [phi_j x]), phi_j = w dt (steps from j-1 to R's time). R is behind this
    // step's sample by the steps not yet integrated (this one among them), so the
    // steps are (n - j + 1) - pending, and sum_j phi_j x a_j is
    // w dt x (sum_j (n - j + 1) a_j - pending sum_j a_j): the first sum is the sum
    // of the running sums, three additions a step. (Each sample is turned by its own
    // phi_j, not the mean by the mean turn: under a 10 g shake while turning, the
    // acceleration changes within the window and the two differ.)
    // In integers: counts * 2^8, the turn per step in 16 bits (Q14 radians: the term
    // is a few percent of the sum, its rounding 6e-5 rad of it).
    // (A subtraction per pending step, a step or two: opaque keeps avr-gcc from making
    // the loop three calls of its 32x32 multiply.)
    Vector3l weighted = accel_sum_of_sums_;
    for (uint8_t i = c.pending_steps; i > 0; --i) {
        weighted.x = linalg::opaque(weighted.x - accel_sum_.x);
        weighted.y = linalg::opaque(weighted.y - accel_sum_.y);
        weighted.z = linalg::opaque(weighted.z - accel_sum_.z);
    }
    weighted = times_256(weighted);  // |weighted| < 15 * 2^15 counts: within 2^31
    const Vector3l turn = k.theta_q26_coarse(gyro_raw_mean - c.offset_units);
    const int16_t tx = q14_of(turn.x * 16), ty = q14_of(turn.y * 16), tz = q14_of(turn.z * 16);
    const Vector3l body(accel_sum.x - mul_q14(ty, weighted.z) + mul_q14(tz, weighted.y),
                        accel_sum.y - mul_q14(tz, weighted.x) + mul_q14(tx, weighted.z),
                        accel_sum.z - mul_q14(tx, weighted.y) + mul_q14(ty, weighted.x));
    const int32_t alpha = c.starting ? q30_of(k.startup_accel_alpha + (linalg::float_from_fixed(k.accel_alpha_q30, 30) -
                                                                      k.startup_accel_alpha) * (1.0f - c.startup_left))
                                     : k.accel_alpha_q30;
    // Into earth axes by the matrix in 16 bits (its rounding turns the earth-frame
    // force by 6e-5 rad at most, 0.003 deg of tilt), the mean, and the low-pass.
    const Vector3l accel_ef = per(
        Vector3l(mul_q14(q14_of(r.a.x), body.x) + mul_q14(q14_of(r.a.y), body.y) + mul_q14(q14_of(r.a.z), body.z),
                 mul_q14(q14_of(r.b.x), body.x) + mul_q14(q14_of(r.b.y), body.y) + mul_q14(q14_of(r.b.z), body.z),
                 mul_q14(q14_of(r.c.x), body.x) + mul_q14(q14_of(r.c.y), body.y) + mul_q14(q14_of(r.c.z), body.z)),
        n, inv_n);
    if (feed_low_pass) low_pass_observation(accel_ef, alpha);
    means.accel_ef = accel_ef;
    means.whole = n >= kCorrectionDivider;
    clear_window();
    return true;
}

void GravityCorrection::low_pass_observation(const Vector3l& observation, int32_t alpha_q30) {
    using linalg::mul_q30;
    lp_ef_ += Vector3l(mul_q30(alpha_q30, observation.x - lp_ef_.x), mul_q30(alpha_q30, observation.y - lp_ef_.y),
                       mul_q30(alpha_q30, observation.z - lp_ef_.z));
}

FIXED_OWN_FRAME void GravityCorrection::tilt_correction(const linalg::Matrix3q30& r, float startup_left,
                                                        bool hold_integrator, const DcmSettings& settings,
                                                        const DcmCoefficients& k, GyroBias& bias, TraceHook trace) {
    trace.gravity(lp_ef_, hold_integrator, startup_left, settings, k);
    using linalg::mul_q30;
    // Earth-frame error: measured down (-lp/|lp|) x earth down (0, 0, 1). |lp|^2 / 2^30
    // in integers (a 256th of its value at least: 1 g is 2^19 units at 16 g full
    // scale), 2^15 / |lp| a Q19 factor from the integer inverse square root (to 1e-4:
    // the gain's error, far below lp2's own 256th), the rest in Q30.
    const Vector3l& lp = lp_ef_;
    const uint32_t lp2 = (uint32_t)mul_q30(lp.x, lp.x) + (uint32_t)mul_q30(lp.y, lp.y) + (uint32_t)mul_q30(lp.z, lp.z);
    if (lp2 <= k.min_lp2) {  // |lp| < g/2: no direction to trust
        correction_units_ = Vector3l();
        return;
    }
    // The unit vector's components in Q30: lp times 2^15 / sqrt(lp2) (at most 2^11 for
    // |lp| >= g/2), that factor in Q19 (within 2^30), the products' low 11 bits dropped
    // (2e-6 rad, below the Q14 the error is used in).
    const uint32_t inv_lp = linalg::inverse_sqrt_q30(lp2);  // 2^30 / |lp|, *16 is 2^34 / |lp|
    const int32_t inv_lp_q34 = inv_lp >= (1UL << 27) ? 0x7FFFFFFF : (int32_t)(inv_lp << 4);
    const int32_t n = -(int32_t)((uint32_t)mul_q30(lp.y, inv_lp_q34) << 11);
    const int32_t e = (int32_t)((uint32_t)mul_q30(lp.x, inv_lp_q34) << 11);
    // In body axes: R^T (error_n, error_e, 0), the matrix in 16 bits (an error of 6e-5 of
    // the correction).
    using linalg::q14_of;
    const Vector3l error(linalg::hot::mul_q14(q14_of(r.a.x), n) + linalg::hot::mul_q14(q14_of(r.b.x), e),
                         linalg::hot::mul_q14(q14_of(r.a.y), n) + linalg::hot::mul_q14(q14_of(r.b.y), e),
                         linalg::hot::mul_q14(q14_of(r.a.z), n) + linalg::hot::mul_q14(q14_of(r.b.z), e));
    // The gain's and the low-pass turn's products below as ordinary calls: five calls at
    // 50 Hz add little to a step, where each inline copy would add its code to the flash.
    using linalg::mul_q14;
    const float kp = startup_left > 0.0f
                         ? settings.kp_rp_1_s + (settings.kp_startup_1_s - settings.kp_rp_1_s) * startup_left
                         : settings.kp_rp_1_s;
    // kp error in units: the error in 16 bits (Q14: steps of 6e-5 rad, 0.003 deg of tilt)
    // times the gain in units per rad/s.
    // (Start-up only: the ordinary call.)
    const int32_t kp_units = startup_left > 0.0f ? linalg::fixed_from_float(kp * k.units_per_rad_s, 0) : k.kp_units;
    const int16_t ex = q14_of(error.x), ey = q14_of(error.y), ez = q14_of(error.z);
    correction_units_ = Vector3l(mul_q14(ex, kp_units), mul_q14(ey, kp_units), mul_q14(ez, kp_units));
    if (!hold_integrator) {
        trace.bias_before(bias, k);
        bias.integrate_tilt_error(ex, ey, ez, k);
        trace.bias_after(BiasSource::kGravity, bias, k);
    }
    // The correction turns the estimated earth frame by kp dt error_ef over the
    // next kCorrectionDivider steps: the low-pass state, kept in that frame, turns
    // with it ((e_n, e_e, 0) x lp, scaled).
    const int32_t turn =
        startup_left > 0.0f ? linalg::fixed_from_float(kp * correction_dt_s(settings), linalg::kQ30) : k.tilt_turn_q30;
    const int32_t turn_n = mul_q14(q14_of(n), turn), turn_e = mul_q14(q14_of(e), turn);
    const Vector3l old = lp_ef_;
    lp_ef_ += Vector3l(mul_q30(turn_e, old.z), -mul_q30(turn_n, old.z),
                             mul_q30(turn_n, old.y) - mul_q30(turn_e, old.x));
}

}  // namespace dcm
