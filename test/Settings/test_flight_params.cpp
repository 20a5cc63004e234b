// SPDX-License-Identifier: GPL-3.0-or-later
// The flight parameters (lib/Settings/Params): the table (index, name, defaults), set's
// checks, the version 3 record and the upgrade of a version 2 one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "Flight.h"
#include "Params.h"
#include "Settings.h"

TEST(FlightParams, TableIndexNameAndDefaults) {
    const uint16_t n = params::count();
    EXPECT_GE(n, 90u);
    EXPECT_LT(n, 255u);
    params::Info in;
    std::vector<std::string> names;
    for (uint16_t i = 0; i < n; ++i) {
        ASSERT_TRUE(params::info(i, in));
        EXPECT_LE(std::strlen(in.name), params::kNameMax);
        EXPECT_EQ(params::find(in.name), (int16_t)i) << in.name;
        for (const auto& s : names) EXPECT_NE(s, in.name);
        names.push_back(in.name);
    }
    EXPECT_FALSE(params::info(n, in));
    EXPECT_EQ(params::find("rc8_reversed"), params::find("RC8_REVERSED"));
    EXPECT_EQ(params::find("RC9_MIN"), -1);
    const settings::Settings s = settings::defaults();
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("RLL2SRV_P")), 1.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("SERVO3_TRIM")), 1500.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("FLTMODE1")), 0.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("FLTMODE6")), 2.0f);
    EXPECT_FLOAT_EQ(params::get(s, (uint16_t)params::find("THR_FS_VALUE")), 950.0f);
    EXPECT_EQ(s.flight.rcmap[flight::kThrottle], 3);
    EXPECT_TRUE(params::all_valid(s));
}

TEST(FlightParams, SetChecksRangeWholenessAndEndPointOrder) {
    settings::Settings s = settings::defaults();
    const uint16_t p = (uint16_t)params::find("RLL2SRV_P");
    EXPECT_TRUE(params::set(s, p, 1.25f));
    EXPECT_FLOAT_EQ(s.flight.roll.p, 1.25f);
    EXPECT_FALSE(params::set(s, p, 5.0f));
    EXPECT_FALSE(params::set(s, p, std::nanf("")));
    EXPECT_FLOAT_EQ(s.flight.roll.p, 1.25f);
    const uint16_t trim = (uint16_t)params::find("SERVO2_TRIM");
    EXPECT_FALSE(params::set(s, trim, 1500.5f));
    EXPECT_FALSE(params::set(s, trim, 2100.0f)) << "above SERVO2_MAX";
    EXPECT_EQ(s.flight.servo[1].trim_us, 1500);
    EXPECT_TRUE(params::set(s, trim, 1520.0f));
    EXPECT_EQ(s.flight.servo[1].trim_us, 1520);
    const uint16_t rev = (uint16_t)params::find("RC5_REVERSED");
    EXPECT_TRUE(params::set(s, rev, 1.0f));
    EXPECT_EQ(s.flight.rc_reversed, 0x10);
    const uint16_t dec = (uint16_t)params::find("COMPASS_DEC");
    EXPECT_TRUE(params::set(s, dec, 0.1f));
    EXPECT_EQ(s.declination_centideg, 573);  // 0.1 rad = 5.73 deg: the first record's copy
    EXPECT_EQ(params::get(s, dec), 0.1f);    // kept as sent (a ground station compares it)
    EXPECT_EQ(s.declination_rad(), 0.1f);    // and in force as sent
    EXPECT_TRUE(params::set(s, dec, 0.2f));
    EXPECT_EQ(params::get(s, dec), 0.2f);
    EXPECT_EQ(s.declination_centideg, 1146);  // 11.459 deg
    EXPECT_TRUE(settings::is_valid(s));
}

