// SPDX-License-Identifier: GPL-3.0-or-later
// MAVLink 2 for ground stations (Mission Planner, QGroundControl): the four messages an
// attitude-only board sends, packed into the caller's byte buffer, and the separation
// of incoming MAVLink frames from console text on the same UART.
//
//   HEARTBEAT    1 Hz      21 bytes   type MAV_TYPE_GENERIC, autopilot MAV_AUTOPILOT_GENERIC
//   ATTITUDE     per line  40 bytes   roll, pitch, yaw (rad, yaw with declination), body rates
//   SYS_STATUS   1 Hz      ~43 bytes  gyro/accel/compass present+enabled+healthy bits, load
//   STATUSTEXT   per "# "  15..66     every "# " console line, severity from its first word
//
// The packing is pymavlink's generated C code (build/mavlink, made by `make mavlink` from
// the common.xml that PyPI's pymavlink ships; nothing generated is committed), so field
// order, CRC_EXTRA and MAVLink 2 zero-trimming are the protocol's own. No signing.
// Sizes are frame bytes: 10 header + payload (trailing zeros trimmed) + 2 CRC.
//
// Why these HEARTBEAT values: QGroundControl creates a vehicle for a heartbeat from
// component MAV_COMP_ID_AUTOPILOT1 (1) unless its type is GCS, ONBOARD_CONTROLLER, GIMBAL
// or ADSB (MultiVehicleManager), and MAVLink tools (pymavlink's mavutil, MAVProxy) take
// autopilot MAV_AUTOPILOT_INVALID to mean "not a flight controller"; so: system 1,
// component 1, MAV_TYPE_GENERIC (the board flies nothing; claiming FIXED_WING would make
// a GCS show plane set-up pages) and MAV_AUTOPILOT_GENERIC (not ArduPilot or PX4: a GCS
// must not try those stacks' parameters and modes). base_mode 0 (never armed).
//
// Plain C++: no Arduino include, the same code on the AVR and the host tests.
#pragma once

#include <stdint.h>

#include "LinAlg.h"
#include "Text.h"

