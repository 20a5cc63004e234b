// SPDX-License-Identifier: GPL-3.0-or-later
// Arming (lib/Flight/Arming.h): the pre-arm checks as ARMING_CHECK selects them, the
// rudder gesture's timing (ArduPlane's rudder_arm_disarm_check), and the throttle held
// at its minimum while disarmed in FlightControl, in every state.
#include <gtest/gtest.h>

#include <cstring>

#include "Arming.h"
#include "Flight.h"
#include "FlightRig.h"
#include "Settings.h"

namespace {

flight::PreArmInputs all_good() {
    flight::PreArmInputs in;
    in.imu_ok = true;
    in.gyro_calibrating = false;
    in.estimator_ok = true;
    in.compass_used = true;
    in.compass_ok = true;
    in.compass_calibrated = true;
    in.compass_calibrating = false;
    in.baro_present = true;
    in.baro_ok = true;
    in.rc_seen = true;
    in.rc_failsafe = false;
    in.throttle_low = true;
    in.settings_loaded = true;
    return in;
}

}  // namespace

TEST(Arming, EachFailedCheckIsItsReason) {
    EXPECT_EQ(flight::prearm_failures(all_good(), flight::kCheckAll), 0u);
    struct Case {
        bool flight::PreArmInputs::*field;
        bool value;
        uint16_t reason;
        uint16_t check;
    };
    const Case cases[] = {
        {&flight::PreArmInputs::imu_ok, false, flight::kPreArmGyrosNotHealthy, flight::kCheckIns},
        {&flight::PreArmInputs::gyro_calibrating, true, flight::kPreArmGyrosNotCalibrated, flight::kCheckIns},
        {&flight::PreArmInputs::estimator_ok, false, flight::kPreArmAhrsNotHealthy, flight::kCheckIns},
        {&flight::PreArmInputs::compass_ok, false, flight::kPreArmCompassNotHealthy, flight::kCheckCompass},
        {&flight::PreArmInputs::compass_calibrated, false, flight::kPreArmCompassNotCalibrated, flight::kCheckCompass},
        {&flight::PreArmInputs::compass_calibrating, true, flight::kPreArmCompassCalibrating, flight::kCheckCompass},
        {&flight::PreArmInputs::baro_ok, false, flight::kPreArmBaroNotHealthy, flight::kCheckBaro},
        {&flight::PreArmInputs::rc_seen, false, flight::kPreArmRcNotFound, flight::kCheckRc},
        {&flight::PreArmInputs::rc_failsafe, true, flight::kPreArmRadioFailsafe, flight::kCheckRc},
        {&flight::PreArmInputs::throttle_low, false, flight::kPreArmThrottleHigh, flight::kCheckRc},
        {&flight::PreArmInputs::settings_loaded, false, flight::kPreArmSettingsNotLoaded, flight::kCheckParameters},
    };
    for (const Case& c : cases) {
        flight::PreArmInputs in = all_good();
        in.*c.field = c.value;
        EXPECT_EQ(flight::prearm_failures(in, flight::kCheckAll), c.reason) << c.reason;
        EXPECT_EQ(flight::prearm_failures(in, c.check), c.reason) << "its own bit: " << c.reason;
        EXPECT_EQ(flight::prearm_failures(in, (uint16_t)(0x1FFEu & ~c.check)), 0u) << "the others' bits: " << c.reason;
        EXPECT_EQ(flight::prearm_failures(in, 0), 0u) << "ARMING_CHECK 0";
    }
}

TEST(Arming, SensorsNotThereAreNotChecked) {
    flight::PreArmInputs in = all_good();
    in.compass_used = false;  // never found: yaw on the gyro, nothing to check
    in.compass_ok = false;
    in.baro_present = false;
    in.baro_ok = false;
    EXPECT_EQ(flight::prearm_failures(in, flight::kCheckAll), 0u);
}

TEST(Arming, SeveralReasonsAtOnceOnePerSensor) {
    flight::PreArmInputs in = all_good();
    in.rc_seen = false;
    in.throttle_low = false;  // no receiver: "RC not found" only
    in.imu_ok = false;
    in.gyro_calibrating = true;  // the first reason of the IMU only
    EXPECT_EQ(flight::prearm_failures(in, flight::kCheckAll), flight::kPreArmRcNotFound | flight::kPreArmGyrosNotHealthy);
}

TEST(Arming, ThrottleZeroIsWithinThreePercent) {
    EXPECT_TRUE(flight::throttle_at_zero(0));
    EXPECT_TRUE(flight::throttle_at_zero(30));
    EXPECT_FALSE(flight::throttle_at_zero(31));
}

