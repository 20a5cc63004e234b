// SPDX-License-Identifier: GPL-3.0-or-later
// The EEPROM settings record (lib/Settings/Settings).
#include <gtest/gtest.h>

#include <cstring>

#include "Settings.h"

using settings::LoadResult;
using settings::Settings;

namespace {

Settings sample() {
    Settings s = settings::defaults();
    s.rate_hz = 25;
    settings::set_declination_centideg(s, -1234);
    s.mode = fmt::OutputMode::Csv;
    s.flags = settings::kFlagGyroCalibrated | settings::kFlagMagCalibrated;
    s.cal.gyro_bias_rad_s = linalg::Vector3f(0.01f, -0.02f, 0.03f);
    s.cal.mag_offset_uT = linalg::Vector3f(12.5f, -30.0f, 4.0f);
    s.cal.mag_scale = linalg::Vector3f(1.1f, 0.95f, 1.02f);
    s.cal.mag_cross = linalg::Vector3f(0.01f, -0.03f, 0.002f);
    s.cal.mag_learned_uT = linalg::Vector3f(-1.5f, 0.25f, 3.0f);
    return s;
}

void expect_defaults(const Settings& s) {
    const Settings d = settings::defaults();
    EXPECT_EQ(s.rate_hz, d.rate_hz);
    EXPECT_EQ(s.declination_centideg, d.declination_centideg);
    EXPECT_EQ(s.mode, d.mode);
    EXPECT_EQ(s.flags, d.flags);
    EXPECT_TRUE(s.cal.gyro_bias_rad_s == d.cal.gyro_bias_rad_s);
    EXPECT_TRUE(s.cal.mag_scale == d.cal.mag_scale);
    EXPECT_TRUE(s.cal.mag_cross == d.cal.mag_cross);
    EXPECT_TRUE(s.cal.mag_learned_uT == d.cal.mag_learned_uT);
}

}  // namespace

TEST(Settings, Crc16CheckValue) {
    const char* check = "123456789";
    EXPECT_EQ(settings::crc16(reinterpret_cast<const uint8_t*>(check), 9), 0x29B1);
}

TEST(Settings, Defaults) {
    const Settings d = settings::defaults();
    EXPECT_EQ(d.rate_hz, 50);
    EXPECT_EQ(d.mode, fmt::OutputMode::Plot);
    EXPECT_TRUE(settings::is_valid(d));
}

TEST(Settings, RoundTrip) {
    uint8_t rec[settings::kRecordSize];
    settings::encode(sample(), rec);
    Settings out;
    ASSERT_EQ(settings::decode(rec, out), LoadResult::Ok);
    const Settings in = sample();
    EXPECT_EQ(out.rate_hz, in.rate_hz);
    EXPECT_EQ(out.declination_centideg, in.declination_centideg);
    EXPECT_EQ(out.mode, in.mode);
    EXPECT_EQ(out.flags, in.flags);
    EXPECT_TRUE(out.cal.gyro_bias_rad_s == in.cal.gyro_bias_rad_s);
    EXPECT_TRUE(out.cal.mag_offset_uT == in.cal.mag_offset_uT);
    EXPECT_TRUE(out.cal.mag_scale == in.cal.mag_scale);
    EXPECT_TRUE(out.cal.mag_cross == in.cal.mag_cross);
    EXPECT_TRUE(out.cal.mag_learned_uT == in.cal.mag_learned_uT);
}

TEST(Settings, LayoutIsFixed) {
    uint8_t rec[settings::kRecordSize];
    settings::encode(sample(), rec);
    EXPECT_EQ(rec[0], 'A');
    EXPECT_EQ(rec[1], 'T');
    EXPECT_EQ(rec[2], settings::kSettingsVersion);
    EXPECT_EQ(rec[3], settings::kPayloadLength);
    EXPECT_EQ(rec[4], 25);
    EXPECT_EQ(rec[5], (uint8_t)(-1234 & 0xFF));  // little-endian int16
    EXPECT_EQ(rec[6], (uint8_t)((uint16_t)-1234 >> 8));
}

TEST(Settings, BlankEepromGivesDefaults) {
    uint8_t rec[settings::kRecordSize];
    std::memset(rec, 0xFF, sizeof rec);
    Settings out = sample();
    EXPECT_EQ(settings::decode(rec, out), LoadResult::Blank);
    expect_defaults(out);
    std::memset(rec, 0x00, sizeof rec);
    out = sample();
    EXPECT_EQ(settings::decode(rec, out), LoadResult::Blank);
    expect_defaults(out);
}

TEST(Settings, EveryFlippedBitIsCaught) {
    uint8_t good[settings::kRecordSize];
    settings::encode(sample(), good);
    for (uint8_t i = 0; i < settings::kRecordSize; ++i) {
        for (uint8_t b = 0; b < 8; ++b) {
            uint8_t rec[settings::kRecordSize];
            std::memcpy(rec, good, sizeof rec);
            rec[i] = (uint8_t)(rec[i] ^ (1u << b));
            Settings out = sample();
            EXPECT_NE(settings::decode(rec, out), LoadResult::Ok) << "byte " << int(i) << " bit " << int(b);
            expect_defaults(out);
        }
    }
}

