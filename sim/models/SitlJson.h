// SPDX-License-Identifier: GPL-3.0-or-later
// ArduPilot's SITL "JSON" physics interface (ArduPilot libraries/SITL/examples/JSON/
// readme.md), the side ArduPilot plays: the binary servo packet it sends each physics
// frame and the JSON state the backend answers with, turned into a trajectory sample for
// the sensor models. Host-only, no sockets, no simavr (unit-tested).
//
// Servo packet, little-endian, 40 bytes: uint16 magic = 18458, uint16 frame_rate (Hz),
// uint32 frame_count, uint16 pwm[16] (us).
// State: one JSON object per datagram (a line; "\n" before and after), fields
//   timestamp (s, physics time), imu.gyro [p, q, r] (rad/s, body), imu.accel_body
//   [x, y, z] (m/s^2, body, specific force: level at rest reads z = -9.81), position
//   [n, e, d] (m), velocity [n, e, d] (m/s), and quaternion [q1..q4] (w, x, y, z: body to
//   NED) or attitude [roll, pitch, yaw] (rad; the quaternion wins when both come);
//   optional rc {rc_1 .. rc_N} (us), airspeed (m/s), velocity_wind [n, e, d] (m/s).
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "RcLink.h"
#include "Trajectory.h"

namespace sim {

constexpr uint16_t kSitlServoMagic = 18458;
constexpr size_t kSitlServoPacketSize = 40;
constexpr int kSitlServoChannels = 16;

// The 40 bytes of one servo packet.
std::string encode_servo_packet(uint16_t frame_rate_hz, uint32_t frame_count, const uint16_t pwm_us[kSitlServoChannels]);

struct PhysicsState {
    double timestamp_s = 0.0;
    double gyro_rad_s[3] = {};
    double accel_body_m_s2[3] = {};
    double position_m[3] = {};
    double velocity_m_s[3] = {};
    double quat[4] = {1, 0, 0, 0};  // w, x, y, z (from `quaternion`, or built from `attitude`)
    // `rc`: has_rc when the object came; rc_channels how many of rc_1..rc_8 it held.
    bool has_rc = false;
    int rc_channels = 0;
    double rc_us[kRcChannels] = {};
    bool has_airspeed = false;
    double airspeed_m_s = 0.0;
    bool has_wind = false;
    double velocity_wind_m_s[3] = {};
};

// Parses the last JSON object in `datagram`. False with `error` naming the field that is
// missing or malformed (a mandatory one, or an optional one present but wrong).
bool parse_physics_state(const std::string& datagram, PhysicsState& state, std::string& error);

// Which replies answer the frame waited for. Lock-step: frame N is sent only after a reply
// to N - 1 was taken, so a reply whose timestamp is not after the last one taken answers
// an earlier send: a frame sent again after a time-out and then answered twice (the
// backend's late first answer and its answer to the resend), or a backend that answers
// each packet twice. Such a reply is stale: dropped, counted, never taken as the next
// frame's state. A backend whose time went back answers every send with stale replies and
// never with a new one: the link's time-out reports it (PhysicsLink).
class ReplyClock {
public:
    // True when `timestamp_s` is after the last one taken (or is the first): it becomes
    // the last. False for a stale reply, counted.
    bool take(double timestamp_s);
    bool started() const { return started_; }
    double last_s() const { return last_s_; }
    uint32_t taken() const { return taken_; }
    uint32_t stale() const { return stale_; }

private:
    bool started_ = false;
    double last_s_ = 0.0;
    uint32_t taken_ = 0;
    uint32_t stale_ = 0;
};

// The sensor models' sample at simulated time t_s: the backend's body rates and specific
// force, its attitude, the earth field (NED, uT) seen in the body frame, and its position
// and velocity (NED from the origin, for the GPS and the barometer).
TrajectorySample physics_sample(const PhysicsState& state, double t_s, const double earth_field_ned_uT[3]);

// The receiver row the backend's `rc` asks for at t_s: all of rc_1..rc_8 (further
// channels ignored) is a live receiver; an `rc` holding none of them, or only zeros, is a
// dead one (this project's reading: ArduPilot's readme has no word for a lost receiver).
// False with `error` when only some channels come or a width is out of RcScript's range.
bool physics_rc_row(const PhysicsState& state, double t_s, RcRow& row, std::string& error);

}  // namespace sim
