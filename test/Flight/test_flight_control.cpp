// SPDX-License-Identifier: GPL-3.0-or-later
// FlightControl (lib/Flight): the modes (MANUAL, STABILIZE), the mode switch and the
// console's choice, failsafe on a lost receiver and on the encoder's own failsafe, the
// fallback to MANUAL without an attitude.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

#include "Flight.h"
#include "FlightRig.h"
#include "Settings.h"

using flight_test::Rig;

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

// --- Failsafe's timing ----------------------------------------------------------------------

TEST(FlightControl, FailsafeTimingToTheMillisecond) {
    Rig r;
    r.fc.on_frame(r.rc, 1000);
    r.fc.update_signal(1000);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    EXPECT_EQ(r.fc.take_events(), 0) << "the first frame is no end of a failsafe";
    EXPECT_FALSE(r.fc.wants_attitude());
    // 500 ms without a frame is a lost receiver; 499 ms is not.
    r.fc.update_signal(1499);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.fc.update_signal(1500);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Lost);
    EXPECT_EQ(r.fc.take_events(), flight::kEvFailsafeLost);
    EXPECT_TRUE(r.fc.wants_attitude());
    r.fc.update_signal(1600);
    EXPECT_EQ(r.fc.take_events(), 0) << "said once";
    // One good frame ends it at once.
    r.fc.on_frame(r.rc, 1700);
    r.fc.update_signal(1700);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::None);
    EXPECT_EQ(r.fc.take_events(), flight::kEvFailsafeEnd);
    // Frames go on with the throttle channel below THR_FS_VALUE (the encoder's own
    // failsafe): 500 ms after the last good one, FAILSAFE for the encoder.
    r.rc[2] = 949;
    for (uint32_t t = 1720; t <= 2300; t += 20) {
        r.fc.on_frame(r.rc, t);
        r.fc.update_signal(t);
        EXPECT_EQ(r.fc.state(), t < 2200 ? flight::State::Manual : flight::State::Failsafe) << t;
    }
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
    EXPECT_EQ(r.fc.take_events(), flight::kEvFailsafeEncoder);
    EXPECT_EQ(r.fc.rc_us()[2], 949) << "the frame is kept all the same";
    // At THR_FS_VALUE itself the frame is good.
    r.rc[2] = 950;
    r.fc.on_frame(r.rc, 2320);
    r.fc.update_signal(2320);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    for (uint32_t t = 2340; t <= 3400; t += 20) r.fc.on_frame(r.rc, t);
    r.fc.update_signal(3400);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    // Frames that stop while the encoder's failsafe is on: still the encoder's, as long as
    // the last frame came within 500 ms.
    r.rc[2] = 900;
    r.fc.on_frame(r.rc, 3500);
    r.fc.update_signal(3900);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
    // Frames that stopped long before the signal is next looked at: lost.
    r.rc[2] = 1100;
    r.fc.on_frame(r.rc, 5000);
    r.fc.update_signal(5000);
    ASSERT_EQ(r.fc.state(), flight::State::Manual);
    r.fc.update_signal(10200);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Lost);
}

TEST(FlightControl, ChannelOneCanBeTheThrottleOrTheModeSwitch) {
    Rig r;
    r.s.flight.rcmap[0] = 3;
    r.s.flight.rcmap[2] = 1;  // throttle on channel 1, roll on 3
    r.rc[0] = 1200;
    r.rc[2] = 1500;
    r.fc.on_frame(r.rc, 0);
    r.fc.update_signal(0);
    ASSERT_EQ(r.fc.state(), flight::State::Manual);
    r.rc[0] = 900;
    for (uint32_t t = 20; t <= 600; t += 20) r.fc.on_frame(r.rc, t);
    r.fc.update_signal(600);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
    Rig m;
    m.s.flight.fltmode_ch = 1;
    m.rc[0] = 2000;  // switch high on channel 1: STABILIZE
    m.run(0.1f);
    EXPECT_EQ(m.fc.state(), flight::State::Stabilize);
}

TEST(FlightControl, EventsAreSixBitsApart) {
    const uint8_t events[6] = {flight::kEvFailsafeLost, flight::kEvFailsafeEncoder, flight::kEvFailsafeEnd,
                               flight::kEvSensorFallback, flight::kEvAttitudeBack, flight::kEvModeChanged};
    uint8_t all = 0;
    for (uint8_t e : events) {
        EXPECT_EQ(e & (e - 1), 0) << (int)e << " is one bit";
        EXPECT_NE(e, 0);
        EXPECT_EQ(all & e, 0) << (int)e << " is its own bit";
        all = (uint8_t)(all | e);
    }
}

