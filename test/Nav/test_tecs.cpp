// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/Tecs: the height filter (no lag on a steady climb), the energy balance's signs
// (height up: pitch and throttle up; speed up: throttle up, pitch down; without airspeed
// the speed demand leaves the pitch alone), the bank's extra throttle, the limits, the
// takeoff, and closed loops on a point mass: a steady climb at TECS_CLMB_MAX with the
// speed held, a new height held without an airspeed sensor.
#include <gtest/gtest.h>

#include <math.h>

#include "PointMass.h"
#include "Tecs.h"

namespace {

nav::TecsInput cruise_input(float height_dem_m, float eas_dem_m_s, const testplane::PointMass& m, bool airspeed) {
    return testplane::tecs_input(m, height_dem_m, eas_dem_m_s, airspeed);
}

struct Flight {
    nav::TecsParams params = testplane::airframe_tecs_params();
    nav::Tecs tecs{params};
    testplane::PointMass plane;
    float t_s = 0.0f;

    // 50 Hz filters and aeroplane, 10 Hz TECS, for `seconds`; `each` after each 10 Hz step.
    template <class F>
    void fly(float seconds, float height_dem_m, float eas_dem_m_s, bool airspeed, F each) {
        const float dt = 0.02f;
        for (int i = 0; i < (int)(seconds / dt + 0.5f); ++i) {
            tecs.update_50hz(plane.height_m, plane.accel_up_m_s2, plane.accel_fwd_m_s2, dt);
            if (i % 5 == 0) {
                tecs.update_pitch_throttle(cruise_input(height_dem_m, eas_dem_m_s, plane, airspeed), 0.1f);
                each();
            }
            plane.step(tecs.pitch_dem_rad(), 0.0f, tecs.throttle_dem(), dt);
            t_s += dt;
        }
    }
    void fly(float seconds, float height_dem_m, float eas_dem_m_s, bool airspeed) {
        fly(seconds, height_dem_m, eas_dem_m_s, airspeed, [] {});
    }
};

TEST(Tecs, HeightFilterFollowsASteadyClimbWithoutLag) {
    nav::Tecs tecs(nav::kTecsDefaults);
    for (int i = 0; i <= 500; ++i) tecs.update_50hz(2.0f * 0.02f * (float)i, 0.0f, 0.0f, 0.02f);
    EXPECT_NEAR(tecs.climb_rate_m_s(), 2.0f, 0.01f);
    // Backward Euler (as AP_TECS) puts the height one sample ahead: 2 m/s x 0.02 s.
    EXPECT_NEAR(tecs.height_m(), 20.04f, 0.005f);
}

TEST(Tecs, HeightFilterPolesAtHgtOmega) {
    // A 1 m step of the barometer at rest: with all three poles at w the estimate is
    // 1 - exp(-w t) (1 - 2 w t + (w t)^2 / 2): 1.184 at w t = 1 (an overshoot), 0.983 at 6.
    nav::Tecs tecs(nav::kTecsDefaults);  // TECS_HGT_OMEGA 3
    tecs.update_50hz(0.0f, 0.0f, 0.0f, 0.02f);
    float at_third = 0.0f;
    for (int i = 1; i <= 100; ++i) {
        tecs.update_50hz(1.0f, 0.0f, 0.0f, 0.02f);
        if (i == 17) at_third = tecs.height_m();  // t = 0.34 s
    }
    EXPECT_NEAR(at_third, 1.0f + 0.184f, 0.03f);
    EXPECT_NEAR(tecs.height_m(), 0.983f, 0.01f);
}

TEST(Tecs, IntegratorsTakeOutATrimError) {
    // The airframe needs 45 % to cruise level, TRIM_THROTTLE says 35, and it flies 3 deg
    // nose up at zero flight path: the throttle and pitch integrators find both.
    Flight f;
    f.params.trim_throttle_pct = 35;
    f.tecs.set_params();
    f.plane.alpha_rad = 0.0524f;
    f.fly(150.0f, 100.0f, 15.0f, true);
    float worst_h = 0.0f, worst_v = 0.0f;
    f.fly(30.0f, 100.0f, 15.0f, true, [&] {
        worst_h = fmaxf(worst_h, fabsf(f.plane.height_m - 100.0f));
        worst_v = fmaxf(worst_v, fabsf(f.plane.tas_m_s - 15.0f));
    });
    EXPECT_LT(worst_h, 0.3f);
    EXPECT_LT(worst_v, 0.2f);
}

TEST(Tecs, EnergyBalanceSigns) {
    // Trimmed level at 100 m and 15 m/s, then one demand changed at a time.
    Flight base;
    base.fly(60.0f, 100.0f, 15.0f, true);
    ASSERT_NEAR(base.plane.height_m, 100.0f, 0.5f);
    ASSERT_NEAR(base.plane.tas_m_s, 15.0f, 0.3f);
    const float pitch0 = base.tecs.pitch_dem_rad(), thr0 = base.tecs.throttle_dem();

    Flight up = base;
    up.fly(1.0f, 120.0f, 15.0f, true);
    EXPECT_GT(up.tecs.pitch_dem_rad(), pitch0 + 0.01f);
    EXPECT_GT(up.tecs.throttle_dem(), thr0 + 0.05f);

    Flight faster = base;
    faster.fly(1.0f, 100.0f, 20.0f, true);
    EXPECT_LT(faster.tecs.pitch_dem_rad(), pitch0 - 0.005f);
    EXPECT_GT(faster.tecs.throttle_dem(), thr0 + 0.05f);

    // Without airspeed the pitch holds the height only: a speed demand changes nothing.
    Flight no_pitot;
    no_pitot.fly(60.0f, 100.0f, 15.0f, false);
    Flight no_pitot_faster = no_pitot;
    no_pitot.fly(1.0f, 100.0f, 15.0f, false);
    no_pitot_faster.fly(1.0f, 100.0f, 20.0f, false);
    EXPECT_FLOAT_EQ(no_pitot.tecs.pitch_dem_rad(), no_pitot_faster.tecs.pitch_dem_rad());
    EXPECT_FLOAT_EQ(no_pitot.tecs.throttle_dem(), no_pitot_faster.tecs.throttle_dem());
}

TEST(Tecs, ThrottleWithoutAirspeedFromTrimPitchAndBank) {
    nav::Tecs tecs(nav::kTecsDefaults);
    testplane::PointMass m;
    for (int i = 0; i < 5; ++i) tecs.update_50hz(100.0f, 0.0f, 0.0f, 0.02f);
    nav::TecsInput in = cruise_input(100.0f, 15.0f, m, false);
    tecs.update_pitch_throttle(in, 0.1f);
    // Level, on the height, wings level: TRIM_THROTTLE.
    EXPECT_NEAR(tecs.throttle_dem(), 0.45f, 1e-4f);
    EXPECT_EQ(tecs.throttle_pct(), 45u);
    // 45 deg of bank: (1/cos^2 - 1) = 1, times TECS_RLL2THR 10 in energy rate, at the
    // throttle per energy rate (THR_MAX - THR_MIN) / ((CLMB_MAX + SINK_MIN) g) = 0.75 / 68.6.
    in.cos_bank_sq = 0.5f;
    tecs.update_pitch_throttle(in, 0.1f);
    EXPECT_NEAR(tecs.throttle_dem(), 0.45f + 10.0f * 0.75f / (7.0f * 9.80665f), 2e-3f);
    // 70 deg: beyond THR_MAX, held there.
    in.cos_bank_sq = 0.117f;
    tecs.update_pitch_throttle(in, 0.1f);
    EXPECT_EQ(tecs.throttle_pct(), 75u);
    // A pitch demand at LIM_PITCH_MAX gives THR_MAX: far below the height demand.
    nav::Tecs climb(nav::kTecsDefaults);
    for (int i = 0; i < 5; ++i) climb.update_50hz(0.0f, 0.0f, 0.0f, 0.02f);
    in = cruise_input(1000.0f, 15.0f, m, false);
    for (int i = 0; i < 300; ++i) {
        climb.update_50hz(0.0f, 0.0f, 0.0f, 0.02f);
        climb.update_pitch_throttle(in, 0.1f);
    }
    EXPECT_EQ(climb.pitch_dem_cd(), 2000);  // LIM_PITCH_MAX
    EXPECT_EQ(climb.throttle_pct(), 75u);    // THR_MAX
}

TEST(Tecs, SteadyClimbAtClimbMaxWithTheSpeedHeld) {
    Flight f;
    f.fly(30.0f, 100.0f, 15.0f, true);
    // 100 m up at TECS_CLMB_MAX 4 m/s: 25 s of climbing; measured over its middle 10 s.
    float h_start = 0.0f, h_end = 0.0f, worst_speed_err = 0.0f;
    const float t0 = f.t_s;
    f.fly(30.0f, 200.0f, 15.0f, true, [&] {
        const float t = f.t_s - t0;
        if (fabsf(t - 8.0f) < 0.01f) h_start = f.plane.height_m;
        if (fabsf(t - 18.0f) < 0.01f) h_end = f.plane.height_m;
        if (t >= 8.0f && t < 18.0f) worst_speed_err = fmaxf(worst_speed_err, fabsf(f.plane.tas_m_s - 15.0f));
    });
    EXPECT_NEAR((h_end - h_start) / 10.0f, 4.0f, 0.2f);
    EXPECT_LT(worst_speed_err, 1.0f);
    f.fly(30.0f, 200.0f, 15.0f, true);
    EXPECT_NEAR(f.plane.height_m, 200.0f, 1.0f);
    EXPECT_NEAR(f.plane.tas_m_s, 15.0f, 0.3f);
}

TEST(Tecs, NewHeightHeldWithoutAirspeed) {
    Flight f;
    f.fly(30.0f, 100.0f, 15.0f, false);
    f.fly(60.0f, 130.0f, 15.0f, false);
    float worst = 0.0f;
    f.fly(30.0f, 130.0f, 15.0f, false, [&] { worst = fmaxf(worst, fabsf(f.plane.height_m - 130.0f)); });
    EXPECT_LT(worst, 1.0f);
    // Down 80 m: the demand sinks at TECS_SINK_MAX 5 m/s, and so does the aeroplane once
    // it follows (measured 6 s to 12 s into it).
    float h6 = 0.0f, h12 = 0.0f;
    int step = 0;
    f.fly(40.0f, 50.0f, 15.0f, false, [&] {
        if (step == 60) h6 = f.plane.height_m;
        if (step == 120) h12 = f.plane.height_m;
        ++step;
    });
    EXPECT_NEAR((h6 - h12) / 6.0f, 5.0f, 0.3f);
    EXPECT_NEAR(f.plane.height_m, 50.0f, 1.0f);
}

TEST(Tecs, UnderspeedAsksForTheLeastAirspeedAndSpeedFirst) {
    // 7 m/s on the pitot (below 0.9 ARSPD_FBW_MIN) while asked for 15 and 50 m up: full
    // throttle, then underspeed: the speed demand goes to ARSPD_FBW_MIN 9 m/s and the pitch
    // puts the speed first (nose down, the height demand above notwithstanding).
    nav::Tecs tecs(nav::kTecsDefaults);
    testplane::PointMass m;
    nav::TecsInput in = cruise_input(150.0f, 15.0f, m, true);
    in.eas_m_s = 7.0f;
    for (int i = 0; i < 5; ++i) tecs.update_50hz(100.0f, 0.0f, 0.0f, 0.02f);
    bool seen = false;
    for (int i = 0; i < 100; ++i) {
        tecs.update_50hz(100.0f, 0.0f, 0.0f, 0.02f);
        tecs.update_pitch_throttle(in, 0.1f);
        seen = seen || tecs.underspeed();
    }
    EXPECT_TRUE(seen);
    EXPECT_TRUE(tecs.underspeed());
    EXPECT_NEAR(tecs.tas_dem_adj_m_s(), 9.0f, 0.01f);
    EXPECT_EQ(tecs.throttle_pct(), 75u);
    EXPECT_LT(tecs.pitch_dem_rad(), 0.0f);
}

TEST(Tecs, TakeoffFullThrottleAndTheTakeoffPitch) {
    nav::Tecs tecs(nav::kTecsDefaults);
    testplane::PointMass m;
    m.tas_m_s = 12.0f;
    nav::TecsInput in = cruise_input(50.0f, 12.0f, m, false);
    in.stage = nav::TecsStage::kTakeoff;
    in.takeoff_pitch_cd = 1500;
    for (int i = 0; i < 50; ++i) {
        tecs.update_50hz(0.0f, 0.0f, 0.0f, 0.02f);
        tecs.update_pitch_throttle(in, 0.1f);
    }
    EXPECT_EQ(tecs.throttle_pct(), 75u);
    EXPECT_GE(tecs.pitch_dem_cd(), 1499);
    EXPECT_LE(tecs.pitch_dem_cd(), 2000);
    // With a pitot too (speed first).
    nav::Tecs pitot(nav::kTecsDefaults);
    in.have_airspeed = true;
    for (int i = 0; i < 50; ++i) {
        pitot.update_50hz(0.0f, 0.0f, 0.0f, 0.02f);
        pitot.update_pitch_throttle(in, 0.1f);
    }
    EXPECT_EQ(pitot.throttle_pct(), 75u);
    EXPECT_GE(pitot.pitch_dem_cd(), 1499);
}

TEST(Tecs, PitchDemandRateLimitedByVerticalAcceleration) {
    // From level, a huge height step: the pitch demand grows by at most
    // dt TECS_VERT_ACC / V per step (7 m/s^2 x 0.1 s / 15 m/s = 2.67 deg).
    nav::Tecs tecs(nav::kTecsDefaults);
    testplane::PointMass m;
    for (int i = 0; i < 5; ++i) tecs.update_50hz(100.0f, 0.0f, 0.0f, 0.02f);
    nav::TecsInput in = cruise_input(100.0f, 15.0f, m, true);
    tecs.update_pitch_throttle(in, 0.1f);
    float last = tecs.pitch_dem_rad();
    in.height_dem_m = 400.0f;
    float biggest = 0.0f;
    for (int i = 0; i < 20; ++i) {
        tecs.update_pitch_throttle(in, 0.1f);
        biggest = fmaxf(biggest, tecs.pitch_dem_rad() - last);
        last = tecs.pitch_dem_rad();
    }
    EXPECT_LE(biggest, 0.1f * 7.0f / 15.0f + 1e-5f);
    EXPECT_GT(biggest, 0.0f);
    EXPECT_LE(tecs.pitch_dem_cd(), 2000);
}

}  // namespace
