// SPDX-License-Identifier: GPL-3.0-or-later
// The HMC5883L's register decoding (lib/HMC5883/Hmc5883Registers): known bytes -> known
// body-frame values, per axis and gain; overflow and absent-sensor patterns are flagged, not
// decoded; the self-test's scale.
#include <gtest/gtest.h>

#include "Bytes.h"
#include "Hmc5883Registers.h"

using linalg::Vector3f;

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
