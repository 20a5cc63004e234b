// SPDX-License-Identifier: GPL-3.0-or-later
#include "Rest.h"

namespace dcm {

using linalg::Vector3l;

namespace {
// The field may move this much in body axes during a rest: the HMC5883L's noise is
// ~0.2 uT with its 8-sample average; a turn of 3 deg moves a 20 uT horizontal field by
// 1 uT, so a steady turn of more than 2 deg/s ends a rest within its first 1.5 s, and
// a slower one before it has lasted 1 uT / (20 uT x rate).
constexpr float kRestFieldMove_uT = 1.0f;
constexpr int16_t kRestFieldMoveQ5 = (int16_t)(kRestFieldMove_uT * (float)(1 << kFieldQ));

// |a - b| > kRestFieldMove_uT for two fields in uT Q5: an axis beyond it decides at
// once; else the squares of the differences.
bool moved(const linalg::Vector3i& a, const linalg::Vector3i& b) {
    const int16_t d[3] = {(int16_t)(a.x - b.x), (int16_t)(a.y - b.y), (int16_t)(a.z - b.z)};
    int32_t sum = 0;
    for (uint8_t i = 0; i < 3; ++i) {
        if (d[i] >= kRestFieldMoveQ5 || d[i] <= -kRestFieldMoveQ5) return true;
        sum += linalg::mul_s16(d[i], d[i]);
    }
    return sum > linalg::mul_s16(kRestFieldMoveQ5, kRestFieldMoveQ5);
}
}  // namespace

void RestDetector::watch_field(const linalg::Vector3i& field_q5) {
    if (moved(field_q5, field_q5_)) {
        field_q5_ = field_q5;
        corrections_ = 0;
    }
}

bool RestDetector::update(const Vector3l& gyro_mean_units, const Vector3l& accel_mean_units,
                          const Vector3l& mean_off_bias_units, bool whole_window, bool compass_watching,
                          const DcmCoefficients& k) {
    // A steady turn passes the deviation test too. The compass tells (watch_field).
    // Without a compass delivering, the mean must be within the tremor bound of the bias
    // estimate instead (VQF's rule, its 2 deg/s bias clip): a larger vertical bias is
    // then not told from a slow turn.
    const Vector3l gyro_change = gyro_mean_units - gyro_mean_, accel_change = accel_mean_units - accel_mean_;
    const bool still = !exceeds(gyro_change, k.rest_gyro_dev) &&
                       (compass_watching || !exceeds(mean_off_bias_units, k.rest_gyro_dev)) &&
                       !exceeds(accel_change, k.rest_accel_dev);
    // mean += alpha (sample - mean): the factor in 16 bits (two 16x16 products an axis),
    // the step rounded to the unit (the changes are counts * 2^8, far below 2^29).
    using linalg::hot::mul_q14_unit;
    gyro_mean_ += Vector3l(mul_q14_unit(k.rest_alpha_q14, gyro_change.x), mul_q14_unit(k.rest_alpha_q14, gyro_change.y),
                           mul_q14_unit(k.rest_alpha_q14, gyro_change.z));
    accel_mean_ += Vector3l(mul_q14_unit(k.rest_alpha_q14, accel_change.x), mul_q14_unit(k.rest_alpha_q14, accel_change.y),
                            mul_q14_unit(k.rest_alpha_q14, accel_change.z));
    if (!still || !whole_window) {
        corrections_ = 0;
        return false;
    }
    if (corrections_ < k.rest_min_corrections) {
        ++corrections_;
        return false;
    }
    return true;
}

}  // namespace dcm
