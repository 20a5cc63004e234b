// SPDX-License-Identifier: GPL-3.0-or-later
// Seeded motions for build/scenario (issue 24, "data that cannot be overfitted"): a board
// moved by a hand, carried while walking, swinging on a string, riding in a car, tapped,
// turned slowly back and forth.
//
// Each motion is a Plan drawn from a seed: sums of smooth parts whose value and first two
// time derivatives are analytic, so that the linear acceleration the accelerometer sees is
// exactly the second derivative of the motion (no numerical second differences):
//   - Step: a cycloidal move by `delta` over dur_s, s(u) = u - sin(2 pi u) / (2 pi):
//     velocity and acceleration are zero at both ends and the acceleration is continuous;
//     its peak rate is 2 delta / dur_s, its peak acceleration 2 pi delta / dur_s^2.
//   - Wave: a sine faded in and out by two such steps (zero before and after).
// Positions: the hand's displacement (NED, m), a path (forward speed and heading: walking,
// driving; velocity = Rz(heading) (speed + forward sway', lateral sway')), or a pendulum
// (a point on a string of fixed length: r = L (sin th cos b, sin th sin b, cos th)).
// Attitude: roll, pitch, yaw tracks in degrees (Z-Y-X, as the keyframed scenarios), the
// yaw on the path's heading for a vehicle or a walker, tilted along the string when hanging.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "Constants.h"
#include "Rotation.h"