namespace mav {

constexpr uint8_t kSystemId = 1;
constexpr uint8_t kComponentId = 1;     // MAV_COMP_ID_AUTOPILOT1
constexpr uint8_t kFrameOverhead = 12;  // MAVLink 2 header (10) + CRC (2), unsigned
constexpr uint8_t kTextChunk = 50;      // STATUSTEXT text field, characters
// The longest frame sent: STATUSTEXT with 50 characters (payload 54 = severity, text,
// id, chunk_seq).
constexpr uint8_t kMaxFrame = kFrameOverhead + 54;

constexpr uint8_t kHeartbeatFrame = kFrameOverhead + 9;  // never trimmed: mavlink_version = 3 last
constexpr uint8_t kAttitudeFrame = kFrameOverhead + 28;  // trimmed only if yawspeed is exactly 0

// HEARTBEAT system_status (MAV_STATE).
enum class State : uint8_t {
    Boot = 1,         // before the first attitude
    Calibrating = 2,  // gyro bias or compass calibration running
    Active = 4,       // estimating
    Critical = 5,     // a sensor is missing or has failed
};

// STATUSTEXT severity (MAV_SEVERITY).
enum class Severity : uint8_t { Error = 3, Warning = 4, Notice = 5, Info = 6 };

// SYS_STATUS sensor bits (MAV_SYS_STATUS_SENSOR_3D_GYRO, _3D_ACCEL, _3D_MAG).
constexpr uint32_t kGyro3d = 1u;
constexpr uint32_t kAccel3d = 2u;
constexpr uint32_t kMag3d = 4u;

struct Health {
    uint32_t present;  // sensor bits found at start-up (also reported as enabled)
    uint32_t healthy;  // sensor bits answering with plausible data now
};
// The MPU6000 is both the 3D gyro and the 3D accelerometer.
Health health(bool mpu_present, bool mpu_ok, bool mag_present, bool mag_ok);

// Packs messages; one sequence counter across all of them (a GCS counts gaps as loss).
// Each call writes one frame into `out` and returns its length (0 only on bad input).
class Packer {
public:
    uint8_t heartbeat(uint8_t out[kMaxFrame], State state);
    // The pipeline's angles in degrees (heading 0..360, declination applied) are sent
    // in radians, heading wrapped to -pi..pi as ATTITUDE's yaw; rates in rad/s, body axes.
    uint8_t attitude(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float roll_deg, float pitch_deg,
                     float heading_deg, const linalg::Vector3f& rate_rad_s);
    // load_permille: loop CPU load, 0..1000; errors: autopilot-specific count 1 (the
    // firmware's loop overruns, saturated). Battery fields say "not measured".
    uint8_t sys_status(uint8_t out[kMaxFrame], const Health& h, uint16_t load_permille, uint16_t errors);
    // text: up to kTextChunk characters (shorter ones NUL-terminated). id 0 = a message
    // in one chunk; otherwise chunks of one message share id and count chunk_seq from 0.
    uint8_t statustext(uint8_t out[kMaxFrame], Severity severity, const char* text, uint8_t len,
                       uint16_t id, uint8_t chunk_seq);
    uint8_t next_sequence() const { return seq_; }

private:
    uint8_t seq_ = 0;
};

// Where frames go (the firmware: its UART; tests: a buffer).
struct FrameSink {
    void* ctx;
    void (*write)(void* ctx, const uint8_t* frame, uint8_t len);
};

// The console's text output in `mode mavlink`: a text::Sink whose "# " lines become
// STATUSTEXT frames, "# " stripped; severity Error for "# error: ...", Warning for
// "# warn: ...", Info for every other "# " line. Lines that do not start with "# "
// (angle or csv lines) are dropped: ATTITUDE carries the angles. A line longer than
// kTextChunk goes out as chunks with one non-zero id, an empty last chunk when it ends
// on a chunk boundary (a receiver takes a chunk with a NUL as the last). Streaming: no
// line buffer beyond one chunk.
class StatusText {
public:
    StatusText(Packer& packer, FrameSink out) : packer_(packer), out_(out) {}
    void write(const char* data, uint8_t len);
    // For text::Sink{&status_text, &StatusText::write_text}.
    static void write_text(void* ctx, const char* data, uint8_t len) {
        static_cast<StatusText*>(ctx)->write(data, len);
    }
    text::Sink sink() { return text::Sink{this, &StatusText::write_text}; }

private:
    enum class Line : uint8_t { Start, Hash, Body, Skip };
    void put(char c);
    void end_line();
    void flush_chunk();

    Packer& packer_;
    FrameSink out_;
    char chunk_[kTextChunk] = {};
    uint8_t len_ = 0;         // characters in chunk_
    uint8_t chunk_seq_ = 0;   // chunks of this line already sent
    uint16_t id_ = 0;         // this line's id when it needs more than one chunk
    uint16_t last_id_ = 0;    // the last id given out
    Severity severity_ = Severity::Info;
    Line state_ = Line::Start;
};

// Splits received bytes into MAVLink frames (from a GCS: its HEARTBEAT, PARAM_REQUEST_LIST
// ...) and console text. A MAVLink frame starts with 0xFD (v2) or 0xFE (v1), bytes that
// never occur in console text (printable ASCII); its length byte gives the frame size,
// so a frame never reaches the console's line reader (where it would be "non-text bytes").
class FrameFilter {
public:
    // True when `byte` belongs to a MAVLink frame (do not give it to the console).
    bool consume(uint8_t byte);
    uint16_t frames() const { return frames_; }  // complete frames seen (not CRC-checked)

private:
    uint16_t remaining_ = 0;  // bytes of the current frame still to come
    uint8_t pos_ = 0;         // bytes of the current frame seen
    bool v2_ = false;
    uint16_t frames_ = 0;
};

}  // namespace mav
