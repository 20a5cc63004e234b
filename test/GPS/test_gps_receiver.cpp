// SPDX-License-Identifier: GPL-3.0-or-later
// lib/GPS Receiver: detection, the u-blox configuration's order, time-outs, the fix's
// quality and glitches, on a fake clock and a fake serial port.
#include <gtest/gtest.h>

#include <string>

#include "GpsReceiver.h"
#include "gps_test_frames.h"

using gps::Event;
using gps::Quality;
using gps::Receiver;
using gpstest::Bytes;

namespace {

struct FakePort {
    std::vector<uint32_t> bauds;  // every set_baud
    std::vector<Bytes> writes;    // every write
    uint8_t room = 255;
};

void set_baud(void* ctx, uint32_t baud) { static_cast<FakePort*>(ctx)->bauds.push_back(baud); }
uint8_t room(void* ctx) { return static_cast<FakePort*>(ctx)->room; }
void write(void* ctx, const uint8_t* data, uint8_t len) {
    static_cast<FakePort*>(ctx)->writes.push_back(Bytes(data, data + len));
}

struct Rig {
    FakePort port;
    const gps::Port seam{&port, set_baud, room, write};
    Receiver rx{seam};
    uint32_t now_ms = 0;
    uint8_t events = 0;  // accumulated

    void begin(gps::Type type, uint8_t nav_filter = 8) {
        gps::Config c;
        c.type = type;
        c.nav_filter = nav_filter;
        rx.begin(c, now_ms);
    }
    // Runs update() every 2 ms for ms milliseconds.
    void run(uint32_t ms) {
        for (uint32_t t = 0; t < ms; t += 2) {
            now_ms += 2;
            rx.update(now_ms);
            events |= rx.take_events();
        }
    }
    void feed(const Bytes& bytes) {
        for (uint8_t b : bytes) rx.feed(b, now_ms);
        events |= rx.take_events();
    }
    void feed(const std::string& text) { feed(Bytes(text.begin(), text.end())); }
    bool take(uint8_t event) {
        const bool had = (events & event) != 0;
        events = (uint8_t)(events & ~event);
        return had;
    }
};

std::string text(const Bytes& b) { return std::string(b.begin(), b.end()); }
bool is_frame(const Bytes& b, uint8_t cls, uint8_t id) { return b.size() >= 8 && b[0] == 0xB5 && b[2] == cls && b[3] == id; }

// The configured u-blox: one epoch every 200 ms, from now for ms milliseconds.
void stream(Rig& r, uint32_t ms, uint32_t& itow, int32_t lat_e7, uint8_t sats = 10, uint8_t fix = 3, uint8_t flags = 0x0D) {
    for (uint32_t t = 0; t < ms; t += 200) {
        r.feed(gpstest::epoch(itow, lat_e7, 0, 0, sats, fix, flags));
        itow += 200;
        r.run(200);
    }
}

// Found and configured at 38400 (the module answers the first probes).
void configured(Rig& r) {
    r.begin(gps::Type::kAuto);
    r.run(10);
    r.feed(gpstest::ack(true, 0x06, 0x01));
    for (int i = 0; i < 10; ++i) r.run(2);
    r.feed(gpstest::nav5(8));
    r.run(2);
    ASSERT_TRUE(r.rx.configured());
    r.events = 0;
}

}  // namespace

// GPS_TYPE 0: nothing sent, no baud set, bytes ignored.
TEST(GpsReceiver, TypeNoneIsSilent) {
    Rig r;
    r.begin(gps::Type::kNone);
    r.feed(gpstest::epoch(0, 1, 2));
    r.run(20000);
    EXPECT_TRUE(r.port.bauds.empty());
    EXPECT_TRUE(r.port.writes.empty());
    EXPECT_EQ(r.events, 0);
    EXPECT_EQ(r.rx.fix_count(), 0u);
}

// Each baud in ArduPilot's order for 1.2 s, the probes at each; "no GPS" once, after a
// round and 38400 again.
TEST(GpsReceiver, DetectionSequence) {
    Rig r;
    r.begin(gps::Type::kAuto);
    r.run(1200 * 6 - 10);
    EXPECT_FALSE(r.take(gps::kEventNoGpsFound));
    EXPECT_EQ(r.port.bauds, (std::vector<uint32_t>{38400, 57600, 9600, 115200, 4800, 38400}));
    r.run(20);
    EXPECT_TRUE(r.take(gps::kEventNoGpsFound));
    ASSERT_EQ(r.port.writes.size(), 14u);
    for (size_t i = 0; i < 12; i += 2) {
        EXPECT_EQ(text(r.port.writes[i]), "$PUBX,41,1,0003,0001,38400,0*26\r\n");
        EXPECT_EQ(r.port.writes[i + 1], (Bytes{0xB5, 0x62, 0x06, 0x01, 0x03, 0x00, 0x01, 0x06, 0x01, 0x12, 0x4F}));
    }
    r.run(1200 * 5);
    EXPECT_FALSE(r.take(gps::kEventNoGpsFound));  // said once
    EXPECT_FALSE(r.rx.found());
}

