// SPDX-License-Identifier: GPL-3.0-or-later
// lib/GPS NmeaParser: checksums, fields, hemispheres, empty fields, lengths.
#include <gtest/gtest.h>

#include <string>

#include "GpsReceiver.h"
#include "NmeaParser.h"
#include "gps_test_frames.h"

using gps::FixType;
using gps::NmeaParser;
using Msg = NmeaParser::Message;

namespace {

std::vector<Msg> feed(NmeaParser& p, const std::string& text) {
    std::vector<Msg> out;
    for (char c : text) {
        const Msg m = p.feed((uint8_t)c);
        if (m != Msg::kNone) out.push_back(m);
    }
    return out;
}

const std::string kGgaSw = "GPGGA,150000.20,0708.10270,S,07307.16526,W,1,08,0.90,1028.3,M,9.0,M,,";
const std::string kRmcSw = "GPRMC,150000.20,A,0708.10270,S,07307.16526,W,15.552,90.00,031013,,,A";

}  // namespace

TEST(NmeaChecksum, Pubx41) {
    const std::string body = "PUBX,41,1,0003,0001,38400,0";
    EXPECT_EQ(gps::nmea::checksum(body.data(), body.size()), 0x26);
    EXPECT_EQ(std::string(gps::kPubx41), "$" + body + "*26\r\n");
}

TEST(NmeaParser, SouthWestFix) {
    gps::Fix work;
    NmeaParser p(work);
    EXPECT_EQ(feed(p, gpstest::sentence(kGgaSw)), std::vector<Msg>{Msg::kOther});  // RMC not yet
    EXPECT_EQ(feed(p, gpstest::sentence(kRmcSw)), std::vector<Msg>{Msg::kFix});
    const gps::Fix& f = p.fix();
    EXPECT_EQ(f.lat_e7, -71350450);   // 7 deg 8.1027' = 7.135045 deg
    EXPECT_EQ(f.lon_e7, -731194210);  // 73 deg 7.16526' = 73.119421 deg
    EXPECT_EQ(f.alt_msl_mm, 1028300);
    EXPECT_EQ(f.sats, 8);
    EXPECT_EQ(f.hdop_cm, 90);
    EXPECT_EQ(f.ground_speed_cm_s, 800u);  // 15.552 kn = 8.0006 m/s
    EXPECT_EQ(f.course_e5, 9000000);
    EXPECT_EQ(f.vel_ned_cm_s[0], 0);
    EXPECT_EQ(f.vel_ned_cm_s[1], 800);
    EXPECT_FALSE(f.have_vertical_velocity);
    EXPECT_EQ(f.fix, FixType::k3D);
    EXPECT_EQ(f.itow_ms, (15u * 3600u) * 1000u + 200u);
    EXPECT_EQ(p.counters().sentences, 2u);
}

TEST(NmeaParser, NorthEastAnyTalkerLowerCaseChecksumEitherOrder) {
    gps::Fix work;
    NmeaParser p(work);
    feed(p, gpstest::sentence("GNRMC,010203.00,A,4807.038,N,01131.000,E,0.000,,230394,,,A", true));
    EXPECT_EQ(feed(p, gpstest::sentence("GNGGA,010203.00,4807.038,N,01131.000,E,2,12,1.5,-12.5,M,47.0,M,,")),
              std::vector<Msg>{Msg::kFix});
    EXPECT_EQ(p.fix().lat_e7, 481173000);  // 48 + 7.038/60
    EXPECT_EQ(p.fix().lon_e7, 115166667);  // 11 + 31/60, rounded
    EXPECT_EQ(p.fix().alt_msl_mm, -12500);
    EXPECT_EQ(p.fix().ground_speed_cm_s, 0u);
}

// No fix: quality 0 and empty fields; the last position is kept, nothing reads garbage.
TEST(NmeaParser, EmptyFieldsNoFix) {
    gps::Fix work;
    NmeaParser p(work);
    feed(p, gpstest::sentence(kGgaSw));
    feed(p, gpstest::sentence(kRmcSw));
    feed(p, gpstest::sentence("GPGGA,150001.00,,,,,0,02,99.99,,,,,,"));
    EXPECT_EQ(feed(p, gpstest::sentence("GPRMC,150001.00,V,,,,,,,031013,,,N")), std::vector<Msg>{Msg::kFix});
    EXPECT_EQ(p.fix().fix, FixType::kNoFix);
    EXPECT_EQ(p.fix().sats, 2);
    EXPECT_EQ(p.fix().lat_e7, -71350450);
}

