// SPDX-License-Identifier: GPL-3.0-or-later
// The pipeline's GPS entry (AttitudePipeline::on_gps_fix): which fixes aid the estimator
// (AHRS_GPS_USE, AHRS_GPS_MINSATS, a 3D fix), the velocity turned into the estimator's
// magnetic-north axes by the declination, the course as the heading without a compass.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Euler.h"
#include "GpsAid.h"
#include "GpsFix.h"
#include "Pipeline.h"
#include "pipeline_test_support.h"

namespace {

using linalg::Vector3f;
using pipeline_test::imu;
using pipeline_test::kLevel;

constexpr float kDeg = 3.14159265f / 180.0f;
constexpr float kG = 9.80665f;

// A board on the ground, then level and accelerating along a true bearing at 2 m/s^2 for
// 20 s (no turn: the accelerometer alone would read 11.5 deg of tilt), with a u-blox's
// fixes at 5 Hz (the velocity 0.2 s old). The field is the one of a level board heading
// north (its heading does not matter here: only its presence).
struct GpsRun {
    pipeline::AttitudePipeline p;
    gps::Fix fix;
    float bearing_deg = 0.0f;
    bool field = true;

    GpsRun() {
        fix.fix = gps::FixType::k3D;
        fix.sats = 10;
        fix.have_vertical_velocity = true;
    }
    void go(float seconds) {
        const float b = bearing_deg * kDeg;
        // The body's x axis along the bearing from true north; the field turned into the body.
        const float decl = p.settings().declination_deg() * kDeg;
        const float h = b - decl;  // the heading from magnetic north
        const Vector3f body_field(20.0f * std::cos(h), -20.0f * std::sin(h), 45.0f);
        p.set_mag_present(field);
        for (uint32_t i = 0; i < (uint32_t)(seconds * 200.0f); ++i) {
            const float t = (float)p.steps() * 0.005f;
            const float a = t > 5.0f ? 2.0f : 0.0f;
            if (field && i % 3 == 0) p.on_mag_sample(body_field);
            p.on_imu_sample(imu(Vector3f(), Vector3f(a, 0.0f, -kG)));
            if (p.steps() % 40 == 0) {
                const float t_then = t - 0.2f;
                const float v = 10.0f + (t_then > 5.0f ? 2.0f * (t_then - 5.0f) : 0.0f);
                fix.itow_ms += 200;
                fix.vel_ned_cm_s[0] = (int32_t)std::lround(100.0f * v * std::cos(b));
                fix.vel_ned_cm_s[1] = (int32_t)std::lround(100.0f * v * std::sin(b));
                fix.ground_speed_cm_s = (uint32_t)std::lround(100.0f * v);
                fix.course_e5 = (int32_t)std::lround(bearing_deg * 1e5f);
                p.on_gps_fix(fix);
            }
        }
    }
    float tilt_deg() const {
        const pipeline::Angles a = p.angles();
        return std::sqrt(a.roll_deg * a.roll_deg + a.pitch_deg * a.pitch_deg);
    }
};

TEST(PipelineGps, AUsableFixAidsTheEstimator) {
    GpsRun r;
    r.go(25.0f);
    EXPECT_TRUE(r.p.estimator().gps_aiding());
    EXPECT_LT(r.tilt_deg(), 0.5f);
}

TEST(PipelineGps, TooFewSatellitesA2dFixOrAhrsGpsUse0DoNot) {
    for (int c = 0; c < 3; ++c) {
        GpsRun r;
        if (c == 0) r.fix.sats = 5;  // AHRS_GPS_MINSATS 6
        if (c == 1) r.fix.fix = gps::FixType::k2D;
        if (c == 2) r.p.settings().flight.ahrs_gps_use = 0;
        r.go(25.0f);
        EXPECT_FALSE(r.p.estimator().gps_aiding()) << c;
        EXPECT_GT(r.tilt_deg(), 8.0f) << c;  // the acceleration read as pitch
    }
    GpsRun r;
    r.p.settings().flight.ahrs_gps_minsats = 5;
    r.fix.sats = 5;
    r.go(25.0f);
    EXPECT_TRUE(r.p.estimator().gps_aiding());
}

// The GPS's north is the true one, the estimator's the magnetic one: with 20 deg of
// declination and the acceleration along true bearing 60, a velocity taken unturned would
// leave 2 m/s^2 sin(20 deg) = 0.68 m/s^2 across the path: 4 deg of tilt.
TEST(PipelineGps, TheVelocityIsTurnedByTheDeclination) {
    GpsRun r;
    settings::set_declination_centideg(r.p.settings(), 2000);
    r.bearing_deg = 60.0f;
    r.go(25.0f);
    EXPECT_TRUE(r.p.estimator().gps_aiding());
    EXPECT_LT(r.tilt_deg(), 0.5f);
}

// Without a compass the course gives the heading (true bearing, declination applied on
// output as a compass's heading is).
TEST(PipelineGps, WithoutACompassTheCourseIsTheHeading) {
    GpsRun r;
    r.field = false;
    settings::set_declination_centideg(r.p.settings(), 500);
    r.bearing_deg = 120.0f;
    r.p.set_mag_present(false);
    r.go(10.0f);
    EXPECT_NEAR(r.p.angles().heading_deg, 120.0f, 0.5f);
}

}  // namespace

