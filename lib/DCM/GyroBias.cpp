// SPDX-License-Identifier: GPL-3.0-or-later
#include "GyroBias.h"

namespace dcm {

using linalg::Vector3f;
using linalg::Vector3l;

namespace {
// The rest mean's difference from the bias, saturated (units): 2^22 units is 1 900 deg/s
// on the 2000 deg/s range, and times 2^8 it stays within 31 bits.
constexpr int32_t kMaxRestDifference = 1L << 22;
}  // namespace

Vector3f GyroBias::estimate_rad_s(const DcmCoefficients& k) const {
    return fine_.scaled(k.gyro_rad_s_per_count * (1.0f / (float)(kTurnScale * kTurnScale)));
}

void GyroBias::set_estimate_rad_s(const Vector3f& bias, const DcmCoefficients& k) {
    if (!bias.is_finite()) return;
    fine_ = linalg::fixed_from_vector(bias * (k.units_per_rad_s * (float)kTurnScale), 0);
    clamp(k);
}

void GyroBias::set_sensor_rad_s(const Vector3f& bias, const DcmCoefficients& k) {
    if (!bias.is_finite()) return;
    sensor_units_ = linalg::fixed_from_vector(bias * k.units_per_rad_s, 0);
}

// The compass teaches the bias only while nothing else has measured it (DcmSettings.h):
// its errors (a residual hard iron, a magnet nearby) turn with the heading.
bool GyroBias::learn_from_heading(const linalg::Vector3l& down_q30, float heading_error, uint16_t interval_steps,
                                  bool starting, const DcmSettings& settings, const DcmCoefficients& k) {
    if (rotating_fast_ || starting || measured() || settings.ki_yaw_1_s2 == 0.0f) return false;
    const float steps = (float)interval_steps;
    const Vector3f error = linalg::vector_from_q30(down_q30) * -heading_error;
    subtract_fine(linalg::fixed_from_vector(
        error * (settings.ki_yaw_1_s2 * settings.step_s * steps * k.units_per_rad_s * (float)kTurnScale), 0), k);
    return true;
}

// bias += alpha (mean - bias), in fine units (the difference within the bias limit and
// the rest test's deviation: far below 2^23 units).
void GyroBias::follow_rest_mean(const Vector3l& rest_mean_units, const DcmCoefficients& k) {
    using linalg::mul_q30;
    int32_t* fine[3] = {&fine_.x, &fine_.y, &fine_.z};
    const int32_t* mean[3] = {&rest_mean_units.x, &rest_mean_units.y, &rest_mean_units.z};
    for (uint8_t i = 0; i < 3; ++i) {
        int32_t difference_units = *mean[i] - (*fine[i] >> 8);
        if (difference_units > kMaxRestDifference) difference_units = kMaxRestDifference;
        if (difference_units < -kMaxRestDifference) difference_units = -kMaxRestDifference;
        *fine[i] += mul_q30(k.rest_bias_alpha_q30, (int32_t)((uint32_t)difference_units << 8) - (*fine[i] & 0xFF));
    }
    clamp(k);
}

// bias -= ki error: the error in 16 bits (Q14 radians) times ki in fine units per rad/s.
void GyroBias::integrate_tilt_error(int16_t ex_q14, int16_t ey_q14, int16_t ez_q14, const DcmCoefficients& k) {
    using linalg::hot::mul_q14;
    const int32_t ki_fine = measured_ ? k.ki_measured_fine : k.ki_fine;
    fine_.x -= mul_q14(ex_q14, ki_fine);
    fine_.y -= mul_q14(ey_q14, ki_fine);
    fine_.z -= mul_q14(ez_q14, ki_fine);
    clamp(k);
}

void GyroBias::clamp(const DcmCoefficients& k) {
    int32_t* axis[3] = {&fine_.x, &fine_.y, &fine_.z};
    const int32_t limit = (measured_ & kByCalibration) ? k.bias_limit_fine >> kCalibratedLimitShift : k.bias_limit_fine;
    for (uint8_t i = 0; i < 3; ++i) {
        if (*axis[i] > limit) *axis[i] = limit;
        if (*axis[i] < -limit) *axis[i] = -limit;
    }
}

}  // namespace dcm
