// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MavLink: the frames checked byte by byte against the MAVLink 2 wire format, with a
// CRC computed here independently of the generated code (CRC-16/MCRF4XX over header and
// payload, then the message's CRC_EXTRA). pymavlink decodes the same frames in
// test/mavlink/decode_frames.py.
#include <gtest/gtest.h>

#include <stdint.h>
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <algorithm>
#include <string>
#include <vector>

#include "MavLink.h"
#include "MissionProtocol.h"
#include "ParamLink.h"
#include "Params.h"
#include "Settings.h"

namespace {

using Bytes = std::vector<uint8_t>;

// CRC-16/MCRF4XX (X.25 as MAVLink uses it: poly 0x1021 reflected, init 0xFFFF, no final xor).
uint16_t x25(const uint8_t* p, size_t n, uint16_t crc = 0xFFFFu) {
    for (size_t i = 0; i < n; ++i) {
        uint8_t t = (uint8_t)(p[i] ^ (uint8_t)(crc & 0xFFu));
        t = (uint8_t)(t ^ (uint8_t)(t << 4));
        crc = (uint16_t)((crc >> 8) ^ ((uint16_t)t << 8) ^ ((uint16_t)t << 3) ^ ((uint16_t)t >> 4));
    }
    return crc;
}

// The CRC_EXTRA seeds of common.xml (the MAVLink message set's published values).
constexpr uint8_t kExtraHeartbeat = 50, kExtraAttitude = 39, kExtraSysStatus = 124, kExtraStatustext = 83;
constexpr uint8_t kExtraParamValue = 220, kExtraParamSet = 168, kExtraParamRequestRead = 214,
                  kExtraParamRequestList = 159, kExtraCommandLong = 152, kExtraCommandAck = 143,
                  kExtraRcChannels = 118, kExtraServoOutputRaw = 222;

struct Frame {
    uint8_t len, seq, sysid, compid;
    uint32_t msgid;
    Bytes payload;  // as sent (trimmed)
    bool crc_ok;
};

Frame parse(const uint8_t* f, uint8_t n, uint8_t crc_extra) {
    Frame r{};
    EXPECT_GE(n, 12u);
    EXPECT_EQ(f[0], 0xFDu) << "MAVLink 2 magic";
    r.len = f[1];
    EXPECT_EQ((unsigned)n, 12u + r.len) << "frame = 10 header + payload + 2 CRC";
    EXPECT_EQ(f[2], 0u) << "incompat flags: unsigned";
    EXPECT_EQ(f[3], 0u) << "compat flags";
    r.seq = f[4];
    r.sysid = f[5];
    r.compid = f[6];
    r.msgid = (uint32_t)f[7] | (uint32_t)f[8] << 8 | (uint32_t)f[9] << 16;
    r.payload.assign(f + 10, f + 10 + r.len);
    uint16_t crc = x25(f + 1, 9u + r.len);
    crc = x25(&crc_extra, 1, crc);
    r.crc_ok = f[10 + r.len] == (crc & 0xFFu) && f[11 + r.len] == (crc >> 8);
    return r;
}

// Little-endian fields of a payload, zero where MAVLink 2 trimmed it.
uint8_t u8(const Bytes& p, size_t off) { return off < p.size() ? p[off] : 0u; }
uint16_t u16(const Bytes& p, size_t off) { return (uint16_t)(u8(p, off) | u8(p, off + 1) << 8); }
uint32_t u32(const Bytes& p, size_t off) { return (uint32_t)u16(p, off) | (uint32_t)u16(p, off + 2) << 16; }
float f32(const Bytes& p, size_t off) {
    const uint32_t b = u32(p, off);
    float f;
    memcpy(&f, &b, sizeof f);
    return f;
}

TEST(MavLink, HeartbeatIsAnArduPlaneOfComponentOneWithItsModeNumber) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Manual, true);
    ASSERT_EQ(n, mav::kHeartbeatFrame);
    ASSERT_EQ(n, 21u);
    const Frame f = parse(buf, n, kExtraHeartbeat);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 0u);
    EXPECT_EQ(f.sysid, 1u);
    EXPECT_EQ(f.compid, 1u);  // MAV_COMP_ID_AUTOPILOT1
    EXPECT_EQ(f.seq, 0u);
    // Wire order: custom_mode (u32), type, autopilot, base_mode, system_status, mavlink_version.
    EXPECT_EQ(u32(f.payload, 0), 0u);  // ArduPlane MANUAL
    EXPECT_EQ(u8(f.payload, 4), 1u);   // MAV_TYPE_FIXED_WING
    EXPECT_EQ(u8(f.payload, 5), 3u);   // MAV_AUTOPILOT_ARDUPILOTMEGA
    // CUSTOM_MODE_ENABLED 1 | MANUAL_INPUT_ENABLED 64 | SAFETY_ARMED 128
    EXPECT_EQ(u8(f.payload, 6), 1u + 64u + 128u);
    EXPECT_EQ(u8(f.payload, 7), 4u);  // MAV_STATE_ACTIVE
    EXPECT_EQ(u8(f.payload, 8), 3u);  // mavlink_version

    const Frame s = parse(buf, p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Stabilize, true), kExtraHeartbeat);
    EXPECT_EQ(u32(s.payload, 0), 2u);                   // ArduPlane STABILIZE
    EXPECT_EQ(u8(s.payload, 6), 1u + 16u + 64u + 128u);  // ... STABILIZE_ENABLED 16
    const Frame fs = parse(buf, p.heartbeat(buf, mav::State::Critical, mav::PlaneMode::FlyByWireA, true), kExtraHeartbeat);
    EXPECT_EQ(u32(fs.payload, 0), 5u);  // ArduPlane FLY_BY_WIRE_A: the failsafe glide
    EXPECT_EQ(u8(fs.payload, 7), 5u);   // MAV_STATE_CRITICAL
    // Disarmed: SAFETY_ARMED clear, the rest as armed.
    const Frame d = parse(buf, p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Stabilize, false), kExtraHeartbeat);
    EXPECT_EQ(u8(d.payload, 6), 1u + 16u + 64u);
}

TEST(MavLink, SequenceCountsAcrossMessagesAndWraps) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    for (int i = 0; i < 300; ++i) {
        const uint8_t n = (i % 2 == 0) ? p.heartbeat(buf, mav::State::Boot, mav::PlaneMode::Manual, false)
                                       : p.attitude(buf, 0u, 1.0f, 2.0f, 3.0f, linalg::Vector3f(0.1f, 0.2f, 0.3f));
        ASSERT_GT(n, 0u);
        EXPECT_EQ(buf[4], (uint8_t)(i & 0xFF));
    }
    EXPECT_EQ(p.next_sequence(), (uint8_t)(300 & 0xFF));
}

TEST(MavLink, AttitudeInRadiansWithHeadingAsSignedYaw) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.attitude(buf, 123456u, -30.0f, 45.0f, 270.0f, linalg::Vector3f(0.5f, -0.25f, 1.5f));
    ASSERT_EQ(n, mav::kAttitudeFrame);
    ASSERT_EQ(n, 40u);
    const Frame f = parse(buf, n, kExtraAttitude);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 30u);
    EXPECT_EQ(u32(f.payload, 0), 123456u);
    EXPECT_NEAR(f32(f.payload, 4), -0.5235988f, 1e-6f);
    EXPECT_NEAR(f32(f.payload, 8), 0.7853982f, 1e-6f);
    EXPECT_NEAR(f32(f.payload, 12), -1.5707963f, 1e-6f);  // heading 270 = yaw -90 deg
    EXPECT_FLOAT_EQ(f32(f.payload, 16), 0.5f);
    EXPECT_FLOAT_EQ(f32(f.payload, 20), -0.25f);
    EXPECT_FLOAT_EQ(f32(f.payload, 24), 1.5f);
}

TEST(MavLink, AttitudeYawStaysWithinPlusMinusPi) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    for (float h = 0.0f; h < 360.0f; h += 7.5f) {
        const uint8_t n = p.attitude(buf, 1u, 0.0f, 0.0f, h, linalg::Vector3f(1.0f, 1.0f, 1.0f));
        const Frame f = parse(buf, n, kExtraAttitude);
        const float yaw = f32(f.payload, 12);
        EXPECT_LE(yaw, 3.1415927f) << h;
        EXPECT_GT(yaw, -3.1415927f) << h;
        const float back = yaw < 0.0f ? yaw * 57.29578f + 360.0f : yaw * 57.29578f;
        EXPECT_NEAR(back, h, 1e-3f);
    }
}

TEST(MavLink, AttitudeWithZeroYawRateIsTrimmedAsMavlink2Requires) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.attitude(buf, 1u, 10.0f, 0.0f, 0.0f, linalg::Vector3f(0.1f, 0.2f, 0.0f));
    const Frame f = parse(buf, n, kExtraAttitude);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.len, 24u);  // the four zero bytes of yawspeed are not sent
    EXPECT_FLOAT_EQ(f32(f.payload, 20), 0.2f);
}

TEST(MavLink, SysStatusReportsSensorBitsLoadAndNoBattery) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    // The compass present but failing: its health bit is clear.
    const mav::Health h = mav::health(true, true, true, false);
    EXPECT_EQ(h.present, 7u);
    EXPECT_EQ(h.healthy, 3u);
    const uint8_t n = p.sys_status(buf, h, 593u, 12u);
    const Frame f = parse(buf, n, kExtraSysStatus);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 1u);
    EXPECT_EQ(f.len, 31u);  // the MAVLink 2 extension fields are zero and trimmed
    EXPECT_EQ(n, 43u);
    EXPECT_EQ(u32(f.payload, 0), 7u);    // present: gyro, accel, mag
    EXPECT_EQ(u32(f.payload, 4), 7u);    // enabled
    EXPECT_EQ(u32(f.payload, 8), 3u);    // healthy: gyro, accel
    EXPECT_EQ(u16(f.payload, 12), 593u);  // load, per mille
    EXPECT_EQ(u16(f.payload, 14), 0xFFFFu);  // voltage: not measured
    EXPECT_EQ(u16(f.payload, 16), 0xFFFFu);  // current -1: not measured
    EXPECT_EQ(u16(f.payload, 22), 12u);      // errors_count1: overruns
    EXPECT_EQ(u8(f.payload, 30), 0xFFu);     // battery_remaining -1
}