namespace {

// A level coordinated turn at 30 deg of bank from t = 5 s (rolled into at 15 deg/s) with
// the cruise speed set (TRIM_ARSPD_CM, grown in the bank as the firmware grows it: the
// speed here is that one, so the turn's term is right), the GPS's first fix at 15 s, in
// the turn. Its sums are paired with velocity changes: the turn's term the windows had
// taken off before the aiding began must go back into them, or the first observations
// take the centripetal acceleration off twice (30 deg of tilt, at the low-pass's pace).
TEST(PipelineGps, AidingThatStartsInATurnTakesOverWithoutAJump) {
    pipeline::AttitudePipeline p;
    p.set_mag_present(true);
    const float bank = 30.0f * kDeg, trim_m_s = 18.0f;
    const float speed = trim_m_s / std::sqrt(std::cos(bank));
    const float k = kG / speed, roll_rate = 15.0f * kDeg, ramp_s = bank / roll_rate;
    const auto bank_at = [&](float t) { return t <= 5.0f ? 0.0f : std::min(roll_rate * (t - 5.0f), bank); };
    const auto heading_at = [&](float t) {
        const float in_s = t - 5.0f;
        float h = in_s > 0.0f ? k * -std::log(std::cos(bank_at(t))) / roll_rate : 0.0f;
        if (in_s > ramp_s) h += k * std::tan(bank) * (in_s - ramp_s);
        return h;
    };
    gps::Fix fix;
    fix.fix = gps::FixType::k3D;
    fix.sats = 10;
    fix.have_vertical_velocity = true;
    float worst_before = 0.0f, worst_after = 0.0f;
    for (int i = 0; i < 60 * 200; ++i) {
        const float t = (float)p.steps() * 0.005f;
        const float b = bank_at(t), h = heading_at(t), rate = k * std::tan(b);
        const float p_rate = t > 5.0f && t - 5.0f < ramp_s ? roll_rate : 0.0f;
        const linalg::Matrix3f r = dcm::dcm_from_euler(b, 0.0f, h);
        if (i % 3 == 0) p.on_mag_sample(r.mul_transpose(Vector3f(20.0f, 0.0f, 45.0f)));
        if (p.steps() % 8 == 0) p.set_cruise_airspeed_m_s(trim_m_s);
        p.on_imu_sample(imu(Vector3f(p_rate, rate * std::sin(b), rate * std::cos(b)), Vector3f(0.0f, 0.0f, -kG / std::cos(b))));
        if (p.steps() % 40 == 0 && t >= 15.0f) {
            const float then = t - dcm::kGpsFixLatency_s, h_then = heading_at(then);
            fix.itow_ms += 200;
            fix.vel_ned_cm_s[0] = (int32_t)std::lround(100.0f * speed * std::cos(h_then));
            fix.vel_ned_cm_s[1] = (int32_t)std::lround(100.0f * speed * std::sin(h_then));
            fix.ground_speed_cm_s = (uint32_t)std::lround(100.0f * speed);
            p.on_gps_fix(fix);
        }
        if (t < 10.0f || !p.output_due()) continue;
        const float err = std::fabs(p.angles().roll_deg - b / kDeg);
        (t < 15.0f ? worst_before : worst_after) = std::max(t < 15.0f ? worst_before : worst_after, err);
    }
    EXPECT_TRUE(p.estimator().gps_aiding());
    EXPECT_LT(worst_before, 1.0f);  // the cruise speed's term
    EXPECT_LT(worst_after, 1.0f);   // the GPS's, from its first fix on
}

}  // namespace

namespace {

// A still board (or one carried at a walk) gets nothing from the GPS but its noise: the
// GPS aids only from 3 m/s of ground speed on, and stops below 1 m/s.
TEST(PipelineGps, AStillBoardIsNotAided) {
    pipeline::AttitudePipeline p;
    p.set_mag_present(true);
    gps::Fix fix;
    fix.fix = gps::FixType::k3D;
    fix.sats = 10;
    // Level, heading north at a steady speed for some seconds, a fix every 40 steps.
    const auto fly = [&](float speed_m_s, float seconds) {
        for (int i = 0; i < (int)(seconds * 200.0f); ++i) {
            if (i % 3 == 0) p.on_mag_sample(Vector3f(20.0f, 0.0f, 45.0f));
            p.on_imu_sample(imu(Vector3f(), kLevel));
            if (p.steps() % 40 != 0) continue;
            fix.itow_ms += 200;
            fix.vel_ned_cm_s[0] = (int32_t)std::lround(100.0f * speed_m_s);
            fix.ground_speed_cm_s = (uint32_t)std::lround(100.0f * speed_m_s);
            p.on_gps_fix(fix);
        }
    };
    fly(0.0f, 6.0f);
    EXPECT_FALSE(p.estimator().gps_aiding());  // still
    fly(2.0f, 2.0f);
    EXPECT_FALSE(p.estimator().gps_aiding());  // a walk
    fly(3.5f, 2.0f);
    EXPECT_TRUE(p.estimator().gps_aiding());   // moving
    fly(2.0f, 2.0f);
    EXPECT_TRUE(p.estimator().gps_aiding());   // slower, still moving
    fly(0.5f, 2.0f);
    EXPECT_FALSE(p.estimator().gps_aiding());  // stopped
}

}  // namespace
