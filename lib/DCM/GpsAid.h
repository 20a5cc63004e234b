// SPDX-License-Identifier: GPL-3.0-or-later
// The GPS-aided gravity reference (ArduPilot's AP_AHRS_DCM::drift_correction on the APM 2,
// after Premerlani & Bizard's "Direction Cosine Matrix IMU: Theory" eq. 26 with the GPS
// velocity for v). The accelerometer reads the specific force f = a - g; in earth axes,
// summed over an interval, it is the velocity change less gravity's:
//   sum(R f) dt = dv - g dt     so     mean(R f) - dv/dt = -g (0, 0, 1)
// with dv from two GPS velocities. What is left of the estimated earth-frame mean after
// the GPS's acceleration is taken off is gravity alone, whatever the aeroplane does: a
// turn's centripetal acceleration, a climb's speed change, a gust's push are all in dv.
// That difference is the gravity correction's input (Gravity.h: its earth-frame low-pass,
// then the roll/pitch error of eq. 27) in place of the accelerometer's window alone.
//
// Timing: a u-blox reports the velocity of a measurement kGpsFixLatency_s before the fix
// is complete on the board: the receiver's own latency (ArduPilot assumed 0.2 s for the
// u-blox on the APM 2) and the epoch's messages on the line. The accelerometer's sums are
// taken between the fixes' arrivals (a sum a fix interval); the GPS's velocity change
// covers the interval that ended kGpsFixLatency_s before this arrival, s = latency /
// interval sums back: at 5 Hz 1.2 (ArduPilot's _ra_delay_buffer takes the sum one fix
// late, 1), at 1 Hz (NMEA) 0.24. Its mean is interpolated between the two sums it spans,
// (1 - f) M_j + f M_(j+1) with j, f the whole and fractional parts of s: exact for an
// acceleration that changes linearly (a turn's entry), where the nearest sum alone would
// read the ramp over the 43 ms as a tilt (a roll into 30 deg of bank in 1.5 s: 0.2 m/s^2,
// 1.2 deg).
//
// Formats: the windows' earth-frame means in accel units (counts * 2^8, Coefficients.h),
// clipped and summed over at most kGpsMaxWindows (within 31 bits); the velocity and the
// observation's arithmetic in float (5 Hz).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace dcm {

// From a u-blox's measurement to its fix complete on the board: the receiver's latency
// (ArduPilot's assumption on the APM 2, 0.2 s) and the epoch's messages the firmware asks
// for (NAV-POSLLH, -STATUS, -SOL, -VELNED: 164 bytes with their frames) at 38400 baud,
// 0.043 s. (A 1 Hz NMEA module's sentences at 9600 baud take longer: not modelled.)
constexpr float kGpsReceiverLag_s = 0.2f;
constexpr float kGpsFixLatency_s = kGpsReceiverLag_s + 0.043f;
// Fixes further apart than this are no derivative: a lost fix (1 Hz NMEA is 1 s apart).
constexpr float kGpsMaxInterval_s = 1.5f;
// A course stands for at most this many steps (kGpsMaxInterval_s at 200 Hz).
constexpr uint16_t kGpsMaxCourseSteps = 300;
// The windows (50 Hz) a sum holds at most: kGpsMaxInterval_s and a late arrival (at 16 g
// full scale a window's mean is 2^23 accel units at most: 80 of them within 2^31).
constexpr uint8_t kGpsMaxWindows = 80;
// A window's earth-frame mean is clipped to this (32 g): a body-axis 16 g on every axis is
// sqrt(3) 2^23 in earth axes, and a sample no accelerometer gives must not wrap the sums.
constexpr int32_t kGpsWindowLimit = (int32_t)1 << 24;
// Without a usable fix for this many windows (1 s: five 5 Hz fixes, a 1 Hz fix late by
// its serial transfer), the window's own low-pass (and the turn's term) takes over again.
constexpr uint8_t kGpsTimeoutWindows = 75;

class GpsAccel {
public:
    // One gravity window's earth-frame mean specific force (accel units).
    void add_window(const linalg::Vector3l& accel_ef) {
        if (since_fix_ < 255u) ++since_fix_;
        if (windows_[0] >= kGpsMaxWindows) return;  // too long for a derivative: the pair is refused
        sums_[0] += linalg::Vector3l(clip(accel_ef.x), clip(accel_ef.y), clip(accel_ef.z));
        ++windows_[0];
    }
    // A usable fix's velocity (m/s, the estimator's earth axes: north the magnetic one) and
    // the time since the fix before (s, from the receiver's time of week; 0: none). True
    // when it completes a pair: `observation` is then the earth-frame mean specific force
    // less gain times the GPS's acceleration (accel units; accel_units_per_m_s2 their
    // scale), gravity's reading: (0, 0, -g) when the attitude is right.
    bool on_velocity(const linalg::Vector3f& vel_m_s, float interval_s, float gain, float accel_units_per_m_s2,
                     linalg::Vector3l& observation);
    // No usable fix (none, 2D, too few satellites, the estimator restarting): no pair
    // across it, and the window's own low-pass at once.
    void stop() {
        fixes_ = 0;
        aiding_ = false;
    }
    // A usable fix came within kGpsTimeoutWindows: the sums will be paired (the turn's term
    // a window had taken off goes back into them: Dcm::correct_gravity).
    bool receiving() const { return since_fix_ <= kGpsTimeoutWindows; }
    // The GPS's observations feed the low-pass (the last within kGpsTimeoutWindows).
    bool aiding() const { return aiding_ && since_fix_ <= kGpsTimeoutWindows; }

private:
    static int32_t clip(int32_t v) { return v > kGpsWindowLimit ? kGpsWindowLimit : v < -kGpsWindowLimit ? -kGpsWindowLimit : v; }
    // The sums of the windows between arrivals: [0] since the last fix, [1] and [2] the
    // two intervals before it (accel units), and their windows.
    linalg::Vector3l sums_[3];
    uint8_t windows_[3] = {0, 0, 0};
    linalg::Vector3f prev_vel_m_s_;
    uint8_t since_fix_ = 255;    // windows since the last usable fix (saturated)
    uint8_t fixes_ = 0;          // usable fixes in a row (up to 3: a velocity and the sums before it)
    bool aiding_ = false;
};

}  // namespace dcm