TEST(MavLink, SysStatusHasArduPlanesControllerBitsAndTheFenceHealthy) {
    mav::Health h = mav::health(true, true, true, true);
    mav::add_plane_status(h, mav::PlaneStatus{true, false, true, true});  // MANUAL, receiver good
    const uint32_t control = mav::kAngularRateControl | mav::kAttitudeStabilization;
    EXPECT_EQ(h.present, 7u | control | mav::kYawPosition | mav::kMotorOutputs | mav::kRcReceiver | mav::kAhrs);
    EXPECT_EQ(h.enabled, 7u | mav::kMotorOutputs | mav::kRcReceiver | mav::kAhrs) << "MANUAL: no controller";
    EXPECT_EQ(h.healthy, h.present | mav::kGeofence) << "MAVProxy: no fence bit in health is a breach";
    mav::Health s = mav::health(true, true, true, true);
    mav::add_plane_status(s, mav::PlaneStatus{true, true, false, false});  // STABILIZE, no receiver, no AHRS
    EXPECT_EQ(s.enabled & control, control);
    EXPECT_EQ(s.healthy & (mav::kRcReceiver | mav::kAhrs), 0u);
    EXPECT_EQ(s.healthy & mav::kGeofence, mav::kGeofence);
    mav::Health a = mav::health(true, true, true, true);
    mav::add_plane_status(a, mav::PlaneStatus{false, false, false, true});  // the attitude-only build
    EXPECT_EQ(a.present, 7u | mav::kAhrs);
    EXPECT_EQ(a.healthy, 7u | mav::kAhrs | mav::kGeofence);
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const Frame f = parse(buf, p.sys_status(buf, h, 100u, 0u), kExtraSysStatus);
    EXPECT_EQ(u32(f.payload, 0), h.present);
    EXPECT_EQ(u32(f.payload, 4), h.enabled);
    EXPECT_EQ(u32(f.payload, 8), h.healthy);
}

TEST(MavLink, SysStatusWithoutTheMpuHasOnlyTheCompass) {
    const mav::Health h = mav::health(false, false, true, true);
    EXPECT_EQ(h.present, mav::kMag3d);
    EXPECT_EQ(h.healthy, mav::kMag3d);
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const Frame f = parse(buf, p.sys_status(buf, h, 5000u, 0u), kExtraSysStatus);
    EXPECT_EQ(u16(f.payload, 12), 1000u) << "load is clamped to 100.0 %";
}

// StatusText with a sink that collects frames.
struct Collected {
    std::vector<Bytes> frames;
    static void write(void* ctx, const uint8_t* data, uint8_t len) {
        static_cast<Collected*>(ctx)->frames.emplace_back(data, data + len);
    }
};

struct Text {
    uint8_t severity;
    std::string text;
    uint16_t id;
    uint8_t chunk_seq;
};

Text decode_text(const Bytes& b) {
    const Frame f = parse(b.data(), (uint8_t)b.size(), kExtraStatustext);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 253u);
    Text t{u8(f.payload, 0), std::string(), u16(f.payload, 51), u8(f.payload, 53)};
    for (size_t i = 1; i <= 50 && u8(f.payload, i) != 0u; ++i) t.text += (char)u8(f.payload, i);
    return t;
}

void say(mav::StatusText& st, const std::string& s) { st.write(s.data(), (uint8_t)s.size()); }

TEST(MavLink, StatusTextSeverityFromTheLinesFirstWord) {
    mav::Packer p;
    Collected c;
    mav::StatusText st(p, mav::FrameSink{&c, &Collected::write});
    say(st, "# error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68)\n");
    say(st, "# warn: compass overflow\n");
    say(st, "# recovered: HMC5883L\n");
    say(st, "# mode mavlink\r\n");
    say(st, "# PreArm: Throttle too high\n");
    ASSERT_EQ(c.frames.size(), 6u);  // the first line is 56 characters: two chunks
    EXPECT_EQ(decode_text(c.frames[0]).severity, 3u);
    EXPECT_EQ(decode_text(c.frames[1]).severity, 3u);
    const Text w = decode_text(c.frames[2]);
    EXPECT_EQ(w.severity, 4u);
    EXPECT_EQ(w.text, "warn: compass overflow");
    EXPECT_EQ(w.id, 0u);
    EXPECT_EQ(c.frames[2].size(), 12u + 1u + 22u) << "trailing NULs trimmed";
    EXPECT_EQ(decode_text(c.frames[3]).severity, 6u);
    EXPECT_EQ(decode_text(c.frames[3]).text, "recovered: HMC5883L");
    EXPECT_EQ(decode_text(c.frames[4]).text, "mode mavlink");
    EXPECT_EQ(decode_text(c.frames[5]).severity, 2u);  // MAV_SEVERITY_CRITICAL, as ArduPilot's PreArm
}

TEST(MavLink, StatusTextChunksLongLinesUnderOneId) {
    mav::Packer p;
    Collected c;
    mav::StatusText st(p, mav::FrameSink{&c, &Collected::write});
    std::string body;
    for (int i = 0; i < 120; ++i) body += (char)('a' + i % 26);
    // Written in pieces, as text::Writer does.
    say(st, "# ");
    for (size_t i = 0; i < body.size(); i += 7) say(st, body.substr(i, 7));
    say(st, "\n");
    ASSERT_EQ(c.frames.size(), 3u);
    const Text a = decode_text(c.frames[0]), b = decode_text(c.frames[1]), d = decode_text(c.frames[2]);
    EXPECT_NE(a.id, 0u);
    EXPECT_EQ(b.id, a.id);
    EXPECT_EQ(d.id, a.id);
    EXPECT_EQ(a.chunk_seq, 0u);
    EXPECT_EQ(b.chunk_seq, 1u);
    EXPECT_EQ(d.chunk_seq, 2u);
    EXPECT_EQ(a.text + b.text + d.text, body);
    EXPECT_EQ(a.severity, 6u);
    EXPECT_EQ(d.severity, 6u);

    // The next long line gets another id; a line of exactly 50 is one chunk with id 0.
    say(st, "# " + body.substr(0, 50) + "\n");
    ASSERT_EQ(c.frames.size(), 4u);
    EXPECT_EQ(decode_text(c.frames[3]).id, 0u);
    EXPECT_EQ(decode_text(c.frames[3]).text, body.substr(0, 50));
    say(st, "# warn: " + body.substr(0, 94) + "\n");  // "warn: " + 94 = 100 characters: two full chunks + an empty one
    ASSERT_EQ(c.frames.size(), 7u);
    const Text e = decode_text(c.frames[4]), g = decode_text(c.frames[6]);
    EXPECT_NE(e.id, 0u);
    EXPECT_NE(e.id, a.id);
    EXPECT_EQ(e.severity, 4u);
    EXPECT_EQ(decode_text(c.frames[5]).severity, 4u);
    EXPECT_EQ(g.text, "");
    EXPECT_EQ(g.chunk_seq, 2u);
    EXPECT_EQ(g.id, e.id);
}

TEST(MavLink, StatusTextDropsLinesThatAreNotHashLines) {
    mav::Packer p;
    Collected c;
    mav::StatusText st(p, mav::FrameSink{&c, &Collected::write});
    say(st, "roll:1.00 pitch:2.00 yaw:3.00\n");
    say(st, "t_ms,roll,pitch,yaw\n");
    say(st, "#no space\n");
    say(st, "\n");
    say(st, "# \n");  // an empty "# " line is still a message (an empty one)
    ASSERT_EQ(c.frames.size(), 1u);
    EXPECT_EQ(decode_text(c.frames[0]).text, "");
    // Sequence numbers are the packer's: shared with the other messages.
    EXPECT_EQ(p.next_sequence(), 1u);
}

TEST(MavLink, ParserKeepsMavlinkAwayFromTheConsole) {
    mav::Packer p;
    uint8_t hb[mav::kMaxFrame], st[mav::kMaxFrame];
    const uint8_t n_hb = p.heartbeat(hb, mav::State::Active, mav::PlaneMode::Manual, true);
    const uint8_t n_st = p.statustext(st, mav::Severity::Info, "status\nhelp\r", 12, 0u, 0u);
    Bytes in;
    const std::string typed = "status\n";
    in.insert(in.end(), hb, hb + n_hb);
    in.insert(in.end(), typed.begin(), typed.end());
    in.insert(in.end(), st, st + n_st);  // its payload holds '\n' and '\r': still not text
    in.insert(in.end(), typed.begin(), typed.end());
    // A MAVLink 1 frame (STX 0xFE, len 2, seq, sys, comp, msgid, payload 2, CRC 2) and a
    // signed MAVLink 2 frame (incompat flag 1: 13 more bytes).
    const uint8_t v1[] = {0xFE, 2, 0, 255, 190, 21, 1, 1, 0xAB, 0xCD};
    in.insert(in.end(), v1, v1 + sizeof v1);
    Bytes signed_frame = {0xFD, 2, 1, 0, 0, 255, 190, 21, 0, 0, '\n', '\n', 0x11, 0x22};
    signed_frame.insert(signed_frame.end(), 13, (uint8_t)'\n');
    in.insert(in.end(), signed_frame.begin(), signed_frame.end());
    in.push_back('x');

    mav::Parser ff;
    std::string text;
    unsigned heartbeats = 0;
    for (uint8_t b : in) {
        if (!ff.consume(b)) text += (char)b;
        if (ff.ready()) {
            heartbeats += ff.frame().msgid == mav::kMsgHeartbeat;
            ff.release();
        }
    }
    EXPECT_EQ(text, "status\nstatus\nx");
    EXPECT_EQ(ff.frames(), 4u);
    EXPECT_EQ(heartbeats, 1u);
    // The v1 and the signed frame are PARAM_REQUEST_LIST with a made-up CRC.
    EXPECT_EQ(ff.bad_crc(), 2u);
}

TEST(MavLink, StatustextRejectsMoreThanOneChunk) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    char text[60] = {};
    EXPECT_EQ(p.statustext(buf, mav::Severity::Info, text, 51, 0u, 0u), 0u);
    EXPECT_EQ(p.next_sequence(), 0u);
    const uint8_t n = p.statustext(buf, mav::Severity::Info, "0123456789012345678901234567890123456789012345678X",
                                   50, 0u, 0u);
    EXPECT_EQ(n, mav::kMaxFrame - 3u) << "50 characters, id and chunk_seq zero (trimmed)";
    EXPECT_EQ(decode_text(Bytes(buf, buf + n)).text.size(), 50u);
}

