// SPDX-License-Identifier: GPL-3.0-or-later
// Each airframe lib/Flight mixes for (the plain aeroplane, elevons, V-tail) flown in
// STABILIZE by FlightControl: a rigid aeroplane whose roll and pitch rates follow what its
// surfaces do, read off the eight output widths by the airframe's own geometry (not by the
// mixer's formulas), its attitude and body rates fed back as the estimator's. A surface on
// the wrong output or with the wrong sign, a rate fed to the wrong axis or with the wrong
// sign, turn coordination the wrong way: the aeroplane does not level, or does not hold its
// turn.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "Flight.h"
#include "Settings.h"

namespace {

constexpr float kPi = 3.14159265f;
constexpr float kG = 9.80665f;

enum class Airframe { Plain, Elevons, Vtail };

// The surfaces' effect, degrees of an equivalent aileron and elevator, from the widths: a
// surface command in degrees is (width - 1500) x 45 / 500 (the default end points). An
// elevon or a ruddervator's positive command is trailing edge up: the right elevon up and
// the left down roll right, both up pitch up; both ruddervators up pitch up, the left one
// up and the right down yaw right (each surface's force is normal to it: the left one's
// up pushes the tail down and left, the right one's down pushes it up and left; the tail
// goes left, the nose right, as under a rudder deflected right).
struct Effect {
    float aileron_deg, elevator_deg, rudder_deg;
};
float deg(uint16_t w) { return ((float)w - 1500.0f) * 45.0f / 500.0f; }
Effect effect(Airframe a, const uint16_t out[8]) {
    switch (a) {
    case Airframe::Plain: return Effect{deg(out[0]), deg(out[1]), deg(out[3])};
    case Airframe::Elevons: return Effect{deg(out[1]) - deg(out[0]), deg(out[0]) + deg(out[1]), deg(out[3])};
    case Airframe::Vtail: return Effect{deg(out[0]), deg(out[1]) + deg(out[3]), deg(out[1]) - deg(out[3])};
    }
    return Effect{0, 0, 0};
}

// The aeroplane the gains are tuned for: body rates p, q first-order (0.2 s) toward 1/P'
// deg/s a degree of surface (P' = (P - I TCONST) TCONST - D, the controller's feed-forward:
// the demanded rate alone then flies itself); a coordinated turn's yaw rate
// r = g sin(bank) / V at the airspeed FlightControl assumes (the mean of ARSPD_FBW_MIN and
// _MAX); Euler angles from the body rates.
struct Aeroplane {
    Airframe frame;
    settings::Settings s = settings::defaults();
    flight::FlightControl fc{s.flight};
    uint16_t rc[8] = {1500, 1500, 1300, 1500, 1500, 1500, 1500, 2000};  // switch high: STABILIZE
    uint16_t out[8] = {};
    float roll_deg = 0, pitch_deg = 0, p_deg_s = 0, q_deg_s = 0;
    Effect last{0, 0, 0};
    uint32_t now_ms = 0;

    explicit Aeroplane(Airframe a) : frame(a) {
        s.flight.elevon_output = a == Airframe::Elevons ? 1 : 0;
        s.flight.vtail_output = a == Airframe::Vtail ? 1 : 0;
        fc.configure();
    }
    static float per_deg(const flight::AxisGains& g) { return 1.0f / ((g.p - g.i * g.tconst_s) * g.tconst_s - g.d); }
    void fly(float seconds) {
        const float v_m_s = 0.5f * (float)(s.flight.arspd_min_m_s + s.flight.arspd_max_m_s);
        const float k_roll = per_deg(s.flight.roll), k_pitch = per_deg(s.flight.pitch);
        for (int i = 0; i < (int)(seconds * 1000.0f); ++i, ++now_ms) {
            if (now_ms % 20u == 0u) {
                fc.on_frame(rc, now_ms);
                const flight::Attitude att{(int32_t)std::lround(roll_deg * 100.0f), (int32_t)std::lround(pitch_deg * 100.0f),
                                           (int32_t)std::lround(p_deg_s * 100.0f), (int32_t)std::lround(q_deg_s * 100.0f), true};
                fc.step(now_ms, att, out);
                last = effect(frame, out);
            }
            const float dt = 0.001f;
            p_deg_s += (k_roll * last.aileron_deg - p_deg_s) * dt / 0.2f;
            q_deg_s += (k_pitch * last.elevator_deg - q_deg_s) * dt / 0.2f;
            const float phi = roll_deg * kPi / 180.0f, theta = pitch_deg * kPi / 180.0f;
            const float r_deg_s = kG * std::sin(phi) / v_m_s * 180.0f / kPi;
            roll_deg += (p_deg_s + std::tan(theta) * (q_deg_s * std::sin(phi) + r_deg_s * std::cos(phi))) * dt;
            pitch_deg += (q_deg_s * std::cos(phi) - r_deg_s * std::sin(phi)) * dt;
        }
    }
};

const Airframe kAirframes[] = {Airframe::Plain, Airframe::Elevons, Airframe::Vtail};
const char* name(Airframe a) { return a == Airframe::Plain ? "plain" : (a == Airframe::Elevons ? "elevons" : "V-tail"); }

}  // namespace