// The probes wait for transmit room; the NMEA type is not probed.
TEST(GpsReceiver, ProbesWaitForRoomAndNmeaIsNotProbed) {
    Rig r;
    r.port.room = 20;
    r.begin(gps::Type::kAuto);
    r.run(100);
    EXPECT_TRUE(r.port.writes.empty());
    r.port.room = 40;
    r.run(4);
    EXPECT_EQ(r.port.writes.size(), 2u);
    Rig n;
    n.begin(gps::Type::kNmea);
    n.run(7000);
    EXPECT_TRUE(n.port.writes.empty());
    EXPECT_EQ(n.port.bauds.size(), 6u);
}

// Found at the baud of the first valid frame, then configured one message per pass, in
// order, with the NAV5 dynamic model written because the module's differs.
TEST(GpsReceiver, ConfigurationOrder) {
    Rig r;
    r.begin(gps::Type::kAuto);
    r.run(1300);  // into 57600
    r.run(1200);  // into 9600
    r.port.writes.clear();
    r.feed(Bytes{0x12, 0xB5, 0x62, 0x05});  // a frame broken off takes the next one with it ...
    r.feed(gpstest::ack(true, 0x06, 0x01));
    EXPECT_FALSE(r.rx.found());
    r.feed(gpstest::ack(true, 0x06, 0x01));  // ... not the one after
    EXPECT_TRUE(r.take(gps::kEventFound));
    EXPECT_EQ(r.rx.baud(), 9600u);
    EXPECT_EQ(r.rx.protocol(), gps::Protocol::kUbx);
    r.port.room = 10;  // no room: nothing
    r.run(10);
    EXPECT_TRUE(r.port.writes.empty());
    r.port.room = 255;
    const uint8_t want[][2] = {{0x06, 0x08}, {0x06, 0x01}, {0x06, 0x01}, {0x06, 0x01}, {0x06, 0x01}, {0x06, 0x24}};
    for (size_t i = 0; i < 6; ++i) {
        r.run(2);
        ASSERT_EQ(r.port.writes.size(), i + 1) << i;  // one a pass
        EXPECT_TRUE(is_frame(r.port.writes[i], want[i][0], want[i][1])) << i;
    }
    EXPECT_EQ(r.port.writes[0], (Bytes{0xB5, 0x62, 0x06, 0x08, 0x06, 0x00, 0xC8, 0x00, 0x01, 0x00, 0x00, 0x00, 0xDD, 0x68}));
    const uint8_t ids[] = {0x02, 0x03, 0x06, 0x12};
    for (size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(r.port.writes[1 + i].size(), 11u);
        EXPECT_EQ(r.port.writes[1 + i][6], 0x01);
        EXPECT_EQ(r.port.writes[1 + i][7], ids[i]);
        EXPECT_EQ(r.port.writes[1 + i][8], 1);
    }
    EXPECT_EQ(r.port.writes[5].size(), 8u);  // the poll: no payload
    r.run(100);
    EXPECT_EQ(r.port.writes.size(), 6u);  // waiting for the answer
    r.feed(gpstest::nav5(0));             // portable: not what GPS_NAVFILTER asks
    r.run(2);
    ASSERT_EQ(r.port.writes.size(), 7u);
    const Bytes& set = r.port.writes[6];
    ASSERT_EQ(set.size(), 44u);
    EXPECT_TRUE(is_frame(set, 0x06, 0x24));
    EXPECT_EQ(set[6], 0x01);  // mask: dynModel only
    EXPECT_EQ(set[7], 0x00);
    EXPECT_EQ(set[8], 8);     // airborne < 4 g
    r.run(2);
    ASSERT_EQ(r.port.writes.size(), 8u);  // polled again
    EXPECT_EQ(r.port.writes[7].size(), 8u);
    EXPECT_FALSE(r.take(gps::kEventConfigured));
    r.feed(gpstest::nav5(8));
    EXPECT_TRUE(r.take(gps::kEventConfigured));
    EXPECT_TRUE(r.rx.configured());
    r.run(2000);
    EXPECT_EQ(r.port.bauds.back(), 9600u);  // stays
}

