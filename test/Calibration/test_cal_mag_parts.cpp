// SPDX-License-Identifier: GPL-3.0-or-later
// `cal mag`'s fit in parts (lib/Calibration MagCalibrator::fit_part, run by lib/Pipeline
// a part a step): the same calibration as the fit at once, the verdict only after the
// parts, and nothing of the fit on the step that ends the 30 s.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "Calibration.h"
#include "Pipeline.h"
#include "PipelineText.h"
#include "../Pipeline/pipeline_test_support.h"

namespace {

using linalg::Vector3f;

using pipeline_test::imu;
using pipeline_test::kLevel;
using pipeline_test::LoggedPipeline;
const Vector3f kHardIron(8.0f, -5.0f, 3.0f);
const int kFitParts = calib::MagCalibrator::kFitParts;  // a value (EXPECT_* take references)

// The earth field (20, 0, 45) uT seen by a board turning about three axes at different
// rates (every direction within 30 s), with hard iron and 3 % soft iron on x.
Vector3f field_at(int step) {
    const float t = (float)step * 0.005f;
    const float a = 1.3f * t, b = 0.71f * t, c = 0.43f * t;
    Vector3f f(20.0f, 0.0f, 45.0f);
    f = Vector3f(cosf(a) * f.x - sinf(a) * f.y, sinf(a) * f.x + cosf(a) * f.y, f.z);
    f = Vector3f(cosf(b) * f.x + sinf(b) * f.z, f.y, -sinf(b) * f.x + cosf(b) * f.z);
    f = Vector3f(f.x, cosf(c) * f.y - sinf(c) * f.z, sinf(c) * f.y + cosf(c) * f.z);
    return Vector3f(1.03f * f.x, f.y, f.z) + kHardIron;
}

TEST(CalMagParts, PartsGiveTheFitAtOnce) {
    calib::MagCalibrator whole, parts;
    whole.restart(Vector3f());
    parts.restart(Vector3f());
    for (int i = 0; i < 6000; i += 3) {
        whole.add(field_at(i));
        parts.add(field_at(i));
    }
    calib::Calibration at_once = calib::default_calibration(), in_parts = calib::default_calibration();
    ASSERT_EQ(whole.finish(at_once), calib::MagCalibrator::Quality::Ok);
    parts.begin_fit();
    int n = 0;
    while (parts.fitting()) {
        parts.fit_part();
        ++n;
    }
    EXPECT_EQ(n, kFitParts);
    ASSERT_EQ(parts.quality(), calib::MagCalibrator::Quality::Ok);
    parts.result(in_parts);
    EXPECT_TRUE(in_parts.mag_offset_uT == at_once.mag_offset_uT);
    EXPECT_TRUE(in_parts.mag_scale == at_once.mag_scale);
    EXPECT_TRUE(in_parts.mag_cross == at_once.mag_cross);
    EXPECT_NEAR(in_parts.mag_offset_uT.x, kHardIron.x, 0.05f);
    EXPECT_NEAR(in_parts.mag_offset_uT.y, kHardIron.y, 0.05f);
    EXPECT_NEAR(in_parts.mag_offset_uT.z, kHardIron.z, 0.05f);
    EXPECT_NEAR(in_parts.mag_scale.y / in_parts.mag_scale.x, 1.03f, 0.002f);
    EXPECT_EQ(parts.count(), 2000);
}

TEST(CalMagParts, PipelineFitsAPartAStepAndThenGivesTheVerdict) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    std::string& log = logged.log;
    p.set_mag_present(true);
    int step = 0;
    auto one_step = [&] {
        if (step % 3 == 0) p.on_mag_sample(field_at(step));
        p.on_imu_sample(imu(Vector3f(), kLevel));
        ++step;
    };
    while (p.phase() != pipeline::Phase::Running) one_step();
    p.start_mag_calibration();
    const int collect_steps = calib::kMagCalSeconds * pipeline::kRateHz;
    for (int i = 0; i < collect_steps; ++i) one_step();
    // The 30 s are over: the fit has begun, nothing of its verdict yet.
    EXPECT_TRUE(p.mag_calibrating());
    EXPECT_EQ(log.find("# cal mag: offset"), std::string::npos);
    int fit_steps = 0;
    while (p.mag_calibrating() && fit_steps < 10 * kFitParts) {
        one_step();
        ++fit_steps;
    }
    EXPECT_FALSE(p.mag_calibrating());
    // A part on a step with room, the verdict on the one after the last.
    EXPECT_GT(fit_steps, kFitParts);
    EXPECT_LT(fit_steps, 4 * kFitParts);
    EXPECT_NE(log.find("# cal mag: offset 8.00 -5.00 3.00 uT"), std::string::npos) << log;
    EXPECT_NEAR(p.settings().cal.mag_offset_uT.x, kHardIron.x, 0.05f);
    EXPECT_TRUE(p.settings().flags & settings::kFlagMagCalibrated);
    // The latest field is calibrated with the new calibration at once (kept in the DCM's
    // integer form: within 1/32 uT an axis of it, where the old calibration is 8 uT off).
    const Vector3f expected = calib::apply_mag(p.settings().cal, field_at((step - 1) / 3 * 3));
    EXPECT_NEAR((p.field_uT() - expected).length(), 0.0f, 0.055f);
}

}  // namespace
