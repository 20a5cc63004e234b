// SPDX-License-Identifier: GPL-3.0-or-later
// The board in its airframe through the pipeline: AHRS_ORIENTATION turns the samples,
// the level calibration sets AHRS_TRIM and the angles and quaternion are the airframe's,
// INS_ACC* correct the accelerometer, the six positions' flow.
#include <gtest/gtest.h>

#include <math.h>

#include "pipeline_test_support.h"

namespace {

using linalg::Vector3f;
using pipeline_test::imu;
using pipeline_test::LoggedPipeline;

constexpr float kG = 9.80665f;

Vector3f force(float roll_deg, float pitch_deg) {
    const float r = roll_deg * linalg::kRadPerDeg, p = pitch_deg * linalg::kRadPerDeg;
    return Vector3f(kG * sinf(p), -kG * cosf(p) * sinf(r), -kG * cosf(p) * cosf(r));
}

TEST(PipelineBoardFrame, LevelCalibrationTrimsTheAnglesAndTheQuaternion) {
    LoggedPipeline l;
    const mpu6000::Sample s = imu(Vector3f(), force(2.0f, 3.0f));
    for (int i = 0; i < 400; ++i) l.p.on_imu_sample(s);
    EXPECT_NEAR(l.p.angles().roll_deg, 2.0f, 0.05f);
    EXPECT_NEAR(l.p.angles().pitch_deg, 3.0f, 0.05f);
    ASSERT_TRUE(l.p.start_level_calibration());
    EXPECT_FALSE(l.p.start_level_calibration()) << "one at a time";
    for (int i = 0; i < 300; ++i) l.p.on_imu_sample(s);
    EXPECT_FALSE(l.p.level_calibrating());
    EXPECT_NE(l.log.find("# cal level: trim roll "), std::string::npos) << l.log;
    EXPECT_NEAR(l.p.settings().vehicle.ahrs_trim_x_rad * linalg::kDegPerRad, 2.0f, 0.05f);
    EXPECT_NEAR(l.p.settings().vehicle.ahrs_trim_y_rad * linalg::kDegPerRad, 3.0f, 0.05f);
    EXPECT_NEAR(l.p.angles().roll_deg, 0.0f, 0.05f);
    EXPECT_NEAR(l.p.angles().pitch_deg, 0.0f, 0.05f);
    EXPECT_NEAR(l.p.angles_centideg().pitch_centideg, 0, 5);
    const linalg::Quaternion q = l.p.quaternion();  // level: no x or y part
    EXPECT_NEAR(q.x, 0.0f, 5e-4f);
    EXPECT_NEAR(q.y, 0.0f, 5e-4f);
}

TEST(PipelineBoardFrame, LevelCalibrationRefusesAMovingBoard) {
    LoggedPipeline l;
    for (int i = 0; i < 400; ++i) l.p.on_imu_sample(imu(Vector3f(), force(2.0f, 3.0f)));
    ASSERT_TRUE(l.p.start_level_calibration());
    for (int i = 0; i < 300; ++i)
        l.p.on_imu_sample(imu(Vector3f(0.3f * sinf(0.05f * i), 0.0f, 0.0f), force(2.0f + 5.0f * sinf(0.05f * i), 3.0f)));
    EXPECT_NE(l.log.find("# error: cal level: board moved"), std::string::npos) << l.log;
    EXPECT_EQ(l.p.settings().vehicle.ahrs_trim_x_rad, 0.0f);
}

TEST(PipelineBoardFrame, OrientationTurnsTheBoardsSamplesIntoTheAirframes) {
    // The board upside down (ROLL_180) in a level airframe reads +g on z: with
    // AHRS_ORIENTATION 8 the airframe reads level.
    pipeline::AttitudePipeline p;
    p.settings().vehicle.ahrs_orientation = 8;
    for (int i = 0; i < 400; ++i) p.on_imu_sample(imu(Vector3f(), Vector3f(0.0f, 0.0f, kG)));
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.05f);
    EXPECT_NEAR(p.accel_m_s2().z, -kG, 0.01f);
    // A change restarts the estimator: now as the arrow says, it reads upside down.
    p.settings().vehicle.ahrs_orientation = 0;
    p.refresh_board_frame();
    for (int i = 0; i < 400; ++i) p.on_imu_sample(imu(Vector3f(), Vector3f(0.0f, 0.0f, kG)));
    EXPECT_NEAR(fabsf(p.angles().roll_deg), 180.0f, 0.05f);
}