// --- Incoming frames -------------------------------------------------------------------

// header + payload + the CRC over both after STX, then CRC_EXTRA.
Bytes with_crc(Bytes f, const Bytes& payload, uint8_t crc_extra) {
    f.insert(f.end(), payload.begin(), payload.end());
    uint16_t crc = x25(f.data() + 1, f.size() - 1);
    crc = x25(&crc_extra, 1, crc);
    f.push_back((uint8_t)(crc & 0xFF));
    f.push_back((uint8_t)(crc >> 8));
    return f;
}

// A frame as a ground station sends it, built here from the wire format (not by lib/MavLink).
Bytes frame_v2(uint8_t msgid, uint8_t crc_extra, Bytes payload, uint8_t seq = 7, bool trim = true) {
    while (trim && payload.size() > 1 && payload.back() == 0) payload.pop_back();  // MAVLink 2 trimming
    return with_crc(Bytes{0xFD, (uint8_t)payload.size(), 0, 0, seq, 255, 190, msgid, 0, 0}, payload, crc_extra);
}

Bytes frame_v1(uint8_t msgid, uint8_t crc_extra, const Bytes& payload, uint8_t seq = 3) {
    return with_crc(Bytes{0xFE, (uint8_t)payload.size(), seq, 255, 190, msgid}, payload, crc_extra);
}

void put_f32(Bytes& b, float v) {
    uint8_t raw[4];
    memcpy(raw, &v, 4);
    b.insert(b.end(), raw, raw + 4);
}
void put_id(Bytes& b, const std::string& id) {
    for (size_t i = 0; i < 16; ++i) b.push_back(i < id.size() ? (uint8_t)id[i] : 0u);
}

// PARAM_SET payload: param_value (f32), target_system, target_component, param_id[16], param_type.
Bytes param_set_payload(const std::string& id, float value, uint8_t target_system = 1) {
    Bytes b;
    put_f32(b, value);
    b.push_back(target_system);
    b.push_back(1);
    put_id(b, id);
    b.push_back(9);
    return b;
}

// COMMAND_LONG payload: param1..7 (f32), command (u16), target_system, target_component, confirmation.
Bytes command_long_payload(uint16_t command, const float (&param)[7]) {
    Bytes b;
    for (float v : param) put_f32(b, v);
    b.push_back((uint8_t)(command & 0xFF));
    b.push_back((uint8_t)(command >> 8));
    b.push_back(1);
    b.push_back(0);
    b.push_back(0);
    return b;
}

// Feeds bytes; returns the frames that came out ready (copied), releasing each.
std::vector<mav::Received> feed(mav::Parser& parser, const Bytes& in, std::string* text = nullptr) {
    std::vector<mav::Received> got;
    for (uint8_t b : in) {
        const bool framed = parser.consume(b);
        if (!framed && text != nullptr) *text += (char)b;
        if (parser.ready()) {
            got.push_back(parser.frame());
            parser.release();
        }
    }
    return got;
}

TEST(MavLinkParser, ParamSetInMavlink2TrimmedAndInMavlink1) {
    for (int v1 = 0; v1 < 2; ++v1) {
        mav::Parser parser;
        const Bytes payload = param_set_payload("RLL2SRV_P", 1.5f);
        const Bytes f = v1 ? frame_v1(23, kExtraParamSet, payload) : frame_v2(23, kExtraParamSet, payload);
        const auto got = feed(parser, f);
        ASSERT_EQ(got.size(), 1u) << (v1 ? "v1" : "v2");
        EXPECT_EQ(got[0].msgid, mav::kMsgParamSet);
        EXPECT_EQ(got[0].sysid, 255u);
        EXPECT_EQ(got[0].compid, 190u);
        mav::ParamSet ps;
        ASSERT_TRUE(mav::decode_param_set(got[0], ps));
        EXPECT_STREQ(ps.name, "RLL2SRV_P");
        EXPECT_EQ(ps.value, 1.5f);
        EXPECT_EQ(parser.bad_crc(), 0u);
    }
}

TEST(MavLinkParser, TrimmedPayloadIsZeroFilled) {
    // PARAM_REQUEST_READ by index 5: param_index (i16), targets, param_id all zero: the
    // MAVLink 2 frame carries 4 bytes of 20.
    Bytes payload = {5, 0, 1, 1};
    payload.resize(20, 0);
    const Bytes f = frame_v2(20, kExtraParamRequestRead, payload);
    ASSERT_EQ(f[1], 4u);
    mav::Parser parser;
    const auto got = feed(parser, f);
    ASSERT_EQ(got.size(), 1u);
    mav::ParamRequest r;
    ASSERT_TRUE(mav::decode_param_request_read(got[0], r));
    EXPECT_EQ(r.index, 5);
    EXPECT_STREQ(r.name, "");
}

TEST(MavLinkParser, SixteenCharacterNameHasNoTerminatorOnTheWire) {
    Bytes payload = {0xFF, 0xFF, 0, 0};  // index -1: by name; target 0/0: everyone
    put_id(payload, "SERVO8_REVERSED1");  // 16 characters (not a parameter: the field is full)
    mav::Parser parser;
    const auto got = feed(parser, frame_v2(20, kExtraParamRequestRead, payload));
    ASSERT_EQ(got.size(), 1u);
    mav::ParamRequest r;
    ASSERT_TRUE(mav::decode_param_request_read(got[0], r));
    EXPECT_EQ(r.index, -1);
    EXPECT_STREQ(r.name, "SERVO8_REVERSED1");
    EXPECT_EQ(mav::requested_index(r), -1);
}

TEST(MavLinkParser, BadCrcIsCountedNotTakenAndTheNextFrameIs) {
    mav::Parser parser;
    Bytes bad = frame_v2(23, kExtraParamSet, param_set_payload("RLL2SRV_P", 2.0f));
    bad[12] ^= 0x01;  // one payload bit
    Bytes wrong_extra = frame_v2(23, kExtraParamSet + 1, param_set_payload("RLL2SRV_P", 2.0f));
    Bytes in = bad;
    in.insert(in.end(), wrong_extra.begin(), wrong_extra.end());
    const Bytes good = frame_v2(21, kExtraParamRequestList, Bytes{1, 1});
    in.insert(in.end(), good.begin(), good.end());
    const auto got = feed(parser, in);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_EQ(got[0].msgid, mav::kMsgParamRequestList);
    EXPECT_TRUE(mav::decode_param_request_list(got[0]));
    EXPECT_EQ(parser.bad_crc(), 2u);
    EXPECT_EQ(parser.frames(), 3u);
}

TEST(MavLinkParser, TruncatedFrameLosesItselfAndAtMostTheNextOne) {
    mav::Parser parser;
    const Bytes whole = frame_v2(23, kExtraParamSet, param_set_payload("RLL2SRV_P", 2.0f));
    Bytes in(whole.begin(), whole.begin() + 15);  // cut short (a link dropout)
    const Bytes list = frame_v2(21, kExtraParamRequestList, Bytes{1, 1});
    for (int i = 0; i < 4; ++i) in.insert(in.end(), list.begin(), list.end());
    const auto got = feed(parser, in);
    // The cut frame claims 21 more bytes: the first request (14 bytes) and 7 of the
    // second are taken as its rest and fail its CRC; the parser then finds the next STX.
    EXPECT_EQ(parser.bad_crc(), 1u);
    EXPECT_GE(got.size(), 2u);
    for (const auto& r : got) EXPECT_EQ(r.msgid, mav::kMsgParamRequestList);
}

TEST(MavLinkParser, GarbageNeverMakesAFrameAndTheParserRecovers) {
    std::vector<uint8_t> noise;
    uint32_t x = 12345u;
    for (int i = 0; i < 200000; ++i) {
        x = x * 1103515245u + 12345u;
        noise.push_back((uint8_t)(x >> 16));
    }
    // Runs of STX with lengths that fit our messages, to reach the CRC check often.
    for (int i = 0; i < 2000; ++i) {
        noise.push_back(0xFD);
        noise.push_back((uint8_t)(i % 34));
    }
    mav::Parser parser;
    const auto got = feed(parser, noise);
    EXPECT_EQ(got.size(), 0u) << "a frame out of noise";
    EXPECT_GT(parser.frames(), 500u);
    // The longest frame is 280 bytes: after that many non-STX bytes, the next frame is whole.
    Bytes in(280, 'x');
    const Bytes good = frame_v2(0, kExtraHeartbeat, Bytes{0, 0, 0, 0, 6, 8, 0, 0, 3});
    in.insert(in.end(), good.begin(), good.end());
    const auto after = feed(parser, in);
    ASSERT_EQ(after.size(), 1u);
    EXPECT_EQ(after[0].msgid, mav::kMsgHeartbeat);
}

TEST(MavLinkParser, RequestsForAnotherSystemOrComponentAreNotOurs) {
    mav::Parser parser;
    auto got = feed(parser, frame_v2(23, kExtraParamSet, param_set_payload("RLL2SRV_P", 2.0f, 2)));
    ASSERT_EQ(got.size(), 1u);
    mav::ParamSet ps;
    EXPECT_FALSE(mav::decode_param_set(got[0], ps));
    EXPECT_FALSE(mav::decode_param_request_list(got[0])) << "not that message";
    got = feed(parser, frame_v2(21, kExtraParamRequestList, Bytes{1, 2}));
    ASSERT_EQ(got.size(), 1u);
    EXPECT_FALSE(mav::decode_param_request_list(got[0]));
    got = feed(parser, frame_v2(21, kExtraParamRequestList, Bytes{0, 0}));
    ASSERT_EQ(got.size(), 1u);
    EXPECT_TRUE(mav::decode_param_request_list(got[0])) << "0/0: broadcast";
}

TEST(MavLinkParser, LongerPayloadThanTheMessagesIsNotTaken) {
    Bytes payload = param_set_payload("RLL2SRV_P", 2.0f);
    payload.push_back(1);  // 24 bytes: no PARAM_SET is that long (an extension we do not know)
    mav::Parser parser;
    EXPECT_EQ(feed(parser, frame_v2(23, kExtraParamSet, payload)).size(), 0u);
    EXPECT_EQ(parser.frames(), 1u);
}

