// SPDX-License-Identifier: GPL-3.0-or-later
// The `cal mag` run as a ground station drives it (firmware/MagCalLink: DO_START_MAG_CAL,
// ACCEPT, CANCEL): a result held for accept and not used until then, accepted, cancelled,
// the state and progress it reports; a calibration set from outside (a parameter).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "Pipeline.h"
#include "pipeline_test_support.h"

namespace {

using linalg::Vector3f;
using pipeline::MagCalState;
using pipeline_test::imu;
using pipeline_test::kLevel;
using pipeline_test::LoggedPipeline;

const Vector3f kGyro(0.02f, -0.01f, 0.005f);
const Vector3f kHardIron_uT(8.0f, -5.0f, 3.0f);
constexpr int kRunSteps = (calib::kMagCalSeconds + 2) * 200;  // the collection, then 2 s for the fit

// Running, with the compass: 250 still steps.
void start(pipeline::AttitudePipeline& p) {
    p.set_mag_present(true);
    for (int i = 0; i < 250; ++i) p.on_imu_sample(imu(kGyro, kLevel));
}

// A 45 uT field seen from every direction (a spiral over the sphere, 10 turns) plus the hard
// iron, a sample every third step, for `steps` steps; the progress at each 5 s kept.
void tumble(pipeline::AttitudePipeline& p, int steps, uint8_t* pct_each_5s = nullptr) {
    for (int i = 0; i < steps; ++i) {
        const float s = (float)i / (float)(calib::kMagCalSeconds * 200);  // 0..1 over the run
        const float z = 1.0f - 2.0f * std::fmod(s, 1.0f), r = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
        const float a = 20.0f * 3.14159265f * s;
        if (i % 3 == 0) p.on_mag_sample(Vector3f(r * std::cos(a), r * std::sin(a), z) * 45.0f + kHardIron_uT);
        p.on_imu_sample(imu(kGyro, kLevel));
        if (pct_each_5s != nullptr && i % 1000 == 999 && i < 6000) pct_each_5s[i / 1000] = p.mag_cal_progress_pct();
    }
}

TEST(PipelineMagCal, HeldResultIsUsedOnlyWhenAccepted) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    start(p);
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kNone);
    EXPECT_EQ(p.mag_cal_progress_pct(), 0u);
    p.start_mag_calibration(true);
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kCollecting);
    uint8_t pct[6] = {};
    tumble(p, kRunSteps, pct);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(pct[i], (uint8_t)(100 * (i + 1) * 5 / calib::kMagCalSeconds - (i == 5)))
        << "the collection's time, percent, at " << (i + 1) * 5 << " s";
    ASSERT_EQ(p.mag_cal_state(), MagCalState::kWaiting) << logged.log;
    EXPECT_EQ(p.mag_cal_progress_pct(), 100u);
    EXPECT_EQ(p.mag_calibrator().cells_seen(), (1u << calib::MagCalibrator::kCells) - 1u) << "every cell seen";
    // Not in use yet: the offset is the default, the compass not flagged calibrated.
    EXPECT_TRUE(p.settings().cal.mag_offset_uT == Vector3f());
    EXPECT_EQ(p.settings().flags & settings::kFlagMagCalibrated, 0);
    EXPECT_NE(logged.log.find("% (accept to use)"), std::string::npos) << logged.log;
    EXPECT_NEAR(p.mag_calibrator().offset_uT().x, 8.0f, 0.05f);
    ASSERT_TRUE(p.accept_mag_calibration());
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kApplied);
    EXPECT_NEAR(p.settings().cal.mag_offset_uT.x, 8.0f, 0.05f);
    EXPECT_NEAR(p.settings().cal.mag_offset_uT.y, -5.0f, 0.05f);
    EXPECT_NEAR(p.settings().cal.mag_offset_uT.z, 3.0f, 0.05f);
    EXPECT_NE(p.settings().flags & settings::kFlagMagCalibrated, 0);
    EXPECT_FALSE(p.accept_mag_calibration()) << "nothing waits any more";
    // The field now read through the new calibration: 45 uT.
    tumble(p, 30);
    EXPECT_NEAR(p.field_uT().length(), 45.0f, 0.3f);
}

