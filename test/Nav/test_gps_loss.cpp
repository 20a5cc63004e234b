// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/GpsLoss: the dead reckoning after a lost fix, the wings level after it, the
// return, and what is said.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "GpsLoss.h"

namespace {

constexpr float kDegToRad = (float)(M_PI / 180.0);
constexpr float kDt_s = 0.1f;  // the navigation's 10 Hz

nav::NorthEast unit(float bearing_deg) { return {cosf(bearing_deg * kDegToRad), sinf(bearing_deg * kDegToRad)}; }
// The attitude's heading: centidegrees 0..35999.
uint16_t heading_cd(float deg) { return (uint16_t)lroundf(fmodf(fmodf(deg, 360.0f) + 360.0f, 360.0f) * 100.0f) % 36000u; }

// An aeroplane at a constant true airspeed turning at a constant rate in a steady wind,
// integrated finely (1 ms) for the truth.
struct Plane {
    float heading_deg;
    float rate_deg_s;
    float air_m_s;
    nav::NorthEast wind_m_s;
    nav::NorthEast pos_m;

    nav::NorthEast ground_velocity() const {
        const nav::NorthEast n = unit(heading_deg);
        return {air_m_s * n.north_m + wind_m_s.north_m, air_m_s * n.east_m + wind_m_s.east_m};
    }
    // In double: 10 000 float sums of 2 cm on 300 m would be off by ~0.1 m.
    void fly(float seconds) {
        double n = pos_m.north_m, e = pos_m.east_m, h = heading_deg;
        for (int i = 0; i < (int)lroundf(seconds * 1000.0f); ++i) {
            const double rad = h * M_PI / 180.0;
            n += (air_m_s * cos(rad) + wind_m_s.north_m) * 0.001;
            e += (air_m_s * sin(rad) + wind_m_s.east_m) * 0.001;
            h += rate_deg_s * 0.001;
        }
        pos_m = {(float)n, (float)e};
        heading_deg = (float)h;
    }
};

struct Step {
    nav::GpsLoss::Event event;
    nav::NorthEast pos_m;
    nav::NorthEast vel_m_s;
};

// One step as the firmware makes it: the navigator's position (frozen at `held` while the
// fix is lost) and velocity in, what to fly out.
Step step(nav::GpsLoss& loss, bool fix_ok, nav::NorthEast nav_pos, nav::NorthEast nav_vel, const Plane& p,
          const nav::NorthEast* wind_estimate, uint32_t now_ms) {
    Step s;
    s.pos_m = nav_pos;
    s.vel_m_s = nav_vel;
    s.event = loss.step(fix_ok, s.pos_m, s.vel_m_s, heading_cd(p.heading_deg), wind_estimate, kDt_s, (uint16_t)now_ms);
    return s;
}

float distance(nav::NorthEast a, nav::NorthEast b) { return hypotf(a.north_m - b.north_m, a.east_m - b.east_m); }

// Flies `plane` for the dead reckoning's 10 s after a loss at 60 s with the navigator
// frozen where the fix left it (its velocity the plane's, or `fix_vel`: an older one);
// returns the worst distance from the truth.
float dead_reckoning_error(Plane plane, const nav::NorthEast* wind_estimate, const nav::NorthEast* fix_vel = nullptr) {
    nav::GpsLoss loss;
    uint32_t now_ms = 60000;
    const nav::NorthEast frozen_pos = plane.pos_m, frozen_vel = fix_vel ? *fix_vel : plane.ground_velocity();
    const Step first = step(loss, false, frozen_pos, frozen_vel, plane, wind_estimate, now_ms);
    EXPECT_EQ(first.event, nav::GpsLoss::kLost);
    float worst = 0.0f;
    for (int i = 1; i < 100; ++i) {
        plane.fly(kDt_s);
        now_ms += 100;
        const Step s = step(loss, false, frozen_pos, frozen_vel, plane, wind_estimate, now_ms);
        EXPECT_EQ(s.event, nav::GpsLoss::kNone);
        EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kDeadReckoning) << i;
        worst = std::fmax(worst, distance(s.pos_m, plane.pos_m));
    }
    return worst;
}

TEST(GpsLoss, WithAFixTheNavigatorsPositionIsFlown) {
    nav::GpsLoss loss;
    const Plane p = {30.0f, 0.0f, 18.0f, {0.0f, 0.0f}, {120.0f, -40.0f}};
    for (uint32_t t = 0; t < 5000; t += 100) {
        const Step s = step(loss, true, p.pos_m, {15.0f, 9.0f}, p, nullptr, t);
        EXPECT_EQ(s.event, nav::GpsLoss::kNone);
        EXPECT_EQ(s.pos_m.north_m, 120.0f);
        EXPECT_EQ(s.vel_m_s.east_m, 9.0f);
    }
    EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kFix);
}

