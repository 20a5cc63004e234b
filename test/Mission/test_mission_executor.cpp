// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Mission/MissionExecutor: waypoints reached within the turn distance or once past
// them, DO_JUMP's counts (and for ever), the loiters' ends, the takeoff, RTL, the end of
// the mission (a loiter at home at ALT_HOLD_RTL), DO_CHANGE_SPEED, the glide slope,
// MISSION_SET_CURRENT, GUIDED's circle (a ground station's "fly to here").
#include <gtest/gtest.h>

#include <math.h>

#include <vector>

#include "MissionExecutor.h"
#include "MissionFixture.h"
#include "NeVector.h"

namespace {

using nav::ne;
using testmission::Fixture;

struct Flight {
    Fixture f;
    mission::ExecutorParams params = mission::kExecutorDefaults;
    nav::L1Control l1{nav::kL1Defaults};
    mission::MissionExecutor exec{f.store, f.map, f.home, params};
    mission::NavState s = {ne(0.0f, 0.0f), 50.0f, 0u};

    // Flies straight onto the target's point (teleported there in one step, with L1's
    // state for 15 m/s towards it), returning the seq current after.
    uint16_t arrive() {
        const mission::NavTarget t = exec.target();
        l1.update_waypoint(s.pos_m, ne(15.0f, 0.0f), t.prev_m, t.next_m);
        s.pos_m = t.next_m;
        s.now_ms += 100;
        exec.update(s, l1);
        return exec.current_seq();
    }
    // One step at pos_m (L1 as it was); the seq current after.
    uint16_t at(float north_m, float east_m) {
        s.pos_m = ne(north_m, east_m);
        exec.update(s, l1);
        return exec.current_seq();
    }
};

TEST(MissionExecutor, WaypointsInOrderThenLoiterAtHome) {
    Flight r;
    r.f.upload({r.f.wp(500.0f, 0.0f, 60.0f), r.f.wp(500.0f, 300.0f, 60.0f), r.f.wp(0.0f, 300.0f, 60.0f)});
    r.exec.start(r.s);
    EXPECT_EQ(r.exec.current_seq(), 1u);
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kWaypoint);
    EXPECT_NEAR(r.exec.target().next_m.north_m, 500.0f, 0.02f);
    EXPECT_NEAR(r.exec.target().prev_m.north_m, 0.0f, 1e-6f);  // from here at the start
    EXPECT_EQ(r.arrive(), 2u);
    EXPECT_EQ(r.exec.reached_seq(), 1u);
    // The next leg starts at the last waypoint.
    EXPECT_NEAR(r.exec.target().prev_m.north_m, 500.0f, 0.02f);
    EXPECT_NEAR(r.exec.target().next_m.east_m, 300.0f, 0.02f);
    EXPECT_EQ(r.arrive(), 3u);
    EXPECT_FALSE(r.exec.complete());
    r.arrive();
    EXPECT_TRUE(r.exec.complete());
    EXPECT_EQ(r.exec.reached_seq(), 3u);
    EXPECT_EQ(r.exec.reached_count(), 3u);
    // ArduPlane 3.x after the last command: loiter at home, WP_LOITER_RAD, ALT_HOLD_RTL.
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kLoiter);
    EXPECT_FLOAT_EQ(r.exec.target().next_m.north_m, 0.0f);
    EXPECT_FLOAT_EQ(r.exec.target().radius_m, 60.0f);
    EXPECT_EQ(r.exec.target().direction, 1);
    EXPECT_FLOAT_EQ(r.exec.target().height_m, 100.0f);
}

TEST(MissionExecutor, ReachedWithinTheTurnDistanceOrOncePast) {
    Flight r;
    r.f.upload({r.f.wp(500.0f, 0.0f, 50.0f), r.f.wp(500.0f, 500.0f, 50.0f), r.f.wp(1000.0f, 500.0f, 50.0f)});
    r.exec.start(r.s);
    r.l1.update_waypoint(r.s.pos_m, ne(15.0f, 0.0f), ne(0.0f, 0.0f), ne(500.0f, 0.0f));
    // A 90-degree turn next: WP_RADIUS 30 (L1 is 71.6 m).
    EXPECT_EQ(r.at(469.0f, 0.0f), 1u);
    EXPECT_EQ(r.at(471.0f, 0.0f), 2u);
    // 100 m off the waypoint but past the line through it across the leg: passed.
    EXPECT_EQ(r.at(400.0f, 499.0f), 2u);
    EXPECT_EQ(r.at(400.0f, 501.0f), 3u);
}