TEST(Arming, FullRightRudderForThreeSecondsArms) {
    flight::Arming a;
    EXPECT_FALSE(a.armed());
    EXPECT_FALSE(a.throttle_live(1));
    EXPECT_TRUE(a.throttle_live(0));
    uint32_t t = 1000;
    flight::Gesture g = flight::Gesture::None;
    for (; t < 1000 + 2999; t += 20) {
        g = a.rudder(flight::kRudderArmOnly, 4500, 0, false, t);
        ASSERT_EQ(g, flight::Gesture::None) << t;
    }
    g = a.rudder(flight::kRudderArmOnly, 4500, 0, false, 4000);  // 3000 ms since 1000
    EXPECT_EQ(g, flight::Gesture::Arm);
    a.arm();
    EXPECT_TRUE(a.armed());
    EXPECT_TRUE(a.throttle_live(1));
}

TEST(Arming, TheGestureStartsAgainWhenInterrupted) {
    flight::Arming a;
    a.rudder(flight::kRudderArmOnly, 4100, 0, false, 0);
    a.rudder(flight::kRudderArmOnly, 4100, 0, false, 2000);
    EXPECT_EQ(a.rudder(flight::kRudderArmOnly, 3900, 0, false, 2020), flight::Gesture::None);  // below full rudder
    EXPECT_EQ(a.rudder(flight::kRudderArmOnly, 4100, 0, false, 2040), flight::Gesture::None);
    EXPECT_EQ(a.rudder(flight::kRudderArmOnly, 4100, 0, false, 5020), flight::Gesture::None) << "3 s from 2040, not 0";
    EXPECT_EQ(a.rudder(flight::kRudderArmOnly, 4100, 0, false, 5040), flight::Gesture::Arm);
    // The throttle off zero, or the receiver gone, starts it again too.
    flight::Arming b;
    b.rudder(flight::kRudderArmOnly, 4500, 0, false, 0);
    EXPECT_EQ(b.rudder(flight::kRudderArmOnly, 4500, 31, false, 1500), flight::Gesture::None);
    b.rudder(flight::kRudderArmOnly, 4500, 30, false, 1520);
    EXPECT_EQ(b.rudder(flight::kRudderArmOnly, 4500, 30, false, 4500), flight::Gesture::None);
    b.rudder_released();
    b.rudder(flight::kRudderArmOnly, 4500, 30, false, 4520);
    EXPECT_EQ(b.rudder(flight::kRudderArmOnly, 4500, 30, false, 7500), flight::Gesture::None);
    EXPECT_EQ(b.rudder(flight::kRudderArmOnly, 4500, 30, false, 7520), flight::Gesture::Arm);
}

TEST(Arming, DisarmByRudderOnlyWithArmingRudderTwoAndNotFlying) {
    for (uint8_t mode : {flight::kRudderDisabled, flight::kRudderArmOnly, flight::kRudderArmDisarm}) {
        for (bool flying : {false, true}) {
            flight::Arming a;
            a.arm();
            flight::Gesture last = flight::Gesture::None;
            for (uint32_t t = 0; t <= 4000; t += 20) {
                const flight::Gesture g = a.rudder(mode, -4500, 0, flying, t);
                if (g != flight::Gesture::None) last = g;
            }
            const bool want = mode == flight::kRudderArmDisarm && !flying;
            EXPECT_EQ(last, want ? flight::Gesture::Disarm : flight::Gesture::None) << (int)mode << flying;
            // Right rudder while armed, left while disarmed: nothing.
            EXPECT_EQ(a.rudder(mode, 4500, 0, false, 10000), flight::Gesture::None);
            EXPECT_EQ(a.rudder(mode, 4500, 0, false, 14000), flight::Gesture::None);
        }
    }
    flight::Arming d;
    for (uint32_t t = 0; t <= 4000; t += 20) EXPECT_EQ(d.rudder(flight::kRudderArmDisarm, -4500, 0, false, t), flight::Gesture::None);
    for (uint32_t t = 0; t <= 4000; t += 20) EXPECT_EQ(d.rudder(flight::kRudderDisabled, 4500, 0, false, t), flight::Gesture::None);
}

using flight_test::Rig;

