// SPDX-License-Identifier: GPL-3.0-or-later
// Euler angles from a body->earth rotation matrix, aerospace Z-Y-X (yaw psi, pitch
// theta, roll phi): R = Rz(psi) Ry(theta) Rx(phi), earth = north-east-down.
//
//   theta = -asin(R31), phi = atan2(R32, R33), psi = atan2(R21, R11)
//
// Gimbal lock (|R31| -> 1, pitch +-90 deg): roll and yaw are not separable there.
// Convention: when cos(theta) is below kGimbalLockCos the whole remaining rotation
// is reported as yaw and roll is 0: psi = atan2(-R12, R22) (exact for phi = 0).
// Away from the lock the ordinary formulas are used; the switch happens where both
// give the same rotation to within ~2e-5, so the output stays finite and the matrix
// rebuilt from the angles matches R everywhere. (Passing over the top, pitch turns
// back from 90 deg and roll and yaw flip by 180 deg: that is Euler angles, not noise.)
// Pitch is atan2(-R31, sqrt(R32^2 + R33^2)), which equals -asin(R31) for an
// orthonormal R and keeps its precision near +-90 deg.
//
// Arithmetic (lib/LinAlg/Fixed.h): the entries are read into Q30 integers and the
// angles come from integer tables (atan2 within 1.5e-5 rad, 0.0009 deg, over its
// whole domain): the angles are within 0.005 deg, half a count of the 0.01 deg the
// output prints, of the same formulas in double (test_fixed.cpp, up to 80 deg pitch:
// nearer the lock roll and yaw are ill-conditioned for any arithmetic), and the same
// bits on the host. The output path (euler_carried_q24 then angles_centideg) has no
// float after the nine entries (its cost: docs/performance.md), and the lines print its
// hundredths as they are.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

struct EulerAngles {
    float roll_rad;
    float pitch_rad;
    float yaw_rad;  // -pi..pi
};

// The same angles in Q24 radians (linalg::kAngleQ), as the integer extraction gives
// them: the output path turns them into printed hundredths of a degree with integers
// only (centideg_from_q24), a float caller converts them exactly (euler_in_rad).
struct EulerQ24 {
    int32_t roll_q24;
    int32_t pitch_q24;
    int32_t yaw_q24;  // -pi..pi
};
EulerAngles euler_in_rad(const EulerQ24& e);

// Below this cos(pitch) (pitch within ~0.001 deg of +-90) roll is folded into yaw.
// Small enough that the folded angles rebuild R to ~2e-5, large enough that roll
// is still well-conditioned just above it.
constexpr float kGimbalLockCos = 2e-5f;

EulerAngles euler_from_dcm(const linalg::Matrix3f& r);
// The same from the seven entries it reads (Rij: row i, column j), for callers that
// have those without a whole matrix.
EulerAngles euler_from_entries(float r11, float r12, float r21, float r22, float r31, float r32, float r33);
// The same from the seven entries in Q30 (1.0 = 2^30, lib/LinAlg/Fixed.h), for a caller
// that keeps R in fixed point and so skips the conversions. Any int32 values give finite angles.
EulerAngles euler_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32, int32_t r33);
EulerQ24 euler_q24_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32,
                            int32_t r33);
// The angles of R carried forward by a small rotation theta (body frame, rad):
// R' = R (I + [theta]x), each row r' = r + r x theta (first order: the output's lead,
// |theta| ~ rate * 3 ms). theta is clamped to +-0.25 rad per axis (beyond it the first
// order is itself off by theta^2/2 > 1.8 deg). Only the entries read are formed (R12
// and R22 only at the gimbal lock).
// theta in Q26 radians (2^26 = 1 rad, 1.5e-8 rad steps) for a caller that sums it in
// integers; the float theta is the same after fixed_from_float(theta, 26).
EulerQ24 euler_carried_q24(const linalg::Matrix3q30& r, int32_t theta_x_q26, int32_t theta_y_q26,
                           int32_t theta_z_q26);
// The same, then turned by a level trim T (Q14 rows, 1.0 = 16384): the angles of
// R' T^T, the airframe's when the board sits at T in it (lib/Calibration/BoardFrame.h,
// ArduPilot's AHRS_TRIM): nine carried entries and 21 32x16 products, then the same
// extraction.
EulerQ24 euler_carried_trimmed_q24(const linalg::Matrix3q30& r, int32_t theta_x_q26, int32_t theta_y_q26,
                                   int32_t theta_z_q26, const int16_t trim_q14[3][3]);
EulerQ24 euler_carried_q24(const linalg::Matrix3f& r, int32_t theta_x_q26, int32_t theta_y_q26,
                           int32_t theta_z_q26);
EulerAngles euler_carried(const linalg::Matrix3f& r, int32_t theta_x_q26, int32_t theta_y_q26,
                          int32_t theta_z_q26);
EulerAngles euler_carried(const linalg::Matrix3f& r, const linalg::Vector3f& theta_rad);
linalg::Matrix3f dcm_from_euler(float roll_rad, float pitch_rad, float yaw_rad);

// Heading in degrees, 0 <= h < 360, from a yaw angle in radians (-pi..pi) and a
// declination (east positive) in degrees (-180..180): the firmware's output
// convention. Beyond those ranges a sum within +-720 deg is still folded into 0..360;
// further out, or for NaN, it gives 0 (never NaN).
float heading_deg(float yaw_rad, float declination_deg);

// The same in hundredths of a degree, 0 <= h < 36000, from yaw in Q24 radians (-pi..pi)
// and a declination (east positive) in hundredths (-18000..18000), in integers: the
// yaw rounded to hundredths (linalg::centideg_from_q24) before the declination, a
// whole number of them, is added.
int32_t heading_centideg(int32_t yaw_q24, int16_t declination_centideg);

// The angles as the output lines print them, in hundredths of a degree, from the
// integer extraction with integers only.
struct AnglesCentideg {
    int32_t roll_centideg;     // -18000..18000
    int32_t pitch_centideg;    // -9000..9000
    int32_t heading_centideg;  // 0 <= h < 36000, declination applied
};
AnglesCentideg angles_centideg(const EulerQ24& e, int16_t declination_centideg);

}  // namespace dcm