TEST(MissionExecutor, GentleTurnSwitchesLater) {
    Flight r;
    // 500 m north, then on north-east: a 45-degree turn, half the turn distance (15 m).
    r.f.upload({r.f.wp(500.0f, 0.0f, 50.0f), r.f.wp(1000.0f, 500.0f, 50.0f)});
    r.exec.start(r.s);
    r.l1.update_waypoint(r.s.pos_m, ne(15.0f, 0.0f), ne(0.0f, 0.0f), ne(500.0f, 0.0f));
    EXPECT_EQ(r.at(484.0f, 0.0f), 1u);
    EXPECT_EQ(r.at(486.0f, 0.0f), 2u);
}

TEST(MissionExecutor, DoJumpCountsAndForever) {
    Flight r;
    // seq 1 WP, 2 WP, 3 DO_JUMP to 1 twice, 4 WP: flown 1 2 1 2 1 2 4 (the jump taken twice).
    r.f.upload({r.f.wp(300.0f, 0.0f, 50.0f), r.f.wp(300.0f, 300.0f, 50.0f), Fixture::jump(1, 2),
                r.f.wp(0.0f, 300.0f, 50.0f)});
    r.exec.start(r.s);
    std::vector<uint16_t> flown = {r.exec.current_seq()};
    for (int i = 0; i < 7 && !r.exec.complete(); ++i) flown.push_back(r.arrive());
    const std::vector<uint16_t> expected = {1, 2, 1, 2, 1, 2, 4, 4};  // the last stays current at the end
    EXPECT_EQ(flown, expected);
    EXPECT_TRUE(r.exec.complete());
    // Started again: the counts start over.
    r.exec.start(r.s);
    for (int i = 0; i < 6; ++i) r.arrive();
    EXPECT_EQ(r.exec.current_seq(), 4u);

    Flight forever;
    forever.f.upload({forever.f.wp(300.0f, 0.0f, 50.0f), forever.f.wp(300.0f, 300.0f, 50.0f), Fixture::jump(1, -1)});
    forever.exec.start(forever.s);
    for (int i = 0; i < 40; ++i) forever.arrive();
    EXPECT_FALSE(forever.exec.complete());
    EXPECT_EQ(forever.exec.current_seq(), 1u);
    // A loop of jumps alone is the end, not a hang; a jump to nowhere is passed over.
    Flight loop;
    loop.f.upload({loop.f.wp(300.0f, 0.0f, 50.0f), Fixture::jump(3, -1), Fixture::jump(2, -1)});
    loop.exec.start(loop.s);
    loop.arrive();
    EXPECT_TRUE(loop.exec.complete());
    Flight nowhere;
    nowhere.f.upload({Fixture::jump(9, 3), nowhere.f.wp(300.0f, 0.0f, 50.0f)});
    nowhere.exec.start(nowhere.s);
    EXPECT_EQ(nowhere.exec.current_seq(), 2u);
}

float kTurnSeconds(float radius_m) { return 2.0f * 3.14159265f * radius_m / 15.0f; }

// Flies the loiter's circle at 15 m/s (radius as the target says), `seconds` long.
void circle(Flight& r, float seconds) {
    const mission::NavTarget t = r.exec.target();
    const float w = 15.0f / t.radius_m * (float)t.direction;
    for (float time = 0.0f; time < seconds && !r.exec.complete(); time += 0.1f) {
        const float a = w * time;
        r.s.pos_m = t.next_m + ne(cosf(a), sinf(a)) * t.radius_m;
        const nav::NorthEast vel = ne(-sinf(a), cosf(a)) * (15.0f * (float)t.direction);
        r.l1.update_loiter(r.s.pos_m, vel, t.next_m, t.radius_m, t.direction);
        r.s.now_ms += 100;
        r.exec.update(r.s, r.l1);
        if (r.exec.current_seq() != 1u) return;
    }
}

