// SPDX-License-Identifier: GPL-3.0-or-later
// The MPU6000's register decoding (lib/MPU6000/Mpu6000Registers): known bytes -> known
// body-frame SI values, per axis and range; overflow and absent-sensor patterns are
// flagged, not decoded. (Mpu6000Axes checks the HMC5883L's axis map beside it.)
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
