// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Flight: the PPM decoder, the attitude controllers, the end points and mixers, the
// modes and failsafe; lib/Params: the parameter table and the version 3 record.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "Console.h"
#include "Flight.h"
#include "Params.h"
#include "Ppm.h"
#include "Settings.h"

using flight::PpmDecoder;

namespace {

// Rising-edge captures of one PPM frame (Timer5 ticks, wrapping at 40000) from `t` on,
// then the sync gap to a 22.5 ms frame; returns the next frame's start.
uint32_t ppm_frame(const std::vector<uint16_t>& widths_us, uint32_t t_ticks, std::vector<uint16_t>& captures) {
    uint32_t t = t_ticks;
    captures.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    for (uint16_t w : widths_us) {
        t += 2u * w;
        captures.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    }
    return t_ticks + 45000u;  // 22.5 ms
}

// Feeds frames; returns how many were accepted, the last accepted in `last`.
int feed_all(PpmDecoder& d, const std::vector<uint16_t>& captures, std::vector<uint16_t>* last = nullptr) {
    int accepted = 0;
    for (uint16_t c : captures)
        if (d.feed(c)) {
            ++accepted;
            if (last) last->assign(d.frame_us(), d.frame_us() + flight::kChannels);
        }
    return accepted;
}

const std::vector<uint16_t> kFrame = {1100, 1200, 1300, 1400, 1500, 1600, 1700, 1900};

settings::Settings defaults() { return settings::defaults(); }

}  // namespace

// --- PPM ----------------------------------------------------------------------------

TEST(FlightPpm, GoodFramesAcceptedFromTheSecondWholeOne) {
    PpmDecoder d;
    std::vector<uint16_t> caps, last;
    uint32_t t = 12345;
    for (int i = 0; i < 5; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));  // the edge after the last sync gap
    // A frame closes at the next frame's first edge. Frame 1 has no sync before it (its
    // widths are ignored); frame 2 is whole but follows no whole frame; 3, 4, 5 are
    // accepted.
    EXPECT_EQ(feed_all(d, caps, &last), 3);
    EXPECT_EQ(last, kFrame);
}

TEST(FlightPpm, WidthsExactThroughTheTimerWrap) {
    PpmDecoder d;
    std::vector<uint16_t> caps, last;
    uint32_t t = 39000;  // the timer wraps inside the first frames
    const std::vector<uint16_t> odd = {800, 2200, 1501, 999, 1000, 2000, 1234, 1777};
    for (int i = 0; i < 6; ++i) t = ppm_frame(odd, t, caps);
    caps.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    EXPECT_EQ(feed_all(d, caps, &last), 4);
    EXPECT_EQ(last, odd);
}

TEST(FlightPpm, ShortFrameAndImplausibleWidthsRejected) {
    std::vector<uint16_t> caps;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    // A 7-channel frame, then a good one (rejected too: it follows an unstable count),
    // then good ones again.
    t = ppm_frame(std::vector<uint16_t>(kFrame.begin(), kFrame.end() - 1), t, caps);
    t = ppm_frame(kFrame, t, caps);
    t = ppm_frame(kFrame, t, caps);
    // A width of 700 us and one of 2300 us: each frame rejected.
    std::vector<uint16_t> low = kFrame, high = kFrame;
    low[2] = 700;
    high[5] = 2300;
    t = ppm_frame(low, t, caps);
    t = ppm_frame(high, t, caps);
    caps.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    // Accepted: frame 3 (after a whole 2), not 4 (7 widths), not 5 (after 7), 6, not 7
    // (700 us), not 8 (2300 us).
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps), 2);
}

TEST(FlightPpm, GlitchSplittingAPulseCostsTheFrameNotAWrongWidth) {
    std::vector<uint16_t> caps, last;
    uint32_t t = 500;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    // A spurious edge 300 us into channel 4: two short widths, nine in all.
    const size_t start = caps.size();
    t = ppm_frame(kFrame, t, caps);
    const uint16_t glitch = (uint16_t)((caps[start + 3] + 600u) % PpmDecoder::kPeriodTicks);
    caps.insert(caps.begin() + (long)start + 4, glitch);
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    PpmDecoder d;
    int n = 0;
    for (uint16_t c : caps)
        if (d.feed(c)) {
            ++n;
            EXPECT_EQ(std::vector<uint16_t>(d.frame_us(), d.frame_us() + 8), kFrame);
        }
    // Accepted: frame 3, not the glitched 4, not 5 (after a 9-count), 6, 7.
    EXPECT_EQ(n, 3);
}

