// SPDX-License-Identifier: GPL-3.0-or-later
// HMC5883L bus driver: moves bytes over I2C; register meaning and decoding live in
// Hmc5883Registers.h. No Arduino include: the firmware implements the I2cBus seam with
// the core's Wire (with its timeout), the host tests with a fake, the replay tool with
// the simulator's register model.
//
// Configuration (why):
//   gain 1.3 Ga (1090 LSB/Ga)  the Earth's field is 0.25..0.65 Ga; 1.3 Ga leaves ~0.6 Ga
//                              for hard iron before overflow, at 0.09 uT resolution.
//   75 Hz, 8-sample average    the fastest continuous rate, averaged against noise; the
//                              estimator folds each sample in as it comes.
// Self-test: positive bias at gain 2.5 Ga in single-measurement mode; the chip
// subtracts the external field itself (datasheet "Self Test Operation"), so each
// reading is the bias field, checked by hmc5883::SelfTest against the datasheet's
// 1.16 / 1.16 / 1.08 Ga; per-axis scale = expected / measured, 1.0 on failure.
#pragma once

#include <stdint.h>

#include "Hmc5883Registers.h"
#include "LinAlg.h"

namespace hmc5883 {

// The bus seam; addresses are 7-bit. Every call returns in bounded time (the firmware
// uses Wire's timeout) and false on NACK, timeout or short read.
struct I2cBus {
    void* ctx;
    bool (*write_reg)(void* ctx, uint8_t addr7, uint8_t reg, uint8_t value);
    bool (*read_regs)(void* ctx, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len);
    void (*delay_ms)(void* ctx, uint16_t ms);
};

constexpr Gain kGain = Gain::Ga1_3;
constexpr uint8_t kConfigA = kConfigA_Avg8_75Hz;
constexpr uint8_t kSelfTestConfigA = 0x10;  // 1 sample, measurement without bias (bias bits OR-ed in)
constexpr uint8_t kSingleWaitMs = 6;        // datasheet: a single measurement takes ~6 ms
constexpr uint8_t kReadyTimeoutMs = 20;

enum class InitStatus : uint8_t {
    Ok,
    NoAnswer,          // no ACK / bus timeout
    WrongIdentity,     // ID registers are not 'H43'
    ReadbackMismatch,  // a configuration register did not keep what was written
};

struct InitResult {
    InitStatus status;
    uint8_t id[kIdLength];  // what the ID registers said
    uint8_t reg, wrote, read;
};

enum class ReadStatus : uint8_t {
    Ok,
    Skipped,   // the first sample after configuration (taken at the old gain): dropped
    Overflow,  // an axis at -4096: dropped
    NoSensor,  // all 0x00 / 0xFF
    BusError,  // NACK or timeout
};

class Hmc5883 {
public:
    explicit constexpr Hmc5883(const I2cBus& bus) : bus_(bus) {}  // constexpr: no start-up code

    // ID check, then (if run_self_test) the self-test (~100 ms), then continuous mode,
    // with read back. Without self-test the previous scale is kept (a quick re-init).
    InitResult begin(bool run_self_test);
    // Reads the data registers (call when DRDY is high): body-frame field, uT, with the
    // self-test scale applied. `out` is written only on Ok.
    ReadStatus read(linalg::Vector3f& field_uT);
    // The status register's RDY bit (a fallback when the DRDY pin is not usable).
    bool ready_by_status(bool& ready);

    bool self_test_passed() const { return self_test_passed_; }
    uint8_t self_test_good_samples() const { return self_test_good_; }
    // Per chip-axis scale (x, y, z of the chip) from the self-test; 1.0 if it failed.
    linalg::Vector3f self_test_scale() const { return scale_chip_; }

private:
    bool write(uint8_t reg, uint8_t value) { return bus_.write_reg(bus_.ctx, kAddress7, reg, value); }
    bool read_regs(uint8_t reg, uint8_t* d, uint8_t n) { return bus_.read_regs(bus_.ctx, kAddress7, reg, d, n); }
    bool single_measurement(uint8_t config_a, Counts& out);
    void run_self_test();

    I2cBus bus_;
    linalg::Vector3f scale_chip_{1.0f, 1.0f, 1.0f};
    linalg::Vector3f scale_body_{1.0f, 1.0f, 1.0f};
    bool self_test_passed_ = false;
    uint8_t self_test_good_ = 0;
    bool discard_next_ = true;
};

}  // namespace hmc5883
