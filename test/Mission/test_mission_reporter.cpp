// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Mission/MissionReporter: MISSION_SET_CURRENT moves the executor in AUTO (the leg from
// where the plane is) and is where AUTO starts out of it; MISSION_CURRENT when the current
// command changes; MISSION_ITEM_REACHED once for each command reached.
#include <gtest/gtest.h>

#include "MissionExecutor.h"
#include "MissionFixture.h"
#include "MissionReporter.h"
#include "NeVector.h"

namespace {

using nav::ne;

struct Link {
    testmission::Fixture f;
    mission::ExecutorParams params = mission::kExecutorDefaults;
    nav::L1Control l1{nav::kL1Defaults};
    mission::MissionExecutor exec{f.store, f.map, f.home, params};
    mission::MissionReporter rep;
    mission::NavState s = {ne(0.0f, 0.0f), 50.0f, 0u};

    Link() {
        f.upload({f.wp(400.0f, 0.0f, 50.0f), f.wp(400.0f, 300.0f, 60.0f), f.wp(-100.0f, 300.0f, 40.0f),
                  f.wp(-100.0f, 0.0f, 50.0f), testmission::Fixture::jump(1, -1)});
    }
    // A step of AUTO at (north, east): the executor, then the reporter.
    void step(float north_m, float east_m) {
        s.pos_m = ne(north_m, east_m);
        s.now_ms += 100;
        const mission::NavTarget t = exec.target();
        l1.update_waypoint(s.pos_m, ne(15.0f, 0.0f), t.prev_m, t.next_m);
        exec.update(s, l1);
        rep.follow(exec, s);
    }
    uint16_t reached() {
        uint16_t seq = 0;
        return rep.take_reached(seq) ? seq : 0u;
    }
};

TEST(MissionReporter, CurrentAndReachedOncePerChange) {
    Link k;
    k.rep.start(k.exec, k.s);
    EXPECT_EQ(k.rep.current_seq(), 1u);
    EXPECT_TRUE(k.rep.news());
    EXPECT_TRUE(k.rep.take_current());
    EXPECT_FALSE(k.rep.take_current());  // once
    EXPECT_FALSE(k.rep.news());
    k.step(100.0f, 0.0f);  // on the way: nothing new
    EXPECT_FALSE(k.rep.news());
    k.step(399.0f, 0.0f);  // at waypoint 1
    EXPECT_EQ(k.rep.current_seq(), 2u);
    EXPECT_EQ(k.reached(), 1u);
    EXPECT_EQ(k.reached(), 0u);  // once
    EXPECT_TRUE(k.rep.take_current());
    k.step(400.0f, 299.0f);
    k.step(-99.0f, 300.0f);
    EXPECT_EQ(k.reached(), 3u);  // the last one reached, when two came before it was sent
    k.step(-100.0f, 1.0f);  // waypoint 4, then DO_JUMP back to 1
    EXPECT_EQ(k.reached(), 4u);
    EXPECT_EQ(k.rep.current_seq(), 1u);
}

TEST(MissionReporter, SetCurrentInAutoTurnsFromHere) {
    Link k;
    k.rep.start(k.exec, k.s);
    k.rep.take_current();
    k.step(200.0f, 0.0f);
    EXPECT_FALSE(k.rep.request(0, k.f.store.count()));  // home
    EXPECT_FALSE(k.rep.request(6, k.f.store.count()));  // past the end
    EXPECT_FALSE(k.rep.news());
    ASSERT_TRUE(k.rep.request(4, k.f.store.count()));
    // Answered at once (MISSION_CURRENT 4), the executor moved at its next step.
    EXPECT_TRUE(k.rep.take_current());
    EXPECT_EQ(k.rep.current_seq(), 4u);
    EXPECT_EQ(k.exec.current_seq(), 1u);
    k.step(210.0f, 0.0f);
    EXPECT_EQ(k.exec.current_seq(), 4u);
    // The leg from where the plane is, not from waypoint 1 it was flying to.
    EXPECT_NEAR(k.exec.target().prev_m.north_m, 210.0f, 1e-3f);
    EXPECT_NEAR(k.exec.target().next_m.north_m, -100.0f, 0.02f);
    EXPECT_NEAR(k.exec.target().next_m.east_m, 0.0f, 0.02f);
    EXPECT_FALSE(k.rep.news());  // no second MISSION_CURRENT: it said 4 already
    EXPECT_EQ(k.reached(), 0u);  // nothing reached by the jump
    // The same seq again: answered again, as ArduPlane.
    ASSERT_TRUE(k.rep.request(4, k.f.store.count()));
    EXPECT_TRUE(k.rep.take_current());
}

TEST(MissionReporter, SetCurrentWaitsForAStepThatReachedNothing) {
    Link k;
    k.rep.start(k.exec, k.s);
    k.rep.take_current();
    ASSERT_TRUE(k.rep.request(3, k.f.store.count()));
    k.step(399.0f, 0.0f);  // reaches waypoint 1 in this step: the jump waits
    EXPECT_EQ(k.reached(), 1u);
    EXPECT_EQ(k.exec.current_seq(), 2u);
    k.step(399.0f, 10.0f);
    EXPECT_EQ(k.exec.current_seq(), 3u);
    EXPECT_EQ(k.rep.current_seq(), 3u);
}

TEST(MissionReporter, OutOfAutoItIsWhereAutoStarts) {
    Link k;
    ASSERT_TRUE(k.rep.request(3, k.f.store.count()));
    EXPECT_TRUE(k.rep.take_current());
    EXPECT_EQ(k.rep.current_seq(), 3u);
    k.rep.start(k.exec, k.s);  // AUTO entered
    EXPECT_EQ(k.exec.current_seq(), 3u);
    EXPECT_NEAR(k.exec.target().next_m.north_m, -100.0f, 0.02f);
    EXPECT_NEAR(k.exec.target().prev_m.north_m, 0.0f, 1e-3f);
    EXPECT_FALSE(k.rep.news());
    // Once: AUTO entered again starts from the first command.
    k.rep.start(k.exec, k.s);
    EXPECT_EQ(k.exec.current_seq(), 1u);
    EXPECT_TRUE(k.rep.take_current());
    // A seq asked for, then another mission committed: forgotten.
    ASSERT_TRUE(k.rep.request(2, k.f.store.count()));
    k.rep.forget();
    k.rep.start(k.exec, k.s);
    EXPECT_EQ(k.exec.current_seq(), 1u);
}

}  // namespace