TEST(FlightControl, NoSignalHoldsEveryOutputAtTrimAndTheThrottleAtItsFailsafeValue) {
    Rig r;
    r.s.flight.thr_fs_pct = 25;
    // Probes (1 us a cd about 5000 + i us) on every output but the throttle's.
    for (uint8_t i = 0; i < 8; ++i) r.s.flight.servo[i] = flight::EndPoints{(uint16_t)(501 + i), (uint16_t)(9499 + i), (uint16_t)(5000 + i)};
    r.s.flight.servo[2] = flight::EndPoints{1000, 2000, 1500};
    r.fc.configure();
    r.fc.step(100000, r.att, r.out);
    EXPECT_EQ(r.fc.state(), flight::State::NoSignal);
    EXPECT_FALSE(r.fc.wants_attitude());
    for (uint8_t i = 0; i < 8; ++i) {
        if (i != 2) {
            EXPECT_EQ(r.out[i], 5000 + i) << (int)i;
        }
    }
    EXPECT_EQ(r.out[2], 1250);
    r.fc.update_signal(4000000000u);
    EXPECT_EQ(r.fc.state(), flight::State::NoSignal) << "no frame ever: no failsafe either";
    EXPECT_EQ(r.fc.take_events(), 0);
}

// --- The modes --------------------------------------------------------------------------------

TEST(FlightControl, EachSwitchPositionIsItsFltmode) {
    Rig r;
    // FLTMODE1..6: STABILIZE, MANUAL, 4 (ACRO, not a mode here: MANUAL), STABILIZE, MANUAL, STABILIZE.
    const uint8_t modes[6] = {2, 0, 4, 2, 0, 2};
    for (uint8_t i = 0; i < 6; ++i) r.s.flight.fltmode[i] = modes[i];
    const uint16_t middle[6] = {1100, 1300, 1420, 1560, 1700, 1900};
    r.rc[7] = middle[0];
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize) << "the first frame reads the switch";
    EXPECT_EQ(r.fc.take_events(), flight::kEvModeChanged);
    for (int round = 0; round < 2; ++round)
        for (uint8_t i = 0; i < 6; ++i) {
            const flight::Mode before = r.fc.chosen();
            r.rc[7] = middle[i];
            r.run(0.1f);
            const flight::Mode want = modes[i] == 2 ? flight::Mode::Stabilize : flight::Mode::Manual;
            EXPECT_EQ(r.fc.chosen(), want) << (int)i;
            EXPECT_EQ(r.fc.state(), want == flight::Mode::Stabilize ? flight::State::Stabilize : flight::State::Manual);
            EXPECT_EQ(r.fc.take_events(), want != before ? flight::kEvModeChanged : 0) << (int)i;
        }
    // The switch on channel 5: channel 8 no longer counts.
    r.s.flight.fltmode_ch = 5;
    r.rc[4] = middle[1];
    r.rc[7] = middle[0];
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.rc[7] = middle[5];
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.rc[4] = middle[3];
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
}

TEST(FlightControl, TheEncodersFailsafeFramesDoNotMoveTheSwitch) {
    Rig r;
    r.run(0.2f);
    r.rc[2] = 900;
    r.rc[7] = 2000;  // the encoder's failsafe values: throttle low, whatever the switch
    r.run(0.2f);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Manual);
    EXPECT_EQ(r.fc.take_events() & flight::kEvModeChanged, 0);
    r.rc[2] = 1100;
    r.run(0.1f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize) << "the first good frame reads it";
}

TEST(FlightControl, AChoiceInFailsafeWaitsForTheSignal) {
    Rig r;
    r.rc[7] = 2000;
    r.run(0.2f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    r.run(0.6f, false);
    ASSERT_EQ(r.fc.state(), flight::State::Failsafe);
    r.fc.choose(flight::Mode::Manual);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Manual);
    r.run(0.1f);  // the switch has not moved: the console's choice holds
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.fc.choose((flight::Mode)4);  // ACRO: not a mode here
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Manual);
    r.fc.choose(flight::Mode::Stabilize);
    r.fc.choose((flight::Mode)8);  // ArduPlane's AUTOTUNE: not one here either
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Manual);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.fc.choose(flight::Mode::FlyByWireA);  // FBWA flies STABILIZE's law
    EXPECT_EQ(r.fc.chosen(), flight::Mode::FlyByWireA);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    r.fc.choose(flight::Mode::Manual);
    // Before the first frame too.
    Rig n;
    n.fc.choose(flight::Mode::Stabilize);
    n.fc.step(0, n.att, n.out);
    EXPECT_EQ(n.fc.state(), flight::State::NoSignal);
    n.s.flight.fltmode_ch = 0;
    n.run(0.1f);
    EXPECT_EQ(n.fc.state(), flight::State::Stabilize);
}

TEST(FlightControl, ManualWithoutAnAttitudeIsNoFallback) {
    Rig r;
    r.att.valid = false;
    r.run(0.2f);
    EXPECT_FALSE(r.fc.without_attitude());
    EXPECT_EQ(r.fc.take_events(), 0);
    EXPECT_FALSE(r.fc.wants_attitude());
}

