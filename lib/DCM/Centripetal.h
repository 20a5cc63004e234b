// SPDX-License-Identifier: GPL-3.0-or-later
// The turn's centripetal acceleration taken off the gravity window (Premerlani &
// Bizard, "Direction Cosine Matrix IMU: Theory", eq. 26; ArduPilot's AP_AHRS_DCM with an
// airspeed): in steady flight the velocity is (V, 0, 0) along the body's x axis and the
// accelerometer reads f = omega x v - g_body, so gravity is f - omega x v = f - (0,
// omega_z V, -omega_y V). The gain (accel counts per gyro count of omega x v at the
// airspeed, Q8) is the pipeline's: it knows the airspeed (lib/Pipeline, Airspeed.h).
//
// omega_z V is the lateral acceleration only while the relative wind turns with the
// flight path. Turbulence yaws the aeroplane into a relative wind that changes while the
// path hardly turns (README, "Flying in simulation"). The accelerometer and the estimate
// say what the lateral acceleration is: a_y = f_y + g down_y (down_y = sin(roll)
// cos(pitch), earth down's body y component, the gyro carries it through a turn's entry;
// a coordinated turn has f_y = 0, a flat skid g down_y = 0). So omega_z V is held between
// 0 and that a_y, widened by a margin of bank: the estimate is moved toward what omega_z
// V says at most that far beyond what it holds, a turn that lasts gets all of it (each
// window the bound moves on with the estimate), a gust's yaw hardly any. The margin is
// the bank error a turn's entry can leave in the estimate: the gyro's +-3 % scale
// tolerance (MPU-6000 datasheet 6.1) over the bank, and the half degree the tilt holds
// before it.
//
// In a turn through turbulence omega_z V swings about its mean (the gusts' yaw) while
// a_y, the bank, stays: clipping the swings at a bound at their mean takes off the upper
// ones only, the term's mean falls short of the turn's, the estimate rolls toward level
// and the bound with it: the estimate runs away (a 30 deg turn in moderate turbulence
// levelled to 5 deg). So the bound holds the term's mean as well: its mean over 1.3 s
// (short against a turn, seconds long against a gust's yaw swing) is what the bounds allow
// omega_z V's mean within a_y's mean; each window is clipped as above, and what the
// clipping took off the mean beyond that is given back. Only in a turn: while a_y's mean
// stays within g sin(kTurnMinBank_deg) of level the aeroplane flies straight, the gusts
// rocking its wings and yawing it about its path, and there is no turn's term whose
// upper swings the clipping took: nothing is given back (given back, the yaw swings' and
// the bank's chance agreement over a second put up to two margins of roll into the
// estimate for seconds, and the heading took it through the dip at start-up: a straight
// gusty flight with the airspeed 1.74 deg RMSE against 1.27 without).
//
// At a start in flight the estimate's tilt is the start window's accelerometer mean, off
// by what the gusts accelerated the aeroplane meanwhile (1-3 deg), and a_y read through it
// widens the bound by that error: the yaw of an aeroplane weathervaning into a growing
// crosswind (a degree a second, for seconds) then fits inside the bound, is taken off as a
// turn's, and holds the estimate at the start's error, which the dip turns into heading
// (README, "Flying in simulation"). So while the start's tilt is unproven, the
// start-up (startup_s: three of the tilt loop's time constants 1 / kp_rp, 95 % of the
// start's error gone), a_y is the accelerometer's f_y alone: a start inside a coordinated
// turn (f_y = 0) is held to the margin for those seconds, and its estimate starts the turn
// over from where the tilt loop left it.
//
// Along the body's x axis the flight's change of speed does the same: a climb's speed
// change reads as pitch, 6 deg a m/s^2. A measured airspeed's change tells it (dV/dt, the
// pipeline's; a configured cruise speed has none), but a gust changes the airspeed while
// the path's speed hardly changes (the aeroplane's inertia), and the accelerometer does
// not feel it. So dV/dt is held between 0 and a_x = f_x + g down_x, the acceleration the
// accelerometer and the estimate say there is, widened by the same margin, window by
// window: a speed change the accelerometer feels is taken off, a gust's hardly. No mean
// is given back here: a climb's dV/dt lasts seconds and sits inside its bound, and what
// clipping takes off is the gusts' swings, which the accelerometer did not feel.
//
// Formats: accel and gyro counts summed over the window (n samples, 4 but for a late
// correction); the means of those sums in Q8.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

