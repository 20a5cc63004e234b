// SPDX-License-Identifier: GPL-3.0-or-later
// lib/GPS UbxParser: framing, checksums, lengths, and the fix NAV-POSLLH/VELNED/SOL/STATUS make.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "UbxParser.h"
#include "gps_test_frames.h"

using gps::FixType;
using gps::UbxParser;
using gpstest::Bytes;
using Msg = UbxParser::Message;

namespace {

// Feeds bytes; the messages that ended.
std::vector<Msg> feed(UbxParser& p, const Bytes& bytes) {
    std::vector<Msg> out;
    for (uint8_t b : bytes) {
        const Msg m = p.feed(b);
        if (m != Msg::kNone) out.push_back(m);
    }
    return out;
}

Bytes cat(std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& b : parts) out.insert(out.end(), b.begin(), b.end());
    return out;
}

}  // namespace

// ArduPilot's APM2 probe, written out by hand: CFG-MSG NAV-SOL rate 1 ends 0x12 0x4F.
TEST(UbxChecksum, KnownFrame) {
    const uint8_t payload[] = {0x01, 0x06, 0x01};
    uint8_t out[16];
    ASSERT_EQ(gps::ubx::write_frame(out, 0x06, 0x01, payload, 3), 11);
    const uint8_t expected[] = {0xB5, 0x62, 0x06, 0x01, 0x03, 0x00, 0x01, 0x06, 0x01, 0x12, 0x4F};
    for (int i = 0; i < 11; ++i) EXPECT_EQ(out[i], expected[i]) << i;
    // CFG-RATE 200 ms, navRate 1, timeRef 0 (u-blox's own example of a 5 Hz rate).
    const uint8_t rate[] = {0xC8, 0x00, 0x01, 0x00, 0x00, 0x00};
    gps::ubx::write_frame(out, 0x06, 0x08, rate, 6);
    EXPECT_EQ(out[12], 0xDD);
    EXPECT_EQ(out[13], 0x68);
}

TEST(UbxParser, DecodesAnEpoch) {
    gps::Fix work;
    UbxParser p(work);
    const Bytes bytes = cat({gpstest::posllh(1000, -71350450, -731194210, 1028300, 1200),
                             gpstest::sol(1000, 3, 0x0D, 9, 180),
                             gpstest::velned(1000, -150, 250, -30, 292, 12103000)});
    const std::vector<Msg> got = feed(p, bytes);
    ASSERT_EQ(got.size(), 3u);
    EXPECT_EQ(got[0], Msg::kOther);
    EXPECT_EQ(got[1], Msg::kOther);
    EXPECT_EQ(got[2], Msg::kFix);
    const gps::Fix& f = p.fix();
    EXPECT_EQ(f.itow_ms, 1000u);
    EXPECT_EQ(f.lat_e7, -71350450);
    EXPECT_EQ(f.lon_e7, -731194210);
    EXPECT_EQ(f.alt_msl_mm, 1028300);
    EXPECT_EQ(f.h_acc_mm, 1200u);
    EXPECT_EQ(f.vel_ned_cm_s[0], -150);
    EXPECT_EQ(f.vel_ned_cm_s[1], 250);
    EXPECT_EQ(f.vel_ned_cm_s[2], -30);
    EXPECT_EQ(f.ground_speed_cm_s, 292u);
    EXPECT_EQ(f.course_e5, 12103000);
    EXPECT_EQ(f.speed_acc_cm_s, 30u);
    EXPECT_EQ(f.sats, 9);
    EXPECT_EQ(f.hdop_cm, 180);
    EXPECT_EQ(f.fix, FixType::k3D);
    EXPECT_TRUE(f.have_vertical_velocity);
    EXPECT_EQ(p.counters().frames, 3u);
}

TEST(UbxParser, TheWeekOfNavSolGivesUnixTime) {
    gps::Fix work;
    UbxParser p(work);
    // GPS week 1760, 399616370 ms into it (the simulator's start): the GPS epoch's UNIX
    // 315964800 s + 1760 weeks + 399616.370 s - 18 leap seconds = 1380812398.370 s; 250 ms
    // after the fix arrived, 0.25 s later.
    const Bytes bytes = cat({gpstest::posllh(399616370, -71350450, -731194210, 1028300, 1200),
                             gpstest::sol(399616370, 3, 0x0D, 9, 180, 1760),
                             gpstest::velned(399616370, -150, 250, -30, 292, 12103000)});
    const std::vector<Msg> got = feed(p, bytes);
    ASSERT_EQ(got.back(), Msg::kFix);
    gps::Fix f = p.fix();
    EXPECT_EQ(f.week, 1760u);
    f.received_ms = 5000u;
    EXPECT_EQ(gps::unix_time_us(f, 5250u), 1380812398620000ull);
    f.fix = FixType::kNoFix;
    EXPECT_EQ(gps::unix_time_us(f, 5250u), 0u) << "no fix: no time";
    f.fix = FixType::k3D;
    f.week = 0;
    EXPECT_EQ(gps::unix_time_us(f, 5250u), 0u) << "no week (NMEA): no time";
}

