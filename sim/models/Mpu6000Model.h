// SPDX-License-Identifier: GPL-3.0-or-later
// MPU6000 register model on SPI (InvenSense MPU-6000 Product Specification rev 3.3,
// Register Map rev 4.2), driven by a trajectory's body-frame values.
//
// Host-only, no simavr: the simavr harness (sim/apm25sim.cpp) and the host replay tool
// drive the same object through the same register protocol the firmware uses.
//
// What is modelled:
// - SPI framing: chip select low starts a transaction; the first byte is the register
//   address (bit 7 = read), then each byte reads or writes that register and the
//   address auto-increments (Register Map section 3). A burst reads a snapshot of the
//   registers taken at chip select, so a sample arriving mid-burst does not tear it.
// - PWR_MGMT_1: power-on and reset leave the chip asleep (0x40); DEVICE_RESET (0x80)
//   restores every register and makes the chip deaf for kResetDuration_s. Asleep,
//   the data registers read 0 and no data-ready is raised.
// - Internal sampling at 1 kHz (DLPF_CFG 1..6) or 8 kHz (0 or 7), a first-order
//   low-pass at the DLPF bandwidth (Register Map 4.3), output and data-ready every
//   1 + SMPLRT_DIV internal samples (Register Map 4.2).
// - GYRO_CONFIG / ACCEL_CONFIG full-scale as written; counts saturate at the int16 ends.
// - INT pin: data-ready when INT_ENABLE bit 0; INT_PIN_CFG INT_LEVEL (bit 7, active low),
//   LATCH_INT_EN (bit 5: held until cleared, else a 50 us pulse), INT_RD_CLEAR (bit 4:
//   any read clears, else only reading INT_STATUS).
// - FIFO (Register Map 4.6, 4.29-4.31): with USER_CTRL FIFO_EN, each output sample
//   appends the registers FIFO_EN selects, in register order; FIFO_COUNTH/L read from
//   the chip-select snapshot; reads of FIFO_R_W pop bytes (a burst stays on FIFO_R_W);
//   USER_CTRL FIFO_RESET empties it; when full, the oldest bytes are dropped and
//   INT_STATUS FIFO_OFLOW is set.
// - Temperature: constant 30 degC.
// Not modelled: self-test bits, the auxiliary I2C master, noise (scenarios add it).
//
// Axis mapping: the inverse of the driver's, mpu6000::body_to_chip (lib/MPU6000).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <deque>

#include "TimeWindow.h"
#include "Trajectory.h"

namespace sim {

struct Mpu6000Faults {
    TimeWindows absent;         // MISO idle (reads 0x00), writes ignored, INT low; registers kept
    TimeWindows int_stuck_low;  // the INT line stays low (data still updates)
    TimeWindows frozen;         // data registers stop updating, no data-ready
    TimeWindows gyro_saturate;  // every gyro axis at the end of its range (sign of the truth)
    TimeWindows accel_saturate; // every accel axis at the end of its range
    TimeWindows spike;          // absurd in-range values on gyro and accel
    int who_am_i = -1;          // >= 0: WHO_AM_I reads this instead of 0x68
};

// Protocol errors and events, counted rather than printed (tests assert on them).
struct Mpu6000Counters {
    uint32_t transactions = 0;         // chip-select low periods with at least one byte
    uint32_t bytes = 0;                // bytes exchanged while selected
    uint32_t register_writes = 0;
    uint32_t samples = 0;              // output samples produced (data-ready events)
    uint32_t samples_not_read = 0;     // a sample replaced before any burst read of it
    uint32_t access_while_absent = 0;  // bytes during an `absent` fault
    uint32_t access_during_reset = 0;  // bytes within kResetDuration_s of DEVICE_RESET
    uint32_t data_read_while_asleep = 0;
    uint32_t writes_to_read_only = 0;  // data, status or WHO_AM_I registers
    uint32_t writes_above_1mhz = 0;    // datasheet: register writes at SCLK <= 1 MHz
    uint32_t bytes_without_select = 0; // transfer() with chip select high
    uint32_t fifo_overflows = 0;       // samples that pushed unread bytes out of the FIFO
    uint32_t fifo_underruns = 0;       // FIFO_R_W reads of an empty FIFO
};

class Mpu6000Model {
public:
    // The samples the model reads; the physics link appends to them as states come.
    Trajectory& trajectory() { return trajectory_; }
    static constexpr double kResetDuration_s = 0.05;  // no datasheet figure; ArduPilot waits 100 ms
    static constexpr double kIntPulse_s = 50e-6;      // Register Map 4.15: 50 us pulse unless latched
    static constexpr float kTemperature_c = 30.0f;

    // Copies the trajectory: each model keeps its own interpolation cursor, so two
    // models sampling at different instants never rewind each other's.
    explicit Mpu6000Model(const Trajectory& trajectory);

    // Runs the internal sampling up to simulated time t_s (never backwards).
    void advance_to(double t_s);
    double time_s() const { return time_s_; }
    // The next instant at which the INT pin or the data can change (for a timer).
    double next_event_s() const;

    // SPI. `selected` is chip select active (CS pin low). transfer() exchanges one byte
    // and returns what the chip drives on MISO; sck_hz is the bus clock (for the
    // 1 MHz write limit check).
    void set_chip_select(bool selected);
    uint8_t transfer(uint8_t mosi, double sck_hz = 1e6);

    // Convenience for the host replay tool: whole transactions through the same path.
    void write_register(uint8_t reg, uint8_t value);
    void read_registers(uint8_t first_reg, uint8_t* out, size_t count);

    // The INT line level (true = high).
    bool int_pin_high() const;

    // The register as the chip holds it now, without the side effects of a read.
    uint8_t peek_register(uint8_t reg) const { return regs_[reg & 0x7F]; }
    bool asleep() const;

    Mpu6000Faults& faults() { return faults_; }
    const Mpu6000Counters& counters() const { return counters_; }

private:
    void reset_registers();
    void internal_sample(double t_s);
    void publish_sample(double t_s);
    void push_fifo_sample();
    void update_fifo_count();
    void clear_data_ready();
    uint8_t read_register_for_spi(uint8_t reg);
    void write_register_from_spi(uint8_t reg, uint8_t value, double sck_hz);
    double internal_rate_hz() const;
    // Counts per deg/s and per g of the configured ranges (GYRO_CONFIG, ACCEL_CONFIG).
    float gyro_lsb_per_dps() const;
    float accel_lsb_per_g() const;
    bool int_asserted() const;

    Trajectory trajectory_;
    Mpu6000Faults faults_;
    Mpu6000Counters counters_;
    uint8_t regs_[128];
    uint8_t snapshot_[128];  // registers as at chip select, for burst reads

    double time_s_ = 0.0;
    double next_internal_s_ = 0.0;
    double reset_until_s_ = -1.0;
    bool filter_primed_ = false;
    float gyro_dps_filtered_[3] = {0, 0, 0};   // chip axes
    float accel_g_filtered_[3] = {0, 0, 0};    // chip axes
    bool data_ready_ = false;
    bool sample_read_ = true;
    double int_pulse_end_s_ = -1.0;

    std::deque<uint8_t> fifo_;

    bool selected_ = false;
    unsigned byte_index_ = 0;
    uint8_t address_ = 0;
    bool reading_ = false;
};

}  // namespace sim
