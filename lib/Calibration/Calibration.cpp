#include "Calibration.h"

namespace calib {

using linalg::Vector3f;

Calibration default_calibration() {
    Calibration c;
    c.gyro_bias_rad_s = Vector3f();
    c.mag_offset_uT = Vector3f();
    c.mag_scale = Vector3f(1.0f, 1.0f, 1.0f);
    return c;
}

static bool within(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN

bool is_plausible(const Calibration& c) {
    // Bias, offset and scale are nine packed floats (three Vector3f).
    static_assert(sizeof(Calibration) == 9 * sizeof(float), "Calibration is nine floats");
    const float* v = &c.gyro_bias_rad_s.x;
    for (uint8_t i = 0; i < 9; ++i) {
        const uint8_t k = (uint8_t)(i / 3u);
        const float lo = k == 0 ? -kGyroBiasMax_rad_s : k == 1 ? -200.0f : 0.5f;
        const float hi = k == 0 ? kGyroBiasMax_rad_s : k == 1 ? 200.0f : 2.0f;
        if (!within(v[i], lo, hi)) return false;
    }
    return true;
}

// ---------------------------------------------------------------------------
void GyroCalibrator::restart() {
    n_ = 0;  // add() starts the sums and extremes afresh at n_ == 0
    done_ = false;
}

GyroCalibrator::Result GyroCalibrator::add(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    if (done_) restart();
    const float g = 9.80665f;
    const float a_norm = accel_m_s2.length();
    bool still = gyro_rad_s.is_finite() && accel_m_s2.is_finite() &&
                 a_norm > g * (1.0f - kAccelNormTol_g) && a_norm < g * (1.0f + kAccelNormTol_g);
    const float v[6] = {gyro_rad_s.x, gyro_rad_s.y, gyro_rad_s.z, accel_m_s2.x, accel_m_s2.y, accel_m_s2.z};
    // The spread (max - min) of every channel over the window so far.
    for (uint8_t i = 0; i < 6 && still; ++i) {
        if (n_ == 0 || v[i] < lo_[i]) lo_[i] = v[i];
        if (n_ == 0 || v[i] > hi_[i]) hi_[i] = v[i];
        still = hi_[i] - lo_[i] <= (i < 3 ? kGyroSpreadMax_rad_s : kAccelSpreadMax_m_s2);
    }
    if (!still) {
        const bool had_samples = n_ > 0;
        restart();
        if (had_samples) ++restarts_;
        return had_samples ? Result::Moved : Result::Collecting;
    }
    for (uint8_t i = 0; i < 6; ++i) sum_[i] = (n_ == 0 ? 0.0f : sum_[i]) + v[i];
    ++n_;
    if (n_ < kGyroWindow) return Result::Collecting;
    const float inv = 1.0f / (float)n_;
    float mean[6];
    for (uint8_t i = 0; i < 6; ++i) mean[i] = sum_[i] * inv;
    for (uint8_t i = 3; i < 6; ++i) bias_[i] = mean[i];  // the mean accel, kept either way
    const float len2 = mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2];
    if (!(len2 <= 3.0f * kGyroBiasMax_rad_s * kGyroBiasMax_rad_s)) {  // steady spin: not a bias
        restart();
        ++restarts_;
        return Result::Moved;
    }
    for (uint8_t i = 0; i < 3; ++i) bias_[i] = mean[i];
    done_ = true;
    return Result::Done;
}

// ---------------------------------------------------------------------------
void MagCalibrator::restart() {
    n_ = 0;
    axis_ = 0;
}

void MagCalibrator::add(const Vector3f& field_uT) {
    if (!field_uT.is_finite()) return;
    const float* v = &field_uT.x;
    for (uint8_t i = 0; i < 3; ++i) {
        if (n_ == 0 || v[i] < min_[i]) min_[i] = v[i];
        if (n_ == 0 || v[i] > max_[i]) max_[i] = v[i];
    }
    if (n_ < 0xFFFFu) ++n_;
}

MagCalibrator::Quality MagCalibrator::finish(Calibration& cal) {
    if (n_ < kMagCalMinSamples) return Quality::TooFewSamples;
    float h[3];
    float lo = 0.0f, hi = 0.0f, sum = 0.0f;
    for (uint8_t i = 0; i < 3; ++i) {
        h[i] = (max_[i] - min_[i]) * 0.5f;
        axis_ = i;
        if (h[i] < kMagMinHalfSpan_uT) return Quality::AxisNotTurned;
        if (h[i] > kMagMaxHalfSpan_uT) return Quality::SpanTooLarge;
        if (i == 0 || h[i] < lo) lo = h[i];
        if (i == 0 || h[i] > hi) hi = h[i];
        sum += h[i];
    }
    if (hi > lo * kMagMaxSpanRatio) return Quality::AxesDisagree;
    const float mean = sum * (1.0f / 3.0f);
    float* offset = &cal.mag_offset_uT.x;
    float* scale = &cal.mag_scale.x;
    for (uint8_t i = 0; i < 3; ++i) {
        offset[i] = (max_[i] + min_[i]) * 0.5f;
        scale[i] = mean / h[i];
    }
    return Quality::Ok;
}

}  // namespace calib
