// SPDX-License-Identifier: GPL-3.0-or-later
// Gyro bias at rest: the mean over kGyroWindow samples (1 s at 200 Hz). The board
// counts as moving, and the window restarts, when a gyro axis spreads by more than
// kGyroSpreadMax_rad_s (min..max), an accel axis spreads by more than
// kAccelSpreadMax_m_s2, or |accel| is off 1 g by more than kAccelNormTol_g. Spreads,
// not thresholds on the value: the MPU6000's zero-rate offset is up to +-20 deg/s.
//
// Body frame (x forward, y right, z down), gyro in rad/s, accel in m/s^2 (specific
// force). Pure C++: no clock, no bus, no Arduino include; the caller feeds samples at
// the fixed 200 Hz step.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

constexpr uint16_t kGyroWindow = 200;
constexpr float kGyroSpreadMax_rad_s = 0.035f;  // 2 deg/s peak to peak (noise: ~0.3)
constexpr float kAccelSpreadMax_m_s2 = 0.4f;    // 5 deg/s of rotation over 1 s moves g by ~0.85
constexpr float kAccelNormTol_g = 0.1f;

class GyroCalibrator {
public:
    enum class Result : uint8_t {
        Collecting,  // keep feeding
        Moved,       // the board moved: the window restarted (say so)
        Done,        // bias() is the mean of a still window
    };

    void restart();
    // Feeds one sample in the MPU6000's counts and their scales (rad/s and m/s^2 per
    // count); returns what happened. In integers, not floats: it runs at every step while
    // it measures, in the background too (its cost: `make bench`).
    Result add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts, float gyro_rad_s_per_count,
               float accel_m_s2_per_count);
    // The same in SI units (tests, tools), held in fine counts (kFloatGyroScale,
    // kFloatAccelScale: +-4 rad/s and +-16 m/s^2, beyond any still board).
    Result add(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2);
    bool done() const { return done_; }
    // Valid once done(), until the next add().
    linalg::Vector3f bias() const { return mean(0, gyro_scale_); }
    // Mean specific force over the still window (gravity for the DCM init); likewise.
    linalg::Vector3f mean_accel_m_s2() const { return mean(3, accel_scale_); }
    uint16_t count() const { return n_; }
    uint16_t restarts() const { return restarts_; }

    static constexpr float kFloatGyroScale = 1.0f / 8192.0f;
    static constexpr float kFloatAccelScale = 1.0f / 2048.0f;

private:
    linalg::Vector3f mean(uint8_t first, float scale) const;
    // Plain arrays, gyro x y z then accel x y z: one loop does all six channels, and
    // the object needs no constructor code. Valid from the first add() of a window
    // (n_ == 0 starts them); the limits in counts follow the scales (set when they change).
    int32_t sum_[6] = {};
    int16_t lo_[6], hi_[6];
    uint16_t spread_max_[2];     // gyro, accel: the spreads in counts
    uint32_t norm2_min_, norm2_max_;  // |accel|^2 in counts^2 for 1 g -+ kAccelNormTol_g
    float gyro_scale_ = 0.0f, accel_scale_ = 0.0f;
    uint16_t n_ = 0;
    uint16_t restarts_ = 0;
    bool done_ = false;
};

}  // namespace calib
