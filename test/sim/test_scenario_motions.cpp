// SPDX-License-Identifier: GPL-3.0-or-later
// The seeded motions of build/scenario (sim/Motions.h): the acceleration they write is the
// second derivative of the motion, their figures lie in the ranges their comments state,
// seeds change them and no seed leaves them fixed. test/e2e/test_scenario_motions.cpp
// checks the files the tool writes from them.
#include <gtest/gtest.h>

#include <cmath>

#include "Motions.h"

namespace {

using namespace sim::motion;

const Kind kKinds[] = {kTranslateSlow, kTranslateFast, kWalk, kPendulum, kCar, kTapping, kKnocking, kSlowRotation};
const uint64_t kSeeds[] = {0, 1, 2, 3};

// The velocity (NED, m/s), written from the plan's parts independently of accel_ned:
// the hand's displacement rate, the path's Rz(heading) (speed + forward', lateral') and the
// pendulum's r' = L th' (cos th cos b, cos th sin b, -sin th).
void velocity_ned(const Plan& p, double t, double v[3]) {
    for (int i = 0; i < 3; ++i) v[i] = p.hand_m[i].at(t).d1;
    const double heading = p.heading_deg.at(t).v * kDeg;
    const double u = p.speed_m_s.at(t).v + p.forward_m.at(t).d1, w = p.lateral_m.at(t).d1;
    v[0] += std::cos(heading) * u - std::sin(heading) * w;
    v[1] += std::sin(heading) * u + std::cos(heading) * w;
    if (p.string_m > 0.0) {
        double plane;
        const D3 th = swing_at(p, t, plane);
        v[0] += p.string_m * th.d1 * std::cos(th.v) * std::cos(plane);
        v[1] += p.string_m * th.d1 * std::cos(th.v) * std::sin(plane);
        v[2] -= p.string_m * th.d1 * std::sin(th.v);
    }
}

double norm3(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// Peak |linear acceleration| sampled every dt_s.
double peak_accel(const Plan& p, double dt_s) {
    double peak = 0.0;
    for (double t = 0.0; t <= p.end_s; t += dt_s) {
        double a[3];
        accel_ned(p, t, a);
        peak = std::fmax(peak, norm3(a));
    }
    return peak;
}

TEST(ScenarioMotions, StepAndWaveDerivativesAreAnalytic) {
    const Step s{1.0, 0.7, 2.5};
    const Wave w{0.5, 4.0, 0.8, 0.3, 1.7, 0.4};
    const double h = 1e-5;
    for (double t = 0.3; t < 4.5; t += 0.013) {
        for (int k = 0; k < 2; ++k) {
            auto at = [&](double x) { return k == 0 ? step_at(s, x) : wave_at(w, x); };
            const D3 c = at(t), p = at(t + h), m = at(t - h);
            EXPECT_NEAR(c.d1, (p.v - m.v) / (2 * h), 1e-5) << "part " << k << " t " << t;
            EXPECT_NEAR(c.d2, (p.d1 - m.d1) / (2 * h), 1e-4) << "part " << k << " t " << t;
        }
    }
    EXPECT_DOUBLE_EQ(step_at(s, 10.0).v, 2.5);
    EXPECT_DOUBLE_EQ(wave_at(w, 4.0).v, 0.0);
}

TEST(ScenarioMotions, AccelerationIsTheDerivativeOfTheVelocity) {
    const double h = 1e-6;
    for (Kind kind : kKinds) {
        for (uint64_t seed : kSeeds) {
            const Plan p = make_plan(kind, seed);
            double worst = 0.0;
            // 0.0371 s does not divide any rate of the motions: the times fall everywhere.
            for (double t = 0.0; t <= p.end_s; t += 0.0371) {
                double a[3], vp[3], vm[3];
                accel_ned(p, t, a);
                velocity_ned(p, t + h, vp);
                velocity_ned(p, t - h, vm);
                for (int i = 0; i < 3; ++i) {
                    ASSERT_TRUE(std::isfinite(a[i])) << kind << " seed " << seed << " t " << t;
                    // The difference's own error grows with the jerk's rate (10 ms taps): relative.
                    worst = std::fmax(worst, std::fabs(a[i] - (vp[i] - vm[i]) / (2 * h)) / (1.0 + std::fabs(a[i])));
                }
            }
            EXPECT_LT(worst, 1e-3) << "kind " << kind << " seed " << seed;
        }
    }
}

TEST(ScenarioMotions, StillForTheFirstTwoSecondsAndAtTheEnd) {
    for (Kind kind : kKinds) {
        for (uint64_t seed : kSeeds) {
            const Plan p = make_plan(kind, seed);
            EXPECT_GE(p.end_s, 60.0) << kind;
            EXPECT_LE(p.end_s, 180.0) << kind;
            const sim::Quat q0 = attitude(p, 0.0);
            for (double t : {0.0, 1.0, 2.0, 2.4}) {
                double a[3], v[3];
                accel_ned(p, t, a);
                velocity_ned(p, t, v);
                EXPECT_EQ(norm3(a), 0.0) << kind << " t " << t;
                EXPECT_EQ(norm3(v), 0.0) << kind << " t " << t;
                const sim::Quat q = attitude(p, t);
                EXPECT_NEAR(std::fabs(q.w * q0.w + q.x * q0.x + q.y * q0.y + q.z * q0.z), 1.0, 1e-12) << kind;
            }
            double v[3];
            velocity_ned(p, p.end_s, v);
            EXPECT_LT(norm3(v), 1e-9) << "kind " << kind << " seed " << seed << " ends moving";
        }
    }
}

TEST(ScenarioMotions, AccelerationsInTheirStatedRanges) {
    for (uint64_t seed : kSeeds) {
        const double slow = peak_accel(make_plan(kTranslateSlow, seed), 0.005);
        EXPECT_GT(slow, 1.0);
        EXPECT_LE(slow, 4.0 + 1e-6);
        const double fast = peak_accel(make_plan(kTranslateFast, seed), 0.005);
        EXPECT_GT(fast, 8.0);
        EXPECT_LE(fast, 20.0 + 1e-6);
        // Walking: the step bounce (1.5-3 m/s^2 vertical) and a turn's v^2/r stay small.
        const Plan walk = make_plan(kWalk, seed);
        double vertical = 0.0;
        for (double t = 0.0; t < walk.end_s; t += 0.005) {
            double a[3];
            accel_ned(walk, t, a);
            vertical = std::fmax(vertical, std::fabs(a[2]));
        }
        EXPECT_GE(vertical, 1.4);
        EXPECT_LE(vertical, 3.0 + 1e-6);
        EXPECT_LT(peak_accel(walk, 0.005), 5.0);
        // Taps of 20-50 m/s^2: sampled finely, since each lasts about 10 ms.
        const double tap = peak_accel(make_plan(kTapping, seed), 0.0001);
        EXPECT_GE(tap, 20.0);
        EXPECT_LE(tap, 50.5);
        // Knocks of 60-150 m/s^2: the same taps, harder.
        const double knock = peak_accel(make_plan(kKnocking, seed), 0.0001);
        EXPECT_GE(knock, 60.0);
        EXPECT_LE(knock, 151.0);
    }
}

TEST(ScenarioMotions, CarDrivesWhereItPointsAtRoadSpeeds) {
    for (uint64_t seed : kSeeds) {
        const Plan p = make_plan(kCar, seed);
        double top = 0.0, horizontal = 0.0, tilt = 0.0;
        for (double t = 0.0; t < p.end_s; t += 0.01) {
            double v[3], a[3];
            velocity_ned(p, t, v);
            accel_ned(p, t, a);
            const double speed = std::hypot(v[0], v[1]);
            top = std::fmax(top, speed);
            horizontal = std::fmax(horizontal, std::hypot(a[0], a[1]));
            const sim::Quat q = attitude(p, t);
            const double yaw = std::atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
            const double sin_pitch = 2 * (q.w * q.y - q.z * q.x);
            tilt = std::fmax(tilt, std::fabs(std::asin(sin_pitch)) / kDeg);
            if (speed > 0.5) {  // no sideslip: the velocity along the car's heading
                const double off = std::remainder(std::atan2(v[1], v[0]) - yaw, 2 * kPi);
                EXPECT_LT(std::fabs(off) / kDeg, 0.01) << "seed " << seed << " t " << t;
            }
            EXPECT_LT(std::fabs(v[2]), 0.1);  // only the body's bounce
        }
        EXPECT_GE(top, 5.0);
        EXPECT_LE(top, 15.0 + 1e-9);
        EXPECT_GT(horizontal, 2.0);
        EXPECT_LE(horizontal, 4.0 * 1.01);
        EXPECT_LT(tilt, 3.0);  // suspension and road: small pitch
    }
}

// The hard case: swinging freely, the specific force stays along the string, i.e. along
// the board's z axis; only the hand's push and catch pull it aside.
TEST(ScenarioMotions, PendulumForceAlongTheString) {
    for (uint64_t seed : kSeeds) {
        const Plan p = make_plan(kPendulum, seed);
        double worst = 0.0, swing_deg = 0.0;
        for (const Swing& s : p.swings) {
            EXPECT_GE(s.amp_rad / kDeg, 10.0);
            EXPECT_LE(s.amp_rad / kDeg, 30.0);
            for (double t = s.t0_s + s.ramp_s; t < s.end_s - s.ramp_s; t += 0.01) {
                double a[3], f_body[3];
                accel_ned(p, t, a);
                a[2] -= kGravity_m_s2;
                sim::earth_to_body(attitude(p, t), a, f_body);
                worst = std::fmax(worst, std::hypot(f_body[0], f_body[1]) / norm3(f_body));
                double plane;
                swing_deg = std::fmax(swing_deg, std::fabs(swing_at(p, t, plane).v) / kDeg);
            }
        }
        EXPECT_LT(worst, 0.03) << "seed " << seed;  // under 2 deg of apparent tilt
        EXPECT_GT(swing_deg, 5.0) << "seed " << seed;
        EXPECT_GE(p.string_m, 1.0);
        EXPECT_LE(p.string_m, 2.0);
    }
}

TEST(ScenarioMotions, SeedsChangeTheMotionAndNoSeedIsFixed) {
    for (Kind kind : kKinds) {
        const Plan a = make_plan(kind, 0), b = make_plan(kind, 0), c = make_plan(kind, 1), d = make_plan(kind, 2);
        int differ_c = 0, differ_d = 0;
        for (double t = 3.5; t < 60.0; t += 0.5) {
            const sim::Quat qa = attitude(a, t), qb = attitude(b, t), qc = attitude(c, t), qd = attitude(d, t);
            double fa[3], fb[3], fc[3], fd[3];
            accel_ned(a, t, fa);
            accel_ned(b, t, fb);
            accel_ned(c, t, fc);
            accel_ned(d, t, fd);
            EXPECT_EQ(qa.w, qb.w);
            EXPECT_EQ(qa.z, qb.z);
            for (int i = 0; i < 3; ++i) EXPECT_EQ(fa[i], fb[i]);
            differ_c += std::fabs(qa.z - qc.z) > 1e-3 || std::fabs(fa[0] - fc[0]) > 1e-3;
            differ_d += std::fabs(qc.z - qd.z) > 1e-3 || std::fabs(fc[0] - fd[0]) > 1e-3;
        }
        EXPECT_GT(differ_c, 50) << "kind " << kind;
        EXPECT_GT(differ_d, 50) << "kind " << kind;
        EXPECT_EQ(a.end_s, b.end_s);
    }
}

// The slow rotation: no linear acceleration, every axis turned, the rate within 50 deg/s
// an axis (the sines' 38 and their fading), and, the mount's vibration aside (each
// track's last wave), turning slowly for long: the yaw rate between 0.05 and 2 deg/s,
// as steady as at rest but turning, for 5 s or more of the file (what a rest test must
// not take for rest).
TEST(ScenarioMotions, SlowRotationTurnsSlowlyAndReversesSlowly) {
    for (uint64_t seed : kSeeds) {
        Plan p = make_plan(kSlowRotation, seed);
        for (Track& track : p.angle_deg) track.waves.pop_back();
        EXPECT_GE(p.end_s, 90.0);
        EXPECT_LT(peak_accel(p, 0.01), 1e-12) << "seed " << seed;
        double peak_rate[3] = {0, 0, 0}, slow_s = 0.0;
        const double h = 1e-4;
        for (double t = kStill_s; t < p.end_s; t += 0.01) {
            for (int i = 0; i < 3; ++i) {
                const double rate = (p.angle_deg[i].at(t + h).v - p.angle_deg[i].at(t - h).v) / (2 * h);
                peak_rate[i] = std::fmax(peak_rate[i], std::fabs(rate));
                if (i == 2 && std::fabs(rate) < 2.0 && std::fabs(rate) > 0.05) slow_s += 0.01;
            }
        }
        for (int i = 0; i < 3; ++i) {
            EXPECT_GT(peak_rate[i], 1.0) << "seed " << seed << " axis " << i;
            EXPECT_LT(peak_rate[i], 50.0) << "seed " << seed << " axis " << i;
        }
        EXPECT_GT(slow_s, 5.0) << "seed " << seed;
    }
}

}  // namespace