TEST(FlightParams, RecordVersion5RoundTripsAndVersion2StillLoads) {
    EXPECT_EQ(params::flight_bytes(), settings::kFlightBytes);
    settings::Settings in = settings::defaults();
    in.rate_hz = 20;
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("PTCH2SRV_D"), 0.05f));
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("SERVO7_REVERSED"), 1.0f));
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("RC3_MIN"), 1050.0f));
    uint8_t rec[settings::kRecordSize];
    settings::encode(in, rec);
    EXPECT_EQ(rec[2], 5);
    settings::Settings out;
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    for (uint16_t i = 0; i < params::count(); ++i) EXPECT_EQ(params::get(out, i), params::get(in, i)) << i;
    EXPECT_EQ(out.flags & settings::kFlagUpgraded, 0);

    // A version 2 record as the previous firmware wrote it: rate, decl, mode, flags,
    // calibration, CRC; EEPROM beyond it erased.
    uint8_t v2[settings::kRecordSize];
    std::memset(v2, 0xFF, sizeof v2);
    settings::Settings old = settings::defaults();
    old.rate_hz = 25;
    settings::set_declination_centideg(old, -345);
    old.mode = fmt::OutputMode::Csv;
    old.flags = settings::kFlagMagCalibrated;
    old.cal.mag_offset_uT = linalg::Vector3f(8.0f, -5.0f, 3.0f);
    settings::encode(old, v2);
    v2[2] = 2;
    v2[3] = settings::kV2PayloadLength;
    std::memset(v2 + 4 + settings::kV2PayloadLength, 0xFF, settings::kRecordSize - 4u - settings::kV2PayloadLength);
    const uint16_t crc = settings::crc16(v2, 4 + settings::kV2PayloadLength);
    v2[4 + settings::kV2PayloadLength] = (uint8_t)(crc & 0xFF);
    v2[5 + settings::kV2PayloadLength] = (uint8_t)(crc >> 8);
    settings::Settings up;
    ASSERT_EQ(settings::decode(v2, up), settings::LoadResult::Ok);
    EXPECT_EQ(up.rate_hz, 25);
    EXPECT_EQ(up.declination_centideg, -345);
    EXPECT_EQ(up.mode, fmt::OutputMode::Csv);
    EXPECT_TRUE(up.cal.mag_offset_uT == old.cal.mag_offset_uT);
    EXPECT_EQ(up.flags, settings::kFlagMagCalibrated | settings::kFlagUpgraded);
    EXPECT_FLOAT_EQ(up.flight.roll.p, 1.0f) << "flight settings at defaults";
    // Saved again: this version, the upgrade flag not stored.
    settings::encode(up, rec);
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    EXPECT_EQ(out.flags, settings::kFlagMagCalibrated);
    // A v2 record with a bad CRC is refused, never misread.
    v2[10] ^= 0x40;
    EXPECT_EQ(settings::decode(v2, up), settings::LoadResult::BadCrc);
}

// TRIM_PITCH_CD: ArduPlane's name, centi-degrees within +-45 deg, 0 by default; the last
// flight row, so that a version 3 record (without it) loads whole with it at its default.
TEST(FlightParams, TrimPitchIsNewInVersion4AndVersion3StillLoads) {
    settings::Settings s = settings::defaults();
    const int16_t p = params::find("TRIM_PITCH_CD");
    ASSERT_GE(p, 0);
    EXPECT_EQ(s.flight.trim_pitch_cd, 0);
    EXPECT_FALSE(params::set(s, (uint16_t)p, 4501.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)p, -4501.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)p, 12.5f));
    EXPECT_TRUE(params::set(s, (uint16_t)p, -140.0f));
    EXPECT_EQ(s.flight.trim_pitch_cd, -140);
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("SERVO8_MAX"), 1900.0f));  // the last row before it
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("RC2_REVERSED"), 1.0f));
    s.rate_hz = 20;
    uint8_t rec[settings::kRecordSize];
    settings::encode(s, rec);
    settings::Settings out;
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    EXPECT_EQ(out.flight.trim_pitch_cd, -140);

    // The same settings as version 3 wrote them: its payload is this one's first part.
    uint8_t v3[settings::kRecordSize];
    std::memcpy(v3, rec, sizeof v3);
    v3[2] = 3;
    v3[3] = settings::kV3PayloadLength;
    const uint16_t crc = settings::crc16(v3, 4 + settings::kV3PayloadLength);
    v3[4 + settings::kV3PayloadLength] = (uint8_t)(crc & 0xFF);
    v3[5 + settings::kV3PayloadLength] = (uint8_t)(crc >> 8);
    settings::Settings up;
    ASSERT_EQ(settings::decode(v3, up), settings::LoadResult::Ok);
    EXPECT_EQ(up.flags & settings::kFlagUpgraded, 0);
    EXPECT_EQ(up.flight.trim_pitch_cd, 0) << "not in version 3: its default";
    for (uint16_t i = 0; i < params::count(); ++i)
        if ((int16_t)i != p) EXPECT_EQ(params::get(up, i), params::get(s, i)) << i;
    // Version 3's length with another version byte, or version 3's byte with this length: refused.
    v3[2] = 4;
    const uint16_t crc4 = settings::crc16(v3, 4 + settings::kV3PayloadLength);
    v3[4 + settings::kV3PayloadLength] = (uint8_t)(crc4 & 0xFF);
    v3[5 + settings::kV3PayloadLength] = (uint8_t)(crc4 >> 8);
    EXPECT_EQ(settings::decode(v3, up), settings::LoadResult::OldVersion);
}

