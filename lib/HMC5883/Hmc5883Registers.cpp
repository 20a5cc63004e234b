// SPDX-License-Identifier: GPL-3.0-or-later
#include "Hmc5883Registers.h"

#include "Bytes.h"

namespace hmc5883 {

using linalg::Vector3f;

float lsb_per_gauss(Gain gain) {
    switch (gain) {
        case Gain::Ga0_88: return 1370.0f;
        case Gain::Ga1_3: return 1090.0f;
        case Gain::Ga1_9: return 820.0f;
        case Gain::Ga2_5: return 660.0f;
        case Gain::Ga4_0: return 440.0f;
        case Gain::Ga4_7: return 390.0f;
        case Gain::Ga5_6: return 330.0f;
        case Gain::Ga8_1: break;
    }
    return 230.0f;
}

float output_rate_hz(uint8_t config_a) {
    static const float kRates[8] = {0.75f, 1.5f, 3.0f, 7.5f, 15.0f, 30.0f, 75.0f, 0.0f};
    return kRates[(config_a >> 2) & 0x07];
}

Counts counts_from_data(const uint8_t raw[kDataLength]) {
    // Register order is X, Z, Y (datasheet table 2).
    Counts c;
    c.x = linalg::int16_from_be(raw[0], raw[1]);
    c.z = linalg::int16_from_be(raw[2], raw[3]);
    c.y = linalg::int16_from_be(raw[4], raw[5]);
    return c;
}

DataStatus decode_data(const uint8_t raw[kDataLength], Gain gain, Vector3f& field_uT) {
    bool all_zero = true, all_ones = true;
    for (uint8_t i = 0; i < kDataLength; ++i) {
        all_zero = all_zero && raw[i] == 0x00;
        all_ones = all_ones && raw[i] == 0xFF;
    }
    if (all_zero || all_ones) return DataStatus::NoSensor;
    const Counts c = counts_from_data(raw);
    if (c.x == kOverflow || c.y == kOverflow || c.z == kOverflow) return DataStatus::Overflow;
    const float uT_per_lsb = linalg::kMicroteslaPerGauss / lsb_per_gauss(gain);
    field_uT = chip_to_body(Vector3f((float)c.x, (float)c.y, (float)c.z)) * uT_per_lsb;
    return DataStatus::Ok;
}

bool id_matches(const uint8_t id[kIdLength]) {
    return id[0] == kId[0] && id[1] == kId[1] && id[2] == kId[2];
}

namespace {
// expected / measured for one axis; false for an absent, overflowed or implausible one.
bool axis_ratio(int16_t measured, float expected, float& ratio) {
    if (measured <= 0 || measured == kOverflow) return false;
    ratio = expected / (float)measured;
    return ratio >= 0.7f && ratio <= 1.3f;
}
}  // namespace

bool SelfTest::add_sample(const Counts& counts) {
    if (done() || failed()) return false;
    ++tries_;
    // Axis by axis with constant indices: a loop over kSelfTestExpected would keep the
    // array in the AVR's SRAM.
    float ratio[3];
    if (!axis_ratio(counts.x, kSelfTestExpected[0], ratio[0]) || !axis_ratio(counts.y, kSelfTestExpected[1], ratio[1]) ||
        !axis_ratio(counts.z, kSelfTestExpected[2], ratio[2]))
        return false;
    for (uint8_t i = 0; i < 3; ++i) sum_ratio_[i] += ratio[i];
    ++good_;
    return true;
}

Vector3f SelfTest::scale() const {
    if (!done()) return Vector3f(1.0f, 1.0f, 1.0f);
    const float inv = 1.0f / (float)good_;
    return Vector3f(sum_ratio_[0] * inv, sum_ratio_[1] * inv, sum_ratio_[2] * inv);
}

}  // namespace hmc5883
