// SPDX-License-Identifier: GPL-3.0-or-later
// MPU6000 register map and decoding (InvenSense MPU-6000 Register Map rev 4.2).
//
// Pure: no bus access, no Arduino include. The bus driver (Mpu6000.h) moves bytes;
// everything that gives those bytes a meaning is here, so it is host-tested and
// shared with the simulator's register model (sim/).
//
// Body frame: x forward (the arrow on the APM case), y right, z down. Units SI.
#pragma once

#include <stdint.h>

#include "Bytes.h"
#include "LinAlg.h"

namespace mpu6000 {

// Register addresses (Register Map section 3). Bit 7 of the address byte = read.
constexpr uint8_t kReadFlag = 0x80;
constexpr uint8_t REG_SMPLRT_DIV = 0x19;
constexpr uint8_t REG_CONFIG = 0x1A;
constexpr uint8_t REG_GYRO_CONFIG = 0x1B;
constexpr uint8_t REG_ACCEL_CONFIG = 0x1C;
constexpr uint8_t REG_FIFO_EN = 0x23;
constexpr uint8_t REG_INT_PIN_CFG = 0x37;
constexpr uint8_t REG_INT_ENABLE = 0x38;
constexpr uint8_t REG_INT_STATUS = 0x3A;
constexpr uint8_t REG_ACCEL_XOUT_H = 0x3B;  // first of the 14-byte burst
constexpr uint8_t REG_USER_CTRL = 0x6A;
constexpr uint8_t REG_PWR_MGMT_1 = 0x6B;
constexpr uint8_t REG_FIFO_COUNTH = 0x72;  // FIFO_COUNTL follows: bytes in the FIFO, big-endian
constexpr uint8_t REG_FIFO_R_W = 0x74;     // reads pop the FIFO; a burst keeps this address
constexpr uint8_t REG_WHO_AM_I = 0x75;

constexpr uint8_t kWhoAmIValue = 0x68;
constexpr uint8_t kPwrDeviceReset = 0x80;    // PWR_MGMT_1 bit 7; the reset takes <= 100 ms
constexpr uint8_t kPwrClockPllGyroZ = 0x03;  // PWR_MGMT_1 CLKSEL = 3
constexpr uint8_t kUserCtrlI2cIfDis = 0x10;  // USER_CTRL: SPI only
constexpr uint8_t kUserCtrlFifoEn = 0x40;    // USER_CTRL: the FIFO runs
constexpr uint8_t kUserCtrlFifoReset = 0x04; // USER_CTRL: empties the FIFO (self-clearing)
// FIFO_EN: TEMP, XG, YG, ZG, ACCEL (Register Map 4.6): the FIFO then holds each sample
// as the same 14 bytes, in the same order, as the burst from ACCEL_XOUT_H.
constexpr uint8_t kFifoEnBurstSample = 0xF8;
constexpr uint16_t kFifoSize = 1024;         // bytes (Product Specification 7.17)
constexpr uint8_t kIntStatusFifoOverflow = 0x10;
constexpr uint8_t kIntPinCfgClearOnRead = 0x10;
constexpr uint8_t kIntEnableDataReady = 0x01;
constexpr uint8_t kIntStatusDataReady = 0x01;
constexpr uint8_t kBurstLength = 14;         // accel xyz, temp, gyro xyz, big-endian int16

// DLPF_CFG values (CONFIG bits 2:0). With the DLPF on, the internal rate is 1 kHz.
enum class Dlpf : uint8_t { Hz188 = 1, Hz98 = 2, Hz42 = 3, Hz20 = 4, Hz10 = 5, Hz5 = 6 };
// FS_SEL values, already shifted into GYRO_CONFIG bits 4:3.
enum class GyroRange : uint8_t { Dps250 = 0x00, Dps500 = 0x08, Dps1000 = 0x10, Dps2000 = 0x18 };
// AFS_SEL values, already shifted into ACCEL_CONFIG bits 4:3.
enum class AccelRange : uint8_t { G2 = 0x00, G4 = 0x08, G8 = 0x10, G16 = 0x18 };

// Sample rate = 1 kHz / (1 + SMPLRT_DIV) with the DLPF on (Register Map 4.2).
constexpr uint8_t smplrt_div_for_hz(uint16_t rate_hz) { return (uint8_t)(1000u / rate_hz - 1u); }

// Sensitivity per configured range (Product Specification 6.1 and 6.2): LSB per deg/s
// and LSB per g, written once; in double for the host's models (sim/), rounded once to
// float where the firmware uses them.
constexpr double kGyroLsbPerDps250 = 131.0, kGyroLsbPerDps500 = 65.5, kGyroLsbPerDps1000 = 32.8,
                 kGyroLsbPerDps2000 = 16.4;
constexpr double kAccelLsbPerG2 = 16384.0, kAccelLsbPerG4 = 8192.0, kAccelLsbPerG8 = 4096.0,
                 kAccelLsbPerG16 = 2048.0;
float gyro_lsb_per_dps(GyroRange range);
float accel_lsb_per_g(AccelRange range);

// Temperature in degrees C from the TEMP_OUT register (Register Map 4.18).
inline float temperature_c_from_raw(int16_t raw) { return (float)raw * (1.0f / 340.0f) + 36.53f; }

// Chip axes <-> body axes on the APM 2.5 (ArduPilot's APM2 mapping, what flew):
// body = (+chip_y, +chip_x, -chip_z). Written once here; the simulator uses the inverse.
inline linalg::Vector3f chip_to_body(const linalg::Vector3f& chip) {
    return linalg::Vector3f(chip.y, chip.x, -chip.z);
}
inline linalg::Vector3f body_to_chip(const linalg::Vector3f& body) {
    return linalg::Vector3f(body.y, body.x, -body.z);
}

enum class BurstStatus : uint8_t {
    Ok,
    NoSensor,  // all 0x00 or all 0xFF: nobody drove MISO
};

// One sample in the sensor's own counts, body frame: the estimator sums counts at
// 200 Hz and turns only the sums into SI units (not six float conversions and
// multiplies a sample, library calls on the 2560). The accessors give SI units.
struct Sample {
    linalg::Vector3i gyro;           // counts of gyro_rad_s_per_count
    linalg::Vector3i accel;          // specific force (level at rest: z < 0), counts of accel_m_s2_per_count
    int16_t temperature_raw;         // TEMP_OUT
    float gyro_rad_s_per_count;      // of the configured ranges
    float accel_m_s2_per_count;
    bool gyro_saturated;             // an axis at the end of its range: the rate is at least that
    bool accel_saturated;