TEST(MissionExecutor, LoiterTurnsAndTimeEndOnTheCircle) {
    Flight turns;
    mission::Command lt = turns.f.at(mission::kNavLoiterTurns, 200.0f, 0.0f, 80.0f);
    lt.p1 = (uint16_t)((50u << 8) | 2u);  // 2 turns of 50 m
    lt.loiter_ccw = true;
    turns.f.upload({lt, turns.f.wp(0.0f, 0.0f, 80.0f)});
    turns.exec.start(turns.s);
    EXPECT_EQ(turns.exec.target().kind, mission::TargetKind::kLoiter);
    EXPECT_FLOAT_EQ(turns.exec.target().radius_m, 50.0f);
    EXPECT_EQ(turns.exec.target().direction, -1);
    // A turn of 50 m at 15 m/s takes 20.9 s: not done at 1.9 turns, done by 2.05.
    circle(turns, 2.0f * kTurnSeconds(50.0f) * 0.95f);
    EXPECT_EQ(turns.exec.current_seq(), 1u);
    EXPECT_GT(turns.exec.loiter_angle_rad(), 1.85f * 6.2832f);
    circle(turns, 2.0f * kTurnSeconds(50.0f) * 0.1f);
    EXPECT_EQ(turns.exec.current_seq(), 2u);

    Flight timed;
    mission::Command t = timed.f.at(mission::kNavLoiterTime, 200.0f, 0.0f, 80.0f);
    t.p1 = 30;
    timed.f.upload({t, timed.f.wp(0.0f, 0.0f, 80.0f)});
    timed.exec.start(timed.s);
    EXPECT_FLOAT_EQ(timed.exec.target().radius_m, 60.0f);  // WP_LOITER_RAD
    circle(timed, 29.5f);
    EXPECT_EQ(timed.exec.current_seq(), 1u);
    circle(timed, 1.0f);
    EXPECT_EQ(timed.exec.current_seq(), 2u);
}

TEST(MissionExecutor, TakeoffThenWaypointAndRtl) {
    Flight r;
    mission::Command takeoff;
    takeoff.id = mission::kNavTakeoff;
    takeoff.p1 = 15;
    takeoff.alt_cm = 4000;
    mission::Command rtl;
    rtl.id = mission::kNavReturnToLaunch;
    r.f.upload({takeoff, r.f.wp(400.0f, 0.0f, 60.0f), rtl, r.f.wp(900.0f, 900.0f, 60.0f)});
    r.s.height_m = 0.0f;
    r.exec.start(r.s);
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kTakeoff);
    EXPECT_EQ(r.exec.target().takeoff_pitch_cd, 1500);
    EXPECT_FLOAT_EQ(r.exec.height_demand_m(r.s), 40.0f);
    r.s.height_m = 39.9f;
    r.exec.update(r.s, r.l1);
    EXPECT_EQ(r.exec.current_seq(), 1u);
    r.s.pos_m = ne(20.0f, 5.0f);
    r.s.height_m = 40.0f;
    r.exec.update(r.s, r.l1);
    EXPECT_EQ(r.exec.current_seq(), 2u);
    // After the takeoff the leg starts here, not at home.
    EXPECT_FLOAT_EQ(r.exec.target().prev_m.north_m, 20.0f);
    r.arrive();
    EXPECT_EQ(r.exec.current_seq(), 3u);  // RTL: loiter at home at ALT_HOLD_RTL
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kLoiter);
    EXPECT_FLOAT_EQ(r.exec.target().height_m, 100.0f);
    r.s.pos_m = ne(25.0f, 0.0f);  // within WP_RADIUS of home: RTL done, on to seq 4
    r.exec.update(r.s, r.l1);
    EXPECT_EQ(r.exec.current_seq(), 4u);
}

TEST(MissionExecutor, ChangeSpeedActsWhenThePrecedingWaypointStarts) {
    Flight r;
    mission::Command speed;
    speed.id = mission::kDoChangeSpeed;
    speed.p1 = 0;
    speed.lat_e7 = 1800;  // 18 m/s
    speed.lon_e7 = 60;
    r.f.upload({r.f.wp(300.0f, 0.0f, 50.0f), r.f.wp(300.0f, 300.0f, 50.0f), speed, r.f.wp(0.0f, 0.0f, 50.0f)});
    r.exec.start(r.s);
    EXPECT_EQ(r.exec.airspeed_cm_s(), 0u);
    EXPECT_EQ(r.exec.throttle_pct(), -1);
    r.arrive();  // seq 2 starts: the DO_CHANGE_SPEED after it acts
    EXPECT_EQ(r.exec.airspeed_cm_s(), 1800u);
    EXPECT_EQ(r.exec.throttle_pct(), 60);
    // Before the first navigation command: at the start.
    Flight first;
    first.f.upload({speed, first.f.wp(300.0f, 0.0f, 50.0f)});
    first.exec.start(first.s);
    EXPECT_EQ(first.exec.current_seq(), 2u);
    EXPECT_EQ(first.exec.airspeed_cm_s(), 1800u);
}