TEST(Settings, CorruptedCrc) {
    uint8_t rec[settings::kRecordSize];
    settings::encode(sample(), rec);
    rec[settings::kRecordSize - 1] ^= 0x01;
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadCrc);
    expect_defaults(out);
}

TEST(Settings, OldVersionGivesDefaults) {
    uint8_t rec[settings::kRecordSize];
    settings::encode(sample(), rec);
    rec[2] = settings::kSettingsVersion - 1;
    // A record that is internally consistent (CRC recomputed) but of another version.
    const uint16_t crc = settings::crc16(rec, 4 + settings::kPayloadLength);
    rec[4 + settings::kPayloadLength] = (uint8_t)(crc & 0xFF);
    rec[5 + settings::kPayloadLength] = (uint8_t)(crc >> 8);
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::OldVersion);
    expect_defaults(out);
}

// What the version-1 firmware wrote (41-byte payload: no cross terms, no learned
// offset), CRC and all: read as another version, never as garbage.
TEST(Settings, Version1RecordGivesDefaults) {
    uint8_t rec[settings::kRecordSize];
    std::memset(rec, 0xFF, sizeof rec);
    const uint8_t v1_payload = 41;
    rec[0] = 'A';
    rec[1] = 'T';
    rec[2] = 1;
    rec[3] = v1_payload;
    rec[4] = 25;
    rec[5] = 0;
    rec[6] = 0;
    rec[7] = 0;
    rec[8] = settings::kFlagMagCalibrated;
    const float v1_cal[9] = {0.0f, 0.0f, 0.0f, 8.0f, -5.0f, 3.0f, 1.0f, 1.0f, 1.0f};
    std::memcpy(rec + 9, v1_cal, sizeof v1_cal);
    const uint16_t crc = settings::crc16(rec, 4 + v1_payload);
    rec[4 + v1_payload] = (uint8_t)(crc & 0xFF);
    rec[5 + v1_payload] = (uint8_t)(crc >> 8);
    Settings out = sample();
    EXPECT_EQ(settings::decode(rec, out), LoadResult::OldVersion);
    expect_defaults(out);
}

TEST(Settings, OutOfRangeLearnedOffsetGivesDefaults) {
    Settings bad = sample();
    bad.cal.mag_learned_uT.z = 500.0f;
    uint8_t rec[settings::kRecordSize];
    settings::encode(bad, rec);
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadValue);
    expect_defaults(out);
    bad = sample();
    bad.cal.mag_cross.x = 0.9f;
    settings::encode(bad, rec);
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadValue);
}

TEST(Settings, WrongMagic) {
    uint8_t rec[settings::kRecordSize];
    settings::encode(sample(), rec);
    rec[0] = 'X';
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadMagic);
}

TEST(Settings, OutOfRangeValueWithGoodCrcGivesDefaults) {
    Settings bad = sample();
    bad.rate_hz = 200;
    uint8_t rec[settings::kRecordSize];
    settings::encode(bad, rec);
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadValue);
    expect_defaults(out);

    bad = sample();
    bad.cal.mag_scale.y = std::nanf("");
    settings::encode(bad, rec);
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadValue);
    expect_defaults(out);
}

TEST(Settings, EveryOutputModeIsStoredAndNothingBeyondTheLast) {
    // quat, raw and mavlink are new values of the mode byte: they need no new field in
    // the record (version 2's 65 bytes: the compass calibration's terms; version 3 adds
    // the flight settings after them).
    EXPECT_EQ(settings::kV2PayloadLength, 65u);
    EXPECT_EQ(settings::kPayloadLength, 65u + settings::kFlightBytes);
    for (uint8_t m = 0; m <= (uint8_t)fmt::kLastOutputMode; ++m) {
        Settings in = sample();
        in.mode = (fmt::OutputMode)m;
        uint8_t rec[settings::kRecordSize];
        settings::encode(in, rec);
        EXPECT_EQ(rec[7], m);
        Settings out;
        ASSERT_EQ(settings::decode(rec, out), LoadResult::Ok) << int(m);
        EXPECT_EQ(out.mode, in.mode);
    }
    EXPECT_EQ((uint8_t)fmt::OutputMode::Quat, 3u);
    EXPECT_EQ((uint8_t)fmt::OutputMode::Raw, 4u);
    EXPECT_EQ((uint8_t)fmt::OutputMode::Mavlink, 5u);
    Settings bad = sample();
    bad.mode = (fmt::OutputMode)((uint8_t)fmt::kLastOutputMode + 1u);
    uint8_t rec[settings::kRecordSize];
    settings::encode(bad, rec);
    Settings out;
    EXPECT_EQ(settings::decode(rec, out), LoadResult::BadValue);
    expect_defaults(out);
}