TEST(FlightControl, ConfiguredLaterFliesAsConfiguredAtOnce) {
    Rig r;
    r.rc[7] = 2000;
    flight::FlightControl later(r.s.flight, flight::FlightControl::ConfiguredLater{});
    later.configure();
    uint16_t out[8];
    for (uint32_t t = 0; t < 2000; t += 20) {
        r.att = flight::Attitude{(int32_t)(t % 700) - 300, 200, 1000, -500, true};
        r.fc.on_frame(r.rc, t);
        later.on_frame(r.rc, t);
        r.fc.step(t, r.att, r.out);
        later.step(t, r.att, out);
        ASSERT_EQ(0, std::memcmp(out, r.out, sizeof out)) << t;
    }
}

TEST(FlightControl, RcMapAndReversedChannelsInManual) {
    Rig r;
    // Roll on channel 2 (reversed, end points 1100-1900 about 1450), pitch on 1, throttle
    // on 6, yaw on 5.
    r.s.flight.rcmap[0] = 2;
    r.s.flight.rcmap[1] = 1;
    r.s.flight.rcmap[2] = 6;
    r.s.flight.rcmap[3] = 5;
    r.s.flight.rc_reversed = 0x02;
    r.s.flight.rc[1] = flight::EndPoints{1100, 1900, 1450};
    r.s.flight.rc[0] = flight::EndPoints{1000, 2000, 1500};
    r.s.flight.rc[5] = flight::EndPoints{1050, 1950, 1500};
    r.s.flight.rc[4] = flight::EndPoints{1000, 2000, 1520};
    r.fc.configure();
    const uint16_t sticks[8] = {1620, 1333, 1100, 1500, 1777, 1600, 1500, 1000};
    std::memcpy(r.rc, sticks, sizeof sticks);
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Manual) << "channel 3 low is no failsafe now";
    const flight::FlightSettings& f = r.s.flight;
    EXPECT_EQ(r.out[0], flight::angle_to_width(flight::width_to_angle(1333, f.rc[1], true), f.servo[0], false));
    EXPECT_EQ(r.out[1], flight::angle_to_width(flight::width_to_angle(1620, f.rc[0], false), f.servo[1], false));
    EXPECT_EQ(r.out[2], flight::throttle_to_width(flight::width_to_throttle(1600, f.rc[5], false), f.servo[2], false));
    EXPECT_EQ(r.out[3], flight::angle_to_width(flight::width_to_angle(1777, f.rc[4], false), f.servo[3], false));
    EXPECT_GT(r.out[0], 1500) << "channel 2 below its trim, reversed: roll right";
    // The scales by role, the outputs' by OUT1-4; a channel number out of 1..8 falls back
    // on the role's own channel.
    flight::Scales sc = flight::scales_of(f);
    EXPECT_EQ(sc.in[0].up, flight::angle_input_scale(f.rc[1]).up);
    EXPECT_EQ(sc.in[0].down, flight::angle_input_scale(f.rc[1]).down);
    EXPECT_EQ(sc.in[2].up, flight::throttle_input_scale(f.rc[5]).up);
    EXPECT_EQ(sc.in[3].up, flight::angle_input_scale(f.rc[4]).up);
    r.s.flight.rc[3] = flight::EndPoints{1150, 1850, 1480};
    r.s.flight.rc[7] = flight::EndPoints{1200, 1800, 1540};
    r.s.flight.rcmap[0] = 0;
    r.s.flight.rcmap[3] = 9;
    r.s.flight.rcmap[1] = 8;
    sc = flight::scales_of(f);
    EXPECT_EQ(sc.in[0].up, flight::angle_input_scale(f.rc[0]).up);
    EXPECT_EQ(sc.in[3].up, flight::angle_input_scale(f.rc[3]).up);
    EXPECT_EQ(sc.in[3].down, flight::angle_input_scale(f.rc[3]).down);
    EXPECT_EQ(sc.in[1].up, flight::angle_input_scale(f.rc[7]).up) << "channel 8 is one of the eight";
    EXPECT_EQ(sc.in[1].down, flight::angle_input_scale(f.rc[7]).down);
    r.s.flight.rcmap[1] = 1;
    // The encoder's failsafe reads the mapped throttle channel.
    r.s.flight.rcmap[0] = 2;
    r.s.flight.rcmap[3] = 5;
    r.rc[5] = 900;
    r.run(0.6f);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
    // ... channel 8 too (the mode switch moved to channel 7).
    r.rc[5] = 1600;
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Manual);
    r.s.flight.rcmap[2] = 8;
    r.s.flight.fltmode_ch = 7;
    r.rc[6] = 1000;
    r.rc[7] = 1500;
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Manual);
    r.rc[7] = 900;
    r.run(0.6f);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.fc.failsafe_cause(), flight::FailsafeCause::Encoder);
}

