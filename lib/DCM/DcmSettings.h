// SPDX-License-Identifier: GPL-3.0-or-later
// The estimator's settings (VQF's params struct): every tuning value with its physical
// meaning and unit, and the one default set with the reason for each value. What the
// step derives from them is DcmCoefficients (Coefficients.h).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

struct DcmSettings {
    float step_s;                    // fixed update step, s (200 Hz: 0.005)
    float kp_rp_1_s;                 // roll/pitch proportional gain, 1/s
    float ki_rp_1_s2;                // roll/pitch integral gain (gyro-bias estimate), 1/s^2
    float ki_rp_measured_1_s2;       // ... once the bias was measured on a still board, 1/s^2
    float kp_yaw_1_s;                // yaw proportional gain, 1/s
    float ki_yaw_1_s2;               // yaw integral gain while no rest or calibration has measured the bias, 1/s^2
    float kp_startup_1_s;            // roll/pitch P gain at a start from one sample (not from a mean:
                                     // Dcm::init), ramping down to the steady one; the heading's at
                                     // rest and at most while moving (then 1/t), 1/s
    float startup_s;                 // length of the start-up ramp (also speeds up the accel low-pass), s
    float accel_max_g;               // beyond any accelerometer's range: such a sample is garbage, g
    float accel_lowpass_s;           // time constant of the earth-frame accel low-pass, s
    float integrator_hold_rate_rad_s;// mean rate (0.5 s) above which the bias integrator is held, rad/s
    float bias_limit_rad_s;          // bound on each axis of the gyro-bias estimate (a quarter once calibrated), rad/s
    float mag_norm_tolerance;        // |field| may differ from the learned one by this fraction
    float mag_dip_tolerance;         // field.down/|field| may differ from the learned one by this
    float mag_recover_s;             // a different field steady this long becomes the reference, s
    float mag_new_min_rate_rad_s;    // ... while the board turned at least this fast on average, rad/s
    float mag_latency_s;             // age of a field sample against the gyro-propagated attitude, s (<= 5.9 steps)
    float rest_gyro_deviation_rad_s; // at rest the gyro stays this close to its recent mean, rad/s
    float rest_accel_deviation_m_s2; // ... and the accelerometer this close to its own, m/s^2
    float rest_min_s;                // rest must last this long before the bias is taken from it, s
    float rest_bias_s;               // time constant of the bias estimate at rest (0: none), s
    float output_lead_s;             // the output is R carried forward by this, s
    float gps_lowpass_s;             // the earth-frame low-pass's time constant while a GPS aids it (GpsAid.h), s
};

// One set for everything, each value with its physical reason beside it; `make tune`
// (bench/tune.py) cross-validates them on recordings (tuned on one half, scored on the
// other) and scores them on scenarios with a real board's errors (docs/estimator.md).
// The gyro bias is learned from gravity (the two horizontal axes, ki_rp) and at rest
// (every axis, rest_*); from the compass (the vertical axis, ki_yaw) only until a rest
// or the start's calibration has measured it: the compass's errors (a residual hard
// iron, a nearby magnet) are degrees and turn with the heading, so an integrator on them
// learns a false bias that makes the heading drift whenever the compass is disturbed
// (VQF makes the same choice).
constexpr DcmSettings kDefaultDcmSettings = {
    0.005f,                         // step_s: 200 Hz
    1.0f,                           // kp_rp_1_s
    // The tilt integrator learns what the tilt error holds for kp_rp / ki_rp, a sustained
    // acceleration's too: 10 s while the bias is unknown (up to degrees per second to
    // find); 33 s once measured still, when only the MPU6000's warm-up drift is left
    // (0.2 deg/s a minute, followed with a lag of 0.1 deg/s).
    0.1f,                           // ki_rp_1_s2
    0.03f,                          // ki_rp_measured_1_s2
    0.1f,                           // kp_yaw_1_s
    // On a board never still since power-on only the compass sees the bias's vertical
    // part in level flight: without ki_yaw the heading stands b / kp_yaw off (0.8 deg/s:
    // 8 deg). kp_yaw^2 / 4 makes that loop critically damped: a compass error does not
    // ring.
    0.0025f,                        // ki_yaw_1_s2: kp_yaw^2 / 4, until the bias is measured (see above)
    5.0f,                           // kp_startup_1_s
    3.0f,                           // startup_s
    16.0f,                          // accel_max_g
    3.0f,                           // accel_lowpass_s
    // No bias learning while the board turns lastingly: a gyro scale error (+-3 %) makes
    // the turn's rate look like bias, and its centripetal acceleration reads as tilt. An
    // aeroplane at 18 m/s banked 18 deg turns at 10 deg/s (ArduPilot's 20 deg/s lets every
    // turn up to 32 deg of bank teach the bias).
    10.0f * linalg::kRadPerDeg,     // integrator_hold_rate_rad_s (see above; ArduPilot's 20 deg/s)
    10.0f * linalg::kRadPerDeg,     // bias_limit_rad_s
    0.1f,                           // mag_norm_tolerance
    0.1f,                           // mag_dip_tolerance
    20.0f,                          // mag_recover_s
    20.0f * linalg::kRadPerDeg,     // mag_new_min_rate_rad_s (VQF's magNewMinGyr)
    // A field sample is ~5 ms old when the step uses it (the HMC5883L's 8-sample average,
    // the wait for the next step), and the recordings the values are tuned on have their
    // magnetometer ~10 ms further behind their gyro: 8 ms serves both.
    0.008f,                         // mag_latency_s
    // Rest: a hand-held board's tremor stays below 2 deg/s and 0.5 m/s^2 (VQF's
    // thresholds); 1.5 s of it is rest.
    2.0f * linalg::kRadPerDeg,      // rest_gyro_deviation_rad_s
    0.5f,                           // rest_accel_deviation_m_s2
    1.5f,                           // rest_min_s
    1.0f,                           // rest_bias_s
    // The MPU6000's 42 Hz DLPF delays the gyro by 4.8 ms (Register Map 4.3), of which the
    // step's end-point integration takes back 2.5 ms: the output leads by 3 ms.
    0.003f,                         // output_lead_s
    // With the GPS's acceleration taken off, no linear acceleration is left for the
    // low-pass to average out: only the GPS's velocity noise, differentiated (0.1 m/s at
    // 5 Hz), which reaches the attitude through the low-pass and kp's loop as about
    // 0.1 deg RMS at 1 s (0.05 at 3 s, 0.2 at 0.5 s). The loop's damping is
    // 1 / (2 sqrt(kp tau)): 0.29 at 3 s rings; 0.5 at 1 s.
    1.0f,                           // gps_lowpass_s
};

using linalg::kGravity_m_s2;
// Beyond any MEMS gyro's range (the MPU6000 stops at 2000 deg/s = 35 rad/s): such a
// sample is garbage, not a rotation, and is not integrated.
constexpr float kMaxCredibleRate_rad_s = 50.0f;

}  // namespace dcm
