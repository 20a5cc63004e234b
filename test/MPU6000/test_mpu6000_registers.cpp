// SPDX-License-Identifier: GPL-3.0-or-later
// Register decoding: known bytes -> known body-frame SI values, per axis and range;
// overflow and absent-sensor patterns are flagged, not decoded.
#include <gtest/gtest.h>

#include <cstring>

#include "Hmc5883Registers.h"
#include "Mpu6000Registers.h"

using linalg::Vector3f;

namespace {
constexpr float kG = mpu6000::kStandardGravity_m_s2;
constexpr float kD2R = linalg::kRadPerDeg;

// A burst with chip-axis counts (ax, ay, az, temp, gx, gy, gz), big-endian.
void make_burst(uint8_t out[14], const int16_t v[7]) {
    for (int i = 0; i < 7; ++i) {
        out[2 * i] = linalg::high_byte(v[i]);
        out[2 * i + 1] = linalg::low_byte(v[i]);
    }
}
}  // namespace

TEST(Mpu6000Decode, EachAxisMapsToTheBodyFrame) {
    // Chip x reads 1 g on accel and 100 deg/s on gyro at +-8 g / +-2000 deg/s:
    // body = (+chip_y, +chip_x, -chip_z), so it lands on body y.
    uint8_t raw[14];
    const int16_t x_only[7] = {4096, 0, 0, 0, 1640, 0, 0};
    make_burst(raw, x_only);
    mpu6000::Sample s{};
    ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::Ok);
    EXPECT_NEAR(s.accel_m_s2().x, 0.0f, 1e-6f);
    EXPECT_NEAR(s.accel_m_s2().y, kG, 1e-4f);
    EXPECT_NEAR(s.gyro_rad_s().y, 100.0f * kD2R, 1e-5f);
    EXPECT_NEAR(s.gyro_rad_s().x, 0.0f, 1e-6f);

    const int16_t y_only[7] = {0, 4096, 0, 0, 0, -1640, 0};
    make_burst(raw, y_only);
    ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::Ok);
    EXPECT_NEAR(s.accel_m_s2().x, kG, 1e-4f);
    EXPECT_NEAR(s.gyro_rad_s().x, -100.0f * kD2R, 1e-5f);

    // Level at rest the chip's z reads +1 g: body z = -1 g (specific force, z down).
    const int16_t z_only[7] = {0, 0, 4096, 0, 0, 0, 164};
    make_burst(raw, z_only);
    ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::Ok);
    EXPECT_NEAR(s.accel_m_s2().z, -kG, 1e-4f);
    EXPECT_NEAR(s.gyro_rad_s().z, -10.0f * kD2R, 1e-5f);
}

TEST(Mpu6000Decode, EveryRangeHasItsScale) {
    struct Case { mpu6000::GyroRange g; float lsb_dps; mpu6000::AccelRange a; float lsb_g; };
    const Case cases[] = {
        {mpu6000::GyroRange::Dps250, 131.0f, mpu6000::AccelRange::G2, 16384.0f},
        {mpu6000::GyroRange::Dps500, 65.5f, mpu6000::AccelRange::G4, 8192.0f},
        {mpu6000::GyroRange::Dps1000, 32.8f, mpu6000::AccelRange::G8, 4096.0f},
        {mpu6000::GyroRange::Dps2000, 16.4f, mpu6000::AccelRange::G16, 2048.0f},
    };
    for (const Case& c : cases) {
        const int16_t v[7] = {0, (int16_t)(c.lsb_g / 2), 0, 0, (int16_t)(c.lsb_dps * 20.0f), 0, 0};
        uint8_t raw[14];
        make_burst(raw, v);
        mpu6000::Sample s{};
        ASSERT_EQ(mpu6000::decode_burst(raw, c.g, c.a, s), mpu6000::BurstStatus::Ok);
        EXPECT_NEAR(s.accel_m_s2().x, 0.5f * kG, 2e-3f);
        EXPECT_NEAR(s.gyro_rad_s().y, 20.0f * kD2R, 2e-3f);
        EXPECT_FLOAT_EQ(mpu6000::gyro_lsb_per_dps(c.g), c.lsb_dps);
        EXPECT_FLOAT_EQ(mpu6000::accel_lsb_per_g(c.a), c.lsb_g);
    }
}

