// SPDX-License-Identifier: GPL-3.0-or-later
// The calibration record (lib/Calibration/SensorCalibration): applied in one place.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Calibration.h"
#include "calibration_test_support.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;
using namespace calib_test;

TEST(SensorCalibration, ApplyInOnePlace) {
    calib::Calibration c = calib::default_calibration();
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == kBias);
    c.gyro_bias_rad_s = kBias;
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == Vector3f());
    c.mag_offset_uT = Vector3f(10.0f, 0.0f, -5.0f);
    c.mag_scale = Vector3f(2.0f, 1.0f, 0.5f);
    EXPECT_TRUE(calib::apply_mag(c, Vector3f(11.0f, 3.0f, -1.0f)) == Vector3f(2.0f, 3.0f, 2.0f));
    // Cross terms: W is symmetric, rows (sx xy xz) (xy sy yz) (xz yz sz); then the
    // learned offset is subtracted.
    c.mag_cross = Vector3f(0.25f, 0.5f, -0.25f);
    c.mag_learned_uT = Vector3f(1.0f, -1.0f, 0.5f);
    EXPECT_TRUE(calib::apply_mag(c, Vector3f(11.0f, 3.0f, -1.0f)) ==
                Vector3f(2.0f + 0.75f + 2.0f - 1.0f, 0.25f + 3.0f - 1.0f + 1.0f, 0.5f - 0.75f + 2.0f - 0.5f));
    EXPECT_TRUE(calib::is_plausible(c));
    c.mag_scale.x = 5.0f;
    EXPECT_FALSE(calib::is_plausible(c));
    c.mag_scale.x = 1.0f;
    c.mag_cross.y = 0.7f;
    EXPECT_FALSE(calib::is_plausible(c));
    c.mag_cross.y = 0.0f;
    c.mag_learned_uT.z = std::nanf("");
    EXPECT_FALSE(calib::is_plausible(c));
}
