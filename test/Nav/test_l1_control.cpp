// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/L1Control: the L1 law's closed-form behaviour (a straight track captured with
// the period NAVL1_PERIOD and the damping NAVL1_DAMPING of the linearised law, paper
// section 2.2), the loiter circle held at its radius either way round, the wind flown
// out by the ground velocity, the signs, the bank limit, the turn distance, and the
// capture from behind and from the far side.
#include <gtest/gtest.h>

#include <math.h>

#include <vector>

#include "L1Control.h"
#include "NeVector.h"

namespace {

using nav::NorthEast;
using nav::ne;

// A point mass flying at air speed va_m_s on heading (unit vector), turning at once as the
// guidance asks (heading rate = a_lat / va), in a steady wind.
struct PointMass {
    NorthEast pos;
    NorthEast heading;
    float va_m_s;
    NorthEast wind;

    NorthEast ground_velocity() const { return heading * va_m_s + wind; }
    void step(float lat_acc_m_s2, float dt_s) {
        pos = pos + ground_velocity() * dt_s;
        const float rate = lat_acc_m_s2 / va_m_s * dt_s;
        heading = nav::rotated(heading, cosf(rate), sinf(rate));
        heading = heading * (1.0f / nav::length(heading));
    }
};

// Flies north along the east = 0 line from (0, 0) to (10 km, 0), starting offset_m east
// of it on a northerly heading; returns the cross-track error every dt_s.
std::vector<float> fly_track(const nav::L1Params& p, float offset_m, float seconds, float dt_s,
                             NorthEast wind = ne(0.0f, 0.0f)) {
    nav::L1Control l1(p);
    PointMass m{ne(0.0f, offset_m), ne(1.0f, 0.0f), 15.0f, wind};
    std::vector<float> xtrack;
    for (float t = 0.0f; t < seconds; t += dt_s) {
        l1.update_waypoint(m.pos, m.ground_velocity(), ne(0.0f, 0.0f), ne(10000.0f, 0.0f));
        xtrack.push_back(l1.crosstrack_error_m());
        m.step(l1.lateral_accel_m_s2(), dt_s);
    }
    return xtrack;
}

TEST(L1Control, TrackCapturedWithThePeriodAndDampingAsked) {
    // Linearised, the law is z'' + 2 zeta w z' + w^2 z = 0 with w = 2 pi / NAVL1_PERIOD:
    // zero crossings half a damped period apart, successive extremes in the ratio
    // exp(-zeta pi / sqrt(1 - zeta^2)). A small offset keeps it linear (sin eta1 ~ 0.03).
    const nav::L1Params p = {20.0f, 0.5f};
    const float dt = 0.01f;
    const std::vector<float> x = fly_track(p, 2.0f, 80.0f, dt);
    std::vector<float> crossings, extremes;
    for (size_t i = 1; i + 1 < x.size(); ++i) {
        if ((x[i - 1] < 0.0f) != (x[i] < 0.0f)) crossings.push_back((float)i * dt);
        if (fabsf(x[i]) > fabsf(x[i - 1]) && fabsf(x[i]) >= fabsf(x[i + 1]) && fabsf(x[i]) > 1e-4f)
            extremes.push_back(fabsf(x[i]));
    }
    ASSERT_GE(crossings.size(), 3u);
    const float damped_period = 20.0f / sqrtf(1.0f - 0.25f);  // 23.09 s
    EXPECT_NEAR(2.0f * (crossings[1] - crossings[0]), damped_period, 0.02f * damped_period);
    EXPECT_NEAR(2.0f * (crossings[2] - crossings[1]), damped_period, 0.02f * damped_period);
    ASSERT_GE(extremes.size(), 2u);
    const float ratio = expf(-0.5f * 3.14159265f / sqrtf(0.75f));  // 0.163
    EXPECT_NEAR(extremes[1] / extremes[0], ratio, 0.1f * ratio);
    // The offset is left to the right of the track: cross-track error negative (ArduPilot's sign).
    EXPECT_LT(x[0], 0.0f);
}

TEST(L1Control, DefaultsSettleWithoutOvershootAndCaptureAt45Degrees) {
    // 200 m off: sin eta1 clamped, so it closes at 45 deg (ground track) until within
    // ~0.7 L1, then settles with damping 0.75 (overshoot exp(-3.56) = 3 %).
    const float dt = 0.05f;
    const std::vector<float> x = fly_track(nav::kL1Defaults, 200.0f, 120.0f, dt);
    float worst_overshoot = 0.0f;
    for (float v : x) worst_overshoot = v > worst_overshoot ? v : worst_overshoot;
    EXPECT_LT(worst_overshoot, 0.05f * 200.0f);
    // 45 deg at 15 m/s closes 10.6 m/s: 10 s in, some 100 m are gone, not much more.
    const float at_10s = -x[(size_t)(10.0f / dt)];
    EXPECT_GT(at_10s, 200.0f - 10.61f * 10.0f - 2.0f);
    EXPECT_LT(at_10s, 200.0f - 8.0f * 10.0f);
    EXPECT_LT(fabsf(x.back()), 0.2f);
}

TEST(L1Control, CrossWindFlownOutByTheGroundVelocity) {
    // 5 m/s from the west across a northbound track: the ground track converges all the same.
    const std::vector<float> x = fly_track(nav::kL1Defaults, 30.0f, 120.0f, 0.05f, ne(0.0f, 5.0f));
    EXPECT_LT(fabsf(x.back()), 0.1f);
    const std::vector<float> y = fly_track(nav::kL1Defaults, -30.0f, 120.0f, 0.05f, ne(0.0f, -5.0f));
    EXPECT_LT(fabsf(y.back()), 0.1f);
}

TEST(L1Control, SignsAndBankLimit) {
    nav::L1Control l1(nav::kL1Defaults);
    // East of a northbound track, flying north: steer left, the L1 point ahead to the left.
    l1.update_waypoint(ne(0.0f, 20.0f), ne(15.0f, 0.0f), ne(-100.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_NEAR(l1.crosstrack_error_m(), -20.0f, 1e-4f);
    EXPECT_LT(l1.lateral_accel_m_s2(), 0.0f);
    EXPECT_LT(l1.nav_roll_cd(4500), 0);
    EXPECT_GT(l1.nav_direction().north_m, 0.0f);
    EXPECT_LT(l1.nav_direction().east_m, 0.0f);
    EXPECT_NEAR(nav::length(l1.nav_direction()), 1.0f, 1e-5f);
    // The L1 point is at asin(-20 / L1) off the track: L1 = 0.75 x 20 x 15 / pi = 71.6 m.
    EXPECT_NEAR(l1.l1_distance_m(), 71.62f, 0.01f);
    EXPECT_NEAR(l1.nav_bearing_rad(), asinf(-20.0f / 71.62f), 1e-3f);
    EXPECT_NEAR(l1.target_bearing_rad(), atan2f(-20.0f, 500.0f), 1e-3f);
    // Flying east (away from the track, 90 deg off): eta = eta1 + eta2 < -90 deg, limited:
    // a_lat = 4 zeta^2 Vg^2 / L1.
    l1.update_waypoint(ne(0.0f, 20.0f), ne(0.0f, 15.0f), ne(-100.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_NEAR(l1.lateral_accel_m_s2(), -4.0f * 0.5625f * 225.0f / 71.62f, 0.01f);
    // 7.07 m/s^2 is 35.8 deg of bank; a limit of 30 deg holds it; cos pitch scales it.
    EXPECT_NEAR(l1.nav_roll_cd(4500), -3581, 3);
    EXPECT_EQ(l1.nav_roll_cd(3000), -3000);
    EXPECT_NEAR(l1.nav_roll_cd(4500, 0.5f), -1790, 3);
}

TEST(L1Control, FliesToPrevFromBehindAndBackToNextWhenPast) {
    nav::L1Control l1(nav::kL1Defaults);
    // 300 m south-east of prev, behind the northbound track: the L1 point is prev itself.
    l1.update_waypoint(ne(-300.0f, 300.0f), ne(15.0f, 0.0f), ne(0.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_NEAR(l1.nav_direction().north_m, 0.7071f, 1e-3f);
    EXPECT_NEAR(l1.nav_direction().east_m, -0.7071f, 1e-3f);
    EXPECT_LT(l1.lateral_accel_m_s2(), 0.0f);  // turning left, towards prev
    // Far past next, still flying north: back to next, turning round.
    l1.update_waypoint(ne(600.0f, 10.0f), ne(15.0f, 0.0f), ne(0.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_LT(l1.nav_direction().north_m, -0.99f);
    EXPECT_NEAR(fabsf(l1.lateral_accel_m_s2()), 4.0f * 0.5625f * 225.0f / 71.62f, 0.01f);
}

TEST(L1Control, KeepsTurningOneWayWithTheTargetBehind) {
    // Flying straight away from next, the velocity wobbling across the line: eta near
    // +-180 deg changes sign each step; the turn must not.
    nav::L1Control l1(nav::kL1Defaults);
    float first = 0.0f;
    for (int i = 0; i < 10; ++i) {
        const float wobble = (i % 2 == 0) ? 0.3f : -0.3f;
        l1.update_waypoint(ne(-1000.0f - 10.0f * (float)i, 0.0f), ne(-15.0f, wobble), ne(-1000.0f, 0.0f),
                           ne(1000.0f, 0.0f));
        if (i == 0) first = l1.lateral_accel_m_s2();
        EXPECT_EQ(l1.lateral_accel_m_s2() > 0.0f, first > 0.0f) << "step " << i;
    }
}

TEST(L1Control, TurnDistanceWithinWpRadiusAndL1) {
    nav::L1Control l1(nav::kL1Defaults);
    l1.update_waypoint(ne(0.0f, 0.0f), ne(15.0f, 0.0f), ne(-100.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_FLOAT_EQ(l1.turn_distance_m(30.0f), 30.0f);           // WP_RADIUS 30 < L1 71.6
    EXPECT_NEAR(l1.turn_distance_m(200.0f), 71.62f, 0.01f);      // never beyond L1
    EXPECT_FLOAT_EQ(l1.turn_distance_m(30.0f, 45.0f), 15.0f);    // a gentle turn: later
    EXPECT_FLOAT_EQ(l1.turn_distance_m(30.0f, -120.0f), 30.0f);
}

// Loiters for `seconds` from `start`; returns the largest |distance - radius| over the last 60 s.
float loiter_error(int8_t direction, NorthEast start, NorthEast wind, float seconds, bool& captured,
                   float& tangent_sign) {
    nav::L1Control l1(nav::kL1Defaults);
    PointMass m{start, ne(0.0f, 1.0f), 15.0f, wind};
    const NorthEast centre = ne(100.0f, -50.0f);
    const float dt = 0.02f;
    float worst = 0.0f;
    for (float t = 0.0f; t < seconds; t += dt) {
        l1.update_loiter(m.pos, m.ground_velocity(), centre, 60.0f, direction);
        if (t > seconds - 60.0f) {
            const NorthEast r = m.pos - centre;
            const float err = fabsf(nav::length(r) - 60.0f);
            worst = err > worst ? err : worst;
            tangent_sign = nav::cross(r, m.ground_velocity()) > 0.0f ? 1.0f : -1.0f;
        }
        m.step(l1.lateral_accel_m_s2(), dt);
    }
    captured = l1.loiter_captured();
    return worst;
}

TEST(L1Control, LoiterHoldsTheRadiusEitherWayRound) {
    bool captured = false;
    float tangent = 0.0f;
    EXPECT_LT(loiter_error(1, ne(-400.0f, 300.0f), ne(0.0f, 0.0f), 150.0f, captured, tangent), 0.3f);
    EXPECT_TRUE(captured);
    EXPECT_EQ(tangent, 1.0f);  // clockwise seen from above
    EXPECT_LT(loiter_error(-1, ne(-400.0f, 300.0f), ne(0.0f, 0.0f), 150.0f, captured, tangent), 0.3f);
    EXPECT_TRUE(captured);
    EXPECT_EQ(tangent, -1.0f);
    // From the centre itself, and in a 5 m/s wind (the circle drifts by a few metres
    // where the ground speed changes: within 5 m).
    EXPECT_LT(loiter_error(1, ne(100.0f, -50.0f), ne(0.0f, 0.0f), 150.0f, captured, tangent), 0.3f);
    EXPECT_LT(loiter_error(1, ne(-400.0f, 300.0f), ne(0.0f, 5.0f), 200.0f, captured, tangent), 5.0f);
    EXPECT_TRUE(captured);
}

TEST(L1Control, LoiterTheWrongWayRoundTurnsBack) {
    // Inside a clockwise circle (50 m of 60), flying it counter-clockwise and drifting out:
    // the radius PD would turn it further the wrong way; it is held at 0, so only the
    // centripetal term is left, to the right: Vt^2 / 50.
    nav::L1Control l1(nav::kL1Defaults);
    l1.update_loiter(ne(0.0f, -50.0f), ne(-15.0f, -1.0f), ne(0.0f, 0.0f), 60.0f, 1);
    EXPECT_TRUE(l1.loiter_captured());
    EXPECT_NEAR(l1.lateral_accel_m_s2(), 225.0f / 50.0f, 1e-3f);
}

TEST(L1Control, LoiterCaptureOnlyOnTheCircle) {
    nav::L1Control l1(nav::kL1Defaults);
    // 500 m out, flying at the centre: the capture law, steering at the centre.
    l1.update_loiter(ne(-500.0f, 0.0f), ne(15.0f, 0.0f), ne(0.0f, 0.0f), 60.0f, 1);
    EXPECT_FALSE(l1.loiter_captured());
    EXPECT_NEAR(l1.lateral_accel_m_s2(), 0.0f, 1e-4f);
    EXPECT_NEAR(l1.crosstrack_error_m(), 440.0f, 1e-3f);
    EXPECT_NEAR(l1.to_target_m().north_m, 500.0f, 1e-3f);
    EXPECT_NEAR(l1.target_bearing_rad(), 0.0f, 1e-5f);
    // On the circle, flying clockwise along it: the centripetal V^2 / R to the right.
    l1.update_loiter(ne(0.0f, -60.0f), ne(15.0f, 0.0f), ne(0.0f, 0.0f), 60.0f, 1);
    EXPECT_TRUE(l1.loiter_captured());
    EXPECT_NEAR(l1.lateral_accel_m_s2(), 225.0f / 60.0f, 1e-3f);
}

}  // namespace

// The leg's length and unit vector and the gains are kept between steps: a new leg or a
// parameter changed in place must give what a fresh controller gives.
TEST(L1Control, NewLegAndChangedParametersTakenAtOnce) {
    nav::L1Params p = nav::kL1Defaults;
    nav::L1Control kept(p);
    const NorthEast pos = ne(40.0f, 30.0f), vel = ne(12.0f, 5.0f);
    kept.update_waypoint(pos, vel, ne(0.0f, 0.0f), ne(500.0f, 0.0f));
    // Another leg from the same prev: east instead of north.
    kept.update_waypoint(pos, vel, ne(0.0f, 0.0f), ne(0.0f, 500.0f));
    nav::L1Control fresh(p);
    fresh.update_waypoint(pos, vel, ne(0.0f, 0.0f), ne(0.0f, 500.0f));
    EXPECT_EQ(kept.lateral_accel_m_s2(), fresh.lateral_accel_m_s2());
    EXPECT_EQ(kept.crosstrack_error_m(), fresh.crosstrack_error_m());
    EXPECT_FLOAT_EQ(kept.crosstrack_error_m(), 40.0f);  // left of the eastward leg (north of it)
    // NAVL1_PERIOD and _DAMPING changed where the controller reads them.
    p.period_s = 12.0f;
    p.damping = 0.9f;
    kept.update_waypoint(pos, vel, ne(0.0f, 0.0f), ne(0.0f, 500.0f));
    nav::L1Control fresh2(p);
    fresh2.update_waypoint(pos, vel, ne(0.0f, 0.0f), ne(0.0f, 500.0f));
    EXPECT_EQ(kept.l1_distance_m(), fresh2.l1_distance_m());
    EXPECT_EQ(kept.lateral_accel_m_s2(), fresh2.lateral_accel_m_s2());
    EXPECT_NE(kept.l1_distance_m(), fresh.l1_distance_m());
    kept.update_loiter(pos, vel, ne(0.0f, 0.0f), 60.0f, 1);
    fresh2.update_loiter(pos, vel, ne(0.0f, 0.0f), 60.0f, 1);
    EXPECT_EQ(kept.lateral_accel_m_s2(), fresh2.lateral_accel_m_s2());
}