TEST(MavLinkParser, CommandLongDecodes) {
    const float param[7] = {1.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    mav::Parser parser;
    const auto got = feed(parser, frame_v2(76, kExtraCommandLong, command_long_payload(241, param)));
    ASSERT_EQ(got.size(), 1u);
    mav::CommandLong c;
    ASSERT_TRUE(mav::decode_command_long(got[0], c));
    EXPECT_EQ(c.command, mav::kCmdPreflightCalibration);
    EXPECT_EQ(c.param[0], 1.0f);
    EXPECT_EQ(c.param[6], 0.0f);
}

TEST(MavLinkParser, MissionRequestsAndTimesyncDecode) {
    // CRC_EXTRA (common.xml): MISSION_REQUEST_LIST 132, MISSION_COUNT 221, MISSION_CLEAR_ALL 232, TIMESYNC 34.
    mav::Parser parser;
    Bytes in = frame_v2(43, 132, Bytes{1, 1, 2});            // rally list, for us
    const Bytes count = frame_v2(44, 221, Bytes{3, 0, 1, 0, 1});  // 3 fence items, for us
    in.insert(in.end(), count.begin(), count.end());
    const Bytes other = frame_v2(45, 232, Bytes{7, 1, 0});   // a clear for system 7: not ours
    in.insert(in.end(), other.begin(), other.end());
    Bytes ts;
    for (int i = 0; i < 8; ++i) ts.push_back(0);              // tc1 0: a request
    for (int i = 0; i < 8; ++i) ts.push_back((uint8_t)(0x11 * (i + 1)));
    const Bytes tsf = frame_v2(111, 34, ts);
    in.insert(in.end(), tsf.begin(), tsf.end());
    ts[0] = 1;                                                // tc1 set: someone's reply, not answered
    const Bytes tsr = frame_v2(111, 34, ts);
    in.insert(in.end(), tsr.begin(), tsr.end());
    const auto got = feed(parser, in);
    ASSERT_EQ(got.size(), 5u);
    EXPECT_EQ(parser.bad_crc(), 0u);
    uint8_t type = 99;
    uint16_t n = 0;
    EXPECT_TRUE(mav::decode_mission_request_list(got[0], type));
    EXPECT_EQ(type, 2u);
    EXPECT_FALSE(mav::decode_mission_count(got[0], n, type));
    EXPECT_TRUE(mav::decode_mission_count(got[1], n, type));
    EXPECT_EQ(n, 3u);
    EXPECT_EQ(type, 1u);
    EXPECT_FALSE(mav::decode_mission_clear_all(got[2], type));
    int64_t ts1 = 0;
    EXPECT_TRUE(mav::decode_timesync_request(got[3], ts1));
    EXPECT_EQ((uint64_t)ts1, 0x8877665544332211ull);
    EXPECT_FALSE(mav::decode_timesync_request(got[4], ts1));
}

// SET_MODE (custom_mode u32, target_system, base_mode), COMMAND_INT (param1-4, x, y, z,
// command, targets, frame, current, autocontinue) and RC_CHANNELS_OVERRIDE (chan1..8 u16,
// targets, then the extension's chan9..18) as a ground station sends them.
TEST(MavLinkParser, SetModeCommandIntAndRcOverrideDecode) {
    constexpr uint8_t kExtraSetMode = 89, kExtraCommandInt = 158, kExtraRcOverride = 124;
    mav::Parser parser;
    Bytes sm = {5, 0, 0, 0, 1, 1};  // FBWA, system 1, CUSTOM_MODE_ENABLED
    auto got = feed(parser, frame_v2(11, kExtraSetMode, sm));
    ASSERT_EQ(got.size(), 1u);
    mav::SetMode m;
    ASSERT_TRUE(mav::decode_set_mode(got[0], m));
    EXPECT_EQ(m.custom_mode, 5u);
    EXPECT_EQ(m.base_mode, mav::kModeFlagCustomModeEnabled);
    sm[4] = 2;  // another system
    got = feed(parser, frame_v2(11, kExtraSetMode, sm));
    ASSERT_EQ(got.size(), 1u);
    EXPECT_FALSE(mav::decode_set_mode(got[0], m));

    Bytes ci;
    for (float v : {1.0f, 2.0f, 0.0f, 0.0f}) put_f32(ci, v);
    for (int32_t v : {71350450, -731194210}) {
        uint8_t raw[4];
        memcpy(raw, &v, 4);
        ci.insert(ci.end(), raw, raw + 4);
    }
    put_f32(ci, 12.5f);
    for (uint8_t b : {176 & 0xFF, 0, 1, 1, 0, 0, 0}) ci.push_back((uint8_t)b);
    ASSERT_EQ(ci.size(), 35u);
    got = feed(parser, frame_v2(75, kExtraCommandInt, ci));
    ASSERT_EQ(got.size(), 1u);
    mav::CommandLong c;
    EXPECT_FALSE(mav::decode_command_long(got[0], c));
    ASSERT_TRUE(mav::decode_command_int(got[0], c));
    EXPECT_EQ(c.command, mav::kCmdDoSetMode);
    EXPECT_EQ(c.param[0], 1.0f);
    EXPECT_EQ(c.param[1], 2.0f);
    EXPECT_EQ(c.param[4], 71350450.0f);
    EXPECT_EQ(c.param[6], 12.5f);

    Bytes ro;
    for (uint16_t w : {1100, 0, 65535, 1500, 1900, 2000, 1000, 1234}) {
        ro.push_back((uint8_t)(w & 0xFF));
        ro.push_back((uint8_t)(w >> 8));
    }
    ro.push_back(1);
    ro.push_back(1);
    for (int i = 0; i < 10; ++i) {  // channels 9-18: not kept
        ro.push_back(0xDC);
        ro.push_back(0x05);
    }
    ASSERT_EQ(ro.size(), 38u);
    got = feed(parser, frame_v2(70, kExtraRcOverride, ro));
    ASSERT_EQ(got.size(), 1u);
    uint16_t w[8];
    ASSERT_TRUE(mav::decode_rc_channels_override(got[0], w));
    const uint16_t want[8] = {1100, 0, 65535, 1500, 1900, 2000, 1000, 1234};
    for (int i = 0; i < 8; ++i) EXPECT_EQ(w[i], want[i]) << i;
}

TEST(MavLinkParser, RequestDataStreamDecodes) {
    mav::Parser parser;
    // Wire order: req_message_rate (u16), target_system, target_component, req_stream_id, start_stop.
    auto got = feed(parser, frame_v2(66, 148, Bytes{2, 0, 1, 1, 3, 1}));
    ASSERT_EQ(got.size(), 1u);
    mav::DataStreamRequest r;
    ASSERT_TRUE(mav::decode_request_data_stream(got[0], r));
    EXPECT_EQ(r.stream_id, 3u);
    EXPECT_EQ(r.rate_hz, 2u);
    EXPECT_EQ(r.start_stop, 1u);
    got = feed(parser, frame_v2(66, 148, Bytes{0x2C, 0x01, 0, 0, 0, 0}));  // ALL at 300 Hz, stop (trimmed)
    ASSERT_EQ(got.size(), 1u);
    ASSERT_TRUE(mav::decode_request_data_stream(got[0], r));
    EXPECT_EQ(r.stream_id, 0u);
    EXPECT_EQ(r.rate_hz, 300u);
    EXPECT_EQ(r.start_stop, 0u);
    got = feed(parser, frame_v2(66, 148, Bytes{2, 0, 9, 1, 3, 1}));  // another system's
    ASSERT_EQ(got.size(), 1u);
    EXPECT_FALSE(mav::decode_request_data_stream(got[0], r));
    mav::CommandLong c;
    EXPECT_FALSE(mav::decode_command_long(got[0], c));
}

// --- Outgoing replies and streams ------------------------------------------------------

TEST(MavLink, ParamValueCommandAckRcChannelsServoOutputRawOnTheWire) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    uint8_t n = p.param_value(buf, "SERVO8_REVERSED", 1.0f, mav::kParamTypeInt8, 97u, 96u);
    ASSERT_EQ(n, mav::kParamValueFrame);
    Frame f = parse(buf, n, kExtraParamValue);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 22u);
    // Wire order: param_value (f32), param_count, param_index (u16), param_id[16], param_type.
    EXPECT_EQ(f32(f.payload, 0), 1.0f);
    EXPECT_EQ(u16(f.payload, 4), 97u);
    EXPECT_EQ(u16(f.payload, 6), 96u);
    EXPECT_EQ(std::string((const char*)f.payload.data() + 8, 15), "SERVO8_REVERSED");
    EXPECT_EQ(u8(f.payload, 8 + 15), 0u);
    EXPECT_EQ(u8(f.payload, 24), 2u);

    n = p.command_ack(buf, 245, mav::Result::Unsupported, 255u, 190u);
    f = parse(buf, n, kExtraCommandAck);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 77u);
    // command (u16), result, progress, result_param2 (i32), target_system, target_component.
    EXPECT_EQ(u16(f.payload, 0), 245u);
    EXPECT_EQ(u8(f.payload, 2), 3u);
    EXPECT_EQ(u8(f.payload, 8), 255u);
    EXPECT_EQ(u8(f.payload, 9), 190u);

    const uint16_t w[8] = {1001, 1102, 1203, 1304, 1405, 1506, 1607, 1708};
    n = p.rc_channels(buf, 123456u, w, 8u);
    ASSERT_EQ(n, mav::kRcChannelsFrame);
    f = parse(buf, n, kExtraRcChannels);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 65u);
    // time_boot_ms, chan1..18_raw (u16), chancount, rssi.
    EXPECT_EQ(u32(f.payload, 0), 123456u);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(u16(f.payload, 4 + 2 * (size_t)i), w[i]);
    for (int i = 8; i < 18; ++i) EXPECT_EQ(u16(f.payload, 4 + 2 * (size_t)i), 0xFFFFu) << "unused channel";
    EXPECT_EQ(u8(f.payload, 40), 8u);
    EXPECT_EQ(u8(f.payload, 41), 255u);

    n = p.servo_output_raw(buf, 4000000u, w);
    f = parse(buf, n, kExtraServoOutputRaw);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 36u);
    EXPECT_EQ(n, mav::kFrameOverhead + 20u) << "port 0 and servo9..16 (extensions) zero: trimmed";
    // time_usec (u32), servo1..8_raw (u16), port.
    EXPECT_EQ(u32(f.payload, 0), 4000000u);
    for (int i = 0; i < 8; ++i) EXPECT_EQ(u16(f.payload, 4 + 2 * (size_t)i), w[i]);
    EXPECT_EQ(u8(f.payload, 20), 0u);
}

