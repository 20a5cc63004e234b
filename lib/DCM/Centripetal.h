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
// clipping took off the mean beyond that is given back.
//
// Formats: accel and gyro counts summed over the window (n samples, 4 but for a late
// correction); the means of those sums in Q8.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

constexpr float kTurnBankMargin_deg = 0.5f;
constexpr float kTurnBankScaleError = 0.03f;

struct LateralBounds {
    int32_t lo, hi;  // accel counts
};
// 0 .. a_y (either side), widened by the margin.
LateralBounds lateral_bounds(int32_t a_y, int32_t margin);

// x n for a window's n samples: two shifts for the usual 4 (avr-gcc's 32-bit multiply
// is a call).
inline int32_t times_n(int32_t x, uint8_t n) { return n == 4 ? x * 4 : x * n; }

// A plain struct (no constructor: the pipeline keeps it in a union, RAM); zero is
// "no gain, no mean yet": the first window sets the means.
class TurnMean {
public:
    static constexpr uint8_t kUpdateEvery = 4;  // windows: 12.5 Hz
    static constexpr uint8_t kMeanShift = 4;    // 1 / 16 an update: 1.28 s at 12.5 Hz
    // The gain (accel counts per gyro count of omega x v, Q8; 0: no correction) and
    // gravity in accel counts; the means go on.
    void configure(int16_t gain_q8, int16_t gravity_counts);
    bool active() const { return gain_q8_ != 0; }
    // The window's sums less omega x v = (0, omega_z V, -omega_y V), the lateral term
    // within the bounds: accel_sum and the running sums' sum, from the gyro's sums less
    // the calibrated bias (counts) and the estimate's down_y (Q30). The term is worked out
    // every kUpdateEvery-th window (12.5 Hz: a turn's term moves at the turn's pace, a
    // gust's swings at a few hertz; the work is 32-bit arithmetic) and kept a sample's
    // worth for the windows between.
    void take_off(int32_t rate_y_sum, int32_t rate_z_sum, int32_t down_y_q30, uint8_t n,
                  linalg::Vector3l& accel_sum, linalg::Vector3l& accel_sum_of_sums) {
        if ((windows_++ & (kUpdateEvery - 1u)) == 0u) update(rate_y_sum, rate_z_sum, down_y_q30, n, accel_sum.y);
        const int32_t lateral = times_n(lateral_per_sample_, n), normal = times_n(normal_per_sample_, n);
        accel_sum.y -= lateral;
        accel_sum.z += normal;
        // Sample j's weight in the running sums' sum is n - j + 1, n (n + 1) / 2 in all:
        // the window's term (n samples' worth) times (n + 1) / 2.
        accel_sum_of_sums.y -= (times_n(lateral, n) + lateral) >> 1;
        accel_sum_of_sums.z += (times_n(normal, n) + normal) >> 1;
    }

private:
    // The window's lateral term (counts summed over the window) from omega_z V's sum.
    int32_t lateral_sum(int32_t raw_sum, int32_t f_y_sum, int32_t down_y_q30, uint8_t n);
    // The term a sample from the window's sums (f_y_sum: the accelerometer's y).
    void update(int32_t rate_y_sum, int32_t rate_z_sum, int32_t down_y_q30, uint8_t n, int32_t f_y_sum);

    int32_t raw_q8_, a_y_q8_, clipped_q8_;  // means of the windows' sums, Q8
    int16_t gain_q8_, gravity_counts_x4_, margin_counts_;
    bool started_;                          // the means hold a window (the first sets them)
    uint8_t windows_;                       // counts the windows: the term is worked out every kUpdateEvery-th
    int32_t lateral_per_sample_, normal_per_sample_;  // the term, accel counts a sample
};

}  // namespace dcm