// --- STABILIZE and FAILSAFE flown by the axis controllers -------------------------------------

namespace {

// End points of 1 us a centi-degree about 5000 us (exact within +-21.8 deg): an output
// that shows a surface command to the unit.
constexpr flight::EndPoints kProbe{501, 9499, 5000};

// FlightControl's two axis controllers stepped beside it: what its surfaces should be for
// the errors given.
struct Beside {
    flight::AxisTerms roll_terms, pitch_terms;
    int16_t turn_gain;
    flight::AxisController roll, pitch;
    explicit Beside(const flight::FlightSettings& f)
        : roll_terms(flight::axis_terms(f.roll, 0.02f)),
          pitch_terms(flight::axis_terms(f.pitch, 0.02f)),
          turn_gain(flight::turn_gain_cds((float)f.trim_arspd_cm * 0.01f, f.pitch_roll_ff)) {}
    void reset() {
        roll.reset();
        pitch.reset();
    }
    // The surfaces for a roll error (already the short way round) and a pitch demand.
    void step(const flight::Attitude& att, int32_t roll_error, int32_t pitch_demand, int16_t& aileron, int16_t& elevator) {
        aileron = roll.step(roll_terms, roll_error, 0, att.roll_rate_cds);
        elevator = pitch.step(pitch_terms, pitch_demand - att.pitch_cd,
                              flight::turn_rate_offset_cds(att.roll_cd, att.pitch_cd, turn_gain), att.pitch_rate_cds);
    }
};

// Settings off the defaults where a slip would show: other gains on each axis, an airspeed
// and a turn gain of their own, OUT1 and OUT2 as probes.
settings::Settings flown_settings() {
    settings::Settings s = settings::defaults();
    s.flight.roll = flight::AxisGains{0.6f, 1.3f, 0.3f, 0.11f, 2500};
    s.flight.pitch = flight::AxisGains{0.45f, 0.9f, 0.2f, 0.07f, 2000};
    s.flight.arspd_min_m_s = 10;
    s.flight.arspd_max_m_s = 25;
    s.flight.pitch_roll_ff = 1.2f;
    s.flight.fs_pitch_cd = -700;
    s.flight.trim_pitch_cd = 300;
    s.flight.trim_arspd_cm = 1650;
    s.flight.thr_fs_pct = 30;
    s.flight.servo[0] = kProbe;
    s.flight.servo[1] = kProbe;
    s.flight.servo[3] = kProbe;
    return s;
}

// An attitude that keeps moving: bank and pitch within +-25 and +-15 deg, rates to 60 deg/s.
flight::Attitude moving(uint32_t t_ms, bool valid = true) {
    const float t = (float)t_ms * 0.001f;
    return flight::Attitude{(int32_t)(2500.0f * std::sin(1.3f * t)), (int32_t)(1500.0f * std::sin(0.7f * t + 1.0f)),
                            (int32_t)(6000.0f * std::cos(2.1f * t)), (int32_t)(-4000.0f * std::sin(1.7f * t)), valid};
}

}  // namespace