// --- The position messages (GPS_RAW_INT, GLOBAL_POSITION_INT, VFR_HUD, HOME_POSITION) ---

constexpr uint8_t kExtraGpsRawInt = 24, kExtraGlobalPositionInt = 104, kExtraVfrHud = 20, kExtraHomePosition = 104;

gps::Fix field_fix() {
    gps::Fix f;
    f.received_ms = 61234u;
    f.lat_e7 = 71350450;
    f.lon_e7 = -731194210;
    f.alt_msl_mm = 1028123;
    f.ground_speed_cm_s = 1834u;
    f.course_e5 = 27012345;  // 270.12345 deg
    f.h_acc_mm = 2100u;
    f.speed_acc_cm_s = 15u;
    f.hdop_cm = 90u;
    f.sats = 10u;
    f.fix = gps::FixType::k3D;
    return f;
}

TEST(MavLinkPosition, GpsRawIntCarriesTheFix) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.gps_raw_int(buf, field_fix());
    const Frame f = parse(buf, n, kExtraGpsRawInt);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 24u);
    // time_usec (u64), lat, lon, alt (i32), eph, epv, vel, cog (u16), fix_type, satellites_visible;
    // extensions: alt_ellipsoid (i32), h_acc, v_acc, vel_acc, hdg_acc (u32), yaw (u16).
    EXPECT_EQ(u32(f.payload, 0), 61234000u);
    EXPECT_EQ(u32(f.payload, 4), 0u);
    EXPECT_EQ((int32_t)u32(f.payload, 8), 71350450);
    EXPECT_EQ((int32_t)u32(f.payload, 12), -731194210);
    EXPECT_EQ((int32_t)u32(f.payload, 16), 1028123);
    EXPECT_EQ(u16(f.payload, 20), 90u);
    EXPECT_EQ(u16(f.payload, 22), 0xFFFFu) << "epv unknown";
    EXPECT_EQ(u16(f.payload, 24), 1834u);
    EXPECT_EQ(u16(f.payload, 26), 27012u) << "course in centi-degrees";
    EXPECT_EQ(u8(f.payload, 28), 3u);
    EXPECT_EQ(u8(f.payload, 29), 10u);
    EXPECT_EQ(u32(f.payload, 34), 2100u);
    EXPECT_EQ(u32(f.payload, 42), 150u) << "vel_acc in mm/s";
    EXPECT_LE(n, mav::kMaxFrame);
    // No receiver at all: fix type 0, speed, course and satellites unknown.
    const uint8_t n0 = p.gps_raw_int(buf, gps::Fix{});
    const Frame none = parse(buf, n0, kExtraGpsRawInt);
    EXPECT_TRUE(none.crc_ok);
    EXPECT_EQ(u8(none.payload, 28), 0u);
    EXPECT_EQ(u16(none.payload, 24), 0xFFFFu);
    EXPECT_EQ(u16(none.payload, 26), 0xFFFFu);
    EXPECT_EQ(u8(none.payload, 29), 255u);
}

mav::PositionReport report() {
    mav::PositionReport r{};
    r.time_boot_ms = 61300u;
    r.lat_e7 = 71351450;
    r.lon_e7 = -731193210;
    r.alt_msl_mm = 1078500;
    r.relative_alt_mm = 50500;
    r.vel_ned_m_s[0] = 12.0f;
    r.vel_ned_m_s[1] = -16.0f;
    r.vel_ned_m_s[2] = -1.5f;
    r.heading_deg = 306.87f;
    r.airspeed_m_s = 19.5f;
    r.climb_m_s = 1.5f;
    r.throttle_pct = 65u;
    return r;
}

TEST(MavLinkPosition, GlobalPositionIntAndVfrHud) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    uint8_t n = p.global_position_int(buf, report());
    Frame f = parse(buf, n, kExtraGlobalPositionInt);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 33u);
    EXPECT_EQ(n, mav::kFrameOverhead + 28u);
    // time_boot_ms, lat, lon, alt, relative_alt (i32), vx, vy, vz (i16 cm/s), hdg (u16 cdeg).
    EXPECT_EQ(u32(f.payload, 0), 61300u);
    EXPECT_EQ((int32_t)u32(f.payload, 4), 71351450);
    EXPECT_EQ((int32_t)u32(f.payload, 8), -731193210);
    EXPECT_EQ((int32_t)u32(f.payload, 12), 1078500);
    EXPECT_EQ((int32_t)u32(f.payload, 16), 50500);
    EXPECT_EQ((int16_t)u16(f.payload, 20), 1200);
    EXPECT_EQ((int16_t)u16(f.payload, 22), -1600);
    EXPECT_EQ((int16_t)u16(f.payload, 24), -150);
    EXPECT_EQ(u16(f.payload, 26), 30687u);

    n = p.vfr_hud(buf, report());
    f = parse(buf, n, kExtraVfrHud);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 74u);
    // airspeed, groundspeed, alt, climb (f32), heading (i16 deg), throttle (u16 %).
    EXPECT_FLOAT_EQ(f32(f.payload, 0), 19.5f);
    EXPECT_FLOAT_EQ(f32(f.payload, 4), 20.0f);
    EXPECT_NEAR(f32(f.payload, 8), 1078.5f, 1e-3f);
    EXPECT_FLOAT_EQ(f32(f.payload, 12), 1.5f);
    EXPECT_EQ((int16_t)u16(f.payload, 16), 307);
    EXPECT_EQ(u16(f.payload, 18), 65u);

    // Out of range and unknown: velocities held at int16's limits, no NaN, heading unknown.
    mav::PositionReport bad = report();
    bad.vel_ned_m_s[0] = 400.0f;
    bad.vel_ned_m_s[1] = NAN;
    bad.vel_ned_m_s[2] = -400.0f;
    bad.heading_deg = -1.0f;
    n = p.global_position_int(buf, bad);
    f = parse(buf, n, kExtraGlobalPositionInt);
    EXPECT_EQ((int16_t)u16(f.payload, 20), 32767);
    EXPECT_EQ((int16_t)u16(f.payload, 22), 0);
    EXPECT_EQ((int16_t)u16(f.payload, 24), -32767);
    EXPECT_EQ(u16(f.payload, 26), 0xFFFFu);
    bad.heading_deg = 359.999f;  // rounds to 360.00: 0
    n = p.global_position_int(buf, bad);
    EXPECT_EQ(u16(parse(buf, n, kExtraGlobalPositionInt).payload, 26), 0u);
}

TEST(MavLinkPosition, HomePositionIsTrimmedToFit) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.home_position(buf, 71350450, -731194210, 1028000);
    const Frame f = parse(buf, n, kExtraHomePosition);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 242u);
    // latitude, longitude, altitude (i32), x, y, z, q[4], approach x, y, z (f32), time_usec
    // (u64): q = (1, 0, 0, 0) ends the payload after q[0].
    EXPECT_EQ(n, mav::kFrameOverhead + 28u);
    EXPECT_EQ((int32_t)u32(f.payload, 0), 71350450);
    EXPECT_EQ((int32_t)u32(f.payload, 4), -731194210);
    EXPECT_EQ((int32_t)u32(f.payload, 8), 1028000);
    EXPECT_EQ(f32(f.payload, 24), 1.0f);
    EXPECT_EQ(p.next_sequence(), 1u);
}

TEST(MavLinkPosition, GpsBitInSysStatus) {
    mav::Health h = mav::health(true, true, true, true);
    mav::add_sensor(h, mav::kGps, true, false);
    EXPECT_EQ(h.present, 7u | 32u);
    EXPECT_EQ(h.healthy, 7u);
    mav::add_sensor(h, mav::kGps, true, true);
    EXPECT_EQ(h.healthy, 7u | 32u);
    mav::Health none = mav::health(true, true, true, true);
    mav::add_sensor(none, mav::kGps, false, true);
    EXPECT_EQ(none.present, 7u);
    EXPECT_EQ(none.healthy, 7u);
}

// --- The parameter protocol over lib/Params ---------------------------------------------

TEST(ParamLink, EveryIndexPacksItsNameValueTypeAndCount) {
    settings::Settings s = settings::defaults();
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint16_t count = params::count();
    ASSERT_GT(count, 90u);
    std::vector<std::string> names;
    for (uint16_t i = 0; i < count; ++i) {
        const uint8_t n = mav::pack_param_value(p, buf, s, i, count);
        ASSERT_EQ(n, mav::kParamValueFrame);
        const Frame f = parse(buf, n, kExtraParamValue);
        ASSERT_TRUE(f.crc_ok);
        params::Info in;
        ASSERT_TRUE(params::info(i, in));
        EXPECT_EQ(u16(f.payload, 4), count);
        EXPECT_EQ(u16(f.payload, 6), i);
        const std::string name((const char*)f.payload.data() + 8, strnlen((const char*)f.payload.data() + 8, 16));
        EXPECT_EQ(name, in.name);
        EXPECT_EQ(f32(f.payload, 0), params::get(s, i)) << name;
        EXPECT_EQ(f32(f.payload, 0), in.def) << name << ": defaults";
        const uint8_t type = u8(f.payload, 24);
        if (params::is_integer(in.type)) {
            EXPECT_TRUE(type == 2u || type == 4u) << name;
            // The value fits the type ArduPilot's GCS code reads it as.
            EXPECT_LE(in.max, type == 2u ? 127.0f : 32767.0f) << name;
            EXPECT_GE(in.min, type == 2u ? -128.0f : -32768.0f) << name;
        } else {
            EXPECT_EQ(type, 9u) << name;
        }
        names.push_back(name);
    }
    EXPECT_EQ(mav::pack_param_value(p, buf, s, count, count), 0u) << "past the end";
    std::sort(names.begin(), names.end());
    EXPECT_EQ(std::adjacent_find(names.begin(), names.end()), names.end()) << "a name twice";
}

