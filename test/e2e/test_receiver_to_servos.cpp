// SPDX-License-Identifier: GPL-3.0-or-later
// The board flies (issue 21), on its pins in simavr: apm25sim's PPM generator drives ICP5
// from a stick script (--rc) and every servo pulse is measured from OUT1-OUT8's pin edges
// (--servo-log). Defaults: MANUAL with the mode switch (channel 8) low, STABILIZE high;
// end points 1000-2000 us around 1500; THR_FS_OUT 0 (OUT3 at 1000 us in failsafe).
// ARMING_REQUIRE 1 holds OUT3 at 1000 us until armed: the tests of the throttle's path
// type `set ARMING_REQUIRE 0` (taken at the first angle line, ~1.4 s: kLiveFrom_s), and
// check OUT3 at 1000 us before it (mavlink.arming tests arming itself).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <vector>

#include "e2e_support.h"

namespace {

// The servo log stamps edges at instruction boundaries (within 0.3 us, apm25sim --help):
// a width exact on the pin reads within kStamp_us; a width within 1 us of the command
// (the receiver's 0.5 us capture ticks rounded to us) reads within kFollow_us.
constexpr double kStamp_us = 0.3;
constexpr double kFollow_us = 1.0 + kStamp_us;

struct Pulse {
    double t_s;
    int out;  // 1..8
    double width_us;
};

std::vector<Pulse> read_pulses(const std::string& path) {
    std::vector<Pulse> pulses;
    std::istringstream in(e2e::read_text(path));
    std::string line;
    std::getline(in, line);  // the header (the harness's own test checks the format)
    while (std::getline(in, line)) {
        Pulse p{};
        if (std::sscanf(line.c_str(), "%lf,%d,%lf", &p.t_s, &p.out, &p.width_us) == 3) pulses.push_back(p);
    }
    return pulses;
}

using Row = std::vector<int>;  // ch1..ch8, us; empty: no signal

struct RcScript {
    std::vector<std::pair<double, Row>> rows;
    void add(double t, const Row& r) { rows.emplace_back(t, r); }
    std::string csv() const {
        std::string s = "t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n";
        char buf[128];
        for (const auto& row : rows) {
            std::snprintf(buf, sizeof buf, "%.4f", row.first);
            s += buf;
            for (int c = 0; c < 8; ++c) s += row.second.empty() ? std::string(",") : "," + std::to_string(row.second[c]);
            s += "\n";
        }
        return s;
    }
};

// A level, north-facing board (20 uT north, 45 uT down), rolled from roll0 to roll1 deg
// (right wing down positive) between t0 and t1, at 100 Hz for `seconds`.
std::string roll_trajectory(const std::string& name, double seconds, double t0, double t1, double roll0_deg,
                            double roll1_deg) {
    const double g = 9.80665, d2r = M_PI / 180.0;
    std::string s = "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz\n";
    char buf[256];
    for (int i = 0; i <= (int)(seconds * 100.0); ++i) {
        const double t = i * 0.01;
        double roll = roll0_deg, rate = 0.0;
        if (t >= t1) roll = roll1_deg;
        else if (t > t0) {
            rate = (roll1_deg - roll0_deg) / (t1 - t0);
            roll = roll0_deg + rate * (t - t0);
        }
        const double phi = roll * d2r, c = std::cos(phi), sn = std::sin(phi);
        std::snprintf(buf, sizeof buf, "%.2f,%.6f,0,0,0,%.5f,%.5f,20,%.4f,%.4f,%.7f,%.7f,0,0\n", t, rate * d2r, -g * sn,
                      -g * c, 45.0 * sn, 45.0 * c, std::cos(phi / 2), std::sin(phi / 2));
        s += buf;
    }
    return e2e::write_work_file(name + "_" + std::to_string(getpid()) + ".csv", s);
}

struct FlightRun {
    e2e::SimRun sim;
    std::vector<Pulse> pulses;
};

constexpr double kLiveFrom_s = 1.6;

FlightRun fly(const std::string& name, const std::string& trajectory, double seconds, const RcScript& rc,
              const std::string& extra = "", bool throttle_live = false) {
    const std::string tag = name + "_" + std::to_string(getpid());
    const std::string rc_path = e2e::write_work_file(tag + "_rc.csv", rc.csv());
    const std::string log = e2e::work_dir() + "/" + tag + "_servo.csv";
    const std::string input =
        throttle_live ? " --input " + e2e::input_file(tag + "_live", "set ARMING_REQUIRE 0\n") : std::string();
    FlightRun r;
    r.sim = e2e::run_sim_file(e2e::firmware_elf(), trajectory, seconds,
                              "--rc " + rc_path + " --servo-log " + log + " " + extra + input);
    r.pulses = read_pulses(log);
    return r;
}

const e2e::Line* first_line(const std::vector<e2e::Line>& lines, const std::string& prefix, double from_s = 0.0) {
    for (const auto& l : lines)
        if (l.t_s >= from_s && l.text.compare(0, prefix.size(), prefix) == 0) return &l;
    return nullptr;
}

// Every output pulses every 20 ms (rising edge to rising edge, within 2 us) from its
// first pulse to the end, and every width lies within the limits.
void expect_steady_and_within_limits(const std::vector<Pulse>& pulses, double end_s) {
    std::map<int, double> last;
    std::map<int, int> count;
    for (const Pulse& p : pulses) {
        ASSERT_GE(p.out, 1);
        ASSERT_LE(p.out, 8);
        EXPECT_GE(p.width_us, 1000.0 - kStamp_us) << "OUT" << p.out << " at " << p.t_s;
        EXPECT_LE(p.width_us, 2000.0 + kStamp_us) << "OUT" << p.out << " at " << p.t_s;
        if (last.count(p.out)) EXPECT_NEAR(p.t_s - last[p.out], 0.020, 2e-6) << "OUT" << p.out << " at " << p.t_s;
        last[p.out] = p.t_s;
        ++count[p.out];
    }
    for (int out = 1; out <= 8; ++out) {
        ASSERT_TRUE(last.count(out)) << "OUT" << out << " never pulsed";
        EXPECT_GT(last[out], end_s - 0.025) << "OUT" << out << " stopped";
        EXPECT_GE(count[out], (int)((end_s - 0.05) / 0.020)) << "OUT" << out;
    }
}

// The widths output `out` had in [from, to).
std::vector<double> widths(const std::vector<Pulse>& pulses, int out, double from_s, double to_s) {
    std::vector<double> w;
    for (const Pulse& p : pulses)
        if (p.out == out && p.t_s >= from_s && p.t_s < to_s) w.push_back(p.width_us);
    return w;
}

}  // namespace

