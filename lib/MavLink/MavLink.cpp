// SPDX-License-Identifier: GPL-3.0-or-later
#include "MavLink.h"

#include <string.h>

// The generated headers (build/mavlink): one channel, no signing (the SHA-256 code and
// the per-channel tables stay out of the AVR image). The generated C is not the
// project's: its warnings (-Wconversion, -Wdouble-promotion, -Wcast-align) are not ours
// to fix, so they are silenced for these includes only.
#define MAVLINK_COMM_NUM_BUFFERS 1
#define MAVLINK_NO_SIGN_PACKET
#define MAVLINK_NO_SIGNATURE_CHECK
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpragmas"  // avr-gcc 5.4 does not know every name below
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wfloat-conversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Waddress-of-packed-member"
// mavlink_types.h first: the Arduino IDE finds a library by a header at its top level,
// so with build/mavlink installed as a library (README) this include makes the IDE add
// it to the include path; common/mavlink.h, one folder down, then resolves.
#include "mavlink_types.h"
#include "common/mavlink.h"
#pragma GCC diagnostic pop

namespace mav {

static_assert(MAVLINK_NUM_NON_PAYLOAD_BYTES == kFrameOverhead, "MAVLink 2 frame overhead");
static_assert(kMaxFrame == kFrameOverhead + MAVLINK_MSG_ID_STATUSTEXT_LEN, "longest frame: STATUSTEXT");
static_assert(kHeartbeatFrame == kFrameOverhead + MAVLINK_MSG_ID_HEARTBEAT_LEN, "HEARTBEAT size");
static_assert(kAttitudeFrame == kFrameOverhead + MAVLINK_MSG_ID_ATTITUDE_LEN, "ATTITUDE size");
static_assert(kMaxFrame >= kFrameOverhead + MAVLINK_MSG_ID_SYS_STATUS_LEN, "SYS_STATUS fits");
static_assert(kTextChunk == MAVLINK_MSG_STATUSTEXT_FIELD_TEXT_LEN, "STATUSTEXT text length");
static_assert((uint8_t)State::Calibrating == MAV_STATE_CALIBRATING && (uint8_t)State::Active == MAV_STATE_ACTIVE &&
                  (uint8_t)State::Critical == MAV_STATE_CRITICAL && (uint8_t)State::Boot == MAV_STATE_BOOT,
              "State values are MAV_STATE's");
static_assert((uint8_t)Severity::Error == MAV_SEVERITY_ERROR && (uint8_t)Severity::Warning == MAV_SEVERITY_WARNING &&
                  (uint8_t)Severity::Notice == MAV_SEVERITY_NOTICE && (uint8_t)Severity::Info == MAV_SEVERITY_INFO,
              "Severity values are MAV_SEVERITY's");
static_assert(kGyro3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_GYRO && kAccel3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_ACCEL &&
                  kMag3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_MAG,
              "SensorBits are MAV_SYS_STATUS_SENSOR's");
static_assert(kComponentId == (uint8_t)MAV_COMP_ID_AUTOPILOT1, "QGroundControl makes vehicles of AUTOPILOT1 only");

namespace {

// The generated pack functions write a mavlink_message_t (291 bytes, on the stack only
// for the call) and count the sequence in a mavlink_status_t; the Packer keeps just
// the sequence byte between calls.
struct Frame {
    mavlink_message_t msg;
    mavlink_status_t status;
    explicit Frame(uint8_t seq) {
        memset(&status, 0, sizeof status);
        status.current_tx_seq = seq;
    }
    uint8_t finish(uint8_t out[kMaxFrame], uint8_t& seq) {
        seq = status.current_tx_seq;
        return (uint8_t)mavlink_msg_to_send_buffer(out, &msg);
    }
};

// Degrees to radians; a heading 0..360 becomes -pi..pi (ATTITUDE's yaw range).
float yaw_rad(float heading_deg) {
    const float h = heading_deg > 180.0f ? heading_deg - 360.0f : heading_deg;
    return h * linalg::kRadPerDeg;
}

}  // namespace

Health health(bool mpu_present, bool mpu_ok, bool mag_present, bool mag_ok) {
    const uint32_t mpu = kGyro3d | kAccel3d;
    Health h{0u, 0u};
    if (mpu_present) h.present |= mpu;
    if (mpu_present && mpu_ok) h.healthy |= mpu;
    if (mag_present) h.present |= kMag3d;
    if (mag_present && mag_ok) h.healthy |= kMag3d;
    return h;
}

uint8_t Packer::heartbeat(uint8_t out[kMaxFrame], State state) {
    Frame f(seq_);
    mavlink_msg_heartbeat_pack_status(kSystemId, kComponentId, &f.status, &f.msg, MAV_TYPE_GENERIC,
                                      MAV_AUTOPILOT_GENERIC, 0u, 0u, (uint8_t)state);
    return f.finish(out, seq_);
}

uint8_t Packer::attitude(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float roll_deg, float pitch_deg,
                         float heading_deg, const linalg::Vector3f& rate_rad_s) {
    Frame f(seq_);
    mavlink_msg_attitude_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_boot_ms,
                                     roll_deg * linalg::kRadPerDeg, pitch_deg * linalg::kRadPerDeg,
                                     yaw_rad(heading_deg), rate_rad_s.x, rate_rad_s.y, rate_rad_s.z);
    return f.finish(out, seq_);
}