TEST(Mpu6000Decode, TemperatureAndSaturation) {
    const int16_t v[7] = {32767, 0, 0, -521, 0, -32768, 0};
    uint8_t raw[14];
    make_burst(raw, v);
    mpu6000::Sample s{};
    ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::Ok);
    EXPECT_NEAR(s.temperature_c(), -521.0f / 340.0f + 36.53f, 1e-4f);
    EXPECT_TRUE(s.accel_saturated);
    EXPECT_TRUE(s.gyro_saturated);
    const int16_t quiet[7] = {1, 2, 3, 0, 4, 5, 6};
    make_burst(raw, quiet);
    mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s);
    EXPECT_FALSE(s.accel_saturated);
    EXPECT_FALSE(s.gyro_saturated);
}

TEST(Mpu6000Decode, AbsentSensorPatternsAreFlagged) {
    uint8_t raw[14];
    mpu6000::Sample s{};
    s.temperature_raw = 1234;
    memset(raw, 0x00, sizeof raw);
    EXPECT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::NoSensor);
    memset(raw, 0xFF, sizeof raw);
    EXPECT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s),
              mpu6000::BurstStatus::NoSensor);
    EXPECT_EQ(s.temperature_raw, 1234);  // untouched
}

TEST(Mpu6000Registers, SampleRateDivider) {
    EXPECT_EQ(mpu6000::smplrt_div_for_hz(200), 4);
    EXPECT_EQ(mpu6000::smplrt_div_for_hz(1000), 0);
    EXPECT_EQ(mpu6000::smplrt_div_for_hz(100), 9);
}

TEST(Mpu6000Axes, BodyToChipIsTheInverse) {
    const Vector3f body(1.0f, -2.0f, 3.0f);
    const Vector3f back = mpu6000::chip_to_body(mpu6000::body_to_chip(body));
    EXPECT_EQ(back, body);
    const Vector3f back_mag = hmc5883::chip_to_body(hmc5883::body_to_chip(body));
    EXPECT_EQ(back_mag, body);
}

TEST(Hmc5883Decode, RegisterOrderIsXZYAndAxesMapToBody) {
    // X = 100, Z = -200, Y = 300 counts at 1.3 Ga (1090 LSB/Ga).
    const uint8_t raw[6] = {0x00, 0x64, 0xFF, 0x38, 0x01, 0x2C};
    const hmc5883::Counts c = hmc5883::counts_from_data(raw);
    EXPECT_EQ(c.x, 100);
    EXPECT_EQ(c.y, 300);
    EXPECT_EQ(c.z, -200);
    Vector3f field;
    ASSERT_EQ(hmc5883::decode_data(raw, hmc5883::Gain::Ga1_3, field), hmc5883::DataStatus::Ok);
    const float uT = 100.0f / 1090.0f;
    // body = (-chip_y, -chip_x, -chip_z)
    EXPECT_NEAR(field.x, -300.0f * uT, 1e-4f);
    EXPECT_NEAR(field.y, -100.0f * uT, 1e-4f);
    EXPECT_NEAR(field.z, 200.0f * uT, 1e-4f);
}

