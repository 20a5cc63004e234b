// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MavLink: the frames checked byte by byte against the MAVLink 2 wire format, with a
// CRC computed here independently of the generated code (CRC-16/MCRF4XX over header and
// payload, then the message's CRC_EXTRA). pymavlink decodes the same frames in
// test/mavlink/decode_frames.py.
#include <gtest/gtest.h>

#include <stdint.h>
#include <string.h>

#include <string>
#include <vector>

#include "MavLink.h"

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

TEST(MavLink, HeartbeatIsAGenericAutopilotOfComponentOne) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    const uint8_t n = p.heartbeat(buf, mav::State::Active);
    ASSERT_EQ(n, mav::kHeartbeatFrame);
    ASSERT_EQ(n, 21u);
    const Frame f = parse(buf, n, kExtraHeartbeat);
    EXPECT_TRUE(f.crc_ok);
    EXPECT_EQ(f.msgid, 0u);
    EXPECT_EQ(f.sysid, 1u);
    EXPECT_EQ(f.compid, 1u);  // MAV_COMP_ID_AUTOPILOT1
    EXPECT_EQ(f.seq, 0u);
    // Wire order: custom_mode (u32), type, autopilot, base_mode, system_status, mavlink_version.
    EXPECT_EQ(u32(f.payload, 0), 0u);
    EXPECT_EQ(u8(f.payload, 4), 0u);  // MAV_TYPE_GENERIC
    EXPECT_EQ(u8(f.payload, 5), 0u);  // MAV_AUTOPILOT_GENERIC (not INVALID = 8)
    EXPECT_EQ(u8(f.payload, 6), 0u);  // base_mode: never armed
    EXPECT_EQ(u8(f.payload, 7), 4u);  // MAV_STATE_ACTIVE
    EXPECT_EQ(u8(f.payload, 8), 3u);  // mavlink_version
}

TEST(MavLink, SequenceCountsAcrossMessagesAndWraps) {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    for (int i = 0; i < 300; ++i) {
        const uint8_t n = (i % 2 == 0) ? p.heartbeat(buf, mav::State::Boot)
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
    ASSERT_EQ(c.frames.size(), 5u);  // the first line is 56 characters: two chunks
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

TEST(MavLink, FrameFilterKeepsMavlinkAwayFromTheConsole) {
    mav::Packer p;
    uint8_t hb[mav::kMaxFrame], st[mav::kMaxFrame];
    const uint8_t n_hb = p.heartbeat(hb, mav::State::Active);
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

    mav::FrameFilter ff;
    std::string text;
    for (uint8_t b : in)
        if (!ff.consume(b)) text += (char)b;
    EXPECT_EQ(text, "status\nstatus\nx");
    EXPECT_EQ(ff.frames(), 4u);
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

}  // namespace
