// SPDX-License-Identifier: GPL-3.0-or-later
// GyroCalibrator (lib/Calibration): the gyro bias at rest, and what restarts it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Calibration.h"
#include "calibration_test_support.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;
using namespace calib_test;

TEST(GyroCalibrator, GyroBiasAtRestTakesOneSecond) {
    GyroCalibrator g;
    uint32_t s = 1;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    int n = 0;
    while (r != GyroCalibrator::Result::Done && n < 1000) {
        const Vector3f gyro = kBias + Vector3f(noise(s, 0.004f), noise(s, 0.004f), noise(s, 0.004f));
        const Vector3f acc = kLevel + Vector3f(noise(s, 0.05f), noise(s, 0.05f), noise(s, 0.05f));
        r = g.add(gyro, acc);
        ASSERT_NE(r, GyroCalibrator::Result::Moved);
        ++n;
    }
    EXPECT_EQ(n, calib::kGyroWindow);
    EXPECT_NEAR(g.bias().x, kBias.x, 0.001f);
    EXPECT_NEAR(g.bias().y, kBias.y, 0.001f);
    EXPECT_NEAR(g.bias().z, kBias.z, 0.001f);
    EXPECT_NEAR(g.mean_accel_m_s2().z, -9.80665f, 0.02f);
    EXPECT_EQ(g.restarts(), 0);
}

TEST(GyroCalibrator, GyroRestartsWhenTheBoardMoves) {
    GyroCalibrator g;
    for (int i = 0; i < 100; ++i) ASSERT_EQ(g.add(kBias, kLevel), GyroCalibrator::Result::Collecting);
    // A 10 deg/s twitch.
    EXPECT_EQ(g.add(kBias + Vector3f(0.0f, 0.0f, 0.17f), kLevel), GyroCalibrator::Result::Moved);
    EXPECT_EQ(g.restarts(), 1);
    EXPECT_EQ(g.count(), 0);
    // Then a full still second completes.
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(kBias, kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Done);
}

TEST(GyroCalibrator, GyroRestartsOnAccelChange) {
    GyroCalibrator g;
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Shaken: |a| 1.3 g.
    EXPECT_EQ(g.add(kBias, kLevel * 1.3f), GyroCalibrator::Result::Moved);
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Slowly tilting: |a| stays 1 g but an axis moves by 0.5 m/s^2.
    EXPECT_EQ(g.add(kBias, Vector3f(0.5f, 0.0f, -9.79f)), GyroCalibrator::Result::Moved);
    // NaN counts as movement, never as data.
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    EXPECT_EQ(g.add(Vector3f(std::nanf(""), 0.0f, 0.0f), kLevel), GyroCalibrator::Result::Moved);
    // So is a reading beyond the fine counts' range (16 m/s^2), held at the range's end,
    // even one whose counts would wrap round to the level board's: 32 m/s^2 above it.
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    EXPECT_EQ(g.add(kBias, Vector3f(kLevel.x, kLevel.y, kLevel.z + 32.0f)), GyroCalibrator::Result::Moved);
}

TEST(GyroCalibrator, SteadySpinIsNotABias) {
    GyroCalibrator g;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(Vector3f(0.0f, 0.0f, 1.0f), kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Moved);
    EXPECT_FALSE(g.done());
}

// A gyro or accel axis may spread by exactly its limit in counts (the limit over the
// scale, truncated) and the window is still; one count more and the board moved.
TEST(GyroCalibrator, GyroSpreadUpToItsLimitExactlyIsStill) {
    const float gyro_scale = 0.001f, accel_scale = 0.005f;  // rad/s and m/s^2 per count
    const int16_t gyro_limit = (int16_t)(calib::kGyroSpreadMax_rad_s / gyro_scale);
    const int16_t accel_limit = (int16_t)(calib::kAccelSpreadMax_m_s2 / accel_scale);
    const int16_t g_counts = (int16_t)std::lround(9.80665f / accel_scale);
    for (int axis = 0; axis < 6; ++axis) {
        for (int16_t beyond : {0, 1}) {
            const int16_t step = (int16_t)((axis < 3 ? gyro_limit : accel_limit) + beyond);
            GyroCalibrator cal;
            GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
            for (int i = 0; i < calib::kGyroWindow && r == GyroCalibrator::Result::Collecting; ++i) {
                int16_t v[6] = {0, 0, 0, 0, 0, g_counts};
                if (i & 1) v[axis] = (int16_t)(v[axis] + step);
                r = cal.add(linalg::Vector3i(v[0], v[1], v[2]), linalg::Vector3i(v[3], v[4], v[5]), gyro_scale, accel_scale);
            }
            EXPECT_EQ(r, beyond ? GyroCalibrator::Result::Moved : GyroCalibrator::Result::Done) << axis << " " << beyond;
        }
    }
}