TEST(FlightControl, StabilizeAndFailsafeAreTheAxisControllersOnTheEstimate) {
    Rig r;
    r.s = flown_settings();
    r.fc.configure();
    Beside b(r.s.flight);
    const flight::EndPoints& probe = kProbe;
    int16_t ail = 0, elev = 0;
    uint32_t t = 0;
    // `frames`: a frame before each step; `expect`: the surfaces beside, or none (MANUAL).
    auto fly = [&](uint32_t ms, bool frames, int phase) {
        for (uint32_t end = t + ms; t < end; t += 20) {
            if (frames) r.fc.on_frame(r.rc, t);
            r.att = moving(t, r.att.valid);
            r.fc.step(t, r.att, r.out);
            if (phase == 0) continue;  // MANUAL: nothing beside
            // The stick centred: the trim; the failsafe's glide from the trim.
            const int32_t demand = r.s.flight.trim_pitch_cd + (phase == 1 ? 0 : r.s.flight.fs_pitch_cd);
            b.step(r.att, -r.att.roll_cd, demand, ail, elev);
            ASSERT_EQ(r.out[0], flight::angle_to_width(ail, probe, false)) << "t " << t << " phase " << phase;
            ASSERT_EQ(r.out[1], flight::angle_to_width(elev, probe, false)) << "t " << t << " phase " << phase;
        }
    };
    r.rc[3] = 1700;  // rudder: passes in STABILIZE, not in FAILSAFE
    r.rc[2] = 1600;
    r.rc[4] = 1234;
    r.rc[7] = 2000;
    fly(1000, true, 1);  // STABILIZE from the first frame: the controllers start afresh
    EXPECT_EQ(r.out[3], flight::angle_to_width(flight::width_to_angle(1700, r.s.flight.rc[3], false), probe, false));
    EXPECT_TRUE(r.fc.wants_attitude());
    EXPECT_EQ(r.out[2], 1600);
    EXPECT_EQ(r.out[4], 1234);
    // The console chooses STABILIZE again: nothing changes.
    r.fc.choose(flight::Mode::Stabilize);
    fly(200, true, 1);
    // To MANUAL and back: afresh.
    r.fc.choose(flight::Mode::Manual);
    fly(100, true, 0);
    EXPECT_EQ(r.out[0], 5000) << "the stick at trim";
    r.fc.choose(flight::Mode::Stabilize);
    b.reset();
    fly(600, true, 1);
    // The receiver lost: FAILSAFE flies wings level and the glide's pitch, afresh; the
    // rudder at trim, the throttle at THR_FS_OUT, OUT5-8 at their trims.
    fly(480, false, 1);
    b.reset();
    fly(600, false, 2);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.out[3], 5000);
    EXPECT_EQ(r.out[2], 1300);
    EXPECT_EQ(r.out[4], 1500);
    // Back: STABILIZE afresh.
    b.reset();
    fly(600, true, 1);
    // The attitude lost: MANUAL; back: afresh.
    r.att.valid = false;
    fly(200, true, 0);
    EXPECT_TRUE(r.fc.without_attitude());
    r.att.valid = true;
    b.reset();
    fly(600, true, 1);
    // FAILSAFE without an attitude: the surfaces at trim; with it again, afresh.
    fly(480, false, 1);
    r.att.valid = false;
    r.fc.take_events();
    fly(200, false, 0);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_FALSE(r.fc.without_attitude()) << "FAILSAFE is no STABILIZE to fall back from";
    EXPECT_EQ(r.fc.take_events(), flight::kEvFailsafeLost);
    EXPECT_EQ(r.out[0], 5000);
    EXPECT_EQ(r.out[1], 5000);
    EXPECT_EQ(r.out[3], 5000);
    EXPECT_EQ(r.out[2], 1300);
    r.att.valid = true;
    b.reset();
    fly(400, false, 2);
}

