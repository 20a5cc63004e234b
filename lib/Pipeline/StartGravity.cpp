// SPDX-License-Identifier: GPL-3.0-or-later
#include "StartGravity.h"

namespace pipeline {

void StartGravity::add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts,
                       float gyro_rad_s_per_count, float accel_m_s2_per_count,
                       const linalg::Vector3f& gyro_bias_rad_s, float dt_s) {
    gyro_counts_ += gyro_counts;
    accel_counts_ += accel_counts;
    if (++pending_ < kFoldSamples) return;
    // The fold's turn, rad: the summed rates less the bias, times the period.
    const linalg::Vector3f turn_rad =
        gyro_counts_.scaled(gyro_rad_s_per_count * dt_s) - gyro_bias_rad_s * (pending_ * dt_s);
    // The fold's samples are on average 3/8 of its turn old: (sum + A) - turn x (sum + 3/8 A).
    const linalg::Vector3f fold_m_s2 = accel_counts_.scaled(accel_m_s2_per_count);
    sum_m_s2_ = sum_m_s2_ + fold_m_s2 - turn_rad.cross(sum_m_s2_ + fold_m_s2 * 0.375f);
    if (folded_ < 0xFFFFu - kFoldSamples) folded_ = (uint16_t)(folded_ + pending_);
    gyro_counts_ = accel_counts_ = linalg::Vector3l();
    pending_ = 0;
}

}  // namespace pipeline