// A poll unanswered for a second is sent again.
TEST(GpsReceiver, Nav5PollRepeated) {
    Rig r;
    r.begin(gps::Type::kUblox);
    r.run(2);
    r.feed(gpstest::ack(true, 0x06, 0x01));
    r.port.writes.clear();
    r.run(1100);
    // RATE, 4 MSG, poll, then the poll again after 1 s; the module answers in between.
    uint32_t itow = 0;
    stream(r, 400, itow, 1);
    int polls = 0;
    for (const Bytes& w : r.port.writes) polls += w.size() == 8u && is_frame(w, 0x06, 0x24);
    EXPECT_EQ(polls, 2);
    EXPECT_FALSE(r.rx.configured());
}

// 5 Hz lost for 15 s: the rates again.
TEST(GpsReceiver, RatesResentWhenFiveHertzLost) {
    Rig r;
    configured(r);
    uint32_t itow = 1000;
    stream(r, 20000, itow, 1);
    r.port.writes.clear();
    for (int k = 0; k < 16; ++k) {  // 1 Hz now
        r.feed(gpstest::epoch(itow, 1, 0));
        itow += 1000;
        r.run(1000);
    }
    ASSERT_FALSE(r.port.writes.empty());
    EXPECT_TRUE(is_frame(r.port.writes[0], 0x06, 0x08));
    EXPECT_FALSE(r.take(gps::kEventLost));
}

// Nothing for 4 s: lost, no fix, detection again from the same baud.
TEST(GpsReceiver, LostAfterSilence) {
    Rig r;
    configured(r);
    uint32_t itow = 0;
    stream(r, 2000, itow, 1);
    EXPECT_EQ(r.rx.quality(), Quality::k3D);
    const uint16_t count = r.rx.fix_count();
    r.run(4100);
    EXPECT_TRUE(r.take(gps::kEventLost));
    EXPECT_TRUE(r.take(gps::kEventQuality));
    EXPECT_EQ(r.rx.fix().fix, gps::FixType::kNoGps);
    EXPECT_EQ(r.rx.fix_count(), count + 1);
    EXPECT_FALSE(r.rx.found());
    EXPECT_EQ(r.port.bauds.back(), 38400u);
    // It talks again: found at once, configured again.
    r.feed(gpstest::epoch(itow, 1, 0));
    EXPECT_TRUE(r.take(gps::kEventFound));
}

// In auto, NMEA is taken only once a u-blox would have left it; NMEA type at once.
TEST(GpsReceiver, NmeaDetection) {
    const std::string gga = gpstest::sentence("GPGGA,150000.00,0708.10270,N,07307.16526,W,1,08,0.90,1028.3,M,9.0,M,,");
    const std::string rmc = gpstest::sentence("GPRMC,150000.00,A,0708.10270,N,07307.16526,W,0.0,,031013,,,A");
    Rig r;
    r.begin(gps::Type::kAuto);
    r.run(4);  // the probes left
    r.feed(gga);
    EXPECT_FALSE(r.rx.found());
    r.run(300);
    r.feed(gga);
    EXPECT_TRUE(r.take(gps::kEventFound));
    EXPECT_EQ(r.rx.protocol(), gps::Protocol::kNmea);
    r.feed(rmc);
    r.feed(gga);
    EXPECT_TRUE(r.take(gps::kEventQuality));
    EXPECT_EQ(r.rx.quality(), Quality::k3D);
    EXPECT_EQ(r.rx.fix().lat_e7, 71350450);
    // UBX is not looked at any more, and no configuration is sent.
    r.port.writes.clear();
    r.feed(gpstest::epoch(0, 5, 5));
    r.run(100);
    EXPECT_EQ(r.rx.fix().lat_e7, 71350450);
    EXPECT_TRUE(r.port.writes.empty());
    // u-blox only: NMEA is never taken.
    Rig u;
    u.begin(gps::Type::kUblox);
    u.run(600);
    u.feed(gga);
    EXPECT_FALSE(u.rx.found());
    Rig n;
    n.begin(gps::Type::kNmea);
    n.feed(gga);
    EXPECT_TRUE(n.rx.found());
}