TEST(ParamLink, ReadByIndexOrName) {
    mav::ParamRequest r{};
    r.index = 3;
    EXPECT_EQ(mav::requested_index(r), 3);
    r.index = (int16_t)params::count();
    EXPECT_EQ(mav::requested_index(r), -1);
    r.index = -1;
    strcpy(r.name, "COMPASS_DEC");
    EXPECT_EQ(mav::requested_index(r), params::find("COMPASS_DEC"));
    strcpy(r.name, "NO_SUCH_PARAM");
    EXPECT_EQ(mav::requested_index(r), -1);
    // params::find's one pass over the rows: every name, in either case, and near misses.
    for (uint16_t i = 0; i < params::count(); ++i) {
        params::Info in;
        ASSERT_TRUE(params::info(i, in));
        strcpy(r.name, in.name);
        EXPECT_EQ(mav::requested_index(r), (int16_t)i) << in.name;
        for (char* c = r.name; *c; ++c) *c = (char)tolower(*c);
        EXPECT_EQ(mav::requested_index(r), (int16_t)i) << r.name;
    }
    for (const char* miss : {"RC0_MIN", "RC9_MIN", "RC#_MIN", "RC1_MI", "RC1_MINX", "SERVO10_MIN", "FLTMODE7",
                             "FLTMODE0", "FLTMODE", "", "RLL2SRV_PX", "RLL2SRV_"}) {
        strcpy(r.name, miss);
        EXPECT_EQ(mav::requested_index(r), -1) << miss;
    }
}

TEST(ParamLink, SetAppliesInRangeAndKeepsTheOldValueOtherwise) {
    settings::Settings s = settings::defaults();
    mav::ParamSet ps{};
    strcpy(ps.name, "RLL2SRV_P");
    ps.value = 1.25f;
    bool changed = false;
    const int16_t i = mav::apply_param_set(s, ps, changed);
    ASSERT_EQ(i, params::find("RLL2SRV_P"));
    EXPECT_TRUE(changed);
    EXPECT_EQ(s.flight.roll.p, 1.25f);
    ps.value = 9.0f;  // above its 4.0
    EXPECT_EQ(mav::apply_param_set(s, ps, changed), i);
    EXPECT_FALSE(changed);
    EXPECT_EQ(params::get(s, (uint16_t)i), 1.25f) << "the reply carries the value in force";
    ps.value = 1.25f;
    mav::apply_param_set(s, ps, changed);
    EXPECT_FALSE(changed) << "the same value: nothing to save";
    strcpy(ps.name, "SERVO1_TRIM");
    ps.value = 2100.0f;  // above SERVO1_MAX 2000: end points out of order
    mav::apply_param_set(s, ps, changed);
    EXPECT_FALSE(changed);
    EXPECT_EQ(s.flight.servo[0].trim_us, 1500u);
    strcpy(ps.name, "THR_FS_OUT");
    ps.value = 12.5f;  // not whole
    mav::apply_param_set(s, ps, changed);
    EXPECT_FALSE(changed);
    strcpy(ps.name, "rll2srv_i");  // ground stations send upper case; the table takes either
    ps.value = 0.5f;
    EXPECT_EQ(mav::apply_param_set(s, ps, changed), params::find("RLL2SRV_I"));
    EXPECT_TRUE(changed);
    strcpy(ps.name, "NOPE");
    EXPECT_EQ(mav::apply_param_set(s, ps, changed), -1);
}

TEST(ParamLink, RepliesSinglesFirstThenTheWholeListOnce) {
    mav::ParamReplies r;
    uint16_t index = 0;
    EXPECT_FALSE(r.peek(index));
    r.request_all();
    r.request_one(40);
    std::vector<uint16_t> sent;
    for (int k = 0; k < 5; ++k) {
        ASSERT_TRUE(r.peek(index));
        sent.push_back(index);
        r.pop();
    }
    r.request_one(7);  // a READ in the middle of the list
    while (r.peek(index)) {
        sent.push_back(index);
        r.pop();
        ASSERT_LT(sent.size(), 400u);
    }
    ASSERT_EQ(sent.size(), params::count() + 2u);
    EXPECT_EQ(sent[0], 40u);
    EXPECT_EQ(sent[1], 0u);
    EXPECT_EQ(sent[5], 7u);
    std::vector<uint16_t> list(sent.begin() + 1, sent.begin() + 5);
    list.insert(list.end(), sent.begin() + 6, sent.end());
    for (uint16_t i = 0; i < params::count(); ++i) EXPECT_EQ(list[i], i);
    // A burst (20 PARAM_SETs before the link has room for one reply, each asked twice):
    // every one answered, once, lowest index first.
    for (int pass = 0; pass < 2; ++pass)
        for (uint16_t i = 0; i < 20; ++i) r.request_one((uint16_t)(params::count() - 1u - i * 3u));
    std::vector<uint16_t> burst;
    while (r.peek(index)) {
        burst.push_back(index);
        r.pop();
        ASSERT_LT(burst.size(), 400u);
    }
    ASSERT_EQ(burst.size(), 20u);
    for (size_t k = 0; k < burst.size(); ++k) EXPECT_EQ(burst[k], params::count() - 1u - (19u - k) * 3u);
}

TEST(ParamLink, EveryParameterFitsTheRepliesBitmapAndIsSentOnce) {
    ASSERT_LE(params::count(), (uint16_t)mav::ParamReplies::kMaxParams);
    mav::ParamReplies r;
    r.request_one(5);
    r.request_every_one();  // the defaults restored: every parameter announced
    std::vector<int> seen(params::count(), 0);
    uint16_t index = 0;
    while (r.peek(index)) {
        ASSERT_LT(index, params::count());
        ++seen[index];
        r.pop();
    }
    for (uint16_t i = 0; i < params::count(); ++i) EXPECT_EQ(seen[i], 1) << i;
    r.request_one((uint16_t)mav::ParamReplies::kMaxParams);  // past the bitmap: ignored, never written past it
    EXPECT_FALSE(r.peek(index));
}

// --- The parameter reference's table (docs/parameters.md) ----------------------------------

std::vector<std::string> split_cells(const std::string& line) {
    std::vector<std::string> cells;
    size_t at = 1;
    while (at < line.size()) {
        const size_t bar = line.find('|', at);
        if (bar == std::string::npos) break;
        std::string c = line.substr(at, bar - at);
        while (!c.empty() && c.front() == ' ') c.erase(c.begin());
        while (!c.empty() && c.back() == ' ') c.pop_back();
        cells.push_back(c);
        at = bar + 1;
    }
    return cells;
}

TEST(MavLink, ParameterReferenceTableIsTheCodes) {
    std::string path(__FILE__);
    path = path.substr(0, path.rfind('/')) + "/../../docs/parameters.md";
    FILE* f = fopen(path.c_str(), "r");
    ASSERT_NE(f, nullptr) << path;
    std::vector<std::string> lines;
    char buf[1024];
    while (fgets(buf, sizeof buf, f)) {
        std::string l(buf);
        while (!l.empty() && (l.back() == '\n' || l.back() == '\r')) l.pop_back();
        lines.push_back(l);
    }
    fclose(f);
    size_t at = 0;
    while (at < lines.size() && lines[at] != "# Parameters") ++at;
    ASSERT_LT(at, lines.size()) << "no '# Parameters' heading";
    while (at < lines.size() && lines[at].rfind("| name | unit | range | default |", 0) != 0) ++at;
    ASSERT_LT(at, lines.size()) << "no table after it";
    at += 2;
    std::vector<int> covered(params::count(), 0);
    unsigned rows = 0;
    for (; at < lines.size() && lines[at].rfind("| `", 0) == 0; ++at, ++rows) {
        const std::vector<std::string> c = split_cells(lines[at]);
        ASSERT_EQ(c.size(), 5u) << lines[at];
        const size_t tick = c[0].find('`', 1);
        ASSERT_NE(tick, std::string::npos) << lines[at];
        const std::string name = c[0].substr(1, tick - 1);
        int first = 0, last = 0;
        const size_t n_at = name.find('n');
        char first_c = 0, last_c = 0;  // or letters ("COMPASS_OFS_n" (n X-Z))
        if (n_at != std::string::npos && sscanf(c[0].c_str() + tick + 1, " (n %d-%d)", &first, &last) != 2) {
            ASSERT_EQ(sscanf(c[0].c_str() + tick + 1, " (n %c-%c)", &first_c, &last_c), 2) << lines[at];
            first = first_c - '0';
            last = last_c - '0';
        }
        float lo = 0, hi = 0, def = 0;
        ASSERT_EQ(sscanf(c[2].c_str(), "%f to %f", &lo, &hi), 2) << lines[at];
        ASSERT_EQ(sscanf(c[3].c_str(), "%f", &def), 1) << lines[at];
        for (int k = first; k <= last; ++k) {
            std::string expanded = name;
            if (n_at != std::string::npos) expanded[n_at] = (char)('0' + k);
            const int16_t i = params::find(expanded.c_str());
            ASSERT_GE(i, 0) << expanded << ": not a parameter";
            ++covered[(size_t)i];
            params::Info in;
            ASSERT_TRUE(params::info((uint16_t)i, in));
            const auto close = [](float a, float b) { return fabsf(a - b) <= 1e-4f * fmaxf(1.0f, fabsf(b)); };
            EXPECT_TRUE(close(lo, in.min) && close(hi, in.max)) << expanded << " range " << c[2];
            EXPECT_TRUE(close(def, in.def)) << expanded << " default " << c[3];
        }
    }
    EXPECT_GT(rows, 30u);
    for (uint16_t i = 0; i < params::count(); ++i) {
        params::Info in;
        params::info(i, in);
        EXPECT_EQ(covered[i], 1) << in.name << " in the reference's table " << covered[i] << " times";
    }
}

}  // namespace