// MANUAL: no pulse but the neutral ones before the receiver's first frame (OUT3, the
// throttle, at its failsafe 1000 us, the others at trim); then each output follows its
// channel within 1 us, clamped to its limits; 50 Hz on every output throughout.
TEST(Flight, PassThroughNeutralBeforeTheReceiverAndLimits) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    RcScript rc;
    rc.add(1.0, {1600, 1400, 1200, 1700, 1300, 1800, 1111, 1000});
    rc.add(2.0, {1234, 1567, 1890, 1001, 1999, 1500, 1650, 1000});
    rc.add(3.0, {900, 2100, 2150, 850, 1500, 1500, 1500, 1000});  // plausible, beyond the limits
    const FlightRun r = fly("passthrough", e2e::scenario_csv("rest", 4.0), 4.0, rc, "", true);
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    expect_steady_and_within_limits(r.pulses, 4.0);
    const double neutral[8] = {1500, 1500, 1000, 1500, 1500, 1500, 1500, 1500};
    ASSERT_FALSE(r.pulses.empty());
    EXPECT_LT(r.pulses.front().t_s, 0.05) << "the outputs start at power-up";
    for (const Pulse& p : r.pulses)
        if (p.t_s < 1.02) EXPECT_NEAR(p.width_us, neutral[p.out - 1], kStamp_us) << "OUT" << p.out << " at " << p.t_s;
    // Each row in force from 0.1 s after its start (a PPM frame, the next control step,
    // the next period) to its end.
    const double expect[3][8] = {{1600, 1400, 1200, 1700, 1300, 1800, 1111, 1000},
                                 {1234, 1567, 1890, 1001, 1999, 1500, 1650, 1000},
                                 {1000, 2000, 2000, 1000, 1500, 1500, 1500, 1000}};
    for (int row = 0; row < 3; ++row)
        for (int out = 1; out <= 8; ++out) {
            const double from = out == 3 && row == 0 ? kLiveFrom_s : 1.1 + row;  // the throttle once live
            const auto w = widths(r.pulses, out, from, 2.0 + row);
            ASSERT_GE(w.size(), 20u);
            for (double x : w) EXPECT_NEAR(x, expect[row][out - 1], kFollow_us) << "row " << row << " OUT" << out;
        }
    // Disarmed until `set ARMING_REQUIRE 0` was taken: the throttle at its minimum.
    for (double x : widths(r.pulses, 3, 0.0, 1.3)) EXPECT_NEAR(x, 1000.0, kStamp_us);
    // The first followed pulse comes within 0.1 s of the first frame.
    const auto early = widths(r.pulses, 1, 1.0, 1.1);
    EXPECT_NEAR(early.back(), 1600.0, kFollow_us);
}

