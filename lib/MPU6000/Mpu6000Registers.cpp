// SPDX-License-Identifier: GPL-3.0-or-later
#include "Mpu6000Registers.h"

namespace mpu6000 {

using linalg::Vector3f;

float gyro_lsb_per_dps(GyroRange range) {
    switch (range) {
        case GyroRange::Dps250: return (float)kGyroLsbPerDps250;
        case GyroRange::Dps500: return (float)kGyroLsbPerDps500;
        case GyroRange::Dps1000: return (float)kGyroLsbPerDps1000;
        case GyroRange::Dps2000: break;
    }
    return (float)kGyroLsbPerDps2000;
}

float accel_lsb_per_g(AccelRange range) {
    switch (range) {
        case AccelRange::G2: return (float)kAccelLsbPerG2;
        case AccelRange::G4: return (float)kAccelLsbPerG4;
        case AccelRange::G8: return (float)kAccelLsbPerG8;
        case AccelRange::G16: break;
    }
    return (float)kAccelLsbPerG16;
}

static bool is_saturated(int16_t v) { return v == 32767 || v == -32768; }
// -(-32768) does not fit: the negated full scale stays at full scale.
static int16_t negated(int16_t v) { return v == -32768 ? (int16_t)32767 : (int16_t)-v; }
// Chip axes to body axes (chip_to_body), in counts.
static linalg::Vector3i counts_to_body(int16_t x, int16_t y, int16_t z) { return linalg::Vector3i{y, x, negated(z)}; }

BurstStatus decode_burst(const uint8_t raw[kBurstLength], GyroRange gyro_range,
                         AccelRange accel_range, Sample& out) {
    bool all_zero = true, all_ones = true;
    for (uint8_t i = 0; i < kBurstLength; ++i) {
        all_zero = all_zero && raw[i] == 0x00;
        all_ones = all_ones && raw[i] == 0xFF;
    }
    if (all_zero || all_ones) return BurstStatus::NoSensor;

    int16_t v[7];
    for (uint8_t i = 0; i < 7; ++i) v[i] = linalg::int16_from_be(raw[2 * i], raw[2 * i + 1]);

    out.accel = counts_to_body(v[0], v[1], v[2]);
    out.gyro = counts_to_body(v[4], v[5], v[6]);
    out.temperature_raw = v[3];
    out.accel_m_s2_per_count = accel_m_s2_per_count(accel_range);
    out.gyro_rad_s_per_count = gyro_rad_s_per_count(gyro_range);
    out.accel_saturated = is_saturated(v[0]) || is_saturated(v[1]) || is_saturated(v[2]);
    out.gyro_saturated = is_saturated(v[4]) || is_saturated(v[5]) || is_saturated(v[6]);
    return BurstStatus::Ok;
}

static int16_t count_of(float value, float per_count) {
    const float c = value / per_count;
    if (!(c > -32768.0f)) return -32768;  // NaN too
    if (c >= 32767.0f) return 32767;
    return (int16_t)(c < 0.0f ? c - 0.5f : c + 0.5f);
}

Sample sample_from_si(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2, float temperature_c,
                      GyroRange gyro_range, AccelRange accel_range) {
    Sample s{};
    s.gyro_rad_s_per_count = gyro_rad_s_per_count(gyro_range);
    s.accel_m_s2_per_count = accel_m_s2_per_count(accel_range);
    s.gyro = linalg::Vector3i{count_of(gyro_rad_s.x, s.gyro_rad_s_per_count), count_of(gyro_rad_s.y, s.gyro_rad_s_per_count),
                              count_of(gyro_rad_s.z, s.gyro_rad_s_per_count)};
    s.accel = linalg::Vector3i{count_of(accel_m_s2.x, s.accel_m_s2_per_count),
                               count_of(accel_m_s2.y, s.accel_m_s2_per_count),
                               count_of(accel_m_s2.z, s.accel_m_s2_per_count)};
    s.temperature_raw = count_of(temperature_c - 36.53f, 1.0f / 340.0f);
    s.gyro_saturated = is_saturated(s.gyro.x) || is_saturated(s.gyro.y) || is_saturated(s.gyro.z);
    s.accel_saturated = is_saturated(s.accel.x) || is_saturated(s.accel.y) || is_saturated(s.accel.z);
    return s;
}

}  // namespace mpu6000