TEST(PipelineBoardFrame, AccelCalibrationAppliedToTheCounts) {
    pipeline::AttitudePipeline p;
    p.settings().vehicle.ins_accoffs_m_s2[0] = 0.5f;
    p.settings().vehicle.ins_accscal[2] = 1.1f;
    for (int i = 0; i < 10; ++i) p.on_imu_sample(imu(Vector3f(), Vector3f(0.5f, 0.0f, -kG / 1.1f)));
    EXPECT_NEAR(p.accel_m_s2().x, 0.0f, 0.01f);
    EXPECT_NEAR(p.accel_m_s2().z, -kG, 0.01f);
}

TEST(PipelineBoardFrame, SixPositionsFitTheAccelerometer) {
    LoggedPipeline l;
    const Vector3f offset(0.3f, -0.2f, 0.25f), scale(1.02f, 0.98f, 1.01f);
    auto sensed = [&](const Vector3f& f) {
        return imu(Vector3f(), Vector3f(scale.x * f.x + offset.x, scale.y * f.y + offset.y, scale.z * f.z + offset.z));
    };
    for (int i = 0; i < 400; ++i) l.p.on_imu_sample(sensed(force(0, 0)));
    ASSERT_TRUE(l.p.start_accel_calibration());
    EXPECT_NE(l.log.find("# Place vehicle level and press any key"), std::string::npos) << l.log;
    const float rp[6][2] = {{1, 2}, {-89, -3}, {91, 2}, {-2, -88}, {3, 89}, {178, -2}};
    // A wrong position first: refused and asked again.
    EXPECT_EQ(l.p.accel_position_asked(), 1);
    ASSERT_TRUE(l.p.confirm_accel_position(1));
    for (int i = 0; i < 250; ++i) l.p.on_imu_sample(sensed(force(-90, 0)));
    EXPECT_NE(l.log.find("not in that position"), std::string::npos) << l.log;
    EXPECT_EQ(l.p.accel_position_asked(), 1);
    EXPECT_FALSE(l.p.confirm_accel_position(2)) << "not the one asked";
    for (int k = 0; k < 6; ++k) {
        ASSERT_EQ(l.p.accel_position_asked(), k + 1) << l.log;
        ASSERT_TRUE(l.p.confirm_accel_position((uint8_t)(k + 1)));
        for (int i = 0; i < 250; ++i) l.p.on_imu_sample(sensed(force(rp[k][0], rp[k][1])));
    }
    for (int i = 0; i < 100 && l.p.accel_calibrating(); ++i) l.p.on_imu_sample(sensed(force(0, 0)));
    EXPECT_FALSE(l.p.accel_calibrating());
    EXPECT_NE(l.log.find("# Calibration successful"), std::string::npos) << l.log;
    const settings::VehicleSettings& v = l.p.settings().vehicle;
    EXPECT_NEAR(v.ins_accoffs_m_s2[0], 0.3f, 0.01f);
    EXPECT_NEAR(v.ins_accoffs_m_s2[1], -0.2f, 0.01f);
    EXPECT_NEAR(v.ins_accoffs_m_s2[2], 0.25f, 0.01f);
    EXPECT_NEAR(v.ins_accscal[0], 1.0f / 1.02f, 1e-3f);
    EXPECT_NEAR(v.ins_accscal[1], 1.0f / 0.98f, 1e-3f);
    EXPECT_NEAR(v.ins_accscal[2], 1.0f / 1.01f, 1e-3f);
    // In use at once: the level board's corrected force is g.
    l.p.on_imu_sample(sensed(force(0, 0)));
    EXPECT_NEAR(l.p.accel_m_s2().z, -kG, 0.01f);
}

}  // namespace