// Version 5: the GPS's and the barometer's rows after version 4's. A version 4 record loads
// whole with them at their defaults; GND_ABS_PRESS, measured at each start, is in no record.
TEST(FlightParams, GpsRowsAreNewInVersion5AndVersion4StillLoads) {
    settings::Settings s = settings::defaults();
    EXPECT_EQ(s.flight.gps_type, 1);
    EXPECT_EQ(s.flight.gps_navfilter, 8);
    EXPECT_FLOAT_EQ(s.flight.ahrs_gps_gain, 1.0f);
    EXPECT_EQ(s.flight.ahrs_gps_use, 1);
    EXPECT_EQ(s.flight.ahrs_gps_minsats, 6);
    EXPECT_FLOAT_EQ(s.flight.gnd_temp_c, 0.0f);
    EXPECT_FLOAT_EQ(s.gnd_abs_press_pa, 0.0f);
    EXPECT_FALSE(params::set(s, (uint16_t)params::find("GPS_NAVFILTER"), 9.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)params::find("AHRS_GPS_GAIN"), 10.5f));
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("TRIM_PITCH_CD"), -140.0f));  // version 4's last row
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("GPS_TYPE"), 5.0f));
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("AHRS_GPS_GAIN"), 0.5f));
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("GND_TEMP"), 31.5f));
    ASSERT_TRUE(params::set(s, (uint16_t)params::find("GND_ABS_PRESS"), 89876.0f));
    uint8_t rec[settings::kRecordSize];
    settings::encode(s, rec);
    settings::Settings out;
    ASSERT_EQ(settings::decode(rec, out), settings::LoadResult::Ok);
    EXPECT_EQ(out.flight.gps_type, 5);
    EXPECT_FLOAT_EQ(out.flight.ahrs_gps_gain, 0.5f);
    EXPECT_FLOAT_EQ(out.flight.gnd_temp_c, 31.5f);
    EXPECT_FLOAT_EQ(out.gnd_abs_press_pa, 0.0f) << "measured at each start, not stored";

    uint8_t v4[settings::kRecordSize];
    std::memcpy(v4, rec, sizeof v4);
    v4[2] = 4;
    v4[3] = settings::kV4PayloadLength;
    const uint16_t crc = settings::crc16(v4, 4 + settings::kV4PayloadLength);
    v4[4 + settings::kV4PayloadLength] = (uint8_t)(crc & 0xFF);
    v4[5 + settings::kV4PayloadLength] = (uint8_t)(crc >> 8);
    settings::Settings up;
    ASSERT_EQ(settings::decode(v4, up), settings::LoadResult::Ok);
    EXPECT_EQ(up.flight.trim_pitch_cd, -140) << "version 4's rows kept";
    EXPECT_EQ(up.flight.gps_type, 1) << "not in version 4: its default";
    EXPECT_FLOAT_EQ(up.flight.ahrs_gps_gain, 1.0f);
    EXPECT_FLOAT_EQ(up.flight.gnd_temp_c, 0.0f);
}

// The second record's rows (Settings::vehicle) are not in the first record's flight
// bytes, and vehicle_part / decode_vehicle carry them whole; a shorter (older) second
// record leaves the values it lacks at their defaults.
TEST(FlightParams, VehicleRowsGoInTheSecondRecordOnly) {
    EXPECT_EQ(params::flight_bytes(), settings::kFlightBytes);
    const uint16_t n = params::vehicle_bytes();
    ASSERT_GE(n, 1u);
    ASSERT_LE(n, 240u);
    settings::Settings in = settings::defaults();
    ASSERT_TRUE(params::set(in, (uint16_t)params::find("ARMING_REQUIRE"), 0.0f));
    uint8_t flight_in[settings::kFlightBytes], flight_def[settings::kFlightBytes];
    params::encode_flight(in, flight_in);
    params::encode_flight(settings::defaults(), flight_def);
    EXPECT_EQ(0, memcmp(flight_in, flight_def, sizeof flight_in));
    uint8_t bytes[240];
    params::vehicle_part(in, 0, (uint8_t)n, bytes);
    settings::Settings out = settings::defaults();
    params::decode_vehicle(bytes, (uint8_t)n, out);
    EXPECT_EQ(out.vehicle.arming_require, 0);
    settings::Settings older = settings::defaults();
    params::decode_vehicle(bytes, 0, older);
    EXPECT_EQ(older.vehicle.arming_require, 1);
}