namespace {

constexpr uint8_t kExtraScaledPressure = 115;  // common.xml's SCALED_PRESSURE

TEST(MavLink, SysStatusAddsTheBarometersBits) {
    mav::Health h = mav::health(true, true, true, true);
    mav::add_sensor(h, mav::kAbsolutePressure, false, false);  // absent: no bit
    EXPECT_EQ(h.present, 7u);
    mav::add_sensor(h, mav::kAbsolutePressure, true, false);   // present, not healthy
    EXPECT_EQ(h.present, 15u);
    EXPECT_EQ(h.healthy, 7u);
    mav::add_sensor(h, mav::kAbsolutePressure, true, true);
    EXPECT_EQ(h.healthy, 15u);
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const Frame f = parse(buf, p.sys_status(buf, h, 100u, 0u), kExtraSysStatus);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(u32(f.payload, 0), 15u);  // present: gyro, accel, mag, absolute pressure (8)
    EXPECT_EQ(u32(f.payload, 4), 15u);
    EXPECT_EQ(u32(f.payload, 8), 15u);
}

TEST(MavLink, ScaledPressureInHectopascalAndCentidegrees) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.scaled_pressure(buf, 123456u, 89569.0f, 8.32f);
    const Frame f = parse(buf, n, kExtraScaledPressure);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 29u);
    EXPECT_LE(n, mav::kScaledPressureFrame);
    EXPECT_EQ(u32(f.payload, 0), 123456u);
    EXPECT_FLOAT_EQ(f32(f.payload, 4), 895.69f);  // hPa
    EXPECT_EQ(f32(f.payload, 8), 0.0f);           // no differential pressure
    EXPECT_EQ((int16_t)u16(f.payload, 12), 832);  // 0.01 degC
    // Out of int16's range: held at its end, never wrapped.
    const Frame hot = parse(buf, p.scaled_pressure(buf, 0u, 1000.0f, 1e6f), kExtraScaledPressure);
    EXPECT_EQ((int16_t)u16(hot.payload, 12), 32767);
    const Frame cold = parse(buf, p.scaled_pressure(buf, 0u, 1000.0f, -1e6f), kExtraScaledPressure);
    EXPECT_EQ((int16_t)u16(cold.payload, 12), -32767);
}

// MAG_CAL_PROGRESS (ardupilotmega.xml 191, CRC_EXTRA 92: not in the common.xml the headers
// are made from, packed by hand) and MAG_CAL_REPORT (common.xml 192, CRC_EXTRA 36), in
// their wire order; pymavlink decodes both in test/mavlink/gcs_mag_cal.py.
TEST(MavLinkMagCal, ProgressFieldsInWireOrder) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.mag_cal_progress(buf, mav::MagCalStatus::RunningStepOne, 1u, 42u, 0x02ABCDEFu,
                                         linalg::Vector3f(0.6f, -0.8f, 0.0f));
    const Frame f = parse(buf, n, 92u);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 191u);
    EXPECT_LE(n, mav::kMagCalProgressFrame);
    EXPECT_EQ(f.payload.size(), 21u) << "the mask's six zero bytes trimmed";
    EXPECT_FLOAT_EQ(f32(f.payload, 0), 0.6f);
    EXPECT_FLOAT_EQ(f32(f.payload, 4), -0.8f);
    EXPECT_FLOAT_EQ(f32(f.payload, 8), 0.0f);
    EXPECT_EQ(u8(f.payload, 12), 0u);  // compass_id
    EXPECT_EQ(u8(f.payload, 13), 1u);  // cal_mask
    EXPECT_EQ(u8(f.payload, 14), 2u);  // MAG_CAL_RUNNING_STEP_ONE
    EXPECT_EQ(u8(f.payload, 15), 1u);  // attempt
    EXPECT_EQ(u8(f.payload, 16), 42u);  // completion_pct
    EXPECT_EQ(u32(f.payload, 17), 0x02ABCDEFu);  // completion_mask[0..3], little-endian bits
    for (size_t i = 21; i < 27; ++i) EXPECT_EQ(u8(f.payload, i), 0u);
    const Frame next = parse(buf, p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Manual, true), kExtraHeartbeat);
    EXPECT_EQ(next.seq, (uint8_t)(f.seq + 1u)) << "one sequence with the others";
}

TEST(MavLinkMagCal, ReportCarriesArduPilotsUnits) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    mav::MagCalReport r;
    r.status = mav::MagCalStatus::Success;
    r.autosaved = true;
    r.fitness_mgauss = 2.3f;
    r.ofs_mgauss = linalg::Vector3f(-80.1f, 50.2f, -30.0f);
    r.diag = linalg::Vector3f(0.99f, 1.0f, 1.02f);
    r.offdiag = linalg::Vector3f(0.01f, -0.02f, 0.0f);
    const uint8_t n = p.mag_cal_report(buf, r);
    const Frame f = parse(buf, n, 36u);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 192u);
    EXPECT_LE(n, mav::kMaxFrame);
    const float want[10] = {2.3f, -80.1f, 50.2f, -30.0f, 0.99f, 1.0f, 1.02f, 0.01f, -0.02f, 0.0f};
    for (size_t i = 0; i < 10; ++i) EXPECT_FLOAT_EQ(f32(f.payload, 4 * i), want[i]) << "field " << i;
    EXPECT_EQ(u8(f.payload, 40), 0u);  // compass_id
    EXPECT_EQ(u8(f.payload, 41), 1u);  // cal_mask
    EXPECT_EQ(u8(f.payload, 42), 4u);  // MAG_CAL_SUCCESS
    EXPECT_EQ(u8(f.payload, 43), 1u);  // autosaved
    r.status = mav::MagCalStatus::Failed;
    r.autosaved = false;
    const Frame failed = parse(buf, p.mag_cal_report(buf, r), 36u);
    EXPECT_TRUE(failed.crc_ok);
    EXPECT_EQ(u8(failed.payload, 42), 5u);  // MAG_CAL_FAILED
    EXPECT_EQ(u8(failed.payload, 43), 0u);
}

}  // namespace

// The battery (lib/Battery's monitor) in SYS_STATUS and BATTERY_STATUS: MAVLink's units
// (mV, 10 mA, mAh, %), and its "unknown" for what BATT_MONITOR does not measure.
namespace {
constexpr uint8_t kExtraBatteryStatus = 154;

battery::Settings module_settings(uint8_t monitor) {
    battery::Settings s{};
    s.monitor = monitor;
    s.volt_mult = 10.1f;
    s.amp_per_volt = 17.0f;
    s.capacity_mah = 2000;
    return s;
}
}  // namespace

TEST(MavLinkBattery, ReportsWhatTheMonitorMeasures) {
    battery::Monitor m;
    battery::Settings s = module_settings(battery::kMonitorVoltageAndCurrent);
    m.update(s, 1.2345f, 12.5f / 17.0f, 0.0f, 0);
    for (int i = 0; i < 100; ++i) m.update(s, 1.2345f, 12.5f / 17.0f, 0.1f, 0);  // 10 s at 12.5 A: 34.7 mAh
    mav::BatteryReport r = mav::battery_report(m, s);
    EXPECT_EQ(r.voltage_mv, 12468u);  // 1.2345 x 10.1 = 12.468 V
    EXPECT_EQ(r.current_ca, 1250);
    EXPECT_EQ(r.consumed_mah, 35);
    EXPECT_EQ(r.remaining_pct, 98);
    EXPECT_FALSE(r.failsafe);
    s.monitor = battery::kMonitorVoltage;
    r = mav::battery_report(m, s);
    EXPECT_EQ(r.voltage_mv, 12468u);
    EXPECT_EQ(r.current_ca, -1);
    EXPECT_EQ(r.consumed_mah, -1);
    EXPECT_EQ(r.remaining_pct, -1);
    s.monitor = battery::kMonitorDisabled;
    r = mav::battery_report(m, s);
    EXPECT_EQ(r.voltage_mv, UINT16_MAX);
    EXPECT_EQ(r.current_ca, -1);
    EXPECT_EQ(r.remaining_pct, -1);
    // A reading beyond a field is held at its end, never wrapped (UINT16_MAX is "unknown").
    s.monitor = battery::kMonitorVoltageAndCurrent;
    battery::Monitor big;
    big.update(s, 100.0f, 2000.0f, 0.0f, 0);  // 1010 V, 34000 A: a wrong multiplier
    r = mav::battery_report(big, s);
    EXPECT_EQ(r.voltage_mv, UINT16_MAX - 1u);
    EXPECT_EQ(r.current_ca, 32767);
}

TEST(MavLinkBattery, SysStatusCarriesTheBattery) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    mav::Health h = mav::health(true, true, true, true);
    mav::add_sensor(h, mav::kBattery, true, true);
    const mav::BatteryReport b{11870u, 1234, 456, 77, false};
    const Frame f = parse(buf, p.sys_status(buf, h, 100u, 0u, &b), kExtraSysStatus);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(u32(f.payload, 0), 7u | 0x2000000u);  // MAV_SYS_STATUS_SENSOR_BATTERY
    EXPECT_EQ(u32(f.payload, 8), 7u | 0x2000000u);
    EXPECT_EQ(u16(f.payload, 14), 11870u);
    EXPECT_EQ(u16(f.payload, 16), 1234u);
    EXPECT_EQ(u8(f.payload, 30), 77u);
}

TEST(MavLinkBattery, BatteryStatusFrame) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const mav::BatteryReport b{11870u, 1234, 456, 77, true};
    const uint8_t n = p.battery_status(buf, b);
    const Frame f = parse(buf, n, kExtraBatteryStatus);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 147u);
    EXPECT_EQ(n, mav::kBatteryStatusFrame);  // trimmed after charge_state
    EXPECT_EQ(u32(f.payload, 0), 456u);                 // current_consumed, mAh
    EXPECT_EQ(u32(f.payload, 4), 0xFFFFFFFFu);          // energy_consumed -1
    EXPECT_EQ(u16(f.payload, 8), 0x7FFFu);              // temperature unknown
    EXPECT_EQ(u16(f.payload, 10), 11870u);              // voltages[0]: the pack
    for (size_t i = 1; i < 10; ++i) EXPECT_EQ(u16(f.payload, 10 + 2 * i), 0xFFFFu) << i;
    EXPECT_EQ(u16(f.payload, 30), 1234u);               // current_battery, 10 mA
    EXPECT_EQ(u8(f.payload, 32), 0u);                   // id
    EXPECT_EQ(u8(f.payload, 35), 77u);                  // battery_remaining
    EXPECT_EQ(u8(f.payload, 40), 2u);                   // charge_state LOW (failsafe)
    const mav::BatteryReport ok{11870u, -1, -1, -1, false};
    const Frame g = parse(buf, p.battery_status(buf, ok), kExtraBatteryStatus);
    EXPECT_EQ(u8(g.payload, 40), 1u);                   // OK
    EXPECT_EQ(u16(g.payload, 30), 0xFFFFu);             // current -1
}