constexpr float kTurnBankMargin_deg = 0.5f;
// The least bank that is a turn: a scale aeroplane's gentlest turns bank 10-15 deg, and
// the wings' rocking in turbulence averages out over the 1.3 s mean to a few degrees.
constexpr float kTurnMinBank_deg = 5.0f;
constexpr float kTurnBankScaleError = 0.03f;

struct LateralBounds {
    int32_t lo, hi;  // accel counts
};
// 0 .. a (either side: a_y, or a_x for dV/dt), widened by the margin.
LateralBounds lateral_bounds(int32_t a_y, int32_t margin);

// x n for a window's n samples: two shifts for the usual 4 (avr-gcc's 32-bit multiply
// is a call).
inline int32_t times_n(int32_t x, uint8_t n) { return n == 4 ? x * 4 : x * n; }
// A window's sum a sample: rounded shifts for the usual 4 (times_n's inverse), a
// division only for a late window's n.
inline int32_t per_sample(int32_t sum, uint8_t n) { return n == 4 ? (sum + 2) >> 2 : sum / n; }

// A plain struct (no constructor: the pipeline keeps it in a union, RAM); zero is
// "no gain, no mean yet": the first window sets the means.
class TurnMean {
public:
    static constexpr uint8_t kUpdateEvery = 2;  // windows: 25 Hz
    static constexpr uint8_t kMeanShift = 5;    // 1 / 32 an update: 1.28 s at 25 Hz
    // The gain (accel counts per gyro count of omega x v, Q8; 0: no correction), gravity
    // and dV/dt in accel counts; the means go on.
    void configure(int16_t gain_q8, int16_t gravity_counts, int16_t dv_dt_counts = 0);
    bool active() const { return gain_q8_ != 0; }
    // The window's sums less (dV/dt, omega_z V, -omega_y V), the first two within their
    // bounds: accel_sum and the running sums' sum, from the gyro's sums less the
    // calibrated bias (counts) and earth down in body axes (R's third row, Q30; while
    // start_tilt, the start-up's, a_y's bound leaves it out). The
    // lateral and normal terms are worked out every kUpdateEvery-th window (25 Hz: a
    // turn's term moves at the turn's pace, a gust's swings at a few hertz; the work is
    // 32-bit arithmetic), dV/dt every eighth window (6.25 Hz: the speed changes at a
    // climb's pace); each is kept for the windows between. The lateral and normal terms
    // come from the rates' and a_y's means over the windows they stand for, not the last
    // window's: one 20 ms window's rate, held for the windows between, is a sample at the
    // update rate, and an oscillation at that rate or its multiples (a propeller's
    // vibration the airframe answers, folded by the sampling) comes out a steady term
    // (from the last of four windows: a flight climbing at full throttle rolled 2.6 deg
    // with the cruise speed, README "Flying in simulation"); the mean over the 40 ms it is
    // held for passes nothing at 25 Hz and its multiples, and what is near 12.5 Hz comes
    // out with its sign alternating.
    void take_off(int32_t rate_y_sum, int32_t rate_z_sum, const linalg::Vector3l& down_q30, uint8_t n,
                  linalg::Vector3l& accel_sum, linalg::Vector3l& accel_sum_of_sums, bool start_tilt) {
        const uint8_t window = windows_++;
        rate_y_means_ += per_sample(rate_y_sum, n);
        rate_z_means_ += per_sample(rate_z_sum, n);
        f_y_means_ += per_sample(accel_sum.y, n);
        if ((window & (kUpdateEvery - 1u)) == 0u) update(down_q30, n, accel_sum, window, start_tilt);
        // Sample j's weight in the running sums' sum is n - j + 1, n (n + 1) / 2 in all:
        // the window's term (n samples' worth) times (n + 1) / 2, 10 samples' worth for 4.
        if (n == 4) {
            take_off_four(term_.x, accel_sum.x, accel_sum_of_sums.x);
            take_off_four(term_.y, accel_sum.y, accel_sum_of_sums.y);
            take_off_four(term_.z, accel_sum.z, accel_sum_of_sums.z);
        } else {
            take_off_late(term_.x, n, accel_sum.x, accel_sum_of_sums.x);
            take_off_late(term_.y, n, accel_sum.y, accel_sum_of_sums.y);
            take_off_late(term_.z, n, accel_sum.z, accel_sum_of_sums.z);
        }
    }

private:
    static void take_off_term(int32_t term, int32_t term_weighted, int32_t& sum, int32_t& sum_of_sums) {
        sum -= term;
        sum_of_sums -= term_weighted;
    }
    // The usual window's 4 samples (a sample's term, counts).
    static void take_off_four(int16_t term, int32_t& sum, int32_t& sum_of_sums) {
        const int32_t term4 = (int32_t)term * 4;
        take_off_term(term4, term4 * 2 + (term4 >> 1), sum, sum_of_sums);
    }
    // A late window's n samples.
    static void take_off_late(int16_t term, uint8_t n, int32_t& sum, int32_t& sum_of_sums) {
        const int32_t term_n = times_n(term, n);
        take_off_term(term_n, (times_n(term_n, n) + term_n) >> 1, sum, sum_of_sums);
    }
    // a = f + g down on one axis (f_sum the accelerometer's sum there, down_q30 earth
    // down's component) and the margin, each summed over the window's n samples.
    struct AxisBound {
        int32_t a, margin;
    };
    AxisBound axis_bound(int32_t f_sum, int32_t down_q30, uint8_t n) const;
    // The window's lateral term (counts summed over the window) from omega_z V's sum.
    int32_t lateral_sum(int32_t raw_sum, int32_t f_y_sum, int32_t down_y_q30, uint8_t n);
    // The lateral and normal terms from the means since the last update (four samples'
    // worth of them), dV/dt from this window's sums (f_sum: the accelerometer's) on every
    // eighth window (window: the count of this one); start_tilt: take_off's.
    void update(const linalg::Vector3l& down_q30, uint8_t n, const linalg::Vector3l& f_sum, uint8_t window,
                bool start_tilt);
    // dV/dt within its bound (f_x_sum: the accelerometer's x).
    void update_longitudinal(int32_t down_x_q30, uint8_t n, int32_t f_x_sum);
    // g sin of an angle whose sine is sin_q14 / 2^14, accel counts (the margin's, a turn's).
    int16_t gravity_times(int16_t sin_q14) const;

    int32_t raw_q8_, a_y_q8_, clipped_q8_;  // means of the windows' sums, Q8
    // The windows' means a sample summed since the last update (gyro counts less the
    // calibrated bias; the accelerometer's y, counts): kUpdateEvery of them, doubled, are
    // four samples' worth of their mean.
    int32_t rate_y_means_, rate_z_means_, f_y_means_;
    int16_t gain_q8_, gravity_counts_x4_, dv_dt_counts_;
    bool started_;                          // the means hold a window (the first sets them)
    uint8_t windows_;                       // counts the windows: when the terms are worked out
    // The terms taken off, a sample's (accel counts; x dV/dt, y omega_z V, z -omega_y V).
    linalg::Vector3i term_;
};

}  // namespace dcm