// GSA's mode 2: a 2D fix; a fix needs RMC's 'A'.
TEST(NmeaParser, GsaModeAndRmcStatus) {
    gps::Fix work;
    NmeaParser p(work);
    feed(p, gpstest::sentence("GPGSA,A,2,01,02,03,,,,,,,,,,2.0,1.5,1.3"));
    feed(p, gpstest::sentence(kGgaSw));
    feed(p, gpstest::sentence(kRmcSw));
    EXPECT_EQ(p.fix().fix, FixType::k2D);
    feed(p, gpstest::sentence("GPGSA,A,3,01,02,03,04,,,,,,,,,2.0,1.5,1.3"));
    feed(p, gpstest::sentence("GPGGA,150000.40,0708.10270,S,07307.16526,W,1,08,0.90,1028.3,M,9.0,M,,"));
    feed(p, gpstest::sentence("GPRMC,150000.40,V,0708.10270,S,07307.16526,W,15.552,90.00,031013,,,A"));
    EXPECT_EQ(p.fix().fix, FixType::kNoFix);
}

TEST(NmeaParser, VtgUpdatesSpeedAndCourse) {
    gps::Fix work;
    NmeaParser p(work);
    feed(p, gpstest::sentence(kRmcSw));
    EXPECT_EQ(feed(p, gpstest::sentence("GPVTG,180.00,T,,M,1.944,N,3.600,K,A")), std::vector<Msg>{Msg::kOther});
    EXPECT_EQ(feed(p, gpstest::sentence(kGgaSw)), std::vector<Msg>{Msg::kFix});
    EXPECT_EQ(p.fix().ground_speed_cm_s, 100u);
    EXPECT_EQ(p.fix().vel_ned_cm_s[0], -100);
    EXPECT_EQ(p.fix().course_e5, 18000000);
}

TEST(NmeaParser, BadChecksumAndMalformed) {
    gps::Fix work;
    NmeaParser p(work);
    std::string bad = gpstest::sentence(kGgaSw);
    bad[10] = '9';
    EXPECT_TRUE(feed(p, bad).empty());
    EXPECT_EQ(p.counters().bad_checksum, 1u);
    EXPECT_TRUE(feed(p, "$" + kGgaSw + "\r\n").empty());  // no *hh
    EXPECT_TRUE(feed(p, "$" + kGgaSw + "*G1\r\n").empty());
    EXPECT_EQ(p.counters().malformed, 2u);
    // Over the length limit: dropped even with a right checksum.
    EXPECT_TRUE(feed(p, gpstest::sentence("GPTXT," + std::string(80, 'x'))).empty());
    EXPECT_EQ(p.counters().malformed, 3u);
    // A field longer than any of ours.
    EXPECT_TRUE(feed(p, gpstest::sentence("GPGGA,150000.2000000000000,,,,,0,00,,,,,,,")).empty());
    EXPECT_EQ(p.counters().malformed, 4u);
    // A sentence broken off by a new '$' is dropped, the new one read.
    EXPECT_EQ(feed(p, "$GPGGA,1500" + gpstest::sentence(kRmcSw)), std::vector<Msg>{Msg::kOther});
    EXPECT_EQ(p.counters().malformed, 5u);
    EXPECT_EQ(p.counters().sentences, 1u);
}

// A sentence split between reads at every character gives the same fix.
TEST(NmeaParser, SplitAtEveryByte) {
    const std::string text = gpstest::sentence(kGgaSw) + gpstest::sentence(kRmcSw);
    for (size_t cut = 0; cut <= text.size(); ++cut) {
        gps::Fix work;
        NmeaParser p(work);
        std::vector<Msg> a = feed(p, text.substr(0, cut)), b = feed(p, text.substr(cut));
        a.insert(a.end(), b.begin(), b.end());
        ASSERT_EQ(a.size(), 2u) << cut;
        EXPECT_EQ(a.back(), Msg::kFix);
        EXPECT_EQ(p.fix().lat_e7, -71350450);
    }
}

TEST(NmeaNumbers, ParseDecimalAndAngle) {
    int32_t v = 0;
    EXPECT_TRUE(gps::nmea::parse_decimal("12.3456", 2, v));
    EXPECT_EQ(v, 1234);
    EXPECT_TRUE(gps::nmea::parse_decimal("-0.5", 3, v));
    EXPECT_EQ(v, -500);
    EXPECT_TRUE(gps::nmea::parse_decimal("7", 2, v));
    EXPECT_EQ(v, 700);
    EXPECT_FALSE(gps::nmea::parse_decimal("", 2, v));
    EXPECT_FALSE(gps::nmea::parse_decimal("1.2.3", 2, v));
    EXPECT_FALSE(gps::nmea::parse_decimal("1e3", 2, v));
    EXPECT_FALSE(gps::nmea::parse_decimal("1234567890", 0, v));
    EXPECT_FALSE(gps::nmea::parse_decimal("99999999", 3, v));  // overflows 10^3 scaling
    EXPECT_TRUE(gps::nmea::parse_angle_e7("17959.99999", 3, v));
    EXPECT_EQ(v, 1799999998);
    EXPECT_FALSE(gps::nmea::parse_angle_e7("0760.000", 2, v));  // 60 minutes
    EXPECT_FALSE(gps::nmea::parse_angle_e7("07", 2, v));
    EXPECT_FALSE(gps::nmea::parse_angle_e7("07-8.1", 2, v));
}