TEST(Arming, DisarmedTheThrottleHoldsItsMinimumInEveryState) {
    Rig r;
    r.rc[2] = 1800;  // throttle 80 %
    r.s.flight.thr_fs_pct = 40;  // a failsafe throttle that is not the minimum
    r.fc.set_throttle_live(false);
    r.fc.step(0, r.att, r.out);
    EXPECT_EQ(r.fc.state(), flight::State::NoSignal);
    EXPECT_EQ(r.out[2], 1000) << "before the receiver, not THR_FS_OUT";
    r.run(0.2f);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    EXPECT_EQ(r.out[2], 1000);
    EXPECT_EQ(r.out[0], 1500);
    r.rc[0] = 1800;  // the surfaces stay live
    r.run(0.1f);
    EXPECT_EQ(r.out[0], 1800);
    r.rc[7] = 2000;
    r.run(0.2f);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize);
    EXPECT_EQ(r.out[2], 1000);
    r.run(0.7f, false);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.out[2], 1000) << "disarmed: not THR_FS_OUT";
    r.fc.set_throttle_live(true);
    r.run(0.1f, false);
    EXPECT_EQ(r.out[2], 1400) << "armed: THR_FS_OUT 40 %";
    r.run(0.1f);
    EXPECT_EQ(r.out[2], 1800);
    // Reversed throttle output: its minimum is SERVO3_MAX's end.
    r.s.flight.servo_reversed = 0x04;
    r.fc.configure();
    r.fc.set_throttle_live(false);
    r.run(0.1f);
    EXPECT_EQ(r.out[2], 2000);
}

TEST(RcOverride, AppliedPerChannelReleasedIgnoredAndTimedOut) {
    Rig r;
    r.fc.set_override_timeout(375);  // 3 s
    r.run(0.2f);
    const uint16_t none = 0xFFFFu;
    const uint16_t o1[8] = {1700, none, none, none, none, none, none, none};
    r.fc.on_override(o1, r.now_ms);
    const uint32_t at = r.now_ms;
    r.run(0.1f);
    EXPECT_EQ(r.out[0], 1700);
    EXPECT_EQ(r.out[1], 1500) << "UINT16_MAX leaves the channel to the receiver";
    EXPECT_EQ(r.fc.input_us(0, r.now_ms), 1700);
    r.run(2.8f);
    EXPECT_EQ(r.out[0], 1700) << "held 3 s after its message";
    while (r.now_ms < at + 3000u + 40u) r.run(0.02f);
    EXPECT_EQ(r.out[0], 1500) << "timed out: the receiver's again";
    // Released by 0 before its time.
    r.fc.on_override(o1, r.now_ms);
    r.run(0.1f);
    EXPECT_EQ(r.out[0], 1700);
    const uint16_t release[8] = {0, none, none, none, none, none, none, none};
    r.fc.on_override(release, r.now_ms);
    r.run(0.05f);
    EXPECT_EQ(r.out[0], 1500);
    // Implausible widths are ignored; the mode switch is a channel as any.
    const uint16_t odd[8] = {500, none, none, none, none, none, none, 2000};
    r.fc.on_override(odd, r.now_ms);
    r.run(0.1f);
    EXPECT_EQ(r.out[0], 1500);
    EXPECT_EQ(r.fc.state(), flight::State::Stabilize) << "ch8 overridden high";
    // RC_OVERRIDE_TIME 0: none taken.
    Rig off;
    off.fc.set_override_timeout(0);
    off.run(0.1f);
    off.fc.on_override(o1, off.now_ms);
    off.run(0.1f);
    EXPECT_EQ(off.out[0], 1500);
}

TEST(RcOverride, AFreshThrottleOverrideIsValidInputWhileTheReceiverIsLost) {
    Rig r;
    r.fc.set_override_timeout(375);
    r.run(0.2f);
    const uint16_t o[8] = {1600, 1500, 1300, 1500, 0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF};
    // The receiver stops; the ground station sends at 10 Hz: no FAILSAFE.
    for (int i = 0; i < 30; ++i) {
        r.fc.on_override(o, r.now_ms);
        r.run(0.1f, false);
        ASSERT_EQ(r.fc.state(), flight::State::Manual) << i;
    }
    EXPECT_EQ(r.out[0], 1600);
    EXPECT_EQ(r.out[2], 1300);
    EXPECT_EQ(r.out[4], 1500) << "not overridden: the receiver's last width";
    // The messages stop (the last 0.1 s ago): FAILSAFE 0.5 s after the last one.
    r.run(0.35f, false);
    EXPECT_EQ(r.fc.state(), flight::State::Manual);
    r.run(0.1f, false);
    EXPECT_EQ(r.fc.state(), flight::State::Failsafe);
    EXPECT_EQ(r.out[2], 1000) << "THR_FS_OUT, not the override";
    // Before the receiver was ever heard, no input.
    Rig b;
    b.fc.set_override_timeout(375);
    b.fc.on_override(o, 0);
    b.fc.step(0, b.att, b.out);
    EXPECT_EQ(b.fc.state(), flight::State::NoSignal);
    // Without a throttle override, no help.
    Rig n;
    n.fc.set_override_timeout(375);
    const uint16_t no_thr[8] = {1600, 1500, 0xFFFF, 1500, 0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF};
    n.run(0.2f);
    for (int i = 0; i < 10; ++i) {
        n.fc.on_override(no_thr, n.now_ms);
        n.run(0.1f, false);
    }
    EXPECT_EQ(n.fc.state(), flight::State::Failsafe);
}