TEST(MissionExecutor, GlideSlopeSpreadsBigChangesOnly) {
    Flight r;
    r.f.upload({r.f.wp(1000.0f, 0.0f, 100.0f), r.f.wp(1000.0f, 1000.0f, 90.0f), r.f.wp(0.0f, 0.0f, 30.0f)});
    r.exec.start(r.s);  // at 50 m (above 20 m): 50 m up along the leg
    EXPECT_FLOAT_EQ(r.exec.target().slope_m, 50.0f);
    EXPECT_NEAR(r.exec.height_demand_m(r.s), 50.0f, 1e-3f);
    mission::NavState half = r.s;
    half.pos_m = ne(500.0f, 30.0f);
    EXPECT_NEAR(r.exec.height_demand_m(half), 75.0f, 0.01f);
    r.s.height_m = 100.0f;
    r.arrive();
    // 10 m down is below GLIDE_SLOPE_MIN 15: asked for at once.
    EXPECT_FLOAT_EQ(r.exec.target().slope_m, 0.0f);
    EXPECT_FLOAT_EQ(r.exec.height_demand_m(r.s), 90.0f);
    // Low (below 20 m) a climb is not spread; a descent always is.
    Flight low;
    low.f.upload({low.f.wp(1000.0f, 0.0f, 100.0f)});
    low.s.height_m = 10.0f;
    low.exec.start(low.s);
    EXPECT_FLOAT_EQ(low.exec.target().slope_m, 0.0f);
    Flight down;
    down.f.upload({down.f.wp(1000.0f, 0.0f, 20.0f)});
    down.s.height_m = 10.0f + 50.0f;
    down.exec.start(down.s);
    EXPECT_FLOAT_EQ(down.exec.target().slope_m, -40.0f);
}

// The look-ahead keeps the commands it read and the place it mapped: a new mission, or
// home moved (DO_SET_HOME), is read and mapped afresh, not taken from what it kept.
TEST(MissionExecutor, TheLookAheadKeepsNothingStale) {
    Flight r;
    r.f.upload({r.f.wp(500.0f, 0.0f, 60.0f), r.f.wp(500.0f, 300.0f, 60.0f)});
    r.exec.start(r.s);
    r.at(0.0f, 0.0f);  // the next command read and mapped, the turn to it
    r.at(0.0f, 0.0f);  // the one after it (none here)
    r.f.upload({r.f.wp(200.0f, 0.0f, 60.0f), r.f.wp(200.0f, -300.0f, 60.0f)});
    r.exec.start(r.s);  // the new mission: its commands at the indices the old one's were read
    EXPECT_NEAR(r.exec.target().next_m.north_m, 200.0f, 0.02f);
    r.at(0.0f, 0.0f);
    r.at(0.0f, 0.0f);
    EXPECT_EQ(r.arrive(), 2u);
    EXPECT_NEAR(r.exec.target().next_m.east_m, -300.0f, 0.02f);

    Flight moved;
    moved.f.upload({moved.f.wp(500.0f, 0.0f, 60.0f), moved.f.wp(500.0f, 300.0f, 60.0f)});
    moved.exec.start(moved.s);
    moved.at(0.0f, 0.0f);
    moved.at(0.0f, 0.0f);
    // Home 100 m east: the next waypoint is 200 m east of it when its leg starts.
    moved.f.home = moved.f.map.moved(moved.f.home, 0.0f, 100.0f);
    moved.f.map.set_origin(moved.f.home);
    EXPECT_EQ(moved.arrive(), 2u);
    EXPECT_NEAR(moved.exec.target().next_m.north_m, 500.0f, 0.05f);
    EXPECT_NEAR(moved.exec.target().next_m.east_m, 200.0f, 0.05f);
}

TEST(MissionExecutor, SetCurrentAndAnEmptyMission) {
    Flight r;
    r.f.upload({r.f.wp(300.0f, 0.0f, 50.0f), r.f.wp(300.0f, 300.0f, 50.0f), r.f.wp(0.0f, 300.0f, 50.0f)});
    r.exec.start(r.s);
    r.s.pos_m = ne(100.0f, 20.0f);
    EXPECT_TRUE(r.exec.set_current(3, r.s));
    EXPECT_EQ(r.exec.current_seq(), 3u);
    EXPECT_NEAR(r.exec.target().next_m.east_m, 300.0f, 0.02f);
    // The leg from here (the plane turns to it), not from waypoint 1 it was flying to.
    EXPECT_FLOAT_EQ(r.exec.target().prev_m.north_m, 100.0f);
    EXPECT_FLOAT_EQ(r.exec.target().prev_m.east_m, 20.0f);
    // AUTO entered with a seq: from it; another seq: from the first.
    r.exec.start(r.s, 2);
    EXPECT_EQ(r.exec.current_seq(), 2u);
    r.exec.start(r.s, 9);
    EXPECT_EQ(r.exec.current_seq(), 1u);
    r.exec.set_current(3, r.s);
    EXPECT_FALSE(r.exec.set_current(0, r.s));
    EXPECT_FALSE(r.exec.set_current(4, r.s));
    EXPECT_EQ(r.exec.current_seq(), 3u);

    Flight empty;
    empty.exec.start(empty.s);
    EXPECT_TRUE(empty.exec.complete());
    EXPECT_EQ(empty.exec.current_seq(), 0u);
    EXPECT_EQ(empty.exec.target().kind, mission::TargetKind::kLoiter);
    // RTL mode: the same loiter, counter-clockwise for a negative WP_LOITER_RAD.
    Flight rtl;
    rtl.params.loiter_radius_m = -80;
    rtl.params.rtl_alt_cm = -1;  // the height now
    rtl.exec.return_home(rtl.s);
    EXPECT_EQ(rtl.exec.target().direction, -1);
    EXPECT_FLOAT_EQ(rtl.exec.target().radius_m, 80.0f);
    EXPECT_FLOAT_EQ(rtl.exec.target().height_m, 50.0f);
}

