// SPDX-License-Identifier: GPL-3.0-or-later
#include "GyroCalibrator.h"

#include "Fixed.h"
#include "SensorCalibration.h"

namespace calib {

using linalg::Vector3f;

void GyroCalibrator::restart() {
    n_ = 0;  // add() starts the sums and extremes afresh at n_ == 0
    done_ = false;
}

GyroCalibrator::Result GyroCalibrator::add(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    // NaN or beyond the fine counts' range: not still (a count at the range's end fails
    // the spread or the 1 g test).
    const float g[3] = {gyro_rad_s.x, gyro_rad_s.y, gyro_rad_s.z}, a[3] = {accel_m_s2.x, accel_m_s2.y, accel_m_s2.z};
    int16_t gc[3], ac[3];
    for (uint8_t i = 0; i < 3; ++i) {
        const float gi = g[i] * (1.0f / kFloatGyroScale), ai = a[i] * (1.0f / kFloatAccelScale);
        gc[i] = linalg::is_finite(gi) ? (int16_t)linalg::constrain(gi, -32767.0f, 32767.0f) : 32767;
        ac[i] = linalg::is_finite(ai) ? (int16_t)linalg::constrain(ai, -32767.0f, 32767.0f) : 32767;
    }
    return add(linalg::Vector3i(gc[0], gc[1], gc[2]), linalg::Vector3i(ac[0], ac[1], ac[2]), kFloatGyroScale,
               kFloatAccelScale);
}

GyroCalibrator::Result GyroCalibrator::add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts,
                                           float gyro_rad_s_per_count, float accel_m_s2_per_count) {
    if (done_) restart();
    if (gyro_rad_s_per_count != gyro_scale_ || accel_m_s2_per_count != accel_scale_) {
        // New scales (the first sample): the limits in counts (a few float operations,
        // once: a board that keeps moving restarts the window every few samples).
        restart();
        gyro_scale_ = gyro_rad_s_per_count;
        accel_scale_ = accel_m_s2_per_count;
        spread_max_[0] = (uint16_t)linalg::constrain(kGyroSpreadMax_rad_s / gyro_rad_s_per_count, 0.0f, 65535.0f);
        spread_max_[1] = (uint16_t)linalg::constrain(kAccelSpreadMax_m_s2 / accel_m_s2_per_count, 0.0f, 65535.0f);
        const float g_counts = linalg::kGravity_m_s2 / accel_m_s2_per_count;
        const float lo = g_counts * (1.0f - kAccelNormTol_g), hi = g_counts * (1.0f + kAccelNormTol_g);
        norm2_min_ = (uint32_t)linalg::constrain(lo * lo, 0.0f, 4.0e9f);
        norm2_max_ = (uint32_t)linalg::constrain(hi * hi, 0.0f, 4.0e9f);
    }
    const int16_t v[6] = {gyro_counts.x, gyro_counts.y, gyro_counts.z, accel_counts.x, accel_counts.y, accel_counts.z};
    const uint32_t norm2 = (uint32_t)linalg::mul_s16(v[3], v[3]) + (uint32_t)linalg::mul_s16(v[4], v[4]) +
                           (uint32_t)linalg::mul_s16(v[5], v[5]);
    bool still = norm2 > norm2_min_ && norm2 < norm2_max_;
    // The spread (max - min) of every channel over the window so far.
    for (uint8_t i = 0; i < 6 && still; ++i) {
        if (n_ == 0 || v[i] < lo_[i]) lo_[i] = v[i];
        if (n_ == 0 || v[i] > hi_[i]) hi_[i] = v[i];
        still = (uint16_t)(hi_[i] - lo_[i]) <= spread_max_[i < 3 ? 0 : 1];
    }
    if (!still) {
        const bool had_samples = n_ > 0;
        restart();
        if (had_samples) ++restarts_;
        return had_samples ? Result::Moved : Result::Collecting;
    }
    for (uint8_t i = 0; i < 6; ++i) sum_[i] = (n_ == 0 ? 0 : sum_[i]) + v[i];
    ++n_;
    if (n_ < kGyroWindow) return Result::Collecting;
    const Vector3f b = bias();
    if (!(b.length_squared() <= 3.0f * kGyroBiasMax_rad_s * kGyroBiasMax_rad_s)) {  // steady spin: not a bias
        restart();
        ++restarts_;
        return Result::Moved;
    }
    done_ = true;
    return Result::Done;
}

Vector3f GyroCalibrator::mean(uint8_t first, float scale) const {
    const float k = n_ > 0 ? scale / (float)n_ : 0.0f;
    return Vector3f((float)sum_[first] * k, (float)sum_[first + 1] * k, (float)sum_[first + 2] * k);
}

}  // namespace calib