TEST(FlightPpm, ResetDropsTheFrameInProgress) {
    std::vector<uint16_t> caps;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    t = ppm_frame(kFrame, t, caps);
    PpmDecoder d;
    // Three frames and the fourth's first 5 edges: frame 3 accepted at the 4th's first edge.
    EXPECT_EQ(feed_all(d, std::vector<uint16_t>(caps.begin(), caps.begin() + 27 + 5)), 1);
    d.reset();  // captures lost mid-frame
    std::vector<uint16_t> more;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, more);
    more.push_back((uint16_t)(t % PpmDecoder::kPeriodTicks));
    EXPECT_EQ(feed_all(d, more), 1);  // as from power-up: the third whole frame is the first accepted
}

// --- End points -----------------------------------------------------------------------

TEST(FlightEndPoints, PassThroughIsExactWithDefaultsAndWithin1usOtherwise) {
    const flight::EndPoints def{1000, 2000, 1500}, odd{1090, 1930, 1521};
    for (uint16_t w = 1000; w <= 2000; ++w) {
        const int16_t a = flight::width_to_angle(w, def, false);
        EXPECT_EQ(flight::angle_to_width(a, def, false), w);
        const int16_t t = flight::width_to_throttle(w, def, false);
        EXPECT_EQ(flight::throttle_to_width(t, def, false), w);
        const int16_t b = flight::width_to_angle(w, odd, false);
        const int back = flight::angle_to_width(b, odd, false);
        if (w >= 1090 && w <= 1930) EXPECT_LE(std::abs(back - (int)w), 1) << w;
    }
    EXPECT_EQ(flight::width_to_angle(2000, def, false), 4500);
    EXPECT_EQ(flight::width_to_angle(2000, def, true), -4500);
    EXPECT_EQ(flight::width_to_angle(2100, def, false), 4500);  // clamped
    EXPECT_EQ(flight::angle_to_width(4500, def, true), 1000);
    EXPECT_EQ(flight::throttle_to_width(1000, def, true), 1000);
    const flight::EndPoints narrow{1100, 1800, 1450};
    for (int a = -4500; a <= 4500; a += 7) {
        const uint16_t w = flight::angle_to_width((int16_t)a, narrow, (a & 1) != 0);
        EXPECT_GE(w, 1100);
        EXPECT_LE(w, 1800);
    }
}

TEST(FlightEndPoints, ModeSwitchBandsAreArduPlanes) {
    EXPECT_EQ(flight::switch_position(1000), 1);
    EXPECT_EQ(flight::switch_position(1230), 1);
    EXPECT_EQ(flight::switch_position(1231), 2);
    EXPECT_EQ(flight::switch_position(1500), 4);
    EXPECT_EQ(flight::switch_position(1750), 6);
    EXPECT_EQ(flight::switch_position(2000), 6);
}

// --- Controllers ------------------------------------------------------------------------

TEST(FlightController, PGainIsDegreesOfSurfacePerDegreeOfError) {
    flight::AxisController c;
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.0f, 0.02f, 3000}, 0.02f);
    // 10 deg of error, no rate: (P - I tau) x 10 deg = 4 deg = 400 cd (to the fixed point's 1 cd).
    EXPECT_NEAR(c.step(t, 1000, 0, 0), 400, 1);
    // A measured rate toward the demand damps: D x 20 deg/s = 0.4 deg less.
    EXPECT_NEAR(c.step(t, 1000, 0, 2000), 360, 1);
    // Full throw at most.
    EXPECT_EQ(c.step(t, 18000, 0, 0), 4500);
    EXPECT_EQ(c.step(t, -18000, 0, 0), -4500);
    // Gains over their whole ranges, errors and rates at their ends: no overflow, the
    // sign of the error, within full throw.
    for (float p : {0.1f, 4.0f})
        for (float d : {0.0f, 0.2f})
            for (float tau : {0.4f, 1.0f}) {
                const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{tau, p, 0.0f, d, 4500}, 0.02f);
                flight::AxisController e, f;
                const int16_t up = e.step(big, 36000, 0, -200000), down = f.step(big, -36000, 0, 200000);
                EXPECT_GT(up, 0);
                EXPECT_LE(up, 4500);
                EXPECT_EQ(down, -up);
            }
}