    linalg::Vector3f gyro_rad_s() const { return linalg::scaled(gyro, gyro_rad_s_per_count); }
    linalg::Vector3f accel_m_s2() const { return linalg::scaled(accel, accel_m_s2_per_count); }
    float temperature_c() const { return temperature_c_from_raw(temperature_raw); }
};

// Standard gravity by the name this driver's users know it (linalg's, not another value).
constexpr float kStandardGravity_m_s2 = linalg::kGravity_m_s2;

// The same sensitivities as scale factors, constant expressions (a float division is
// the 2560's slowest library call and the decode runs 200 times a second; a switch here
// becomes a table in RAM).
constexpr float gyro_rad_s_per_count(GyroRange range) {
    return range == GyroRange::Dps250    ? linalg::kRadPerDeg / (float)kGyroLsbPerDps250
           : range == GyroRange::Dps500  ? linalg::kRadPerDeg / (float)kGyroLsbPerDps500
           : range == GyroRange::Dps1000 ? linalg::kRadPerDeg / (float)kGyroLsbPerDps1000
                                         : linalg::kRadPerDeg / (float)kGyroLsbPerDps2000;
}
constexpr float accel_m_s2_per_count(AccelRange range) {
    return range == AccelRange::G2   ? linalg::kGravity_m_s2 / (float)kAccelLsbPerG2
           : range == AccelRange::G4 ? linalg::kGravity_m_s2 / (float)kAccelLsbPerG4
           : range == AccelRange::G8 ? linalg::kGravity_m_s2 / (float)kAccelLsbPerG8
                                     : linalg::kGravity_m_s2 / (float)kAccelLsbPerG16;
}

// The sample the sensor would give for these SI values (rounded to counts, clipped
// at full scale, saturation flagged): a host test's or a model's input.
Sample sample_from_si(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2,
                      float temperature_c, GyroRange gyro_range, AccelRange accel_range);

// Decodes one 14-byte burst read from ACCEL_XOUT_H, in the configured ranges.
// On NoSensor `out` is left untouched.
BurstStatus decode_burst(const uint8_t raw[kBurstLength], GyroRange gyro_range,
                         AccelRange accel_range, Sample& out);


}  // namespace mpu6000
