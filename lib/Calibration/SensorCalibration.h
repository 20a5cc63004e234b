// SPDX-License-Identifier: GPL-3.0-or-later
// The sensor calibration, applied in one place (apply_gyro / apply_mag): what the
// settings record stores and every sample goes through. The procedures that measure it
// have a file each: GyroCalibrator (gyro bias at rest), MagCalibrator (`cal mag`'s
// ellipsoid fit), OffsetLearner (hard iron learned in motion).
//
// Body frame (x forward, y right, z down), gyro in rad/s, accel in m/s^2 (specific
// force), field in uT. Pure C++: no clock, no bus, no Arduino include.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

struct Calibration {
    linalg::Vector3f gyro_bias_rad_s;  // subtracted from every gyro sample
    linalg::Vector3f mag_offset_uT;    // hard iron from `cal mag`, subtracted first
    linalg::Vector3f mag_scale;        // then the soft-iron matrix W: its diagonal
    linalg::Vector3f mag_cross;        //   and its off-diagonal terms (xy, xz, yz); W symmetric
    linalg::Vector3f mag_learned_uT;   // then the offset learned in motion (OffsetLearner)
};

// Zero bias and offset, unit scale.
Calibration default_calibration();

inline linalg::Vector3f apply_gyro(const Calibration& c, const linalg::Vector3f& gyro_rad_s) {
    return gyro_rad_s - c.gyro_bias_rad_s;
}
// f = W (m - offset) - learned. W symmetric: a soft-iron correction that stretches
// the ellipsoid back to a sphere without turning the compass's axes.
linalg::Vector3f apply_mag(const Calibration& c, const linalg::Vector3f& field_uT);

// True when every number is finite and within what a real board could need (bias
// below 30 deg/s per axis, offsets below 200 uT, soft-iron diagonal within 0.5..2,
// cross terms within +-0.5): a record that fails this is treated as corrupt.
bool is_plausible(const Calibration& c);
constexpr float kGyroBiasMax_rad_s = 0.5236f;   // 30 deg/s: more is not a bias (GyroCalibrator too)

}  // namespace calib