TEST(Airframes, EachLevelsFromAnUpset) {
    for (Airframe a : kAirframes) {
        Aeroplane ap(a);
        ap.fly(0.1f);
        ASSERT_EQ(ap.fc.state(), flight::State::Stabilize);
        // Right wing down 40 deg, nose down 15, rolling further right at 30 deg/s.
        ap.roll_deg = 40.0f;
        ap.pitch_deg = -15.0f;
        ap.p_deg_s = 30.0f;
        ap.fly(0.02f);
        EXPECT_LT(ap.last.aileron_deg, 0.0f) << name(a) << ": rolls left";
        EXPECT_GT(ap.last.elevator_deg, 0.0f) << name(a) << ": pitches up";
        float peak = 0.0f;
        for (int i = 0; i < 40; ++i) {
            ap.fly(0.1f);
            peak = std::max(peak, std::fabs(ap.roll_deg));
        }
        EXPECT_LT(peak, 45.0f) << name(a);
        EXPECT_LT(std::fabs(ap.roll_deg), 1.0f) << name(a);
        EXPECT_LT(std::fabs(ap.pitch_deg), 1.0f) << name(a);
        EXPECT_LT(std::fabs(ap.p_deg_s), 1.0f) << name(a);
        EXPECT_LT(std::fabs(ap.q_deg_s), 1.0f) << name(a);
    }
}

TEST(Airframes, EachHoldsTheBankTheStickAsksAndItsPitchInTheTurn) {
    for (Airframe a : kAirframes) {
        for (int side : {1, -1}) {
            Aeroplane ap(a);
            ap.rc[0] = (uint16_t)(1500 + side * 250);  // half stick: 22.5 deg of bank (LIM_ROLL_CD 45)
            ap.fly(6.0f);
            EXPECT_NEAR(ap.roll_deg, side * 22.5f, 1.0f) << name(a) << " " << side;
            // The turn's pitch rate is flown, not left to pull the nose down.
            EXPECT_NEAR(ap.pitch_deg, 0.0f, 1.0f) << name(a) << " " << side;
            EXPECT_NEAR(ap.q_deg_s, kG * std::sin(22.5f * kPi / 180.0f) * std::tan(22.5f * kPi / 180.0f) / 15.5f * 180.0f / kPi,
                        0.5f)
                << name(a) << " " << side;
            // Pitch stick up: 10 deg of pitch (LIM_PITCH_MAX 25 deg at full stick).
            ap.rc[0] = 1500;
            ap.rc[1] = 1700;
            ap.fly(6.0f);
            EXPECT_NEAR(ap.roll_deg, 0.0f, 1.0f) << name(a);
            EXPECT_NEAR(ap.pitch_deg, 10.0f, 1.0f) << name(a);
        }
    }
}

TEST(Airframes, EachPassesTheSticksInManualWithTheirSumsAndDifferences) {
    for (Airframe a : kAirframes) {
        Aeroplane ap(a);
        ap.rc[7] = 1000;  // MANUAL
        ap.rc[0] = 1600;  // roll right 9 deg
        ap.rc[1] = 1400;  // pitch down 9 deg
        ap.rc[3] = 1550;  // yaw right 4.5 deg
        ap.fly(0.1f);
        ASSERT_EQ(ap.fc.state(), flight::State::Manual);
        EXPECT_NEAR(ap.last.aileron_deg, 9.0f, 0.2f) << name(a);
        EXPECT_NEAR(ap.last.elevator_deg, -9.0f, 0.2f) << name(a);
        EXPECT_NEAR(ap.last.rudder_deg, 4.5f, 0.2f) << name(a);
        EXPECT_EQ(ap.out[2], 1300) << name(a) << ": the throttle passes";
    }
}
