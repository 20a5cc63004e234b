#include "Mpu6000Registers.h"

namespace mpu6000 {

using linalg::Vector3f;

float gyro_lsb_per_dps(GyroRange range) {
    switch (range) {
        case GyroRange::Dps250: return 131.0f;
        case GyroRange::Dps500: return 65.5f;
        case GyroRange::Dps1000: return 32.8f;
        case GyroRange::Dps2000: break;
    }
    return 16.4f;
}

float accel_lsb_per_g(AccelRange range) {
    switch (range) {
        case AccelRange::G2: return 16384.0f;
        case AccelRange::G4: return 8192.0f;
        case AccelRange::G8: return 4096.0f;
        case AccelRange::G16: break;
    }
    return 2048.0f;
}

static bool is_saturated(int16_t v) { return v == 32767 || v == -32768; }

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

    const float m_s2_per_lsb = kStandardGravity_m_s2 / accel_lsb_per_g(accel_range);
    const float rad_s_per_lsb = linalg::kRadPerDeg / gyro_lsb_per_dps(gyro_range);
    const Vector3f accel_chip((float)v[0], (float)v[1], (float)v[2]);
    const Vector3f gyro_chip((float)v[4], (float)v[5], (float)v[6]);
    out.accel_m_s2 = chip_to_body(accel_chip) * m_s2_per_lsb;
    out.gyro_rad_s = chip_to_body(gyro_chip) * rad_s_per_lsb;
    out.temperature_c = temperature_c_from_raw(v[3]);
    out.accel_saturated = is_saturated(v[0]) || is_saturated(v[1]) || is_saturated(v[2]);
    out.gyro_saturated = is_saturated(v[4]) || is_saturated(v[5]) || is_saturated(v[6]);
    return BurstStatus::Ok;
}

}  // namespace mpu6000
