// SPDX-License-Identifier: GPL-3.0-or-later
// MPU6000 bus driver: moves bytes over SPI; register meaning and decoding live in
// Mpu6000Registers.h (decode_burst). No Arduino include: the firmware implements the
// SpiDevice seam with the core's SPI library, the host tests with a fake, and the
// replay tool with the simulator's register model.
//
// Configuration (why):
//   200 Hz sample rate    SMPLRT_DIV = 4 with the DLPF on: the estimator's fixed step.
//   DLPF 42 Hz            below the 100 Hz Nyquist limit of 200 Hz sampling (20 Hz would
//                         also do, but costs 8.3 ms of group delay against 4.8 ms: one step)
//   +-2000 deg/s          a hand-thrown or crashing board exceeds 1000 deg/s; 16.4 LSB/(deg/s)
//                         still resolves 0.06 deg/s, far below the drift the DCM corrects
//   +-16 g                shocks pass 8 g (a hand's stroke, a tap, a landing); a clipped
//                         sample is a rectified error that the gravity low-pass keeps as
//                         tilt (ArduPilot sets 16 g too). 2048 LSB/g = 0.5 mg, a fifth of
//                         the noise in the 42 Hz band (400 ug/sqrt(Hz), Product Spec 6.2).
//   INT latched, cleared on any read (INT_PIN_CFG 0x30): the data-ready pin stays high
//                         until the burst read, so polling it cannot miss a 50 us pulse.
// Register writes at 1 MHz (datasheet limit for writes), sensor reads at 8 MHz.
// FIFO: off unless the INT pin fails (start_fifo), then the loop reads from it.
#pragma once

#include <stdint.h>

#include "Mpu6000Registers.h"

namespace mpu6000 {

// The bus seam. Every function must return in bounded time (SPI always does).
struct SpiDevice {
    void* ctx;
    // selected = true: start a transaction (SPI mode 0, MSB first, at clock_hz) and drive
    // the MPU6000's chip select low. false: chip select high, end the transaction.
    void (*select)(void* ctx, bool selected, uint32_t clock_hz);
    // One full-duplex byte.
    uint8_t (*transfer)(void* ctx, uint8_t out);
    // Blocking wait (only begin() uses it: the 100 ms reset and the PLL start).
    void (*delay_ms)(void* ctx, uint16_t ms);
};

constexpr uint32_t kConfigClockHz = 1000000;
constexpr uint32_t kReadClockHz = 8000000;
constexpr uint16_t kRateHz = 200;
constexpr Dlpf kDlpf = Dlpf::Hz42;
constexpr GyroRange kGyroRange = GyroRange::Dps2000;
constexpr AccelRange kAccelRange = AccelRange::G16;
constexpr uint8_t kIntPinCfgLatchClearOnRead = 0x30;  // LATCH_INT_EN | INT_RD_CLEAR
constexpr uint16_t kResetWaitMs = 100;

enum class InitStatus : uint8_t {
    Ok,
    WrongIdentity,     // WHO_AM_I is not 0x68 (0x00 / 0xFF: nobody answered)
    ReadbackMismatch,  // a configuration register did not keep what was written
};

struct InitResult {
    InitStatus status;
    uint8_t reg;    // WHO_AM_I or the register that failed the read back
    uint8_t wrote;  // expected value
    uint8_t read;   // what the chip answered
};

class Mpu6000 {
public:
    constexpr explicit Mpu6000(const SpiDevice& dev) : dev_(dev) {}

    // WHO_AM_I at the configuration clock; `who` receives what the chip answered.
    bool probe(uint8_t& who);
    // Full bring-up: WHO_AM_I, reset (100 ms), wake on the gyro-Z PLL, SPI only, rate,
    // DLPF, ranges, data-ready interrupt, then every written register read back.
    // ~110 ms, blocking.
    InitResult begin();
    // INT_STATUS data-ready bit (reading it clears the latched interrupt).
    bool data_ready();

    // The FIFO, for when the INT pin cannot pace the loop: each sample is queued as the
    // same 14 bytes as the burst, so a poll can neither race a new sample (reading
    // INT_STATUS clears the flag of one that lands during the read) nor come too late
    // (the FIFO holds 73 samples, 365 ms). start_fifo empties it and starts it.
    void start_fifo();
    void stop_fifo();
    // Whole samples waiting; 0 when the count is impossible (nobody on the bus).
    uint16_t fifo_samples();
    // The oldest queued sample, decoded (call only when fifo_samples() > 0).
    BurstStatus read_fifo(Sample& out);
    // The 14-byte burst from ACCEL_XOUT_H at 8 MHz, decoded. NoSensor leaves `out`
    // untouched. `raw` (optional) receives the bytes.
    BurstStatus read(Sample& out, uint8_t* raw = nullptr);

    uint8_t read_register(uint8_t reg, uint32_t clock_hz = kConfigClockHz);
    void write_register(uint8_t reg, uint8_t value);

private:
    void read_burst(uint8_t first_reg, uint8_t* buf);
    SpiDevice dev_;
};

}  // namespace mpu6000