TEST(GpsLoss, StraightInAKnownWind) {
    // 18 m/s of air heading 30 deg, 5 m/s of wind blowing east, the estimate right.
    const Plane p = {30.0f, 0.0f, 18.0f, {0.0f, 5.0f}, {100.0f, 200.0f}};
    const nav::NorthEast wind = {0.0f, 5.0f};
    EXPECT_LT(dead_reckoning_error(p, &wind), 0.01f);
    // An estimate off by (-2, -2) m/s: its part across the nose, 0.73 m/s, carries the
    // position off (the part along it is taken off at the loss and added back).
    const nav::NorthEast wrong = {2.0f, 7.0f};
    EXPECT_NEAR(dead_reckoning_error(p, &wrong), 0.732f * 9.9f, 0.05f);
}

TEST(GpsLoss, StraightInAnUnknownWind) {
    // No wind estimate (no pitot): the last ground velocity carries the crab on.
    const Plane p = {30.0f, 0.0f, 18.0f, {0.0f, 5.0f}, {100.0f, 200.0f}};
    EXPECT_LT(dead_reckoning_error(p, nullptr), 0.01f);
}

TEST(GpsLoss, ATurnFollowsTheHeading) {
    // 9 deg/s (a 15-deg bank at 18 m/s) for the 10 s: 90 degrees of turn, a quarter circle of
    // 115 m radius. Each 10 Hz step flies the heading at its end: half a step's turn of lag,
    // V omega T dt / 2 = 1.4 m after the 10 s.
    const Plane calm = {0.0f, 9.0f, 18.0f, {0.0f, 0.0f}, {0.0f, 0.0f}};
    EXPECT_LT(dead_reckoning_error(calm, nullptr), 2.0f);
    // In a known wind, the same.
    const Plane windy = {0.0f, 9.0f, 18.0f, {3.0f, 4.0f}, {0.0f, 0.0f}};
    const nav::NorthEast wind = {3.0f, 4.0f};
    EXPECT_LT(dead_reckoning_error(windy, &wind), 2.0f);
    // Without the estimate the unknown wind turns with the aeroplane: off by the integral
    // of (e^(i omega t) - 1) w, |w| |(e^(i omega T) - 1) / (i omega) - T| = 5 x 7.3 = 37 m at
    // the end, where the position frozen would be 180 m off.
    const float unknown = dead_reckoning_error(windy, nullptr);
    EXPECT_GT(unknown, 30.0f);
    EXPECT_LT(unknown, 42.0f);
}

TEST(GpsLoss, LostInATurnTheFixsVelocityIsOlderThanTheHeading) {
    // The fix's velocity was measured 0.4 s before the loss's step (the receiver's 0.2 s and
    // the fix's age): 8 degrees behind the heading at 20 deg/s; the turn ends at the loss.
    const Plane p = {90.0f, 0.0f, 18.0f, {0.0f, 0.0f}, {0.0f, 0.0f}};
    const nav::NorthEast old_vel = {18.0f * cosf(82.0f * kDegToRad), 18.0f * sinf(82.0f * kDegToRad)};
    // With a wind estimate the air goes along the nose: 1 - cos 8 deg of the speed lost.
    const nav::NorthEast calm = {0.0f, 0.0f};
    EXPECT_LT(dead_reckoning_error(p, &calm, &old_vel), 0.01f * 180.0f + 0.1f);
    // Without, the 8 degrees are taken for a crab: sin 8 deg x 180 m = 25 m.
    EXPECT_NEAR(dead_reckoning_error(p, nullptr, &old_vel), 25.0f, 1.0f);
}

TEST(GpsLoss, WingsLevelAfterTenSecondsAndSaidOnce) {
    nav::GpsLoss loss;
    Plane p = {0.0f, 0.0f, 18.0f, {0.0f, 0.0f}, {0.0f, 0.0f}};
    int lost = 0, back = 0;
    nav::NorthEast last = {0.0f, 0.0f};
    for (uint32_t t = 0; t <= 30000; t += 100) {
        const Step s = step(loss, false, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, 65000u + t);
        lost += s.event == nav::GpsLoss::kLost;
        back += s.event == nav::GpsLoss::kBack;
        if (t < nav::GpsLoss::kDeadReckoning_ms) {
            EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kDeadReckoning) << t;  // across the uint16 wrap
            last = s.pos_m;
        } else {
            EXPECT_TRUE(loss.wings_level()) << t;
            EXPECT_EQ(s.pos_m.north_m, last.north_m);  // the last dead-reckoned one, never flown
        }
    }
    EXPECT_EQ(lost, 1);
    EXPECT_EQ(back, 0);
    EXPECT_NEAR(last.north_m, 9.9f * 18.0f, 0.01f);
}