TEST(FlightController, StepResponseOfAModelAircraftSettles) {
    // A roll axis as a first-order rate response to the surface (rate -> k x surface with
    // a 0.2 s lag): the default gains bring a 20 deg demand within 1 deg in 3 s, no
    // overshoot beyond 10 %.
    flight::AxisController c;
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.04f, 0.02f, 3000}, 0.02f);
    float angle_deg = 0.0f, rate_deg_s = 0.0f, peak = 0.0f;
    for (int i = 0; i < 250; ++i) {
        const int16_t out = c.step(t, (int32_t)lroundf((20.0f - angle_deg) * 100.0f), 0, (int32_t)lroundf(rate_deg_s * 100.0f));
        const float target_rate = 15.0f * (float)out / 100.0f;  // 15 deg/s per deg of surface
        rate_deg_s += (target_rate - rate_deg_s) * 0.02f / 0.2f;
        angle_deg += rate_deg_s * 0.02f;
        peak = std::max(peak, angle_deg);
        if (i == 150) EXPECT_NEAR(angle_deg, 20.0f, 1.0f);
    }
    EXPECT_NEAR(angle_deg, 20.0f, 0.5f);
    EXPECT_LT(peak, 22.0f);
}

TEST(FlightController, IntegratorLimitedAndFrozenWhenSaturated) {
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.5f, 0.0f, 1000}, 0.02f);  // imax 10 deg
    flight::AxisController c;
    // A steady 2 deg error, no motion: the integrator grows to its limit and stops there.
    for (int i = 0; i < 2000; ++i) c.step(t, 200, 0, 0);
    EXPECT_FLOAT_EQ(c.integrator_deg(), 10.0f);
    // Saturated (a huge error): the integrator may not grow the way the output is pinned.
    flight::AxisController s;
    const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{0.5f, 4.0f, 0.2f, 0.0f, 4500}, 0.02f);
    s.step(big, 9000, 0, 0);  // saturates
    const float before = s.integrator_deg();
    for (int i = 0; i < 50; ++i) EXPECT_EQ(s.step(big, 9000, 0, 0), 4500);
    EXPECT_FLOAT_EQ(s.integrator_deg(), before);
    // ... but it unwinds at once when the error turns.
    s.step(big, -100, 0, 0);
    EXPECT_LT(s.integrator_deg(), before);
}

TEST(FlightController, TurnCoordinationPitchesUpInABankEitherWay) {
    // 30 deg bank at 15.5 m/s: g/V tan sin = 9.81/15.5 x 0.577 x 0.5 rad/s = 10.5 deg/s
    // (the tables at 5.12 deg steps: within 1 %).
    const int16_t k = flight::turn_gain_cds(15.5f, 1.0f);
    const int32_t r = flight::turn_rate_offset_cds(3000, 0, k);
    EXPECT_NEAR((double)r, 5729.578 * 9.80665 / 15.5 * std::tan(0.5236) * std::sin(0.5236), 0.01 * 1046.0);
    EXPECT_EQ(flight::turn_rate_offset_cds(-3000, 0, k), r);
    EXPECT_EQ(flight::turn_rate_offset_cds(0, 0, k), 0);
    // Between the table's points, and with the pitch's cosine.
    EXPECT_NEAR((double)flight::turn_rate_offset_cds(4250, 3000, k),
                5729.578 * 9.80665 / 15.5 * std::tan(0.74176) * std::sin(0.74176) * std::cos(0.5236), 0.01 * r + 3.0);
    // Limited at 80 deg, none inverted.
    EXPECT_EQ(flight::turn_rate_offset_cds(8900, 0, k), flight::turn_rate_offset_cds(8000, 0, k));
    EXPECT_EQ(flight::turn_rate_offset_cds(17000, 0, k), 0);
    // The largest gain at the largest bank fits.
    EXPECT_GT(flight::turn_rate_offset_cds(8000, 0, flight::turn_gain_cds(5.0f, 1.5f)), 0);
}

