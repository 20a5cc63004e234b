// SPDX-License-Identifier: GPL-3.0-or-later
// The board in its airframe: what turns the sensor's vectors into the vehicle's frame
// before the estimator, and the level trim after it.
//
//  - The accelerometer's calibration (ArduPilot's INS_ACCOFFS_*, INS_ACCSCAL_*), in the
//    board's own axes as AP_InertialSensor applies it: a = (raw - offset) .* scale.
//  - The board's orientation (AHRS_ORIENTATION, ArduPilot's enum Rotation of
//    AP_Math/rotations.h, numbers 0..37): v_vehicle = R(roll, pitch, yaw) v_board with
//    R = Rz(yaw) Ry(pitch) Rx(roll), as Vector3::rotate() and from_euler(). Every one of
//    0..37 is a signed permutation of the axes, some followed by a 45 deg yaw: a table
//    of one byte each, no float multiply (a 45 deg one four 16x16 products on counts).
//  - The level trim (AHRS_TRIM_X, AHRS_TRIM_Y, radians): the board's roll and pitch on a
//    level airframe. As ArduPilot's AP_AHRS (_body_dcm_matrix = _dcm_matrix *
//    vehicle_body_to_autopilot_body): R_vehicle = R_board T^T with T = Ry(trim_y) Rx(trim_x),
//    applied where the angles are taken (lib/DCM/Euler.h), not in the estimator.
//
// Frames: body x forward, y right, z down. Counts are the MPU6000's (16 bits); fields uT.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

// AHRS_ORIENTATION's values: ArduPilot's ROTATION_NONE (0) .. ROTATION_ROLL_90_YAW_270
// (37); 38 (ROLL_90_PITCH_68_YAW_293) and beyond are not taken (the parameter's range).
constexpr uint8_t kRotationCount = 38;

// v turned by rotation r (0..kRotationCount-1; others leave it as it is). Counts saturate
// at +-32767 (a 45 deg turn of a full-scale pair, or -(-32768)).
void rotate(uint8_t r, linalg::Vector3i& v);
void rotate(uint8_t r, linalg::Vector3f& v);

// ArduPilot's AHRS_TRIM range: +-10 deg.
constexpr float kTrimMax_rad = 0.1745f;
// INS_ACCOFFS_*: +-3.5 m/s^2; INS_ACCSCAL_*: 0.8..1.2 (AP_InertialSensor's accepted fit).
constexpr float kAccelOffsetMax_m_s2 = 3.5f;
constexpr float kAccelScaleMin = 0.8f;
constexpr float kAccelScaleMax = 1.2f;

// The trim's rotation T = Ry(trim_y) Rx(trim_x) in Q14 (1.0 = 16384), rows; identity
// when both trims are 0 (then nothing is applied: `active`).
struct TrimQ14 {
    int16_t t[3][3];
    bool active;
};
// sin and cos by their series (|x| <= kTrimMax_rad: below 1e-9 off), a few multiplies.
void small_sin_cos(float x_rad, float& s, float& c);
TrimQ14 trim_q14(float trim_x_rad, float trim_y_rad);
// The trims that make a board reading this specific force at rest read level
// (AP_InertialSensor::_calculate_trim): pitch atan2(ax, |(ay, az)|), roll atan2(-ay, -az).
// False (trims untouched) when either is beyond kTrimMax_rad or the force is no gravity.
bool level_trim(const linalg::Vector3f& accel_m_s2, float& trim_x_rad, float& trim_y_rad);

// What the sample path applies to each MPU6000 sample and compass field, made from the
// settings once (make_board_frame) so that a sample costs integer work only.
struct BoardFrame {
    int16_t accel_offset_counts[3];  // INS_ACCOFFS in counts
    int16_t accel_scale_q14[3];      // INS_ACCSCAL in Q14
    uint8_t rotation;                // AHRS_ORIENTATION
    uint8_t src[3];                  // its table row decoded: out[i] = +-in[src[i]] ...
    uint8_t signs;                   // ... negated where bit i is set; bit 3: then a 45 deg yaw
    bool accel_corrected;            // offsets or scales not the identity's
};
BoardFrame make_board_frame(const linalg::Vector3f& accel_offset_m_s2, const linalg::Vector3f& accel_scale,
                            uint8_t rotation, float accel_m_s2_per_count);
// The accelerometer's counts corrected (offset, scale) and turned; the gyro's turned.
void apply_accel(const BoardFrame& f, linalg::Vector3i& accel_counts);
void apply_gyro(const BoardFrame& f, linalg::Vector3i& gyro_counts);

}  // namespace calib