// The receiver stops (a dead row) and comes back; then the encoder's own failsafe
// (throttle below THR_FS_VALUE 950). Each entered within 1.5 s and left when good frames
// return, said on the console naming the receiver; every output keeps pulsing at 50 Hz
// and the throttle goes to its failsafe value.
TEST(Flight, FailsafeEnteredAndLeft) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    RcScript rc;
    const Row fly_row = {1500, 1500, 1700, 1500, 1500, 1500, 1500, 2000};  // STABILIZE, throttle 70 %
    rc.add(0.5, fly_row);
    rc.add(3.0, {});
    rc.add(5.0, fly_row);
    Row encoder = fly_row;
    encoder[2] = 900;
    rc.add(6.0, encoder);
    rc.add(7.5, fly_row);
    const FlightRun r = fly("failsafe", e2e::scenario_csv("rest", 9.0), 9.0, rc, "", true);
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    expect_steady_and_within_limits(r.pulses, 9.0);
    const e2e::Line* lost = first_line(r.sim.lines, "# failsafe: receiver lost");
    ASSERT_NE(lost, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(lost->t_s, 3.0);
    EXPECT_LT(lost->t_s, 4.5);
    const e2e::Line* back = first_line(r.sim.lines, "# failsafe cleared: receiver back, flight STABILIZE");
    ASSERT_NE(back, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(back->t_s, 5.0);
    EXPECT_LT(back->t_s, 5.2);
    const e2e::Line* enc = first_line(r.sim.lines, "# failsafe: receiver's encoder failsafe");
    ASSERT_NE(enc, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(enc->t_s, 6.0);
    EXPECT_LT(enc->t_s, 7.5);
    EXPECT_NE(first_line(r.sim.lines, "# failsafe cleared", 7.5), nullptr) << e2e::dump(r.sim);
    // Throttle: 70 % while flying, 1000 us in failsafe.
    for (double w : widths(r.pulses, 3, 2.0, 3.0)) EXPECT_NEAR(w, 1700.0, kFollow_us);
    for (double w : widths(r.pulses, 3, lost->t_s + 0.03, 5.0)) EXPECT_NEAR(w, 1000.0, kStamp_us);
    for (double w : widths(r.pulses, 3, enc->t_s + 0.03, 7.5)) EXPECT_NEAR(w, 1000.0, kStamp_us);
    for (double w : widths(r.pulses, 3, 7.7, 9.0)) EXPECT_NEAR(w, 1700.0, kFollow_us);
}

// STABILIZE on a board rolled right (right wing down): the aileron output commands roll
// to the left (OUT1 below its trim), MANUAL on the switch's low position gives the stick
// back; the mode changes are said on the console.
TEST(Flight, StabilizeRollsLeftForARightTiltAndTheSwitchChoosesTheMode) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    const std::string traj = roll_trajectory("roll_right", 9.0, 4.0, 5.0, 0.0, 30.0);
    ASSERT_FALSE(traj.empty());
    RcScript rc;
    rc.add(0.5, {1500, 1500, 1100, 1500, 1500, 1500, 1500, 1000});  // MANUAL
    rc.add(2.5, {1500, 1500, 1100, 1500, 1500, 1500, 1500, 2000});  // STABILIZE
    rc.add(7.5, {1620, 1500, 1100, 1500, 1500, 1500, 1500, 1000});  // MANUAL, stick a little right
    const FlightRun r = fly("stabilize", traj, 9.0, rc);
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    expect_steady_and_within_limits(r.pulses, 9.0);
    const e2e::Line* stab = first_line(r.sim.lines, "# flight STABILIZE");
    ASSERT_NE(stab, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(stab->t_s, 2.5);
    EXPECT_LT(stab->t_s, 2.6);
    // Level in STABILIZE: the ailerons near trim.
    for (double w : widths(r.pulses, 1, 3.0, 4.0)) EXPECT_NEAR(w, 1500.0, 15.0);
    // Rolled right 30 deg, wings level demanded: (P - I tau) x 30 deg = 11.4 deg of 45 of
    // surface at least, ~125 us below trim: roll LEFT.
    const auto rolled = widths(r.pulses, 1, 5.5, 7.5);
    ASSERT_FALSE(rolled.empty());
    for (double w : rolled) EXPECT_LT(w, 1400.0);
    // The switch low: MANUAL, the stick passed through.
    const e2e::Line* man = first_line(r.sim.lines, "# flight MANUAL", 7.5);
    ASSERT_NE(man, nullptr) << e2e::dump(r.sim);
    for (double w : widths(r.pulses, 1, 7.7, 9.0)) EXPECT_NEAR(w, 1620.0, kFollow_us);
}

// A sensor fault in STABILIZE: the MPU6000 stops answering for 2 s. The controller falls
// back to MANUAL (the stick passes through) and says so, and STABILIZE resumes when the
// attitude does; no pulse leaves the limits and none is missed, before, during and after.
// (The switch is high from power-up: until the estimator runs, ~1.4 s, the same
// fallback flies MANUAL.)
TEST(Flight, SensorFaultInStabilizeFallsBackToManualWithinLimits) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    RcScript rc;
    rc.add(0.3, {2000, 1000, 1500, 1500, 1500, 1500, 1500, 2000});  // STABILIZE from the start, full stick
    const FlightRun r = fly("fault", e2e::scenario_csv("tilt_tour", 8.0), 8.0, rc, "--fault mpu:absent@4-6");
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    expect_steady_and_within_limits(r.pulses, 8.0);
    const e2e::Line* start = first_line(r.sim.lines, "# warn: STABILIZE without an attitude");
    ASSERT_NE(start, nullptr) << e2e::dump(r.sim);
    EXPECT_LT(start->t_s, 1.0);
    const e2e::Line* running = first_line(r.sim.lines, "# attitude back: flight STABILIZE");
    ASSERT_NE(running, nullptr) << e2e::dump(r.sim);
    EXPECT_LT(running->t_s, 2.0);
    const e2e::Line* fallback = first_line(r.sim.lines, "# warn: STABILIZE without an attitude", 3.0);
    ASSERT_NE(fallback, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(fallback->t_s, 4.0);
    EXPECT_LT(fallback->t_s, 4.5);
    const e2e::Line* back = first_line(r.sim.lines, "# attitude back: flight STABILIZE", fallback->t_s);
    ASSERT_NE(back, nullptr) << e2e::dump(r.sim);
    EXPECT_GT(back->t_s, 6.0);
    // Full stick right and down, passed through while the attitude is missing.
    for (double w : widths(r.pulses, 1, fallback->t_s + 0.05, 6.0)) EXPECT_NEAR(w, 2000.0, kStamp_us);
    for (double w : widths(r.pulses, 2, fallback->t_s + 0.05, 6.0)) EXPECT_NEAR(w, 1000.0, kFollow_us);
}

// 60 s of sticks that change every 5 ms (every loop step) in MANUAL: every pulse of every
// output at 20 ms and within 1 us of a width its channel had in the 0.1 s before it (no
// glitched pulse: no width cut by an OCR write, none from a torn frame).
TEST(Flight, SixtySecondsOfChangingCommandsWithoutAGlitch) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    RcScript rc;
    const double f_hz[7] = {0.7, 1.1, 0.3, 1.9, 2.3, 0.5, 3.1};
    for (int i = 0; i <= 60 * 200; ++i) {
        const double t = 0.2 + i * 0.005;
        Row row(8);
        for (int c = 0; c < 7; ++c) row[c] = 1500 + (int)std::lround(480.0 * std::sin(2.0 * M_PI * f_hz[c] * t + c));
        row[7] = 1000;  // MANUAL
        rc.add(t, row);
    }
    const double seconds = 60.0;
    const FlightRun r = fly("glitch", e2e::scenario_csv("rest", seconds), seconds, rc, "", true);
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    expect_steady_and_within_limits(r.pulses, seconds);
    size_t checked = 0, glitches = 0;
    for (const Pulse& p : r.pulses) {
        if (p.t_s < 0.5 || p.out > 7 || (p.out == 3 && p.t_s < kLiveFrom_s)) continue;
        bool matched = false;
        for (const auto& row : rc.rows)
            if (row.first <= p.t_s && row.first >= p.t_s - 0.1 && std::fabs(row.second[p.out - 1] - p.width_us) <= kFollow_us)
                matched = true;
        ++checked;
        if (!matched) {
            ++glitches;
            if (glitches < 5) ADD_FAILURE() << "OUT" << p.out << " at " << p.t_s << ": " << p.width_us << " us";
        }
    }
    EXPECT_GT(checked, 7u * 2900u);
    EXPECT_EQ(glitches, 0u);
}

// --- The body rates reach the controllers (firmware/FlightIo: gyro counts less the bias) --

namespace {

// A level, north-facing board that rolls or pitches (never both at once) through the
// piecewise-linear (t, roll, pitch) points, degrees, at 100 Hz for `seconds`: body rates
// p = roll rate (pitch 0), q = pitch rate (roll 0), read by a gyro with a constant bias
// (deg/s, x and y); specific force and field rotated by R = Ry(pitch) Rx(roll).
std::string roll_pitch_trajectory(const std::string& name, double seconds,
                                  const std::vector<std::array<double, 3>>& points, double bias_x_deg_s,
                                  double bias_y_deg_s) {
    const double g = 9.80665, d2r = M_PI / 180.0;
    std::string s = "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz\n";
    char buf[320];
    for (int i = 0; i <= (int)(seconds * 100.0); ++i) {
        const double t = i * 0.01;
        double roll = points.back()[1], pitch = points.back()[2], p = 0.0, q = 0.0;
        for (size_t k = 0; k + 1 < points.size(); ++k) {
            const auto& a = points[k];
            const auto& b = points[k + 1];
            if (t >= a[0] && t < b[0]) {
                const double f = (t - a[0]) / (b[0] - a[0]);
                roll = a[1] + f * (b[1] - a[1]);
                pitch = a[2] + f * (b[2] - a[2]);
                p = (b[1] - a[1]) / (b[0] - a[0]);
                q = (b[2] - a[2]) / (b[0] - a[0]);
                break;
            }
        }
        if (t < points.front()[0]) roll = points.front()[1], pitch = points.front()[2], p = q = 0.0;
        const double cr = std::cos(roll * d2r), sr = std::sin(roll * d2r), cp = std::cos(pitch * d2r),
                     sp = std::sin(pitch * d2r);
        const double mx = 20.0 * cp - 45.0 * sp, mz0 = 20.0 * sp + 45.0 * cp;
        const double hr = roll * d2r / 2.0, hp = pitch * d2r / 2.0;
        std::snprintf(buf, sizeof buf, "%.2f,%.6f,%.6f,0,%.5f,%.5f,%.5f,%.4f,%.4f,%.4f,%.7f,%.7f,%.7f,%.7f\n", t,
                      (p + bias_x_deg_s) * d2r, (q + bias_y_deg_s) * d2r, g * sp, -g * cp * sr, -g * cp * cr, mx, sr * mz0, cr * mz0,
                      std::cos(hp) * std::cos(hr), std::cos(hp) * std::sin(hr), std::sin(hp) * std::cos(hr),
                      -std::sin(hp) * std::sin(hr));
        s += buf;
    }
    return e2e::write_work_file(name + "_" + std::to_string(getpid()) + ".csv", s);
}

}  // namespace

// STABILIZE, wings level and nose level asked, no integrator (RLL2SRV_I and PTCH2SRV_I 0),
// D at 0.2 on both axes (its maximum: the rate's part large beside the angle's): the board
// rolls right to 20 deg at 40 deg/s and back, then pitches up to 20 deg and back, its gyro
// biased by 2 and -1.5 deg/s on x and y (the start's calibration learns them). Every
// aileron and elevator pulse in the motion is the controller's equation (docs/flight.md)
// on the board's own angle and the motion's body rate, the bias taken out:
//   surface = P' w_d + D (w_d - w),  w_d = -angle / TCONST,  P' = P TCONST - D = 0.3,
// at 100 cd of surface per 1.11 us (500 us for 4500 cd). The rate's part is D x 40 deg/s =
// 8 deg of surface, 89 us: a rate with the wrong sign, scale or axis is 89 us or more off,
// a bias left in or added twice 3 to 9 us. The angle is the board's angle line begun in the
// 20 ms before the pulse (at 50 Hz the step prints the angles it controls on, and the pulse
// starts at the servo period after it: depending on the servo timers' phase against the
// samples, before or after the line's last byte has left). Within 2 us: the width's rounding
// to 1 us, the line's 0.01 deg, the servo log's 0.3 us.
TEST(Flight, StabilizeDampsTheBodyRatesItMeasures) {
    E2E_REQUIRE_TOOLS("apm25sim");
    const double seconds = 10.0;
    // (t, roll, pitch): still 4 s (the gyro calibration, the estimator's start), then each
    // leg 0.5 s at 40 deg/s, 0.7 s of hold between.
    const std::vector<std::array<double, 3>> points = {{4.0, 0, 0},  {4.5, 20, 0}, {5.2, 20, 0}, {5.7, 0, 0},
                                                       {6.5, 0, 0},  {7.0, 0, 20}, {7.7, 0, 20}, {8.2, 0, 0}};
    const std::string traj = roll_pitch_trajectory("rates", seconds, points, 2.0, -1.5);
    ASSERT_FALSE(traj.empty());
    const std::string input = e2e::input_file("rates", "set RLL2SRV_I 0\nset PTCH2SRV_I 0\nset RLL2SRV_D 0.2\n"
                                                       "set PTCH2SRV_D 0.2\n");
    RcScript rc;
    rc.add(0.5, {1500, 1500, 1100, 1500, 1500, 1500, 1500, 1000});  // MANUAL
    rc.add(2.5, {1500, 1500, 1100, 1500, 1500, 1500, 1500, 2000});  // STABILIZE
    const FlightRun r = fly("rates", traj, seconds, rc, "--input " + input + " --input-at 2");
    ASSERT_EQ(r.sim.result.exit_code, 0) << e2e::dump(r.sim);
    for (const char* said : {"# RLL2SRV_I 0", "# PTCH2SRV_I 0", "# RLL2SRV_D 0.2", "# PTCH2SRV_D 0.2"})
        ASSERT_NE(first_line(r.sim.lines, said), nullptr) << said << "\n" << e2e::dump(r.sim);
    ASSERT_NE(first_line(r.sim.lines, "# flight STABILIZE", 2.5), nullptr) << e2e::dump(r.sim);
    const e2e::Line* bias = first_line(r.sim.lines, "# gyro bias: ");
    ASSERT_NE(bias, nullptr) << e2e::dump(r.sim);
    double bx = NAN, by = NAN;
    ASSERT_EQ(std::sscanf(bias->text.c_str(), "# gyro bias: %lf %lf", &bx, &by), 2) << bias->text;
    EXPECT_NEAR(bx, 2.0, 0.05) << bias->text;  // to the gyro's counts (16.4 a deg/s)
    EXPECT_NEAR(by, -1.5, 0.05) << bias->text;
    expect_steady_and_within_limits(r.pulses, seconds);
    // One leg: output `out`, the angle (roll or pitch) of the board's lines, the rate.
    struct Leg {
        double t0, t1;
        int out;
        bool roll;
        double rate_deg_s;
    };
    const Leg legs[4] = {{4.0, 4.5, 1, true, 40.0}, {5.2, 5.7, 1, true, -40.0}, {6.5, 7.0, 2, false, 40.0},
                         {7.7, 8.2, 2, false, -40.0}};
    const double tau = 0.5, p_ff = 0.3, d = 0.2, us_per_deg = 500.0 / 45.0, kEquation_us = 2.0;
    auto expected_us = [&](double angle_deg, double rate_deg_s) {
        const double w_d = -angle_deg / tau;
        return 1500.0 + us_per_deg * (p_ff * w_d + d * (w_d - rate_deg_s));
    };
    for (const Leg& leg : legs) {
        int checked = 0;
        double worst = 0.0;
        // From 0.06 s into the leg (the gyro's low-pass settled) to its end.
        for (const Pulse& p : r.pulses) {
            if (p.out != leg.out || p.t_s < leg.t0 + 0.06 || p.t_s > leg.t1) continue;
            const e2e::Line* line = nullptr;
            int lines = 0;
            for (const e2e::Line& l : r.sim.lines) {
                // The line's first byte: its step (the output task, before the control
                // task) was then; the stamp is its newline, the line's bytes later at
                // 115200 baud, which may be after a pulse the step's control already set.
                const double start_s = l.t_s - (double)(l.text.size() + 1) * 10.0 / 115200.0;
                if (l.is_angle && start_s >= p.t_s - 0.020 && start_s < p.t_s) line = &l, ++lines;
            }
            ASSERT_EQ(lines, 1) << "angle lines begun in the 20 ms before the pulse at " << p.t_s;
            // The trajectory's rows are 10 ms apart: the rate ramps to the hold's after the
            // leg's last row at t1 - 0.01; a step on a later sample (its line begun ~1 ms
            // after it) controls on that ramp, not on the leg's rate.
            if (line->t_s - (double)(line->text.size() + 1) * 10.0 / 115200.0 > leg.t1 - 0.008) continue;
            const double want = expected_us(leg.roll ? line->roll : line->pitch, leg.rate_deg_s);
            const double off = std::fabs(p.width_us - want);
            worst = std::max(worst, off);
            EXPECT_LE(off, kEquation_us) << "OUT" << leg.out << " at " << p.t_s << ": " << p.width_us
                                         << " us, the equation " << want << " (" << line->text << ")";
            ++checked;
        }
        EXPECT_GE(checked, 20) << "leg from " << leg.t0;
        std::printf("rates: OUT%d, %+.0f deg/s from %.1f s: %d pulses, at most %.2f us from the equation\n", leg.out,
                    leg.rate_deg_s, leg.t0, checked, worst);
    }
}