// --- Mixers -----------------------------------------------------------------------------

TEST(FlightMixer, PlainElevonAndVtail) {
    settings::Settings s = defaults();
    uint16_t out[8];
    const uint16_t aux[4] = {2000, 1000, 1500, 1750};
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, -900, 500, 450}, aux, out);
    EXPECT_EQ(out[0], 1600);  // aileron: +900 cd of 4500 = +100 us
    EXPECT_EQ(out[1], 1400);  // elevator
    EXPECT_EQ(out[2], 1500);  // throttle 50 %
    EXPECT_EQ(out[3], 1550);  // rudder
    EXPECT_EQ(out[4], 2000);
    EXPECT_EQ(out[5], 1000);
    EXPECT_EQ(out[6], 1500);
    EXPECT_EQ(out[7], 1750);
    s.flight.elevon_output = 1;
    // Elevons: left = (elevator - aileron) / 2, right = (elevator + aileron) / 2 (trailing
    // edge up positive): roll right lowers the left trailing edge and raises the right.
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, 0, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1450);
    EXPECT_EQ(out[1], 1550);
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{0, 900, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1550);
    EXPECT_EQ(out[1], 1550);
    EXPECT_EQ(out[4], 1500);  // aux at trim without aux commands
    s.flight.elevon_output = 0;
    s.flight.vtail_output = 1;
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, 900, 0, 900}, nullptr, out);
    EXPECT_EQ(out[0], 1600);  // the aileron stays on OUT1
    EXPECT_EQ(out[1], 1500);  // left ruddervator: (900 - 900) / 2
    EXPECT_EQ(out[3], 1600);  // right: (900 + 900) / 2
    // Reverse and limits.
    s.flight.vtail_output = 0;
    s.flight.servo_reversed = 0x01;
    s.flight.servo[0] = flight::EndPoints{1100, 1900, 1500};
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{4500, 0, 0, 0}, aux, out);
    EXPECT_EQ(out[0], 1100);
    s.flight.servo_reversed = 0x10;  // an aux output reversed about its trim
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{0, 0, 0, 0}, aux, out);
    EXPECT_EQ(out[4], 1000);
    EXPECT_EQ(out[5], 1000);
}

// --- Modes --------------------------------------------------------------------------------

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

TEST(FlightModes, NeutralBeforeTheFirstFrameThenManualPassThrough) {
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

TEST(FlightModes, RightWingDownMakesStabilizeRollLeftAndNoseDownPitchUp) {
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

TEST(FlightModes, SwitchAndConsoleChooseTheMode) {
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

TEST(FlightModes, LossEntersFailsafeWithinASecondAndTheModeReturns) {
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

TEST(FlightModes, EncoderFailsafeThrottleBelowThrFsValue) {
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

TEST(FlightModes, SensorFaultInStabilizeFallsBackToManualUntilTheAttitudeReturns) {
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

// --- Parameters ---------------------------------------------------------------------------

TEST(FlightParams, TableIndexNameAndDefaults) {
    const uint16_t n = params::count();
    EXPECT_GE(n, 90u);
    EXPECT_LT(n, 255u);
    params::Info in;
    std::vector<std::string> names;
    for (uint16_t i = 0; i < n; ++i) {
        ASSERT_TRUE(params::info(i, in));
        EXPECT_LE(std::strlen(in.name), params::kNameMax);
        EXPECT_EQ(params::find(in.name), (int16_t)i) << in.name;
        for (const auto& s : names) EXPECT_NE(s, in.name);
        names.push_back(in.name);
    }
    EXPECT_FALSE(params::info(n, in));
    EXPECT_EQ(params::find("rc8_reversed"), params::find("RC8_REVERSED"));
    EXPECT_EQ(params::find("RC9_MIN"), -1);
    const settings::Settings s = settings::defaults();
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("RLL2SRV_P")), 1.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("SERVO3_TRIM")), 1500.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("FLTMODE1")), 0.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("FLTMODE6")), 2.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("THR_FS_VALUE")), 950.0f);
    EXPECT_EQ(s.flight.rcmap[flight::kThrottle], 3);
    EXPECT_TRUE(params::all_valid(s));
}