TEST(FlightControl, SticksDemandTheirLimitsAndRollErrorsGoTheShortWayRound) {
    // Unit gains (TCONST 1 s, P 1, no I or D): a surface command in cd is the attitude
    // error itself, shown to the unit on the probe outputs.
    Rig r;
    r.s.flight.roll = flight::AxisGains{1.0f, 1.0f, 0.0f, 0.0f, 0};
    r.s.flight.pitch = flight::AxisGains{1.0f, 1.0f, 0.0f, 0.0f, 0};
    r.s.flight.servo[0] = kProbe;
    r.s.flight.servo[1] = kProbe;
    r.s.flight.lim_roll_cd = 2000;
    r.s.flight.lim_pitch_max_cd = 1800;
    r.s.flight.lim_pitch_min_cd = -900;
    r.fc.configure();
    r.rc[7] = 2000;
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    // Full stick is the limit, within 1 cd; a stick is its share of it, within 1 cd, and
    // its mirror image demands the opposite.
    for (uint16_t w = 1000; w <= 2000; w += 5) {
        r.rc[0] = w;
        r.rc[1] = w;
        r.run(0.02f);
        const int32_t stick = flight::width_to_angle(w, r.s.flight.rc[0], false);
        const int32_t roll = (int32_t)r.out[0] - 5000, pitch = (int32_t)r.out[1] - 5000;
        EXPECT_LE(std::abs(roll - stick * 2000 / 4500), 1) << w;
        EXPECT_LE(std::abs(pitch - stick * (stick >= 0 ? 1800 : 900) / 4500), 1) << w;
        r.rc[0] = (uint16_t)(3000 - w);
        r.rc[1] = (uint16_t)(3000 - w);
        r.run(0.02f);
        EXPECT_EQ((int32_t)r.out[0] - 5000, -roll) << w;
        if (w != 1500) {
            EXPECT_NE((int32_t)r.out[1] - 5000, -pitch) << "up and down have their own limits";
        }
    }
    r.rc[0] = 2000;
    r.rc[1] = 1000;
    r.run(0.02f);
    EXPECT_EQ((int32_t)r.out[0] - 5000, 1999);
    EXPECT_EQ((int32_t)r.out[1] - 5000, -899);
    // The stick's sign picks the limit, to the last centi-degree: a pitch stick of -0.01
    // deg (a receiver of 1 cd a us) with LIM_PITCH_MAX 90 deg and _MIN -1 deg asks 0 (it
    // would ask -0.01 deg of LIM_PITCH_MAX's).
    r.s.flight.rc[1] = flight::EndPoints{500, 9500, 5000};
    r.s.flight.lim_pitch_max_cd = 9000;
    r.s.flight.lim_pitch_min_cd = -100;
    r.fc.configure();
    r.rc[0] = 1500;
    r.rc[1] = 4999;
    r.run(0.02f);
    ASSERT_EQ(flight::width_to_angle(4999, r.s.flight.rc[1], false), -1);
    EXPECT_EQ((int32_t)r.out[1] - 5000, 0);
    r.rc[1] = 5001;
    r.run(0.02f);
    EXPECT_EQ((int32_t)r.out[1] - 5000, 1) << "+0.01 deg of LIM_PITCH_MAX's 90 deg";
    // Errors beyond 180 deg go the other way round: from a bank of -160.02 deg to the
    // full stick's demand of +19.99 deg is 180.01 deg to the right: -179.99 deg, left.
    r.rc[0] = 2000;
    r.rc[1] = 1500;
    auto aileron_at = [&r](int32_t roll_cd) {
        r.att.roll_cd = roll_cd;
        r.run(0.02f);
        return (int32_t)r.out[0] - 5000;
    };
    // (Full throw reads 4499 on the probe: it is exact within +-21.8 deg.)
    EXPECT_EQ(aileron_at(-15999), 4499) << "an error of 179.98 deg: right";
    EXPECT_EQ(aileron_at(-16001), 4499) << "180 deg exactly: as it is";
    EXPECT_EQ(aileron_at(-16002), -4499) << "180.01 deg: left";
    r.rc[0] = 1000;  // and the other way: -19.99 deg asked from a bank of 160.02 deg
    EXPECT_EQ(aileron_at(15999), -4499);
    EXPECT_EQ(aileron_at(16001), -4499) << "-180 deg exactly: as it is";
    EXPECT_EQ(aileron_at(16002), 4499) << "-180.01 deg: right";
    r.rc[0] = 1500;
    EXPECT_EQ(aileron_at(-18000), 4499) << "180 deg exactly: as it is (right)";
    EXPECT_EQ(aileron_at(18000), -4499) << "-180 deg exactly: as it is (left)";
    // Within reach of the probe: P' 0.1 (410 / 4096), a demand of 0 and a bank of -179.9
    // deg (an error of 179.9 deg: 18.01 deg of aileron) or +179.9 deg; and one beyond.
    r.s.flight.roll = flight::AxisGains{1.0f, 0.1f, 0.0f, 0.0f, 0};
    r.fc.configure();
    EXPECT_EQ(aileron_at(-17990), 1801);
    EXPECT_EQ(aileron_at(17990), -1801);
    EXPECT_EQ(aileron_at(-18010), -1801) << "an error of 180.1 deg is -179.9";
    EXPECT_EQ(aileron_at(18010), 1801);
    // The turn is 360 deg to the centi-degree: P' 0.25 (a quarter of the error, rounded
    // away from zero) at errors of 180.02 and 180.03 deg, i.e. -179.98 and -179.97.
    r.s.flight.roll = flight::AxisGains{1.0f, 0.25f, 0.0f, 0.0f, 0};
    r.fc.configure();
    r.rc[0] = 2000;  // a demand of 19.99 deg
    auto width_at = [&r](int32_t roll_cd) {
        r.att.roll_cd = roll_cd;
        r.run(0.02f);
        return r.out[0];
    };
    EXPECT_EQ(width_at(-16003), flight::angle_to_width(-4500, kProbe, false)) << "-17998 / 4 = -4499.5";
    EXPECT_EQ(width_at(-16004), flight::angle_to_width(-4499, kProbe, false)) << "-17997 / 4 = -4499.25";
    r.rc[0] = 1000;  // -19.99 deg
    EXPECT_EQ(width_at(16003), flight::angle_to_width(4500, kProbe, false));
    EXPECT_EQ(width_at(16004), flight::angle_to_width(4499, kProbe, false));
}