// A frame split between two reads at every byte decodes the same.
TEST(UbxParser, FramesSplitAtEveryByte) {
    const Bytes bytes = gpstest::epoch(5000, 71350450, -731194210, 1500);
    for (size_t cut = 0; cut <= bytes.size(); ++cut) {
        gps::Fix work;
        UbxParser p(work);
        const std::vector<Msg> first = feed(p, Bytes(bytes.begin(), bytes.begin() + (long)cut));
        const std::vector<Msg> second = feed(p, Bytes(bytes.begin() + (long)cut, bytes.end()));
        ASSERT_EQ(first.size() + second.size(), 4u) << cut;
        EXPECT_EQ(second.empty() ? first.back() : second.back(), Msg::kFix) << cut;
        EXPECT_EQ(p.fix().vel_ned_cm_s[0], 1500) << cut;
        EXPECT_EQ(p.fix().lat_e7, 71350450) << cut;
    }
}

// Random bytes between frames (sync bytes among them) lose no frame.
TEST(UbxParser, GarbageBetweenFrames) {
    std::mt19937 rng(7);
    gps::Fix work;
    UbxParser p(work);
    int fixes = 0;
    for (uint32_t k = 0; k < 200; ++k) {
        Bytes junk(rng() % 40);
        for (uint8_t& b : junk) b = (uint8_t)rng();
        if (!junk.empty() && rng() % 2) junk.back() = 0xB5;  // a false sync right before the frame
        feed(p, junk);
        for (Msg m : feed(p, gpstest::epoch(200 * k, 71350450 + (int32_t)k, 0)))
            if (m == Msg::kFix) {
                ++fixes;
                EXPECT_EQ(p.fix().lat_e7, 71350450 + (int32_t)k);
            }
    }
    EXPECT_EQ(fixes, 200);
}

TEST(UbxParser, BadChecksumCountedAndDropped) {
    gps::Fix work;
    UbxParser p(work);
    Bytes bad = gpstest::posllh(1000, 1, 2, 3);
    bad[10] ^= 0x40;  // a payload bit flipped on the line
    EXPECT_TRUE(feed(p, bad).empty());
    EXPECT_EQ(p.counters().bad_checksum, 1u);
    Bytes bad_ck = gpstest::posllh(1000, 1, 2, 3);
    bad_ck.back() ^= 1;
    EXPECT_TRUE(feed(p, bad_ck).empty());
    EXPECT_EQ(p.counters().bad_checksum, 2u);
    // The next good frame after both.
    EXPECT_EQ(feed(p, gpstest::epoch(1200, 4, 5)).back(), Msg::kFix);
    EXPECT_EQ(p.fix().lat_e7, 4);
    EXPECT_EQ(p.counters().frames, 4u);
}

// Longer than the buffer: skipped while summed (a valid frame, not decoded); beyond
// kMaxSkip: noise, and the very next frame is found.
TEST(UbxParser, OversizedLengths) {
    gps::Fix work;
    UbxParser p(work);
    const Bytes long_frame = gpstest::frame(0x01, 0x30, Bytes(300, 0xB5));  // NAV-SVINFO-sized, sync bytes inside
    EXPECT_EQ(feed(p, long_frame), std::vector<Msg>{Msg::kOther});
    EXPECT_EQ(p.counters().too_long, 1u);
    EXPECT_EQ(p.counters().frames, 1u);
    // A NAV-POSLLH that claims 200 bytes: too long for its buffer, never decoded as one.
    Bytes fake = gpstest::frame(0x01, 0x02, Bytes(200, 0x11));
    EXPECT_EQ(feed(p, fake), std::vector<Msg>{Msg::kOther});
    EXPECT_EQ(p.fix().lat_e7, 0);
    // A length of 60000: noise; the frame right after it is decoded.
    const Bytes noise = {0xB5, 0x62, 0x01, 0x02, 0x60, 0xEA};
    EXPECT_EQ(feed(p, cat({noise, gpstest::epoch(400, 9, 8)})).back(), Msg::kFix);
    EXPECT_EQ(p.fix().lat_e7, 9);
    EXPECT_EQ(p.counters().too_long, 3u);
}