TEST(GpsLoss, BackAfterASecondOfFixes) {
    nav::GpsLoss loss;
    const Plane p = {0.0f, 0.0f, 18.0f, {0.0f, 0.0f}, {0.0f, 0.0f}};
    uint32_t t = 0;
    for (; t < 20000; t += 100) step(loss, false, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, t);
    ASSERT_TRUE(loss.wings_level());
    for (uint8_t i = 1; i < nav::GpsLoss::kBackSteps; ++i, t += 100) {
        const Step s = step(loss, true, {500.0f, 20.0f}, {0.0f, 18.0f}, p, nullptr, t);
        EXPECT_EQ(s.event, nav::GpsLoss::kNone);
        EXPECT_TRUE(loss.wings_level());
    }
    const Step s = step(loss, true, {500.0f, 20.0f}, {0.0f, 18.0f}, p, nullptr, t);
    EXPECT_EQ(s.event, nav::GpsLoss::kBack);
    EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kFix);
    EXPECT_EQ(s.pos_m.north_m, 500.0f);  // the navigator's again
    EXPECT_EQ(s.vel_m_s.east_m, 18.0f);
    // Back during the dead reckoning too, then lost again: said again.
    EXPECT_EQ(step(loss, false, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, t + 100).event,
              nav::GpsLoss::kLost);
    for (uint8_t i = 1; i < nav::GpsLoss::kBackSteps; ++i)
        step(loss, true, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, t + 100u + 100u * i);
    EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kDeadReckoning);
    EXPECT_EQ(step(loss, true, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, t + 1100).event,
              nav::GpsLoss::kBack);
}

TEST(GpsLoss, AFixThatComesAndGoesIsNotBack) {
    nav::GpsLoss loss;
    const Plane p = {0.0f, 0.0f, 18.0f, {0.0f, 0.0f}, {0.0f, 0.0f}};
    int events = 0;
    for (uint32_t t = 0; t < 30000; t += 100) {
        const bool ok = t > 0 && (t / 100) % 9 != 0;  // 8 good steps, one bad, over and over
        events += step(loss, ok, {0.0f, 0.0f}, {18.0f, 0.0f}, p, nullptr, t).event != nav::GpsLoss::kNone;
    }
    EXPECT_EQ(events, 1);  // the loss, said once
    EXPECT_TRUE(loss.wings_level());
}

TEST(GpsLoss, ANaNIsNeverFlown) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    nav::GpsLoss loss;
    nav::NorthEast pos = {10.0f, 20.0f}, vel = {nan, 0.0f};
    EXPECT_EQ(loss.step(false, pos, vel, 0, nullptr, kDt_s, 0), nav::GpsLoss::kLost);
    EXPECT_TRUE(loss.wings_level());
    EXPECT_EQ(pos.north_m, 10.0f);
    // A NaN mid-way (the wind's): the last finite position kept, wings level.
    nav::GpsLoss later;
    vel = {18.0f, 0.0f};
    later.step(false, pos, vel, 0, nullptr, kDt_s, 0);
    later.step(false, pos, vel, 0, nullptr, kDt_s, 100);
    ASSERT_EQ(later.phase(), nav::GpsLoss::Phase::kDeadReckoning);
    const nav::NorthEast bad_wind = {0.0f, nan};
    later.step(false, pos, vel, 0, &bad_wind, kDt_s, 200);
    EXPECT_TRUE(later.wings_level());
    EXPECT_NEAR(pos.north_m, 11.8f, 1e-4f);
    EXPECT_TRUE(std::isfinite(pos.east_m) && std::isfinite(vel.east_m));
}

TEST(GpsLoss, ATurnThroughNorth) {
    // 350 -> 10 degrees: a 20-degree turn, not 340 the other way.
    nav::GpsLoss loss;
    nav::NorthEast pos = {0.0f, 0.0f}, vel = {18.0f * cosf(-10.0f * kDegToRad), 18.0f * sinf(-10.0f * kDegToRad)};
    loss.step(false, pos, vel, 35000, nullptr, kDt_s, 0);
    loss.step(false, pos, vel, 1000, nullptr, kDt_s, 100);
    EXPECT_NEAR(vel.north_m, 18.0f * cosf(10.0f * kDegToRad), 1e-3f);
    EXPECT_NEAR(vel.east_m, 18.0f * sinf(10.0f * kDegToRad), 1e-3f);
}

TEST(GpsLoss, ResetForgetsSilently) {
    nav::GpsLoss loss;
    nav::NorthEast pos = {0.0f, 0.0f}, vel = {18.0f, 0.0f};
    loss.step(false, pos, vel, 0, nullptr, kDt_s, 0);
    loss.reset();
    EXPECT_EQ(loss.phase(), nav::GpsLoss::Phase::kFix);
    EXPECT_EQ(loss.step(true, pos, vel, 0, nullptr, kDt_s, 100), nav::GpsLoss::kNone);
}

}  // namespace