// The turn coordination's airspeed: the pitot's when there is one (not below ARSPD_FBW_MIN,
// as AP_PitchController), else the cruise speed, else the mean of ARSPD_FBW_MIN and _MAX.
TEST(FlightControl, TurnCoordinationTakesTheMeasuredAirspeed) {
    settings::Settings s = flown_settings();  // ARSPD 10..25 m/s, TRIM_ARSPD_CM 16.5 m/s
    EXPECT_EQ(flight::coordination_airspeed_cm_s(s.flight, 2100), 2100);
    EXPECT_EQ(flight::coordination_airspeed_cm_s(s.flight, 1), 1000) << "at least ARSPD_FBW_MIN";
    EXPECT_EQ(flight::coordination_airspeed_cm_s(s.flight, 0), 1650) << "no pitot: the cruise speed";
    s.flight.trim_arspd_cm = 0;
    EXPECT_EQ(flight::coordination_airspeed_cm_s(s.flight, 0), 1750) << "nor a cruise speed: the mean";
    s.flight.trim_arspd_cm = 1650;

    // In STABILIZE, a banked attitude with the sticks centred. A pitot reading v flies as a
    // board without one whose cruise speed is v (the coordination's only input that differs),
    // step for step while v changes; and a slower measured airspeed asks more up elevator.
    Rig measured, cruise, slow;
    measured.s = s;
    slow.s = s;
    for (Rig* r : {&measured, &cruise, &slow}) {
        if (r == &cruise) r->s = s;
        r->rc[7] = 2000;  // STABILIZE
        r->fc.configure();
    }
    const uint16_t speeds[] = {1200, 2400, 1800, 1800, 1000, 3000, 1500};
    int checked = 0;
    for (uint32_t t = 0; t < 7000; t += 20) {
        const uint16_t v = speeds[(t / 500) % 7];
        if (cruise.s.flight.trim_arspd_cm != v) {  // the twin's cruise speed follows (configure: afresh)
            cruise.s.flight.trim_arspd_cm = v;
            cruise.fc.configure();
        }
        const flight::Attitude att{4000 + (int32_t)(t % 300), 300, 500, -200, true, v};
        flight::Attitude none = att;
        none.airspeed_cm_s = 0;
        flight::Attitude at_min = att;
        at_min.airspeed_cm_s = 1000;  // ARSPD_FBW_MIN
        measured.fc.on_frame(measured.rc, t);
        cruise.fc.on_frame(cruise.rc, t);
        slow.fc.on_frame(slow.rc, t);
        measured.fc.step(t, att, measured.out);
        cruise.fc.step(t, none, cruise.out);
        slow.fc.step(t, at_min, slow.out);
        if (t % 500 == 0) continue;  // the twin's configure() restarted its integrators
        ASSERT_EQ(measured.out[1], cruise.out[1]) << "t " << t << " v " << v;
        if (v > 1000) {
            EXPECT_GT(slow.out[1], measured.out[1]) << "t " << t << " v " << v;
            ++checked;
        }
    }
    EXPECT_GT(checked, 200);
}

TEST(FlightControl, ACoordinatedTurnsBodyPitchRateIsFlownNotFought) {
    // AP_PitchController's coordination: in a level turn at bank phi and airspeed V the
    // heading turns at w = g tan(phi) / V, and the body's pitch axis, banked phi, sees
    // w sin(phi) of it (x cos(pitch)): the nose must pitch at that body rate to follow the
    // path. 30 deg of bank at a measured 15.5 m/s: 9.80665 / 15.5 x tan 30 x sin 30 rad/s =
    // 10.465 deg/s. With the nose at its demand and the gyro measuring that body rate, the
    // rate error is 0: the elevator is the feed-forward P' x the turn's rate alone, the same
    // every step (no D, the integrator still), either way round. Not measured (the nose not
    // following), all of it is rate error: D x it more at once, and the integrator grows
    // by I TCONST dt x it a step.
    Rig r;
    r.s.flight.servo[1] = kProbe;  // 1 us a centi-degree
    r.fc.configure();
    r.rc[7] = 2000;
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    const flight::AxisGains& g = r.s.flight.pitch;
    const double p_ff = ((double)g.p - (double)g.i * g.tconst_s) * g.tconst_s - g.d;
    constexpr double kPi = 3.14159265358979;
    const double turn_cds = 100.0 * 180.0 / kPi * 9.80665 / 15.5 * std::tan(kPi / 6.0) * std::sin(kPi / 6.0);
    ASSERT_NEAR(turn_cds, 1046.5, 0.1);
    // The body rate as lib/Flight's tables give it (pinned to the formula entry by entry in
    // test_axis_controller.cpp): within 1 % of the equation's here.
    const int32_t q_cds = flight::turn_rate_offset_cds(3000, 0, flight::turn_gain_cds(15.5f, r.s.flight.pitch_roll_ff));
    ASSERT_NEAR((double)q_cds, turn_cds, 0.01 * turn_cds);
    for (int side : {1, -1}) {
        const flight::Attitude flown{side * 3000, 0, 0, q_cds, true, 1550};
        int32_t first = 0;
        for (int i = 0; i < 100; ++i) {
            r.fc.on_frame(r.rc, r.now_ms);
            r.fc.step(r.now_ms, flown, r.out);
            r.now_ms += 20;
            const int32_t elevator = (int32_t)r.out[1] - 5000;
            if (i == 0) first = elevator;
            ASSERT_EQ(elevator, first) << "side " << side << " step " << i;
        }
        EXPECT_NEAR((double)first, p_ff * q_cds, 1.0) << "side " << side;
        EXPECT_NEAR((double)first, p_ff * turn_cds, 0.01 * p_ff * turn_cds + 1.0) << "side " << side;
        // The same turn, the gyro reading no pitch rate: D x the turn's rate more at once,
        // then I TCONST dt x it a step (the integrator's whole centi-degrees).
        const flight::Attitude lagging{side * 3000, 0, 0, 0, true, 1550};
        const double i_step = (double)g.i * g.tconst_s * 0.02 * q_cds;
        double integral = 0.0;
        for (int i = 0; i < 50; ++i) {
            r.fc.on_frame(r.rc, r.now_ms);
            r.fc.step(r.now_ms, lagging, r.out);
            r.now_ms += 20;
            integral += i_step;
            const double want = p_ff * q_cds + (double)g.d * q_cds + integral;
            ASSERT_NEAR((double)((int32_t)r.out[1] - 5000), want, 2.0) << "side " << side << " step " << i;
        }
        // Back to STABILIZE afresh for the other side (the integrator emptied).
        r.fc.choose(flight::Mode::Manual);
        r.fc.choose(flight::Mode::Stabilize);
    }
}