TEST(FlightParams, SetChecksRangeWholenessAndEndPointOrder) {
    settings::Settings s = settings::defaults();
    const uint16_t p = (uint16_t)params::find("RLL2SRV_P");
    EXPECT_TRUE(params::set(s, p, 1.25f));
    EXPECT_FLOAT_EQ(s.flight.roll.p, 1.25f);
    EXPECT_FALSE(params::set(s, p, 5.0f));
    EXPECT_FALSE(params::set(s, p, std::nanf("")));
    EXPECT_FLOAT_EQ(s.flight.roll.p, 1.25f);
    const uint16_t trim = (uint16_t)params::find("SERVO2_TRIM");
    EXPECT_FALSE(params::set(s, trim, 1500.5f));
    EXPECT_FALSE(params::set(s, trim, 2100.0f)) << "above SERVO2_MAX";
    EXPECT_EQ(s.flight.servo[1].trim_us, 1500);
    EXPECT_TRUE(params::set(s, trim, 1520.0f));
    EXPECT_EQ(s.flight.servo[1].trim_us, 1520);
    const uint16_t rev = (uint16_t)params::find("RC5_REVERSED");
    EXPECT_TRUE(params::set(s, rev, 1.0f));
    EXPECT_EQ(s.flight.rc_reversed, 0x10);
    const uint16_t dec = (uint16_t)params::find("COMPASS_DEC");
    EXPECT_TRUE(params::set(s, dec, 0.1f));
    EXPECT_EQ(s.declination_centideg, 573);  // 0.1 rad = 5.73 deg
    EXPECT_NEAR(params::get(s, dec), 0.1f, 1e-4f);
}

TEST(FlightParams, RecordVersion3RoundTripsAndVersion2StillLoads) {
    EXPECT_EQ(params::flight_bytes(), settings::kFlightBytes);
    settings::Settings in = settings::defaults();
    in.rate_hz = 20;
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("PTCH2SRV_D"), 0.05f));
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("SERVO7_REVERSED"), 1.0f));
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("RC3_MIN"), 1050.0f));
    uint8_t rec[settings::kRecordSize];
    settings::encode(in, rec);
    EXPECT_EQ(rec[2], 3);
    settings::Settings out;
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    for (uint16_t i = 0; i < params::count(); ++i) EXPECT_EQ(params::get(out, i), params::get(in, i)) << i;
    EXPECT_EQ(out.flags & settings::kFlagUpgraded, 0);

    // A version 2 record as the previous firmware wrote it: rate, decl, mode, flags,
    // calibration, CRC; EEPROM beyond it erased.
    uint8_t v2[settings::kRecordSize];
    std::memset(v2, 0xFF, sizeof v2);
    settings::Settings old = settings::defaults();
    old.rate_hz = 25;
    old.declination_centideg = -345;
    old.mode = fmt::OutputMode::Csv;
    old.flags = settings::kFlagMagCalibrated;
    old.cal.mag_offset_uT = linalg::Vector3f(8.0f, -5.0f, 3.0f);
    settings::encode(old, v2);
    v2[2] = 2;
    v2[3] = settings::kV2PayloadLength;
    std::memset(v2 + 4 + settings::kV2PayloadLength, 0xFF, settings::kRecordSize - 4u - settings::kV2PayloadLength);
    const uint16_t crc = settings::crc16(v2, 4 + settings::kV2PayloadLength);
    v2[4 + settings::kV2PayloadLength] = (uint8_t)(crc & 0xFF);
    v2[5 + settings::kV2PayloadLength] = (uint8_t)(crc >> 8);
    settings::Settings up;
    ASSERT_EQ(settings::decode(v2, up), settings::LoadResult::Ok);
    EXPECT_EQ(up.rate_hz, 25);
    EXPECT_EQ(up.declination_centideg, -345);
    EXPECT_EQ(up.mode, fmt::OutputMode::Csv);
    EXPECT_TRUE(up.cal.mag_offset_uT == old.cal.mag_offset_uT);
    EXPECT_EQ(up.flags, settings::kFlagMagCalibrated | settings::kFlagUpgraded);
    EXPECT_FLOAT_EQ(up.flight.roll.p, 1.0f) << "flight settings at defaults";
    // Saved again: version 3, the upgrade flag not stored.
    settings::encode(up, rec);
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    EXPECT_EQ(out.flags, settings::kFlagMagCalibrated);
    // A v2 record with a bad CRC is refused, never misread.
    v2[10] ^= 0x40;
    EXPECT_EQ(settings::decode(v2, up), settings::LoadResult::BadCrc);
}