// GUIDED (ArduPlane's set_guided_WP): WP_LOITER_RAD about the place given, at its height
// (above home or above mean sea level), the mission left; without a place, where it is.
TEST(MissionExecutor, GuidedCirclesThePlaceGivenAtItsHeight) {
    Flight r;
    r.f.upload({r.f.wp(500.0f, 0.0f, 60.0f), r.f.wp(500.0f, 300.0f, 60.0f)});
    r.exec.start(r.s);
    ASSERT_EQ(r.exec.current_seq(), 1u);
    const mission::Command to = r.f.wp(300.0f, -200.0f, 80.0f);
    r.exec.guide_to(&to, r.s);
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kLoiter);
    EXPECT_NEAR(r.exec.target().next_m.north_m, 300.0f, 0.02f);
    EXPECT_NEAR(r.exec.target().next_m.east_m, -200.0f, 0.02f);
    EXPECT_FLOAT_EQ(r.exec.target().radius_m, 60.0f);
    EXPECT_EQ(r.exec.target().direction, 1);
    EXPECT_FLOAT_EQ(r.exec.target().height_m, 80.0f);
    EXPECT_FLOAT_EQ(r.exec.height_demand_m(r.s), 80.0f);  // a climb: no slope (ArduPlane's)
    EXPECT_EQ(r.exec.current_seq(), 0u);                  // out of the mission
    // The steps after fly the circle: the mission's waypoint reached is not flown on to.
    EXPECT_EQ(r.at(500.0f, 0.0f), 0u);
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kLoiter);
    EXPECT_NEAR(r.exec.target().next_m.north_m, 300.0f, 0.02f);

    // Above mean sea level (MAVProxy's AMSL frame): home's 1028 m + 40 m is 40 m above home;
    // a negative WP_LOITER_RAD circles counter-clockwise.
    Flight amsl;
    amsl.params.loiter_radius_m = -45;
    amsl.s.height_m = 80.0f;
    mission::Command high = amsl.f.wp(-100.0f, 50.0f, 0.0f);
    high.relative_alt = false;
    high.alt_cm = amsl.f.home.alt_cm + 4000;
    amsl.exec.guide_to(&high, amsl.s);
    EXPECT_FLOAT_EQ(amsl.exec.target().height_m, 40.0f);
    EXPECT_FLOAT_EQ(amsl.exec.target().radius_m, 45.0f);
    EXPECT_EQ(amsl.exec.target().direction, -1);
    EXPECT_NEAR(amsl.exec.target().next_m.east_m, 50.0f, 0.02f);
    // 40 m below the aircraft: the glide slope spreads the descent from where it is.
    EXPECT_NEAR(amsl.exec.height_demand_m(amsl.s), 80.0f, 0.01f);

    // GUIDED from SET_MODE alone: around the aircraft's position, at its height.
    Flight here;
    here.s.pos_m = ne(120.0f, 80.0f);
    here.s.height_m = 35.0f;
    here.exec.guide_to(nullptr, here.s);
    EXPECT_FLOAT_EQ(here.exec.target().next_m.north_m, 120.0f);
    EXPECT_FLOAT_EQ(here.exec.target().next_m.east_m, 80.0f);
    EXPECT_FLOAT_EQ(here.exec.target().height_m, 35.0f);
    EXPECT_EQ(here.exec.target().kind, mission::TargetKind::kLoiter);
    // AUTO again: the mission from its start.
    r.exec.start(r.s);
    EXPECT_EQ(r.exec.current_seq(), 1u);
    EXPECT_EQ(r.exec.target().kind, mission::TargetKind::kWaypoint);
}

}  // namespace