// In auto with an NMEA receiver, the probes again every 15 s (a u-blox that missed them).
TEST(GpsReceiver, NmeaReprobedInAuto) {
    Rig r;
    r.begin(gps::Type::kAuto);
    r.run(400);
    for (int k = 0; k < 17; ++k) {
        char body[96];
        std::snprintf(body, sizeof body, "GPGGA,1500%02d.00,0708.10270,N,07307.16526,W,1,08,0.90,1028.3,M,9.0,M,,", k);
        r.feed(gpstest::sentence(body));
        if (k == 0) r.port.writes.clear();
        r.run(1000);
    }
    ASSERT_EQ(r.port.writes.size(), 2u);
    EXPECT_EQ(text(r.port.writes[0]), "$PUBX,41,1,0003,0001,38400,0*26\r\n");
    EXPECT_TRUE(r.rx.found());
}

// The fix's quality as the user hears it: 3D, too few satellites, 2D, none.
TEST(GpsReceiver, QualityEvents) {
    Rig r;
    configured(r);
    uint32_t itow = 0;
    stream(r, 400, itow, 1, 10);
    EXPECT_TRUE(r.take(gps::kEventQuality));
    EXPECT_EQ(r.rx.quality(), Quality::k3D);
    stream(r, 400, itow, 1, 10);
    EXPECT_FALSE(r.take(gps::kEventQuality));  // no change, no event
    stream(r, 400, itow, 1, 5);
    EXPECT_TRUE(r.take(gps::kEventQuality));
    EXPECT_EQ(r.rx.quality(), Quality::k3DFewSats);
    stream(r, 400, itow, 1, 3, 2, 0x01);
    EXPECT_EQ(r.rx.quality(), Quality::k2D);
    stream(r, 400, itow, 1, 2, 0, 0);
    EXPECT_TRUE(r.take(gps::kEventQuality));
    EXPECT_EQ(r.rx.quality(), Quality::kNoFix);
    EXPECT_EQ(r.rx.fix().fix, gps::FixType::kNoFix);
    stream(r, 400, itow, 1, 10);
    EXPECT_EQ(r.rx.quality(), Quality::k3D);
}

// A 50 m jump: a glitch, flagged, until the acceleration allowance covers it
// (2 m + 5 m/s/s * t^2 >= 50 m: t ~ 3.1 s), then accepted.
TEST(GpsReceiver, GlitchRejectedThenAccepted) {
    Rig r;
    configured(r);
    uint32_t itow = 0;
    stream(r, 2000, itow, 71350450);
    EXPECT_FALSE(r.take(gps::kEventGlitch));
    const int32_t jump_e7 = 4492;  // 50 m north
    stream(r, 200, itow, 71350450 + jump_e7);
    EXPECT_TRUE(r.take(gps::kEventGlitch));
    EXPECT_TRUE(r.rx.fix().glitching);
    EXPECT_NEAR(r.rx.glitch_m(), 50.0f, 0.5f);
    stream(r, 2800, itow, 71350450 + jump_e7);
    EXPECT_TRUE(r.rx.fix().glitching);
    EXPECT_FALSE(r.take(gps::kEventGlitchOver));
    stream(r, 600, itow, 71350450 + jump_e7);
    EXPECT_TRUE(r.take(gps::kEventGlitchOver));
    EXPECT_FALSE(r.rx.fix().glitching);
}

// A valid frame with a position off the earth is no fix.
TEST(GpsReceiver, AbsurdPositionIsNoFix) {
    Rig r;
    configured(r);
    uint32_t itow = 0;
    stream(r, 400, itow, 71350450);
    EXPECT_EQ(r.rx.quality(), Quality::k3D);
    stream(r, 400, itow, 910000000);  // 91 deg north
    EXPECT_EQ(r.rx.fix().fix, gps::FixType::kNoFix);
    EXPECT_EQ(r.rx.quality(), Quality::kNoFix);
    EXPECT_TRUE(r.take(gps::kEventQuality));
    stream(r, 400, itow, -900000000);  // the south pole is on the earth
    EXPECT_EQ(r.rx.fix().fix, gps::FixType::k3D);
}

// Moving at 20 m/s north is no glitch: the velocity explains the distance.
TEST(GpsReceiver, MotionIsNoGlitch) {
    Rig r;
    configured(r);
    uint32_t itow = 0;
    int32_t lat = 71350450;
    for (int k = 0; k < 50; ++k) {
        r.feed(gpstest::epoch(itow, lat, 0, 2000));
        lat += 359;  // 4 m north each 0.2 s
        itow += 200;
        r.run(200);
    }
    EXPECT_FALSE(r.take(gps::kEventGlitch));
    EXPECT_LT(r.rx.glitch_m(), 0.2f);
}