TEST(Hmc5883Decode, EveryGainHasItsScale) {
    const struct { hmc5883::Gain g; float lsb; } gains[] = {
        {hmc5883::Gain::Ga0_88, 1370}, {hmc5883::Gain::Ga1_3, 1090}, {hmc5883::Gain::Ga1_9, 820},
        {hmc5883::Gain::Ga2_5, 660},   {hmc5883::Gain::Ga4_0, 440},  {hmc5883::Gain::Ga4_7, 390},
        {hmc5883::Gain::Ga5_6, 330},   {hmc5883::Gain::Ga8_1, 230},
    };
    for (const auto& g : gains) {
        const int16_t counts = (int16_t)(g.lsb * 0.5f);  // 0.5 Ga on chip X
        const uint8_t raw[6] = {linalg::high_byte(counts), linalg::low_byte(counts), 0, 1, 0, 1};
        Vector3f field;
        ASSERT_EQ(hmc5883::decode_data(raw, g.g, field), hmc5883::DataStatus::Ok);
        EXPECT_NEAR(field.y, -50.0f, 0.2f);
        EXPECT_FLOAT_EQ(hmc5883::lsb_per_gauss(g.g), g.lsb);
    }
}

TEST(Hmc5883Decode, OverflowAndAbsentAreFlagged) {
    Vector3f field(7.0f, 7.0f, 7.0f);
    const uint8_t overflow_z[6] = {0x00, 0x10, 0xF0, 0x00, 0x00, 0x10};  // Z = -4096
    EXPECT_EQ(hmc5883::decode_data(overflow_z, hmc5883::Gain::Ga1_3, field), hmc5883::DataStatus::Overflow);
    const uint8_t zeros[6] = {0, 0, 0, 0, 0, 0};
    EXPECT_EQ(hmc5883::decode_data(zeros, hmc5883::Gain::Ga1_3, field), hmc5883::DataStatus::NoSensor);
    const uint8_t ones[6] = {0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
    EXPECT_EQ(hmc5883::decode_data(ones, hmc5883::Gain::Ga1_3, field), hmc5883::DataStatus::NoSensor);
    EXPECT_EQ(field, Vector3f(7.0f, 7.0f, 7.0f));  // untouched
}

TEST(Hmc5883Registers, IdentityAndOutputRate) {
    const uint8_t good[3] = {'H', '4', '3'};
    const uint8_t bad[3] = {'H', '4', '4'};
    EXPECT_TRUE(hmc5883::id_matches(good));
    EXPECT_FALSE(hmc5883::id_matches(bad));
    EXPECT_FLOAT_EQ(hmc5883::output_rate_hz(hmc5883::kConfigA_Avg8_75Hz), 75.0f);
    EXPECT_FLOAT_EQ(hmc5883::output_rate_hz(0x10), 15.0f);
}

TEST(Hmc5883SelfTest, FiveGoodSamplesMakeTheScale) {
    hmc5883::SelfTest st;
    // A chip 10 % weak on every axis: the bias field reads 1/1.1 of the datasheet's.
    const hmc5883::Counts good{(int16_t)(1.16f * 660 / 1.1f), (int16_t)(1.16f * 660 / 1.1f), (int16_t)(1.08f * 660 / 1.1f)};
    const hmc5883::Counts absurd{100, 100, 100};
    EXPECT_FALSE(st.add_sample(absurd));
    for (int i = 0; i < 5; ++i) EXPECT_TRUE(st.add_sample(good));
    ASSERT_TRUE(st.done());
    EXPECT_NEAR(st.scale().x, 1.1f, 0.01f);
    EXPECT_NEAR(st.scale().y, 1.1f, 0.01f);
    EXPECT_NEAR(st.scale().z, 1.1f, 0.01f);
}

TEST(Hmc5883SelfTest, FailsAfterTwentyImplausibleTriesAndKeepsUnitScale) {
    hmc5883::SelfTest st;
    const hmc5883::Counts absurd{2000, 10, -4096};
    for (int i = 0; i < 20; ++i) EXPECT_FALSE(st.add_sample(absurd));
    EXPECT_TRUE(st.failed());
    EXPECT_FALSE(st.done());
    EXPECT_EQ(st.scale(), Vector3f(1.0f, 1.0f, 1.0f));
}