// --- The mission protocol --------------------------------------------------------------

// MISSION_ITEM_INT on the wire (common.xml, CRC_EXTRA 38): param1..4, x, y (int32), z,
// seq, command, target_system, target_component, frame, current, autocontinue,
// mission_type; and back through the parser into the same fields.
TEST(MavLinkMission, ItemIntOnTheWireAndBack) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    mission::Item it = {};
    it.seq = 7;
    it.command = mission::kDoJump;
    it.frame = mission::kFrameGlobalRelativeAltInt;
    it.autocontinue = 1;
    it.param1 = 3.0f;
    it.param2 = -1.0f;
    it.param3 = 60.0f;
    it.param4 = 0.5f;
    it.x = -731194210;
    it.y = 1799999999;
    it.z = 120.25f;
    it.mission_type = 0;
    it.int_form = true;
    const uint8_t n = p.mission_item(buf, 1u, 1u, it);
    const Frame f = parse(buf, n, 38);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 73u);
    EXPECT_EQ(f32(f.payload, 0), 3.0f);
    EXPECT_EQ(f32(f.payload, 4), -1.0f);
    EXPECT_EQ(f32(f.payload, 8), 60.0f);
    EXPECT_EQ(f32(f.payload, 12), 0.5f);
    EXPECT_EQ((int32_t)u32(f.payload, 16), -731194210);
    EXPECT_EQ((int32_t)u32(f.payload, 20), 1799999999);
    EXPECT_EQ(f32(f.payload, 24), 120.25f);
    EXPECT_EQ(u16(f.payload, 28), 7u);
    EXPECT_EQ(u16(f.payload, 30), 177u);
    EXPECT_EQ(u8(f.payload, 32), 1u);
    EXPECT_EQ(u8(f.payload, 33), 1u);
    EXPECT_EQ(u8(f.payload, 34), 6u);
    EXPECT_EQ(u8(f.payload, 36), 1u);
    EXPECT_EQ(u8(f.payload, 37), 0u);
    EXPECT_LE(f.payload.size(), 37u) << "mission_type 0 trimmed";

    mav::Parser parser;
    auto got = feed(parser, Bytes(buf, buf + n));
    ASSERT_EQ(got.size(), 1u);
    mission::Item back = {};
    ASSERT_TRUE(mav::decode_mission_item(got[0], back));
    EXPECT_TRUE(back.int_form);
    EXPECT_EQ(back.seq, it.seq);
    EXPECT_EQ(back.command, it.command);
    EXPECT_EQ(back.frame, it.frame);
    EXPECT_EQ(back.autocontinue, 1u);
    EXPECT_EQ(back.param2, -1.0f);
    EXPECT_EQ(back.param4, 0.5f);
    EXPECT_EQ(back.x, it.x);
    EXPECT_EQ(back.y, it.y);
    EXPECT_EQ(back.z, it.z);
    uint16_t seq = 0;
    EXPECT_FALSE(mav::decode_mission_set_current(got[0], seq));
    // Addressed to another system: not ours.
    got = feed(parser, Bytes(buf, buf + p.mission_item(buf, 2u, 1u, it)));
    ASSERT_EQ(got.size(), 1u);
    EXPECT_FALSE(mav::decode_mission_item(got[0], back));
}

// MISSION_ITEM (CRC_EXTRA 254): x, y as float degrees, to 1e-7 degrees within a float's
// 24 bits (~1 m of longitude at 73 degrees).
TEST(MavLinkMission, ItemInFloatDegreesBothWays) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    mission::Item it = {};
    it.seq = 2;
    it.command = mission::kNavWaypoint;
    it.frame = mission::kFrameGlobalRelativeAlt;
    it.x = 71350450;
    it.y = -731194210;
    it.z = 100.0f;
    it.mission_type = 0;
    it.int_form = false;
    const uint8_t n = p.mission_item(buf, 1u, 1u, it);
    const Frame f = parse(buf, n, 254);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 39u);
    EXPECT_NEAR(f32(f.payload, 16), 7.1350450f, 1e-6f);
    EXPECT_NEAR(f32(f.payload, 20), -73.1194210f, 1e-5f);
    EXPECT_EQ(u8(f.payload, 34), 3u);
    mav::Parser parser;
    const auto got = feed(parser, Bytes(buf, buf + n));
    ASSERT_EQ(got.size(), 1u);
    mission::Item back = {};
    ASSERT_TRUE(mav::decode_mission_item(got[0], back));
    EXPECT_FALSE(back.int_form);
    EXPECT_NEAR(back.x, it.x, 5);
    EXPECT_NEAR(back.y, it.y, 80);
    EXPECT_EQ(back.frame, 3u);
}

// The requests both ways (MISSION_REQUEST 230, _INT 196: seq, targets, mission_type), the
// ACK (153: targets, type, mission_type), COUNT (221), CURRENT (28: seq, total, state,
// mode) and ITEM_REACHED (11: seq).
TEST(MavLinkMission, RequestsAckCountCurrentReached) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    mav::Parser parser;
    for (int int_form = 0; int_form < 2; ++int_form) {
        const uint8_t n = p.mission_request(buf, 1u, 1u, 513u, int_form != 0, 0u);
        const Frame f = parse(buf, n, int_form ? 196 : 230);
        EXPECT_TRUE(f.crc_ok);
        EXPECT_EQ(f.msgid, int_form ? 51u : 40u);
        EXPECT_EQ(u16(f.payload, 0), 513u);
        EXPECT_EQ(u8(f.payload, 2), 1u);
        const auto got = feed(parser, Bytes(buf, buf + n));
        ASSERT_EQ(got.size(), 1u);
        uint16_t seq = 0;
        bool as_int = !int_form;
        uint8_t type = 9;
        ASSERT_TRUE(mav::decode_mission_request(got[0], seq, as_int, type));
        EXPECT_EQ(seq, 513u);
        EXPECT_EQ(as_int, int_form != 0);
        EXPECT_EQ(type, 0u);
    }
    uint8_t n = p.mission_ack(buf, 1u, 1u, (mav::MissionResult)mission::Result::kNoSpace, 2u);
    Frame f = parse(buf, n, 153);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(u8(f.payload, 2), 4u);
    EXPECT_EQ(u8(f.payload, 3), 2u);
    auto got = feed(parser, Bytes(buf, buf + n));
    ASSERT_EQ(got.size(), 1u);
    uint8_t type = 0;
    ASSERT_TRUE(mav::decode_mission_ack(got[0], type));
    EXPECT_EQ(type, 2u);
    n = p.mission_count(buf, 1u, 1u, 101u, 0u);
    got = feed(parser, Bytes(buf, buf + n));
    ASSERT_EQ(got.size(), 1u);
    uint16_t count = 0;
    ASSERT_TRUE(mav::decode_mission_count(got[0], count, type));
    EXPECT_EQ(count, 101u);
    n = p.mission_current(buf, 4u, 10u);
    f = parse(buf, n, 28);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 42u);
    EXPECT_EQ(u16(f.payload, 0), 4u);
    EXPECT_EQ(u16(f.payload, 2), 10u);
    n = p.mission_item_reached(buf, 3u);
    f = parse(buf, n, 11);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 46u);
    EXPECT_EQ(u16(f.payload, 0), 3u);
}

// A ground station's MISSION_SET_CURRENT (CRC_EXTRA 28: seq, targets) and a MISSION_ITEM
// in MAVLink 1 (no mission_type: 0).
TEST(MavLinkMission, SetCurrentAndAnOldItemFromAGroundStation) {
    mav::Parser parser;
    auto got = feed(parser, frame_v2(41, 28, Bytes{5, 0, 1, 1}));
    ASSERT_EQ(got.size(), 1u);
    uint16_t seq = 0;
    ASSERT_TRUE(mav::decode_mission_set_current(got[0], seq));
    EXPECT_EQ(seq, 5u);
    Bytes item;
    for (float v : {0.0f, 0.0f, 0.0f, 0.0f, 7.5f, -73.25f, 50.0f}) put_f32(item, v);
    for (uint8_t b : {1, 0, 16, 0, 1, 1, 3, 0, 1}) item.push_back(b);  // seq 1, WAYPOINT, frame 3
    ASSERT_EQ(item.size(), 37u);
    got = feed(parser, frame_v1(39, 254, item));
    ASSERT_EQ(got.size(), 1u);
    mission::Item it = {};
    ASSERT_TRUE(mav::decode_mission_item(got[0], it));
    EXPECT_EQ(it.seq, 1u);
    EXPECT_EQ(it.command, 16u);
    EXPECT_EQ(it.x, 75000000);
    EXPECT_NEAR(it.y, -732500000, 64) << "1e7 x degrees in a float: 24 bits";
    EXPECT_EQ(it.z, 50.0f);
    EXPECT_EQ(it.mission_type, 0u);
    EXPECT_FALSE(it.int_form);
}

namespace {

// NAV_CONTROLLER_OUTPUT (62, CRC_EXTRA 183): the fields where common.xml puts them.
TEST(MavLink, NavControllerOutputCarriesTheNavigationsFigures) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const mav::NavOutput n{12.5f, -3.25f, 271, 90, 1234, -2.5f, 1.75f};
    const uint8_t len = p.nav_controller_output(buf, n);
    const Frame f = parse(buf, len, 183);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 62u);
    EXPECT_EQ(f32(f.payload, 0), 12.5f);    // nav_roll
    EXPECT_EQ(f32(f.payload, 4), -3.25f);   // nav_pitch
    EXPECT_EQ(f32(f.payload, 8), -2.5f);    // alt_error
    EXPECT_EQ(f32(f.payload, 12), 0.0f);    // aspd_error: not sent
    EXPECT_EQ(f32(f.payload, 16), 1.75f);   // xtrack_error
    EXPECT_EQ((int16_t)u16(f.payload, 20), 271);  // nav_bearing
    EXPECT_EQ((int16_t)u16(f.payload, 22), 90);   // target_bearing
    EXPECT_EQ(u16(f.payload, 24), 1234u);         // wp_dist
}

}  // namespace