// --- Console ------------------------------------------------------------------------------

TEST(FlightConsole, SetGetFlightShowParse) {
    console::Command c = console::parse_line("set RLL2SRV_P 0.55");
    ASSERT_EQ(c.id, console::CommandId::Set);
    EXPECT_EQ(c.arg, params::find("RLL2SRV_P"));
    EXPECT_EQ(c.value, 5500);
    c = console::parse_line("set servo1_min 1100");
    ASSERT_EQ(c.id, console::CommandId::Set);
    EXPECT_EQ(c.value, 1100 * console::kParamScale);
    EXPECT_EQ(console::parse_line("set SERVO1_MIN 1100.5").error, console::Error::ParamRange);
    EXPECT_EQ(console::parse_line("set SERVO1_MIN 3000").error, console::Error::ParamRange);
    EXPECT_EQ(console::parse_line("set NOPE 1").error, console::Error::UnknownParam);
    EXPECT_EQ(console::parse_line("set RLL2SRV_P").error, console::Error::MissingArgument);
    EXPECT_EQ(console::parse_line("set RLL2SRV_P x").error, console::Error::BadNumber);
    EXPECT_EQ(console::parse_line("get LIM_ROLL_CD").id, console::CommandId::Get);
    EXPECT_EQ(console::parse_line("flight stabilize").arg, 1);
    EXPECT_EQ(console::parse_line("flight manual").arg, 0);
    EXPECT_EQ(console::parse_line("flight acro").error, console::Error::BadFlightMode);
    EXPECT_EQ(console::parse_line("rc").arg, console::kShowRc);
    EXPECT_EQ(console::parse_line("servo").arg, console::kShowServo);
    EXPECT_EQ(console::parse_line("params").arg, console::kShowParams);
    EXPECT_EQ(console::parse_line("rc 1").error, console::Error::ExtraArgument);
    // Through the queue, across the ring's wrap.
    console::CommandQueue q;
    for (int round = 0; round < 30; ++round) {
        for (const char* line : {"set RLL2SRV_D -0.0", "set LIM_PITCH_MIN -2000", "get RC8_TRIM", "flight stabilize",
                                 "servo", "set RC1_MIN 3000", "params"}) {
            const console::Command in = console::parse_line(line);
            ASSERT_TRUE(q.push(in));
            const console::Command back = q.pop();
            EXPECT_EQ(back.id, in.id) << line;
            EXPECT_EQ(back.error, in.error) << line;
            EXPECT_EQ(back.arg, in.arg) << line;
            EXPECT_EQ(back.value, in.value) << line;
        }
    }
}

TEST(FlightConsole, SetAndGetReplies) {
    std::string out;
    const text::Sink sink{&out, [](void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }};
    settings::Settings s = settings::defaults();
    EXPECT_TRUE(console::apply_setting(console::parse_line("set ptch2srv_p 0.7"), s, &sink));
    EXPECT_EQ(out, "# PTCH2SRV_P 0.7000\n");
    out.clear();
    console::apply_setting(console::parse_line("get RC3_MAX"), s, &sink);
    EXPECT_EQ(out, "# RC3_MAX 2000\n");
    out.clear();
    console::apply_setting(console::parse_line("set SERVO1_MIN 1600"), s, &sink);
    EXPECT_NE(out.find("# error: SERVO1_MIN"), std::string::npos) << out;
    EXPECT_EQ(s.flight.servo[0].min_us, 1000);
    out.clear();
    console::print_error(console::parse_line("set RLL2SRV_P 9"), &sink);
    EXPECT_EQ(out, "# error: RLL2SRV_P must be 0.1000..4.0000; nothing changed\n");
}
