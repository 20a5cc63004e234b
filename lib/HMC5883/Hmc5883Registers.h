// SPDX-License-Identifier: GPL-3.0-or-later
// HMC5883L register map and decoding (Honeywell HMC5883L datasheet, rev E).
//
// Pure: no bus access, no Arduino include. Shared by the bus driver (Hmc5883.h), the
// host tests and the simulator's register model.
//
// Body frame: x forward, y right, z down. Field in microtesla (1 gauss = 100 uT).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace hmc5883 {

constexpr uint8_t kAddress7 = 0x1E;  // 7-bit I2C address

constexpr uint8_t REG_CONFIG_A = 0x00;
constexpr uint8_t REG_CONFIG_B = 0x01;
constexpr uint8_t REG_MODE = 0x02;
constexpr uint8_t REG_DATA_X_MSB = 0x03;  // then X LSB, Z MSB, Z LSB, Y MSB, Y LSB
constexpr uint8_t REG_STATUS = 0x09;
constexpr uint8_t REG_ID_A = 0x0A;        // 'H', '4', '3'
constexpr uint8_t kDataLength = 6;
constexpr uint8_t kIdLength = 3;
constexpr uint8_t kId[kIdLength] = {'H', '4', '3'};

// Config A: 8-sample average (MA = 11), 75 Hz output (DO = 110), normal measurement.
constexpr uint8_t kConfigA_Avg8_75Hz = 0x78;
constexpr uint8_t kConfigA_BiasMask = 0x03;
constexpr uint8_t kConfigA_PositiveBias = 0x01;
constexpr uint8_t kConfigA_NegativeBias = 0x02;
constexpr uint8_t kModeContinuous = 0x00;
constexpr uint8_t kModeSingle = 0x01;
constexpr uint8_t kStatusReady = 0x01;
constexpr int16_t kOverflow = -4096;  // datasheet: the axis' ADC overflowed

// Gain (Config B bits 7:5, already shifted) and its resolution (datasheet table 9).
enum class Gain : uint8_t {
    Ga0_88 = 0x00, Ga1_3 = 0x20, Ga1_9 = 0x40, Ga2_5 = 0x60,
    Ga4_0 = 0x80, Ga4_7 = 0xA0, Ga5_6 = 0xC0, Ga8_1 = 0xE0,
};
float lsb_per_gauss(Gain gain);
// Output rate in Hz for Config A bits 4:2 (DO); 0 for the reserved code.
float output_rate_hz(uint8_t config_a);

// Chip axes <-> body axes on the APM 2.5 (ArduPilot's APM2 on-board compass):
// body = (-chip_y, -chip_x, -chip_z). Written once here; the simulator uses the inverse.
inline linalg::Vector3f chip_to_body(const linalg::Vector3f& chip) {
    return linalg::Vector3f(-chip.y, -chip.x, -chip.z);
}
inline linalg::Vector3f body_to_chip(const linalg::Vector3f& body) {
    return linalg::Vector3f(-body.y, -body.x, -body.z);
}

// The six data bytes (registers 3..8, X, Z, Y order) as chip-axis counts (x, y, z).
struct Counts { int16_t x, y, z; };
Counts counts_from_data(const uint8_t raw[kDataLength]);

enum class DataStatus : uint8_t {
    Ok,
    Overflow,  // an axis reads -4096: not a field value, drop the sample
    NoSensor,  // all 0x00 or all 0xFF
};

// Decodes one data read into the body-frame field in uT (before calibration).
// `out` is written only when the status is Ok.
DataStatus decode_data(const uint8_t raw[kDataLength], Gain gain, linalg::Vector3f& field_uT);

bool id_matches(const uint8_t id[kIdLength]);

// Self-test with the positive bias (datasheet "Self Test Operation"): the offset
// straps add 1.16 Ga on X and Y and 1.08 Ga on Z, and the chip itself subtracts a
// measurement of the external field, so the data registers hold the bias field
// alone. A sample is plausible when expected/measured is within 0.7..1.3 on every
// axis; five good samples of at most twenty tries make the scale. (ArduPilot
// expected 713 counts on Y like Z; the datasheet gives Y the same 1.16 Ga as X, and
// with 713 a perfect chip would be "corrected" 7 % off between X and Y, which turns
// into ~2 deg of heading error. The register model uses the same field.)
constexpr Gain kSelfTestGain = Gain::Ga2_5;
constexpr float kSelfTestField_Ga[3] = {1.16f, 1.16f, 1.08f};
constexpr float kSelfTestExpected[3] = {1.16f * 660.0f, 1.16f * 660.0f, 1.08f * 660.0f};  // counts at 2.5 Ga
constexpr uint8_t kSelfTestSamplesNeeded = 5;
constexpr uint8_t kSelfTestMaxTries = 20;

class SelfTest {
public:
    // Feeds one positive-bias sample in chip counts; returns true if it was accepted.
    bool add_sample(const Counts& counts);
    bool done() const { return good_ >= kSelfTestSamplesNeeded; }
    bool failed() const { return !done() && tries_ >= kSelfTestMaxTries; }
    uint8_t good_samples() const { return good_; }
    // Per-chip-axis scale factors (expected / measured, averaged); 1.0 until done().
    linalg::Vector3f scale() const;

private:
    float sum_ratio_[3] = {0.0f, 0.0f, 0.0f};
    uint8_t good_ = 0;
    uint8_t tries_ = 0;
};

}  // namespace hmc5883
