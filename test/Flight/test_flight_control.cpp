// SPDX-License-Identifier: GPL-3.0-or-later
// FlightControl (lib/Flight): the modes (MANUAL, STABILIZE), the mode switch and the
// console's choice, failsafe on a lost receiver and on the encoder's own failsafe, the
// fallback to MANUAL without an attitude.
#include <gtest/gtest.h>

#include <cstring>

#include "Flight.h"
#include "Settings.h"

namespace {

struct Rig {
    settings::Settings s = settings::defaults();
    flight::FlightControl fc{s.flight};
    uint16_t rc[8] = {1500, 1500, 1100, 1500, 1500, 1500, 1500, 1000};  // mode switch low: MANUAL
    uint32_t now_ms = 0;
    flight::Attitude att{0, 0, 0, 0, true};
    uint16_t out[8] = {};

    // Runs `seconds` of 50 Hz steps with frames every 22 ms while `signal`.
    void run(float seconds, bool signal = true) {
        const uint32_t end = now_ms + (uint32_t)(seconds * 1000.0f);
        uint32_t next_frame = now_ms;
        while (now_ms < end) {
            if (signal && now_ms >= next_frame) {
                fc.on_frame(rc, now_ms);
                next_frame += 22;
            }
            if (now_ms % 20u == 0u) fc.step(now_ms, att, out);
            ++now_ms;
        }
    }
};

}  // namespace

TEST(FlightControl, NeutralBeforeTheFirstFrameThenManualPassThrough) {
    Rig r;
    r.s.flight.thr_fs_pct = 0;
    r.fc.step(0, r.att, r.out);
    EXPECT_EQ(r.fc.state(), flight::State::NoSignal);
    const uint16_t neutral[8] = {1500, 1500, 1000, 1500, 1500, 1500, 1500, 1500};
    EXPECT_EQ(0, std::memcmp(r.out, neutral, sizeof neutral));
    const uint16_t sticks[8] = {1700, 1234, 1456, 1999, 1100, 1900, 1510, 1000};
    std::memcpy(r.rc, sticks, sizeof sticks);
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    for (int i = 0; i < 7; ++i) EXPECT_EQ(r.out[i], sticks[i]) << i;  // OUT8 = ch8, the switch
    EXPECT_EQ(r.fc.take_events() & flight::kEvFailsafeLost, 0);
}

TEST(FlightControl, RightWingDownMakesStabilizeRollLeftAndNoseDownPitchUp) {
    Rig r;
    r.rc[7] = 2000;  // switch high: STABILIZE
    r.att.roll_cd = 1500;  // right wing down 15 deg
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_LT(r.out[0], 1500) << "aileron below trim: roll left";
    r.att.roll_cd = 0;
    r.att.pitch_cd = -1000;  // nose down 10 deg
    r.run(0.1f);
    EXPECT_GT(r.out[1], 1500) << "elevator above trim: nose up";
    // A stick right demands a bank right: level wings get aileron right.
    r.att.pitch_cd = 0;
    r.rc[0] = 2000;
    r.run(0.1f);
    EXPECT_GT(r.out[0], 1500);
    // Throttle and rudder pass through.
    r.rc[2] = 1600;
    r.rc[3] = 1300;
    r.run(0.05f);
    EXPECT_EQ(r.out[2], 1600);
    EXPECT_EQ(r.out[3], 1300);
}

TEST(FlightControl, SwitchAndConsoleChooseTheMode) {
    Rig r;
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.rc[7] = 1500;  // middle: STABILIZE
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_TRUE(r.fc.take_events() & flight::kEvModeChanged);
    r.fc.choose(flight::Mode::Manual);  // the console
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual) << "the switch has not moved: the console's choice holds";
    r.rc[7] = 1000;
    r.run(0.1f);
    r.rc[7] = 2000;
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    r.s.flight.fltmode_ch = 0;  // no switch: only the console
    r.rc[7] = 1000;
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
}

TEST(FlightControl, LossEntersFailsafeWithinASecondAndTheModeReturns) {
    Rig r;
    r.s.flight.thr_fs_pct = 0;
    r.rc[7] = 2000;
    r.run(1.0f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    r.fc.take_events();
    r.att.roll_cd = -2000;  // left wing down when the signal goes
    r.rc[2] = 1800;         // and throttle up
    r.run(0.45f, false);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize) << "0.45 s without frames: not yet";
    r.run(0.1f, false);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Lost);
    EXPECT_EQ(r.fc.take_events() & flight::kEvFailsafeLost, flight::kEvFailsafeLost);
    EXPECT_GT(r.out[0], 1500) << "wings level: roll right";
    EXPECT_EQ(r.out[2], 1000) << "throttle at THR_FS_OUT 0 %";
    r.att.roll_cd = 0;
    r.run(0.5f, false);
    EXPECT_LT(r.out[1], 1500) << "level: the glide's nose-down pitch";
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_TRUE(r.fc.take_events() & flight::kEvFailsafeEnd);
}

TEST(FlightControl, EncoderFailsafeThrottleBelowThrFsValue) {
    Rig r;
    r.run(0.5f);
    r.fc.take_events();
    r.rc[2] = 900;  // the encoder's failsafe forces the throttle low; frames keep coming
    r.run(0.6f);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
    EXPECT_TRUE(r.fc.take_events() & flight::kEvFailsafeEncoder);
    r.rc[2] = 1100;
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
}

TEST(FlightControl, SensorFaultInStabilizeFallsBackToManualUntilTheAttitudeReturns) {
    Rig r;
    r.rc[7] = 2000;
    r.run(0.2f);
    r.fc.take_events();
    r.att.valid = false;
    r.rc[0] = 1700;
    r.run(0.1f);
    EXPECT_TRUE(r.fc.without_attitude());
    EXPECT_EQ(r.fc.take_events(), flight::kEvSensorFallback);
    EXPECT_EQ(r.out[0], 1700) << "the stick passes through";
    r.run(0.5f);
    EXPECT_EQ(r.fc.take_events(), 0) << "said once";
    r.att.valid = true;
    r.rc[0] = 1500;
    r.att.roll_cd = 1000;
    r.run(0.1f);
    EXPECT_FALSE(r.fc.without_attitude());
    EXPECT_EQ(r.fc.take_events(), flight::kEvAttitudeBack);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_LT(r.out[0], 1500) << "stabilising again";
}