// The navigation's modes: the bank, pitch and throttle from set_nav_demands, through the
// same controllers; disarmed, the throttle at its minimum.
TEST(FlightControl, NavigationModesFlyTheNavigationsDemands) {
    Rig r;
    r.s.flight.fltmode[5] = (uint8_t)flight::Mode::Rtl;  // switch high
    r.rc[7] = 2000;
    r.fc.set_nav_demands(2000, 500, 600);  // bank right 20 deg, pitch up 5, throttle 60 %
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Navigate);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Rtl);
    EXPECT_GT(r.out[0], 1500) << "aileron right: the bank asked for";
    EXPECT_GT(r.out[1], 1500) << "elevator up: the pitch asked for";
    EXPECT_EQ(r.out[2], 1600) << "the navigation's throttle, not the stick's (1100)";
    r.fc.set_throttle_live(false);
    r.run(0.05f);
    EXPECT_EQ(r.out[2], 1000) << "disarmed: the throttle at its minimum";
    r.fc.set_throttle_live(true);
    // The demands, not the sticks: a full left stick changes nothing.
    r.rc[0] = 1000;
    r.att.roll_cd = 2000;
    r.att.pitch_cd = 500;
    r.fc.set_nav_demands(2000, 500, 600);
    r.run(0.5f);
    EXPECT_NEAR(r.out[0], 1500, 15) << "on the demanded bank: about trim";
}

TEST(FlightControl, TheSwitchKeepsTheModeWhenTheOneItPicksCannotRun) {
    Rig r;
    r.s.flight.fltmode[5] = (uint8_t)flight::Mode::Auto;
    r.rc[7] = 1500;  // STABILIZE
    r.run(0.1f);
    ASSERT_EQ(r.fc.state(), flight::State::Stabilize);
    r.fc.take_events();
    r.fc.set_unavailable(1u << flight::mode_index((uint8_t)flight::Mode::Auto));
    r.rc[7] = 2000;
    r.run(0.2f);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Stabilize);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_EQ(r.fc.refused_mode(), flight::Mode::Auto);
    EXPECT_EQ(r.fc.take_events(), flight::kEvModeRefused);
    // Available later: the switch must move again (ArduPlane's).
    r.fc.set_unavailable(0);
    r.run(0.2f);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Stabilize);
    r.rc[7] = 1500;
    r.run(0.1f);
    r.rc[7] = 2000;
    r.run(0.1f);
    EXPECT_EQ(r.fc.chosen(), flight::Mode::Auto);
}

// ArduPlane's short failsafe: AUTO, RTL, LOITER and CIRCLE fly on; FBWB and CRUISE glide.
TEST(FlightControl, TheShortFailsafeLetsAutoGoOnButFbwbGlides) {
    for (flight::Mode m : {flight::Mode::Auto, flight::Mode::FlyByWireB}) {
        Rig r;
        r.run(0.1f);  // the first frame reads the switch (MANUAL)
        r.fc.choose(m);
        r.fc.set_nav_demands(-1500, 300, 700);
        r.run(0.2f);
        ASSERT_EQ(r.fc.state(), flight::State::Navigate);
        r.run(1.0f, false);
        ASSERT_EQ(r.fc.state(), flight::State::Failsafe);
        if (m == flight::Mode::Auto) {
            EXPECT_TRUE(r.fc.navigating_in_failsafe());
            EXPECT_LT(r.out[0], 1500) << "the navigation's bank left, not wings level";
            EXPECT_EQ(r.out[2], 1700) << "the navigation's throttle";
        } else {
            EXPECT_FALSE(r.fc.navigating_in_failsafe());
            EXPECT_EQ(r.out[2], 1000) << "THR_FS_OUT 0: the glide";
        }
        r.run(0.2f);
        EXPECT_EQ(r.fc.state(), flight::State::Navigate) << "the receiver back: the mode again";
    }
}