uint8_t Packer::sys_status(uint8_t out[kMaxFrame], const Health& h, uint16_t load_permille, uint16_t errors) {
    Frame f(seq_);
    const uint16_t load = load_permille > 1000u ? 1000u : load_permille;
    // Battery: voltage UINT16_MAX, current -1, remaining -1 = "not measured" (the board has no sensor).
    mavlink_msg_sys_status_pack_status(kSystemId, kComponentId, &f.status, &f.msg, h.present, h.present,
                                       h.healthy, load, UINT16_MAX, -1, -1, 0u, 0u, errors, 0u, 0u, 0u, 0u,
                                       0u, 0u);
    return f.finish(out, seq_);
}

uint8_t Packer::statustext(uint8_t out[kMaxFrame], Severity severity, const char* text, uint8_t len,
                           uint16_t id, uint8_t chunk_seq) {
    if (len > kTextChunk) return 0;
    char field[kTextChunk];  // the generated code copies all 50: pad with NUL
    memset(field, 0, sizeof field);
    memcpy(field, text, len);
    Frame f(seq_);
    mavlink_msg_statustext_pack_status(kSystemId, kComponentId, &f.status, &f.msg, (uint8_t)severity, field, id,
                                       chunk_seq);
    return f.finish(out, seq_);
}

// ---------------------------------------------------------------------------------------

void StatusText::write(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) put(data[i]);
}

void StatusText::put(char c) {
    if (c == '\r') return;
    if (c == '\n') {
        end_line();
        return;
    }
    switch (state_) {
        case Line::Start: state_ = c == '#' ? Line::Hash : Line::Skip; return;
        case Line::Hash: state_ = c == ' ' ? Line::Body : Line::Skip; return;
        case Line::Skip: return;
        case Line::Body: break;
    }
    if (len_ == kTextChunk) {
        // A 51st character: this line takes more than one chunk.
        if (chunk_seq_ == 0) {
            if (++last_id_ == 0u) last_id_ = 1u;  // 0 means "a single chunk"
            id_ = last_id_;
        }
        flush_chunk();
    }
    chunk_[len_++] = c;
}

void StatusText::end_line() {
    if (state_ == Line::Body) {
        // A multi-chunk line that ends on a chunk boundary gets an empty last chunk.
        const bool terminator = chunk_seq_ > 0 && len_ == kTextChunk;
        flush_chunk();
        if (terminator) flush_chunk();
    }
    state_ = Line::Start;
    len_ = 0;
    chunk_seq_ = 0;
    id_ = 0;
}

namespace {
// True if the len bytes at s begin with the TXT string prefix (flash on the AVR: not
// SRAM).
bool starts_with(const char* s, uint8_t len, text::Flash prefix) {
    for (uint8_t i = 0;; ++i) {
        const char ch = (char)text::flash_byte(prefix.p + i);
        if (ch == '\0') return true;
        if (i >= len || s[i] != ch) return false;
    }
}
}  // namespace

void StatusText::flush_chunk() {
    if (chunk_seq_ == 0) {
        // The first word gives the severity ("# error: ..." and "# warn: ..." lines).
        severity_ = Severity::Info;
        if (starts_with(chunk_, len_, TXT("error:"))) severity_ = Severity::Error;
        else if (starts_with(chunk_, len_, TXT("warn:"))) severity_ = Severity::Warning;
    }
    uint8_t frame[kMaxFrame];
    const uint8_t n = packer_.statustext(frame, severity_, chunk_, len_, id_, chunk_seq_);
    if (out_.write != nullptr && n > 0) out_.write(out_.ctx, frame, n);
    ++chunk_seq_;
    len_ = 0;
}

// ---------------------------------------------------------------------------------------

bool FrameFilter::consume(uint8_t byte) {
    if (pos_ == 0) {
        if (byte != MAVLINK_STX && byte != MAVLINK_STX_MAVLINK1) return false;
        v2_ = byte == MAVLINK_STX;
        pos_ = 1;
        return true;
    }
    if (pos_ == 1) {
        // After STX and length: the rest of the header (v2: 8, v1: 4), payload, CRC.
        remaining_ = (uint16_t)((v2_ ? 8u : 4u) + byte + 2u);
        pos_ = 2;
        return true;
    }
    if (pos_ == 2) {
        if (v2_ && (byte & MAVLINK_IFLAG_SIGNED) != 0u) remaining_ = (uint16_t)(remaining_ + MAVLINK_SIGNATURE_BLOCK_LEN);
        pos_ = 3;
    }
    if (--remaining_ == 0u) {
        pos_ = 0;
        ++frames_;
    }
    return true;
}

}  // namespace mav