TEST(PipelineMagCal, CancelKeepsTheCalibrationInUse) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    start(p);
    p.start_mag_calibration(true);
    tumble(p, 2000);
    p.cancel_mag_calibration();
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kNone);
    EXPECT_FALSE(p.mag_calibrating());
    tumble(p, kRunSteps);
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kNone) << "no fit after a cancel";
    // A result waiting, cancelled: never used.
    p.start_mag_calibration(true);
    tumble(p, kRunSteps);
    ASSERT_EQ(p.mag_cal_state(), MagCalState::kWaiting);
    p.cancel_mag_calibration();
    EXPECT_FALSE(p.accept_mag_calibration());
    EXPECT_TRUE(p.settings().cal.mag_offset_uT == Vector3f());
    EXPECT_EQ(p.settings().flags & settings::kFlagMagCalibrated, 0);
    // Without hold (`cal mag`, autosave) the result is in use at once.
    p.start_mag_calibration();
    tumble(p, kRunSteps);
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kApplied);
    EXPECT_NEAR(p.settings().cal.mag_offset_uT.y, -5.0f, 0.05f);
    EXPECT_NE(logged.log.find("% (save to keep)"), std::string::npos) << logged.log;
}

TEST(PipelineMagCal, FailedRunSaysSoAndChangesNothing) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    start(p);
    p.start_mag_calibration(true);
    for (int i = 0; i < kRunSteps; ++i) p.on_imu_sample(imu(kGyro, kLevel));  // no compass samples
    EXPECT_EQ(p.mag_cal_state(), MagCalState::kFailed);
    EXPECT_EQ(p.mag_calibrator().quality(), calib::MagCalibrator::Quality::TooFewSamples);
    EXPECT_FALSE(p.accept_mag_calibration());
    EXPECT_EQ(p.settings().flags & settings::kFlagMagCalibrated, 0);
}

// A calibration set as parameters (COMPASS_OFS_* ...) is in use from the next sample, the
// learned offset cleared and the compass flagged calibrated, as after `cal mag`.
TEST(PipelineMagCal, CalibrationTakenFromOutside) {
    LoggedPipeline logged;
    pipeline::AttitudePipeline& p = logged.p;
    start(p);
    p.settings().cal.mag_learned_uT = Vector3f(1.0f, 2.0f, 3.0f);
    p.settings().cal.mag_offset_uT = kHardIron_uT;
    p.take_mag_calibration();
    EXPECT_TRUE(p.settings().cal.mag_learned_uT == Vector3f());
    EXPECT_NE(p.settings().flags & settings::kFlagMagCalibrated, 0);
    p.on_mag_sample(Vector3f(45.0f, 0.0f, 0.0f) + kHardIron_uT);
    p.on_imu_sample(imu(kGyro, kLevel));
    EXPECT_NEAR(p.field_uT().x, 45.0f, 0.1f);
    EXPECT_NEAR(p.field_uT().y, 0.0f, 0.1f);
}

}  // namespace

namespace {

// COMPASS_USE 0: the field does not turn the heading (the gyro's alone), `cal mag` still
// collects; COMPASS_LEARN 0: a board turning with hard iron learns no offset.
TEST(PipelineMagCal, CompassUseAndLearnSwitches) {
    for (const int use : {1, 0}) {
        LoggedPipeline logged;
        pipeline::AttitudePipeline& p = logged.p;
        p.settings().vehicle.compass_use = (uint8_t)use;
        start(p);
        // The field says north is 90 deg away: with the compass the heading goes there.
        for (int i = 0; i < 2000; ++i) {
            if (i % 3 == 0) p.on_mag_sample(Vector3f(0.0f, -20.0f, 40.0f));
            p.on_imu_sample(imu(kGyro, kLevel));
        }
        const float h = p.angles().heading_deg;
        if (use == 1) EXPECT_NEAR(h, 90.0f, 2.0f);
        else EXPECT_LT(std::fabs(h > 180.0f ? h - 360.0f : h), 1.0f) << "the gyro's heading from the start";
        p.start_mag_calibration();
        tumble(p, 300);
        EXPECT_GT(p.mag_calibrator().count(), 50u) << "cal mag collects with COMPASS_USE " << use;
    }
    for (const int learn : {1, 0}) {
        LoggedPipeline logged;
        pipeline::AttitudePipeline& p = logged.p;
        p.settings().vehicle.compass_learn = (uint8_t)learn;
        start(p);
        // Turning about down at 1 rad/s (the gyro says so), the field turning with it, hard iron on top.
        const Vector3f rate(0.0f, 0.0f, 1.0f);
        for (int i = 0; i < 20 * 200; ++i) {
            const float a = -(float)i * 0.005f;
            if (i % 3 == 0) p.on_mag_sample(Vector3f(20.0f * std::cos(a), 20.0f * std::sin(a), 40.0f) + kHardIron_uT);
            p.on_imu_sample(imu(kGyro + rate, kLevel));
        }
        const float learned = p.settings().cal.mag_learned_uT.length();
        if (learn == 1) EXPECT_GT(learned, 5.0f) << "the hard iron learned";
        else EXPECT_EQ(learned, 0.0f);
    }
}

}  // namespace