// A known message with the wrong length is not decoded.
TEST(UbxParser, WrongLengthNotDecoded) {
    gps::Fix work;
    UbxParser p(work);
    Bytes short_pos = gpstest::frame(0x01, 0x02, Bytes(20, 0x22));
    feed(p, short_pos);
    feed(p, gpstest::velned(0x22222222u, 1, 2, 3, 4, 5));
    EXPECT_NE(p.fix().lat_e7, 0x22222222);
}

// A fix only when POSLLH and VELNED carry the same iTOW.
TEST(UbxParser, ItowPairing) {
    gps::Fix work;
    UbxParser p(work);
    EXPECT_EQ(feed(p, gpstest::posllh(1000, 10, 20, 30)).back(), Msg::kOther);
    EXPECT_EQ(feed(p, gpstest::velned(1200, 1, 2, 3, 4, 5)).back(), Msg::kOther);  // another epoch
    EXPECT_EQ(feed(p, gpstest::posllh(1200, 11, 21, 31)).back(), Msg::kFix);       // pairs with it
    EXPECT_EQ(p.fix().itow_ms, 1200u);
    EXPECT_EQ(p.fix().lat_e7, 11);
    EXPECT_EQ(p.fix().vel_ned_cm_s[0], 1);
    // Each half once: another VELNED of the same epoch is no second fix.
    EXPECT_EQ(feed(p, gpstest::velned(1200, 1, 2, 3, 4, 5)).back(), Msg::kOther);
    // VELNED missing from an epoch: no fix until the next epoch's pair.
    EXPECT_EQ(feed(p, gpstest::posllh(1400, 12, 22, 32)).back(), Msg::kOther);
    EXPECT_EQ(feed(p, gpstest::posllh(1600, 13, 23, 33)).back(), Msg::kOther);
    EXPECT_EQ(feed(p, gpstest::velned(1600, 7, 2, 3, 4, 5)).back(), Msg::kFix);
    EXPECT_EQ(p.fix().lat_e7, 13);
}

TEST(UbxParser, FixTypeNeedsTheValidFlag) {
    struct Case {
        uint8_t gps_fix, flags;
        FixType want;
    } cases[] = {{3, 0x0D, FixType::k3D}, {3, 0x0C, FixType::kNoFix}, {2, 0x01, FixType::k2D},
                 {2, 0x00, FixType::kNoFix}, {0, 0x00, FixType::kNoFix}, {4, 0x01, FixType::k3D},
                 {1, 0x01, FixType::kNoFix}, {5, 0x01, FixType::kNoFix}};
    for (const Case& c : cases) {
        gps::Fix work;
        UbxParser p(work);
        feed(p, gpstest::epoch(1000, 1, 2, 0, 8, c.gps_fix, c.flags));
        EXPECT_EQ(p.fix().fix, c.want) << (int)c.gps_fix << " " << (int)c.flags;
    }
    // NAV-STATUS alone (no SOL) decides too.
    gps::Fix work;
    UbxParser p(work);
    feed(p, cat({gpstest::status(1000, 3, 0x01), gpstest::posllh(1000, 1, 2, 3), gpstest::velned(1000, 0, 0, 0, 0, 0)}));
    EXPECT_EQ(p.fix().fix, FixType::k3D);
    feed(p, cat({gpstest::status(1200, 3, 0x00), gpstest::posllh(1200, 1, 2, 3), gpstest::velned(1200, 0, 0, 0, 0, 0)}));
    EXPECT_EQ(p.fix().fix, FixType::kNoFix);
}

TEST(UbxParser, AcksAndNav5) {
    gps::Fix work;
    UbxParser p(work);
    EXPECT_EQ(feed(p, gpstest::ack(true, 0x06, 0x08)).back(), Msg::kAck);
    EXPECT_EQ(p.acked_class(), 0x06);
    EXPECT_EQ(p.acked_id(), 0x08);
    EXPECT_EQ(feed(p, gpstest::ack(false, 0x06, 0x24)).back(), Msg::kNak);
    EXPECT_EQ(p.acked_id(), 0x24);
    EXPECT_EQ(feed(p, gpstest::nav5(8)).back(), Msg::kNav5);
    EXPECT_EQ(p.dyn_model(), 8);
}

// A repeated first sync byte (0xB5 0xB5 0x62) still starts the frame.
TEST(UbxParser, RepeatedSync) {
    gps::Fix work;
    UbxParser p(work);
    EXPECT_EQ(feed(p, cat({Bytes{0xB5}, gpstest::ack(true, 6, 1)})).back(), Msg::kAck);
}
