// SPDX-License-Identifier: GPL-3.0-or-later
// The board's frame (lib/Calibration/BoardFrame.h): each AHRS_ORIENTATION against
// ArduPilot's definition R = Rz(yaw) Ry(pitch) Rx(roll), the accelerometer's correction
// in counts, the level trim and its angles.
#include <gtest/gtest.h>

#include <math.h>

#include "BoardFrame.h"
#include "Euler.h"
#include "Fixed.h"

namespace {

using linalg::Vector3f;
using linalg::Vector3i;

// Roll, pitch, yaw (deg) of ArduPilot's rotations 0..37 (MAVLink's MAV_SENSOR_ORIENTATION).
const int kRpy[calib::kRotationCount][3] = {
    {0, 0, 0},  //  0 NONE
    {0, 0, 45},  //  1 YAW_45
    {0, 0, 90},  //  2 YAW_90
    {0, 0, 135},  //  3 YAW_135
    {0, 0, 180},  //  4 YAW_180
    {0, 0, 225},  //  5 YAW_225
    {0, 0, 270},  //  6 YAW_270
    {0, 0, 315},  //  7 YAW_315
    {180, 0, 0},  //  8 ROLL_180
    {180, 0, 45},  //  9 ROLL_180_YAW_45
    {180, 0, 90},  // 10 ROLL_180_YAW_90
    {180, 0, 135},  // 11 ROLL_180_YAW_135
    {0, 180, 0},  // 12 PITCH_180
    {180, 0, 225},  // 13 ROLL_180_YAW_225
    {180, 0, 270},  // 14 ROLL_180_YAW_270
    {180, 0, 315},  // 15 ROLL_180_YAW_315
    {90, 0, 0},  // 16 ROLL_90
    {90, 0, 45},  // 17 ROLL_90_YAW_45
    {90, 0, 90},  // 18 ROLL_90_YAW_90
    {90, 0, 135},  // 19 ROLL_90_YAW_135
    {270, 0, 0},  // 20 ROLL_270
    {270, 0, 45},  // 21 ROLL_270_YAW_45
    {270, 0, 90},  // 22 ROLL_270_YAW_90
    {270, 0, 135},  // 23 ROLL_270_YAW_135
    {0, 90, 0},  // 24 PITCH_90
    {0, 270, 0},  // 25 PITCH_270
    {0, 180, 90},  // 26 PITCH_180_YAW_90
    {0, 180, 270},  // 27 PITCH_180_YAW_270
    {90, 90, 0},  // 28 ROLL_90_PITCH_90
    {180, 90, 0},  // 29 ROLL_180_PITCH_90
    {270, 90, 0},  // 30 ROLL_270_PITCH_90
    {90, 180, 0},  // 31 ROLL_90_PITCH_180
    {270, 180, 0},  // 32 ROLL_270_PITCH_180
    {90, 270, 0},  // 33 ROLL_90_PITCH_270
    {180, 270, 0},  // 34 ROLL_180_PITCH_270
    {270, 270, 0},  // 35 ROLL_270_PITCH_270
    {90, 180, 90},  // 36 ROLL_90_PITCH_180_YAW_90
    {90, 0, 270},  // 37 ROLL_90_YAW_270
};

// R = Rz(y) Ry(p) Rx(r) in double, rows.
void reference(const int rpy[3], double m[3][3]) {
    const double d = 3.14159265358979323846 / 180.0;
    const double cr = cos(rpy[0] * d), sr = sin(rpy[0] * d), cp = cos(rpy[1] * d), sp = sin(rpy[1] * d),
                 cy = cos(rpy[2] * d), sy = sin(rpy[2] * d);
    const double r[3][3] = {{cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr},
                            {sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr},
                            {-sp, cp * sr, cp * cr}};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m[i][j] = r[i][j];
}

TEST(BoardFrame, EveryRotationIsArduPilotsMatrix) {
    const double v[3] = {1000.0, -2000.0, 3000.0};
    for (uint8_t r = 0; r < calib::kRotationCount; ++r) {
        double m[3][3];
        reference(kRpy[r], m);
        double want[3];
        for (int i = 0; i < 3; ++i) want[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
        Vector3i vi((int16_t)v[0], (int16_t)v[1], (int16_t)v[2]);
        calib::rotate(r, vi);
        EXPECT_NEAR(vi.x, want[0], 1.0) << "rotation " << (int)r;
        EXPECT_NEAR(vi.y, want[1], 1.0) << "rotation " << (int)r;
        EXPECT_NEAR(vi.z, want[2], 1.0) << "rotation " << (int)r;
        Vector3f vf((float)v[0], (float)v[1], (float)v[2]);
        calib::rotate(r, vf);
        EXPECT_NEAR(vf.x, want[0], 1e-3) << "rotation " << (int)r;
        EXPECT_NEAR(vf.y, want[1], 1e-3) << "rotation " << (int)r;
        EXPECT_NEAR(vf.z, want[2], 1e-3) << "rotation " << (int)r;
    }
}

TEST(BoardFrame, UnknownRotationAndFullScaleSaturate) {
    Vector3i v(1, 2, 3);
    calib::rotate(calib::kRotationCount, v);
    EXPECT_EQ(v.x, 1);
    EXPECT_EQ(v.z, 3);
    Vector3i full(-32768, -32768, -32768);
    calib::rotate(8, full);  // ROLL_180: y and z negated
    EXPECT_EQ(full.y, 32767);
    EXPECT_EQ(full.z, 32767);
    Vector3i pair(32767, -32767, 0);
    calib::rotate(1, pair);  // YAW_45: x' = (x - y)/sqrt2 = 46340 -> saturated
    EXPECT_EQ(pair.x, 32767);
    EXPECT_EQ(pair.y, 0);
}

TEST(BoardFrame, AccelOffsetThenScaleInTheBoardsAxesThenTurned) {
    const float per_count = 9.80665f / 2048.0f;
    const calib::BoardFrame f =
        calib::make_board_frame(Vector3f(0.3f, -0.2f, 0.5f), Vector3f(1.02f, 0.98f, 1.0f), 2, per_count);
    EXPECT_TRUE(f.accel_corrected);
    Vector3i a(1000, 500, -2048);
    calib::apply_accel(f, a);
    const float x = (1000 * per_count - 0.3f) * 1.02f, y = (500 * per_count + 0.2f) * 0.98f,
                z = (-2048 * per_count - 0.5f);
    // YAW_90: (x, y, z) -> (-y, x, z).
    EXPECT_NEAR(a.x * per_count, -y, 2 * per_count);
    EXPECT_NEAR(a.y * per_count, x, 2 * per_count);
    EXPECT_NEAR(a.z * per_count, z, 2 * per_count);
    // Out of range: not applied.
    EXPECT_FALSE(calib::make_board_frame(Vector3f(5.0f, 0, 0), Vector3f(1, 1, 1), 0, per_count).accel_corrected);
    EXPECT_FALSE(calib::make_board_frame(Vector3f(), Vector3f(1, 1, 1), 0, per_count).accel_corrected);
}

TEST(BoardFrame, SmallSinCosWithinTheTrimsRange) {
    for (float x = -0.1745f; x <= 0.1746f; x += 0.005f) {
        float s, c;
        calib::small_sin_cos(x, s, c);
        EXPECT_NEAR(s, sinf(x), 2e-7f);
        EXPECT_NEAR(c, cosf(x), 2e-7f);
    }
}

TEST(BoardFrame, LevelTrimIsTheBoardsRollAndPitch) {
    // A board rolled 2 deg and pitched 3 deg on a level airframe: f = -R^T g.
    const float r = 2.0f * linalg::kRadPerDeg, p = 3.0f * linalg::kRadPerDeg, g = 9.80665f;
    const Vector3f f(g * sinf(p), -g * cosf(p) * sinf(r), -g * cosf(p) * cosf(r));
    float tx = 0, ty = 0;
    ASSERT_TRUE(calib::level_trim(f, tx, ty));
    EXPECT_NEAR(tx, r, 1e-6f);
    EXPECT_NEAR(ty, p, 1e-6f);
    // Beyond 10 deg, or no gravity: refused, untouched.
    tx = ty = 7.0f;
    EXPECT_FALSE(calib::level_trim(Vector3f(g * sinf(0.2f), 0, -g * cosf(0.2f)), tx, ty));
    EXPECT_FALSE(calib::level_trim(Vector3f(0, 0, 0), tx, ty));
    EXPECT_FALSE(calib::level_trim(Vector3f(NAN, 0, -g), tx, ty));
    EXPECT_EQ(tx, 7.0f);
}

// The trimmed angles are those of R T^T: a board at the trim's attitude reads level, and
// any attitude reads as the airframe's, within 0.005 deg of the double computation.
TEST(BoardFrame, TrimmedAnglesAreTheAirframes) {
    const float tx = 2.0f * linalg::kRadPerDeg, ty = 3.0f * linalg::kRadPerDeg;
    const calib::TrimQ14 t = calib::trim_q14(tx, ty);
    ASSERT_TRUE(t.active);
    EXPECT_FALSE(calib::trim_q14(0.0f, 0.0f).active);
    const float cases[][3] = {{0, 0, 0}, {10, -5, 30}, {-40, 20, -120}, {60, 70, 200}, {0, -85, 10}};
    for (const auto& c : cases) {
        const float d = linalg::kRadPerDeg;
        // The airframe at c; the board turned by T in it: R_board = R_vehicle T.
        const linalg::Matrix3f rv = dcm::dcm_from_euler(c[0] * d, c[1] * d, c[2] * d);
        const linalg::Matrix3f tm = dcm::dcm_from_euler(tx, ty, 0.0f);
        const linalg::Matrix3f rb = rv * tm;
        const dcm::EulerQ24 e = dcm::euler_carried_trimmed_q24(linalg::q30_from_matrix(rb), 0, 0, 0, t.t);
        const dcm::EulerAngles a = dcm::euler_in_rad(e);
        EXPECT_NEAR(a.roll_rad / d, c[0], 0.005f) << c[0] << " " << c[1] << " " << c[2];
        EXPECT_NEAR(a.pitch_rad / d, c[1], 0.005f) << c[0] << " " << c[1] << " " << c[2];
        float yaw = a.yaw_rad / d - c[2];
        while (yaw > 180.0f) yaw -= 360.0f;
        while (yaw < -180.0f) yaw += 360.0f;
        EXPECT_NEAR(yaw, 0.0f, 0.005f) << c[0] << " " << c[1] << " " << c[2];
    }
}

// With an identity trim the trimmed path gives the untrimmed one's angles (a carried
// turn too).
TEST(BoardFrame, IdentityTrimIsTheUntrimmedPath) {
    const calib::TrimQ14 t = calib::trim_q14(0.0f, 0.0f);
    const linalg::Matrix3q30 r = linalg::q30_from_matrix(dcm::dcm_from_euler(0.3f, -0.2f, 1.0f));
    const int32_t th = linalg::fixed_from_float(0.01f, 26);
    const dcm::EulerQ24 a = dcm::euler_carried_q24(r, th, -th, th);
    const dcm::EulerQ24 b = dcm::euler_carried_trimmed_q24(r, th, -th, th, t.t);
    EXPECT_NEAR(a.roll_q24, b.roll_q24, 40);  // 40 / 2^24 rad: 0.00014 deg
    EXPECT_NEAR(a.pitch_q24, b.pitch_q24, 40);
    EXPECT_NEAR(a.yaw_q24, b.yaw_q24, 40);
}

}  // namespace
