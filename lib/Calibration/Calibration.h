// Sensor calibration, applied in one place (apply_gyro / apply_mag), and the two
// procedures that measure it: gyro bias at rest and magnetometer hard iron + per-axis
// scale from the extremes of a rotation.
//
// Body frame (x forward, y right, z down), gyro in rad/s, accel in m/s^2 (specific
// force), field in uT. Pure C++: no clock, no bus, no Arduino include; the caller
// feeds samples at the fixed 200 Hz step (gyro) and as they come (mag).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

struct Calibration {
    linalg::Vector3f gyro_bias_rad_s;  // subtracted from every gyro sample
    linalg::Vector3f mag_offset_uT;    // hard iron, subtracted first
    linalg::Vector3f mag_scale;        // then multiplied per axis (soft-iron diagonal)
};

// Zero bias and offset, unit scale.
Calibration default_calibration();

inline linalg::Vector3f apply_gyro(const Calibration& c, const linalg::Vector3f& gyro_rad_s) {
    return gyro_rad_s - c.gyro_bias_rad_s;
}
inline linalg::Vector3f apply_mag(const Calibration& c, const linalg::Vector3f& field_uT) {
    const linalg::Vector3f d = field_uT - c.mag_offset_uT;
    return linalg::Vector3f(d.x * c.mag_scale.x, d.y * c.mag_scale.y, d.z * c.mag_scale.z);
}

// True when every number is finite and within what a real board could need (bias
// below 30 deg/s per axis, offset below 200 uT, scale within 0.5..2): a record
// that fails this is treated as corrupt.
bool is_plausible(const Calibration& c);

// ---------------------------------------------------------------------------
// Gyro bias at rest: the mean over kGyroWindow samples (1 s at 200 Hz). The board
// counts as moving, and the window restarts, when a gyro axis spreads by more than
// kGyroSpreadMax_rad_s (min..max), an accel axis spreads by more than
// kAccelSpreadMax_m_s2, or |accel| is off 1 g by more than kAccelNormTol_g. Spreads,
// not thresholds on the value: the MPU6000's zero-rate offset is up to +-20 deg/s.
constexpr uint16_t kGyroWindow = 200;
constexpr float kGyroSpreadMax_rad_s = 0.035f;  // 2 deg/s peak to peak (noise: ~0.3)
constexpr float kAccelSpreadMax_m_s2 = 0.4f;    // 5 deg/s of rotation over 1 s moves g by ~0.85
constexpr float kAccelNormTol_g = 0.1f;
constexpr float kGyroBiasMax_rad_s = 0.5236f;   // 30 deg/s: more is not a bias

class GyroCalibrator {
public:
    enum class Result : uint8_t {
        Collecting,  // keep feeding
        Moved,       // the board moved: the window restarted (say so)
        Done,        // bias() is the mean of a still window
    };

    void restart();
    // Feeds one sample (raw gyro, raw accel); returns what happened.
    Result add(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2);
    bool done() const { return done_; }
    linalg::Vector3f bias() const { return linalg::Vector3f(bias_[0], bias_[1], bias_[2]); }
    // Mean specific force over the last complete still window (gravity for the DCM init).
    linalg::Vector3f mean_accel_m_s2() const { return linalg::Vector3f(bias_[3], bias_[4], bias_[5]); }
    uint16_t count() const { return n_; }
    uint16_t restarts() const { return restarts_; }

private:
    // Plain arrays, gyro x y z then accel x y z: one loop does all six channels, and
    // the object needs no constructor code. Valid from the first add() of a window
    // (n_ == 0 starts them); bias_ once done().
    float sum_[6];
    float lo_[6], hi_[6];
    float bias_[6] = {};  // mean gyro (the bias), then mean accel
    uint16_t n_ = 0;
    uint16_t restarts_ = 0;
    bool done_ = false;
};

// ---------------------------------------------------------------------------
// Magnetometer: hard-iron offset = centre of the extremes per axis, scale = mean
// half-span / half-span of that axis. The user turns the board through every
// orientation for kMagCalSeconds; the result is rejected (and the old calibration
// kept) when an axis saw too little of the field or the axes disagree.
constexpr uint8_t kMagCalSeconds = 30;
constexpr uint16_t kMagCalMinSamples = 200;     // at 75 Hz the 30 s give ~2 250
constexpr float kMagMinHalfSpan_uT = 12.0f;     // Earth: 25..65 uT; a full turn gives that each side
constexpr float kMagMaxHalfSpan_uT = 150.0f;    // beyond: not the Earth's field (magnet nearby)
constexpr float kMagMaxSpanRatio = 1.5f;        // largest/smallest half-span: soft iron this bad = not turned enough

class MagCalibrator {
public:
    enum class Quality : uint8_t {
        Ok,
        TooFewSamples,
        AxisNotTurned,   // an axis' half-span is below kMagMinHalfSpan_uT: axis() says which
        SpanTooLarge,    // a half-span above kMagMaxHalfSpan_uT
        AxesDisagree,    // half-span ratio above kMagMaxSpanRatio
    };

    void restart();
    // Feeds one field sample (uT, body frame, BEFORE calibration); non-finite ignored.
    void add(const linalg::Vector3f& field_uT);
    uint16_t count() const { return n_; }
    // Checks the collected extremes; on Ok writes offset and scale into cal (gyro bias untouched).
    Quality finish(Calibration& cal);
    // The axis (0 = x, 1 = y, 2 = z) that failed AxisNotTurned / SpanTooLarge.
    uint8_t axis() const { return axis_; }
    linalg::Vector3f min_uT() const { return linalg::Vector3f(min_[0], min_[1], min_[2]); }
    linalg::Vector3f max_uT() const { return linalg::Vector3f(max_[0], max_[1], max_[2]); }

private:
    float min_[3], max_[3];  // valid once count() > 0
    uint16_t n_ = 0;
    uint8_t axis_ = 0;
};

}  // namespace calib
