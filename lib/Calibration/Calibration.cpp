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
    const float g[3] = {c.gyro_bias_rad_s.x, c.gyro_bias_rad_s.y, c.gyro_bias_rad_s.z};
    const float o[3] = {c.mag_offset_uT.x, c.mag_offset_uT.y, c.mag_offset_uT.z};
    const float s[3] = {c.mag_scale.x, c.mag_scale.y, c.mag_scale.z};
    for (uint8_t i = 0; i < 3; ++i) {
        if (!within(g[i], -kGyroBiasMax_rad_s, kGyroBiasMax_rad_s)) return false;
        if (!within(o[i], -200.0f, 200.0f)) return false;
        if (!within(s[i], 0.5f, 2.0f)) return false;
    }
    return true;
}

// ---------------------------------------------------------------------------
static void widen(Vector3f& lo, Vector3f& hi, const Vector3f& v) {
    if (v.x < lo.x) lo.x = v.x;
    if (v.y < lo.y) lo.y = v.y;
    if (v.z < lo.z) lo.z = v.z;
    if (v.x > hi.x) hi.x = v.x;
    if (v.y > hi.y) hi.y = v.y;
    if (v.z > hi.z) hi.z = v.z;
}

static float max_spread(const Vector3f& lo, const Vector3f& hi) {
    const Vector3f d = hi - lo;
    float m = d.x;
    if (d.y > m) m = d.y;
    if (d.z > m) m = d.z;
    return m;
}

void GyroCalibrator::restart() {
    n_ = 0;
    done_ = false;
    gyro_sum_ = accel_sum_ = Vector3f();
}

GyroCalibrator::Result GyroCalibrator::add(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    if (done_) restart();
    const float g = 9.80665f;
    const float a_norm = accel_m_s2.length();
    bool still = gyro_rad_s.is_finite() && accel_m_s2.is_finite() &&
                 a_norm > g * (1.0f - kAccelNormTol_g) && a_norm < g * (1.0f + kAccelNormTol_g);
    if (still && n_ > 0) {
        Vector3f glo = gyro_min_, ghi = gyro_max_, alo = accel_min_, ahi = accel_max_;
        widen(glo, ghi, gyro_rad_s);
        widen(alo, ahi, accel_m_s2);
        still = max_spread(glo, ghi) <= kGyroSpreadMax_rad_s && max_spread(alo, ahi) <= kAccelSpreadMax_m_s2;
        gyro_min_ = glo; gyro_max_ = ghi; accel_min_ = alo; accel_max_ = ahi;
    }
    if (!still) {
        const bool had_samples = n_ > 0;
        restart();
        if (had_samples) ++restarts_;
        return had_samples ? Result::Moved : Result::Collecting;
    }
    if (n_ == 0) {
        gyro_min_ = gyro_max_ = gyro_rad_s;
        accel_min_ = accel_max_ = accel_m_s2;
    }
    gyro_sum_ += gyro_rad_s;
    accel_sum_ += accel_m_s2;
    ++n_;
    if (n_ < kGyroWindow) return Result::Collecting;
    const float inv = 1.0f / (float)n_;
    const Vector3f mean = gyro_sum_ * inv;
    mean_accel_ = accel_sum_ * inv;
    if (!(mean.length() <= kGyroBiasMax_rad_s * 1.7320508f)) {  // steady spin: not a bias
        restart();
        ++restarts_;
        return Result::Moved;
    }
    bias_ = mean;
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
    if (n_ == 0) {
        min_ = max_ = field_uT;
    } else {
        widen(min_, max_, field_uT);
    }
    if (n_ < 0xFFFFu) ++n_;
}

MagCalibrator::Quality MagCalibrator::finish(Calibration& cal) {
    if (n_ < kMagCalMinSamples) return Quality::TooFewSamples;
    const Vector3f half = (max_ - min_) * 0.5f;
    const float h[3] = {half.x, half.y, half.z};
    float lo = h[0], hi = h[0];
    for (uint8_t i = 0; i < 3; ++i) {
        if (h[i] < kMagMinHalfSpan_uT) {
            axis_ = i;
            return Quality::AxisNotTurned;
        }
        if (h[i] > kMagMaxHalfSpan_uT) {
            axis_ = i;
            return Quality::SpanTooLarge;
        }
        if (h[i] < lo) lo = h[i];
        if (h[i] > hi) hi = h[i];
    }
    if (hi > lo * kMagMaxSpanRatio) return Quality::AxesDisagree;
    const float mean = (h[0] + h[1] + h[2]) * (1.0f / 3.0f);
    cal.mag_offset_uT = (max_ + min_) * 0.5f;
    cal.mag_scale = Vector3f(mean / h[0], mean / h[1], mean / h[2]);
    return Quality::Ok;
}

}  // namespace calib
