// SPDX-License-Identifier: GPL-3.0-or-later
// The turn's centripetal acceleration taken off the gravity window (Premerlani &
// Bizard, "Direction Cosine Matrix IMU: Theory", eq. 26; ArduPilot's AP_AHRS_DCM with an
// airspeed). In steady flight the velocity is (V, 0, 0) along the body's x axis and the
// accelerometer reads f = omega x v - g_body, so gravity is
//   f - (dV/dt, omega_z V, -omega_y V)     (body axes)
// The gain (accel counts per gyro count of omega x v at the airspeed, Q8) and dV/dt are
// the pipeline's: it knows the airspeed (lib/Pipeline, Airspeed.h).
//
// The rules, each with its reason (the whole argument: docs/estimator.md):
// - omega_z V is held between 0 and a_y = f_y + g down_y (down_y = sin(roll) cos(pitch),
//   earth down's body y component), widened by a margin of bank: turbulence yaws the
//   aeroplane into a new relative wind while its path hardly turns, and only a lateral
//   acceleration the accelerometer and the estimate agree on is a turn's. The margin is
//   the bank error a turn's entry can leave: kTurnBankMargin_deg and the gyro's
//   kTurnBankScaleError of the bank (+-3 % scale tolerance, MPU-6000 product
//   specification 6.1).
// - In a turn (a_y's 1.3 s mean beyond g sin kTurnMinBank_deg) what the clipping took off
//   the term's mean beyond what the bounds allow it is given back: clipping only the
//   gusts' upper swings would leave the term short of the turn's, and the estimate
//   would roll toward level and its bound with it. In straight flight nothing is given
//   back: there is no turn's term to restore.
// - While the start's tilt is unproven (start_tilt: startup_s, three of the tilt loop's
//   time constants) a_y is f_y alone: read through the start's tilt error, a_y would
//   widen the bound by that error.
// - dV/dt is held between 0 and a_x = f_x + g down_x, widened by the same margin, window
//   by window: a speed change the accelerometer feels is taken off (6 deg of pitch a
//   m/s^2), a gust's change of airspeed hardly. No mean is given back.
//
// Formats: accel and gyro counts summed over the window (n samples, 4 but for a late
// correction); the means of those sums in Q8.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

// The margin of bank: the half degree of tilt error the estimate holds before a turn,
// plus kTurnBankScaleError of the bank.
constexpr float kTurnBankMargin_deg = 0.5f;
// The least bank that is a turn: a scale aeroplane's gentlest turns bank 10-15 deg, and
// the wings' rocking in turbulence averages out over the 1.3 s mean to a few degrees.
constexpr float kTurnMinBank_deg = 5.0f;
// The gyro's scale tolerance (MPU-6000 product specification 6.1: +-3 %).
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
    // The terms the last window had taken off, a sample's (accel counts; x dV/dt, y omega_z
    // V, z -omega_y V): what a GPS's sums give back (Dcm::correct_gravity).
    const linalg::Vector3i& term() const { return term_; }
    // The window's sums less (dV/dt, omega_z V, -omega_y V), the first two within their
    // bounds: accel_sum and the running sums' sum, from the gyro's sums less the
    // calibrated bias (counts) and earth down in body axes (R's third row, Q30;
    // start_tilt: a_y's bound leaves it out). The lateral and normal terms are worked out
    // every kUpdateEvery-th window (25 Hz: a turn's pace) from the means over the windows
    // they stand for (one window's rate, held, would alias a vibration at 25 Hz or its
    // multiples into a steady term); dV/dt every eighth window (6.25 Hz: a climb's pace).
    // Each is kept for the windows between.
    void subtract_from_window(int32_t rate_y_sum, int32_t rate_z_sum, const linalg::Vector3l& down_q30, uint8_t n,
                              linalg::Vector3l& accel_sum, linalg::Vector3l& accel_sum_of_sums, bool start_tilt) {
        const uint8_t window = windows_++;
        rate_y_means_ += per_sample(rate_y_sum, n);
        rate_z_means_ += per_sample(rate_z_sum, n);
        f_y_means_ += per_sample(accel_sum.y, n);
        if ((window & (kUpdateEvery - 1u)) == 0u) update(down_q30, n, accel_sum, window, start_tilt);
        // Sample j's weight in the running sums' sum is n - j + 1, n (n + 1) / 2 in all:
        // the window's term (n samples' worth) times (n + 1) / 2, 10 samples' worth for 4.
        if (n == 4) {
            subtract_four(term_.x, accel_sum.x, accel_sum_of_sums.x);
            subtract_four(term_.y, accel_sum.y, accel_sum_of_sums.y);
            subtract_four(term_.z, accel_sum.z, accel_sum_of_sums.z);
        } else {
            subtract_late(term_.x, n, accel_sum.x, accel_sum_of_sums.x);
            subtract_late(term_.y, n, accel_sum.y, accel_sum_of_sums.y);
            subtract_late(term_.z, n, accel_sum.z, accel_sum_of_sums.z);
        }
    }

private:
    static void subtract_term(int32_t term, int32_t term_weighted, int32_t& sum, int32_t& sum_of_sums) {
        sum -= term;
        sum_of_sums -= term_weighted;
    }
    // The usual window's 4 samples (a sample's term, counts).
    static void subtract_four(int16_t term, int32_t& sum, int32_t& sum_of_sums) {
        const int32_t term4 = (int32_t)term * 4;
        subtract_term(term4, term4 * 2 + (term4 >> 1), sum, sum_of_sums);
    }
    // A late window's n samples.
    static void subtract_late(int16_t term, uint8_t n, int32_t& sum, int32_t& sum_of_sums) {
        const int32_t term_n = times_n(term, n);
        subtract_term(term_n, (times_n(term_n, n) + term_n) >> 1, sum, sum_of_sums);
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
    // eighth window (window: the count of this one); start_tilt: subtract_from_window's.
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