namespace sim {

// Deterministic uniform and Gaussian numbers: xorshift64* and Box-Muller (the same numbers
// on every libc).
struct Random {
    uint64_t state = 0x9E3779B97F4A7C15ull;
    double uniform() {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        return ((state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
    }
    double gauss() {
        const double u1 = uniform() + 1e-300, u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * linalg::dbl::kPi * u2);
    }
    double between(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    double sign() { return uniform() < 0.5 ? -1.0 : 1.0; }
};

namespace motion {

using linalg::dbl::kGravity_m_s2;
using linalg::dbl::kPi;
constexpr double kDeg = linalg::dbl::kRadPerDeg;  // x * kDeg: x degrees in rad
constexpr double kStill_s = 3.0;  // every motion starts after this long at rest

// A value and its first two time derivatives.
struct D3 {
    double v = 0.0, d1 = 0.0, d2 = 0.0;
    D3& operator+=(const D3& o) {
        v += o.v;
        d1 += o.d1;
        d2 += o.d2;
        return *this;
    }
};

struct Step {
    double t0_s, dur_s, delta;
};

inline D3 step_at(const Step& s, double t_s) {
    D3 out;
    if (t_s <= s.t0_s) return out;
    if (t_s >= s.t0_s + s.dur_s) {
        out.v = s.delta;
        return out;
    }
    const double u = (t_s - s.t0_s) / s.dur_s, w = 2 * kPi * u;
    out.v = s.delta * (u - std::sin(w) / (2 * kPi));
    out.d1 = s.delta / s.dur_s * (1.0 - std::cos(w));
    out.d2 = s.delta / (s.dur_s * s.dur_s) * 2 * kPi * std::sin(w);
    return out;
}

// A step of the velocity instead (the same shape, delta in units per second): the
// value is its integral, so a stop can be abrupt where the start was gentle.
inline D3 velocity_step_at(const Step& s, double t_s) {
    D3 out;
    if (t_s <= s.t0_s) return out;
    if (t_s >= s.t0_s + s.dur_s) {
        out.v = s.delta * (s.dur_s / 2 + (t_s - s.t0_s - s.dur_s));
        out.d1 = s.delta;
        return out;
    }
    const double u = (t_s - s.t0_s) / s.dur_s, w = 2 * kPi * u;
    out.v = s.delta * s.dur_s * (u * u / 2 + (std::cos(w) - 1.0) / (4 * kPi * kPi));
    out.d1 = s.delta * (u - std::sin(w) / (2 * kPi));
    out.d2 = s.delta / s.dur_s * (1.0 - std::cos(w));
    return out;
}

struct Wave {
    double on_s, off_s, ramp_s, amp, freq_hz, phase_rad;
};

inline D3 wave_at(const Wave& w, double t_s) {
    D3 out;
    if (t_s <= w.on_s || t_s >= w.off_s) return out;
    const D3 up = step_at(Step{w.on_s, w.ramp_s, 1.0}, t_s);
    const D3 down = step_at(Step{w.off_s - w.ramp_s, w.ramp_s, 1.0}, t_s);
    const double e = up.v - down.v, e1 = up.d1 - down.d1, e2 = up.d2 - down.d2;
    const double om = 2 * kPi * w.freq_hz, s = std::sin(om * t_s + w.phase_rad), c = std::cos(om * t_s + w.phase_rad);
    out.v = e * w.amp * s;
    out.d1 = e1 * w.amp * s + e * w.amp * om * c;
    out.d2 = e2 * w.amp * s + 2 * e1 * w.amp * om * c - e * w.amp * om * om * s;
    return out;
}

struct Track {
    double base = 0.0;
    std::vector<Step> steps;
    std::vector<Step> velocity_steps;
    std::vector<Wave> waves;
    D3 at(double t_s) const {
        D3 out;
        out.v = base;
        for (const Step& s : steps) out += step_at(s, t_s);
        for (const Step& s : velocity_steps) out += velocity_step_at(s, t_s);
        for (const Wave& w : waves) out += wave_at(w, t_s);
        return out;
    }
};

// One push of the pendulum: th = amp E(t) exp(-(t - t0) / decay) sin(omega (t - t0)) in the
// vertical plane at azimuth plane_rad, E faded in (the push) and out (a hand stops it).
struct Swing {
    double t0_s, end_s, ramp_s, amp_rad, decay_s, plane_rad;
};

struct Plan {
    double end_s = 0.0;
    Track angle_deg[3];  // roll, pitch, yaw
    Track hand_m[3];     // displacement, NED
    Track speed_m_s, heading_deg, forward_m, lateral_m;  // the path
    bool yaw_on_path = false;          // yaw = the path's heading + angle_deg[2]
    double pitch_deg_per_m_s2 = 0.0;   // suspension: pitch with the forward acceleration
    double roll_deg_per_m_s2 = 0.0;    // and roll against the lateral one
    double string_m = 0.0;             // > 0: hanging on a string this long
    std::vector<Swing> swings;
};

// The path's heading (rad) and its acceleration in the path's frame (forward, right).
struct PathState {
    double heading_rad, forward_m_s2, lateral_m_s2;
};

inline PathState path_at(const Plan& p, double t_s) {
    const D3 v = p.speed_m_s.at(t_s), h = p.heading_deg.at(t_s), f = p.forward_m.at(t_s), l = p.lateral_m.at(t_s);
    const double heading_rate = h.d1 * kDeg;
    const double u = v.v + f.d1, du = v.d1 + f.d2, w = l.d1, dw = l.d2;
    // d/dt (Rz(psi) (u, w)) = Rz(psi) (du - w psi', dw + u psi')
    return PathState{h.v * kDeg, du - w * heading_rate, dw + u * heading_rate};
}

inline double pendulum_rate_rad_s(const Plan& p, const Swing& s) {
    // Small-angle pendulum, with the first amplitude correction of its period.
    return std::sqrt(kGravity_m_s2 / p.string_m) * (1.0 - s.amp_rad * s.amp_rad / 16.0);
}

// The string's angle from the vertical and the swing's azimuth.
inline D3 swing_at(const Plan& p, double t_s, double& plane_rad) {
    plane_rad = 0.0;
    for (const Swing& s : p.swings) {
        if (t_s <= s.t0_s || t_s >= s.end_s) continue;
        plane_rad = s.plane_rad;
        const D3 up = step_at(Step{s.t0_s, s.ramp_s, 1.0}, t_s);
        const D3 down = step_at(Step{s.end_s - s.ramp_s, s.ramp_s, 1.0}, t_s);
        const double x = t_s - s.t0_s, d = std::exp(-x / s.decay_s);
        // g = E * decay and its derivatives; th = amp * g * sin(omega x)
        const double e = up.v - down.v, e1 = up.d1 - down.d1, e2 = up.d2 - down.d2;
        const double g = e * d, g1 = (e1 - e / s.decay_s) * d,
                     g2 = (e2 - 2 * e1 / s.decay_s + e / (s.decay_s * s.decay_s)) * d;
        const double om = pendulum_rate_rad_s(p, s), sn = std::sin(om * x), cs = std::cos(om * x);
        D3 th;
        th.v = s.amp_rad * g * sn;
        th.d1 = s.amp_rad * (g1 * sn + g * om * cs);
        th.d2 = s.amp_rad * (g2 * sn + 2 * g1 * om * cs - g * om * om * sn);
        return th;
    }
    return D3{};
}

// Body -> earth (NED) at t_s.
inline Quat attitude(const Plan& p, double t_s) {
    double roll = p.angle_deg[0].at(t_s).v, pitch = p.angle_deg[1].at(t_s).v, yaw = p.angle_deg[2].at(t_s).v;
    if (p.yaw_on_path || p.pitch_deg_per_m_s2 != 0.0 || p.roll_deg_per_m_s2 != 0.0) {
        const PathState s = path_at(p, t_s);
        if (p.yaw_on_path) yaw += s.heading_rad / kDeg;
        pitch += p.pitch_deg_per_m_s2 * s.forward_m_s2;
        roll -= p.roll_deg_per_m_s2 * s.lateral_m_s2;
    }
    const Quat q = from_euler(roll * kDeg, pitch * kDeg, yaw * kDeg);
    if (p.string_m <= 0.0) return q;
    // Hanging: the body z axis along the string, (sin th cos b, sin th sin b, cos th): a turn
    // by th about the horizontal axis (-sin b, cos b, 0), then the board's own angles.
    double plane;
    const double th = swing_at(p, t_s, plane).v;
    const Quat tilt{std::cos(th / 2), -std::sin(plane) * std::sin(th / 2), std::cos(plane) * std::sin(th / 2), 0.0};
    return tilt * q;
}

// Linear acceleration, NED, m/s^2 at t_s.
inline void accel_ned(const Plan& p, double t_s, double a[3]) {
    for (int i = 0; i < 3; ++i) a[i] = p.hand_m[i].at(t_s).d2;
    const PathState s = path_at(p, t_s);
    const double c = std::cos(s.heading_rad), sn = std::sin(s.heading_rad);
    a[0] += c * s.forward_m_s2 - sn * s.lateral_m_s2;
    a[1] += sn * s.forward_m_s2 + c * s.lateral_m_s2;
    if (p.string_m > 0.0) {
        // r = L (sin th cos b, sin th sin b, cos th): r'' = L th'' dr/dth - L th'^2 r / L
        double plane;
        const D3 th = swing_at(p, t_s, plane);
        const double cb = std::cos(plane), sb = std::sin(plane), ct = std::cos(th.v), st = std::sin(th.v);
        const double L = p.string_m, k1 = L * th.d2, k2 = L * th.d1 * th.d1;
        a[0] += k1 * ct * cb - k2 * st * cb;
        a[1] += k1 * ct * sb - k2 * st * sb;
        a[2] += -k1 * st - k2 * ct;
    }
}

// ---------------------------------------------------------------------------
// The motions. Each draws its random parts from r; the ranges are in the comments.

// (A new kind goes last: the kind is part of each plan's seed.)
enum Kind { kNone = 0, kTranslateSlow, kTranslateFast, kWalk, kPendulum, kCar, kTapping, kKnocking, kSlowRotation };

// Small hand wobble on every angle, from kStill_s - 0.5 to end_s.
inline void add_wobble(Plan& p, Random& r, double amp_lo_deg, double amp_hi_deg, double f_lo, double f_hi) {
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 2; ++k)
            p.angle_deg[i].waves.push_back(Wave{kStill_s - 0.5, p.end_s, 1.0, r.between(amp_lo_deg, amp_hi_deg),
                                                r.between(f_lo, f_hi), r.between(0, 2 * kPi)});
}

// Back and forth along the board's x, y, z and diagonals (strokes 0.3-1 m at 0.3-0.8 Hz,
// peak 4 m/s^2; fast: 0.3-0.8 m at 0.8-1.5 Hz, peak 20 m/s^2), 3-8 strokes a bout, pauses
// of 0.8-2.5 s, a slow yaw change of 30-120 deg after 40 % of the bouts.
inline Plan translate(Random& r, bool fast) {
    static const double kDirs[11][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, -1, 0}, {1, 0, 1},
                                        {0, 1, 1}, {1, 0, -1}, {0, 1, -1}, {1, 1, 1}, {1, -1, 1}};
    Plan p;
    double yaw_deg = r.between(0, 360);
    p.angle_deg[2].base = yaw_deg;
    const double length_s = fast ? r.between(60, 120) : r.between(90, 150);
    double t = kStill_s;
    while (t < length_s) {
        const double* d = kDirs[(int)(r.uniform() * 11) % 11];
        const double norm = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), sign = r.sign();
        const double c = std::cos(yaw_deg * kDeg), s = std::sin(yaw_deg * kDeg);
        const double dir[3] = {sign * (c * d[0] - s * d[1]) / norm, sign * (s * d[0] + c * d[1]) / norm,
                               sign * d[2] / norm};
        const double f_hz = fast ? r.between(0.8, 1.5) : r.between(0.3, 0.8);
        double stroke_m = fast ? r.between(0.3, 0.8) : r.between(0.3, 1.0);
        const double dur_s = 0.5 / f_hz, peak_m_s2 = 2 * kPi * stroke_m / (dur_s * dur_s);
        const double cap_m_s2 = fast ? 20.0 : 4.0;
        if (peak_m_s2 > cap_m_s2) stroke_m *= cap_m_s2 / peak_m_s2;
        const int strokes = 2 * (int)r.between(2, 5);  // there and back: 2 to 4 times
        for (int k = 0; k < strokes; ++k) {
            const double there = (k % 2 == 0) ? stroke_m : -stroke_m;
            for (int i = 0; i < 3; ++i) p.hand_m[i].steps.push_back(Step{t, dur_s, there * dir[i]});
            t += dur_s;
        }
        t += r.between(0.8, 2.5);
        if (r.uniform() < 0.4) {
            const double turn_deg = r.sign() * r.between(30, 120), turn_s = r.between(2.5, 5.0);
            p.angle_deg[2].steps.push_back(Step{t, turn_s, turn_deg});
            yaw_deg += turn_deg;
            t += turn_s + r.between(0.5, 1.5);
        }
    }
    p.end_s = t + 2.0;
    add_wobble(p, r, 0.3, 1.5, fast ? 0.3 : 0.1, fast ? 1.5 : 0.6);
    return p;
}

// Walking with the board in hand: bouts of 12-30 s at 1.1-1.6 m/s, steps at 1.8-2.2 Hz
// (vertical 1.5-3 m/s^2, fore-aft 0.7-1.2 m/s^2 peak), arm sway at half the step rate
// (lateral 0.3-0.8 m/s^2, pitch 3-8 deg, roll 2-5 deg, yaw 2-4 deg), one or two turns of
// 60-120 deg over 3-6 s while walking, pauses of 2-6 s with a turn on the spot half the time.
inline Plan walk(Random& r) {
    Plan p;
    p.yaw_on_path = true;
    p.heading_deg.base = r.between(0, 360);
    p.angle_deg[2].base = r.between(-20, 20);  // the board's heading in the hand
    p.angle_deg[1].base = r.between(-10, 5);
    const double step_hz = r.between(1.8, 2.2), speed_m_s = r.between(1.1, 1.6);
    const double length_s = r.between(100, 160);
    double t = kStill_s;
    while (t < length_s) {
        const double ramp_s = r.between(1.2, 2.0), dur_s = r.between(12, 30), end = t + dur_s;
        p.speed_m_s.steps.push_back(Step{t, ramp_s, speed_m_s});
        p.speed_m_s.steps.push_back(Step{end - ramp_s, ramp_s, -speed_m_s});
        const double w = 2 * kPi * step_hz, phase = r.between(0, 2 * kPi);
        p.hand_m[2].waves.push_back(Wave{t, end, ramp_s, r.between(1.5, 3.0) / (w * w), step_hz, phase});
        p.forward_m.waves.push_back(Wave{t, end, ramp_s, r.between(0.7, 1.2) / (w * w), step_hz, phase + kPi / 2});
        const double sway = r.between(0, 2 * kPi);
        p.lateral_m.waves.push_back(Wave{t, end, ramp_s, r.between(0.3, 0.8) / (w * w / 4), step_hz / 2, sway});
        p.angle_deg[1].waves.push_back(Wave{t, end, ramp_s, r.between(3, 8), step_hz / 2, sway + kPi / 2});
        p.angle_deg[0].waves.push_back(Wave{t, end, ramp_s, r.between(2, 5), step_hz / 2, sway});
        p.angle_deg[2].waves.push_back(Wave{t, end, ramp_s, r.between(2, 4), step_hz / 2, sway + 1.0});
        p.angle_deg[1].waves.push_back(Wave{t, end, ramp_s, 1.0, step_hz, phase});
        const int turns = 1 + (r.uniform() < 0.5);
        double turn_at = t + ramp_s + 1.0;
        for (int k = 0; k < turns; ++k) {
            const double turn_s = r.between(3, 6);
            const double latest = end - ramp_s - 1.0 - turn_s * (turns - k);
            if (latest <= turn_at) break;
            turn_at = r.between(turn_at, latest);
            p.heading_deg.steps.push_back(Step{turn_at, turn_s, r.sign() * r.between(60, 120)});
            turn_at += turn_s + 0.5;
        }
        t = end + r.between(2, 6);
        if (r.uniform() < 0.5) {
            const double turn_s = r.between(2, 4);
            p.heading_deg.steps.push_back(Step{t - turn_s - 0.5, turn_s, r.sign() * r.between(60, 180)});
        }
    }
    p.end_s = t;
    add_wobble(p, r, 0.3, 1.0, 0.2, 1.0);
    return p;
}

// Swinging on a 1-2 m string: pushes of 10-30 deg in a random vertical plane, decaying
// over 15-40 s, each stopped by a hand after 20-40 s; a slow twist about the string
// (15-40 deg at 0.03-0.08 Hz). The specific force stays near the string: the board's own z.
inline Plan pendulum(Random& r) {
    Plan p;
    p.string_m = r.between(1.0, 2.0);
    p.angle_deg[2].base = r.between(0, 360);
    const double length_s = r.between(90, 150);
    double t = kStill_s;
    while (t < length_s) {
        const double dur_s = r.between(20, 40);
        p.swings.push_back(Swing{t, t + dur_s, r.between(1.0, 2.0), r.between(10, 30) * kDeg, r.between(15, 40),
                                 r.between(0, kPi)});
        t += dur_s + r.between(2, 5);
    }
    p.end_s = t + 1.0;
    p.angle_deg[2].waves.push_back(
        Wave{kStill_s - 0.5, p.end_s, 3.0, r.between(15, 40), r.between(0.03, 0.08), r.between(0, 2 * kPi)});
    return p;
}

// A car on a flat road: accelerations and braking of 2-4 m/s^2 peak over 2-5 s, corners of
// 45-120 deg at 5-15 m/s with a peak lateral acceleration of 2-4 m/s^2, cruising 2-8 s;
// pitch 0.3-0.5 deg and roll 0.4-0.7 deg per m/s^2 from the suspension, a 1.2-1.8 Hz body
// bounce (0.3-0.6 m/s^2) and road roughness on pitch and roll.
inline Plan car(Random& r) {
    Plan p;
    p.yaw_on_path = true;
    p.heading_deg.base = r.between(0, 360);
    p.pitch_deg_per_m_s2 = r.between(0.3, 0.5);
    p.roll_deg_per_m_s2 = r.between(0.4, 0.7);
    const double length_s = r.between(110, 150);
    double t = kStill_s, v = 0.0;
    auto change_speed = [&](double dv, double peak_m_s2) {
        const double dur_s = std::fmax(2.0, 2.0 * std::fabs(dv) / peak_m_s2);
        p.speed_m_s.steps.push_back(Step{t, dur_s, dv});
        v += dv;
        t += dur_s;
    };
    while (t < length_s) {
        const double pick = r.uniform();
        if (v < 5.0 || (pick < 0.3 && v < 13.0)) {
            const double peak = r.between(2, 4), dur_s = r.between(2, 5);
            change_speed(std::fmin(peak * dur_s / 2, 15.0 - v), peak);
        } else if (pick < 0.45) {
            const double peak = r.between(2, 4), dur_s = r.between(2, 5);
            const double dv = std::fmin(peak * dur_s / 2, v);
            change_speed(-(v - dv < 5.0 ? v : dv), peak);
            if (v == 0.0) t += r.between(2, 4);
        } else if (pick < 0.8) {
            const double turn_rad = r.between(45, 120) * kDeg, lateral = r.between(2, 4);
            const double dur_s = std::fmax(2.0, 2.0 * turn_rad * v / lateral);
            p.heading_deg.steps.push_back(Step{t, dur_s, r.sign() * turn_rad / kDeg});
            t += dur_s;
        } else {
            t += r.between(2, 8);
        }
        t += r.between(0.5, 2.0);
    }
    if (v > 0.0) change_speed(-v, r.between(2, 4));
    p.end_s = t + 3.0;
    const double w = 2 * kPi * r.between(1.2, 1.8);
    p.hand_m[2].waves.push_back(Wave{kStill_s - 0.5, p.end_s - 1.0, 1.0, r.between(0.3, 0.6) / (w * w), w / (2 * kPi),
                                     r.between(0, 2 * kPi)});
    for (int i = 0; i < 2; ++i)
        p.angle_deg[i].waves.push_back(Wave{kStill_s - 0.5, p.end_s - 1.0, 1.0, r.between(0.2, 0.4),
                                            r.between(1.0, 2.0), r.between(0, 2 * kPi)});
    return p;
}

// Held still in a hand (tremor 0.1-0.3 deg at 3-8 Hz, 0.05-0.2 m/s^2 at 6-10 Hz, a slow
// drift of 1-3 deg) and tapped every 1-3 s along the board's z (60 %) or x or y, with a
// 0.1-0.5 deg jolt. A tap (knock false): a there-and-back displacement of 8-12 ms peaking
// at 20-50 m/s^2, its push and pull alike. A knock (knock true): the board brought to
// the same surface every time (one axis and side for the file) at 0.25-0.9 m/s over
// 0.1-0.2 s and stopped by it in 8-12 ms, 60-150 m/s^2 one way only (beyond an 8 g
// range), then lifted back over 0.3 s.
inline Plan tapping(Random& r, bool knock) {
    Plan p;
    const double yaw_deg = r.between(0, 360);
    p.angle_deg[2].base = yaw_deg;
    const double length_s = r.between(60, 120);
    double t = kStill_s + 1.0;
    std::vector<Step> taps[3], jolts[3];
    // A knock's surface is the same every time: its axis and side drawn once.
    const double knock_pick = knock ? r.uniform() : 0.0, knock_sign = knock ? r.sign() : 0.0;
    while (t < length_s) {
        t += r.between(1, 3);
        const double pick = knock ? knock_pick : r.uniform(), sign = knock ? knock_sign : r.sign();
        const int axis = pick < 0.6 ? 2 : (pick < 0.8 ? 0 : 1);
        double dir[3] = {0, 0, 0};
        if (axis == 2) {
            dir[2] = sign;
        } else {  // the board's x or y, on a board near level
            const double a = (yaw_deg + (axis == 1 ? 90.0 : 0.0)) * kDeg;
            dir[0] = sign * std::cos(a);
            dir[1] = sign * std::sin(a);
        }
        if (knock) {
            // The stop's peak is 2 v / its length (velocity_step_at's d2 at mid-way).
            const double peak = r.between(60, 150), stop_s = r.between(0.008, 0.012);
            const double speed = peak * stop_s / 2, approach_s = r.between(0.1, 0.2);
            const double travel_m = speed * (approach_s + stop_s) / 2;
            const double start_s = t - approach_s;
            for (int i = 0; i < 3; ++i) {
                p.hand_m[i].velocity_steps.push_back(Step{start_s, approach_s, speed * dir[i]});
                p.hand_m[i].velocity_steps.push_back(Step{t, stop_s, -speed * dir[i]});
                p.hand_m[i].steps.push_back(Step{t + stop_s + 0.1, 0.3, -travel_m * dir[i]});
            }
        } else {
            const double peak = r.between(20, 50), half_s = r.between(0.008, 0.012) / 2;
            const double there_m = peak * half_s * half_s / (2 * kPi);
            for (int i = 0; i < 3; ++i) {
                p.hand_m[i].steps.push_back(Step{t, half_s, there_m * dir[i]});
                p.hand_m[i].steps.push_back(Step{t + half_s, half_s, -there_m * dir[i]});
            }
        }
        const int jolt_axis = (int)(r.uniform() * 3) % 3;
        const double jolt_deg = r.sign() * r.between(0.1, 0.5);
        p.angle_deg[jolt_axis].steps.push_back(Step{t, 0.01, jolt_deg});
        p.angle_deg[jolt_axis].steps.push_back(Step{t + 0.01, 0.03, -jolt_deg});
    }
    p.end_s = t + 3.0;
    for (int i = 0; i < 3; ++i) {
        p.angle_deg[i].waves.push_back(
            Wave{kStill_s - 0.5, p.end_s, 1.0, r.between(0.1, 0.3), r.between(3, 8), r.between(0, 2 * kPi)});
        p.angle_deg[i].waves.push_back(
            Wave{kStill_s - 0.5, p.end_s, 1.0, r.between(1, 3), r.between(0.05, 0.2), r.between(0, 2 * kPi)});
        const double f = r.between(6, 10), w = 2 * kPi * f;
        p.hand_m[i].waves.push_back(
            Wave{kStill_s - 0.5, p.end_s, 1.0, r.between(0.05, 0.2) / (w * w), f, r.between(0, 2 * kPi)});
    }
    return p;
}

// Turned slowly back and forth on a pan-tilt head or a slow turntable (a camera's pan, a
// board shown round): bouts of 20-40 s, half of them about one axis alone (a turntable's
// yaw, a tilt head's roll or pitch), the others about all three; yaw swings 15-60 deg,
// roll and pitch 5-25 deg, each a sine of a 10-40 s period (peak rates 1-38 deg/s an
// axis, up to 50 as a bout fades; at each turning point the rate passes slowly through
// zero, 0.1-24 deg/s^2, as steady as a board at rest), faded in and out over 2-4 s,
// pauses of 2-6 s between; the mount's vibration (0.005-0.02 deg at 3-8 Hz, a rate of
// 0.1-1 deg/s).
inline Plan slow_rotation(Random& r) {
    Plan p;
    p.angle_deg[2].base = r.between(0, 360);
    const double length_s = r.between(90, 150);
    double t = kStill_s;
    while (t < length_s) {
        const double dur_s = r.between(20, 40), ramp_s = r.between(2, 4);
        const int only_axis = r.uniform() < 0.5 ? (int)(r.uniform() * 3) % 3 : -1;
        for (int i = 0; i < 3; ++i) {
            const double amp_deg = i == 2 ? r.between(15, 60) : r.between(5, 25);
            const double period_s = r.between(10, 40), phase_rad = r.between(0, 2 * kPi);
            if (only_axis >= 0 && i != only_axis) continue;
            p.angle_deg[i].waves.push_back(Wave{t, t + dur_s, ramp_s, amp_deg, 1.0 / period_s, phase_rad});
        }
        t += dur_s + r.between(2, 6);
    }
    p.end_s = t;
    for (int i = 0; i < 3; ++i)
        p.angle_deg[i].waves.push_back(
            Wave{kStill_s - 0.5, p.end_s, 1.0, r.between(0.005, 0.02), r.between(3, 8), r.between(0, 2 * kPi)});
    return p;
}

// The plan of kind drawn from seed (0: the fixed default motion).
inline Plan make_plan(Kind kind, uint64_t seed) {
    Random r;
    r.state = 0x6A09E667F3BCC909ull ^ (seed * 0xD1B54A32D192ED03ull) ^ ((uint64_t)kind << 56);
    if (r.state == 0) r.state = 1;
    switch (kind) {
        case kTranslateSlow: return translate(r, false);
        case kTranslateFast: return translate(r, true);
        case kWalk: return walk(r);
        case kPendulum: return pendulum(r);
        case kCar: return car(r);
        case kTapping: return tapping(r, false);
        case kKnocking: return tapping(r, true);
        case kSlowRotation: return slow_rotation(r);
        default: return Plan{};
    }
}

}  // namespace motion
}  // namespace sim
