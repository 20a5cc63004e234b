// SPDX-License-Identifier: GPL-3.0-or-later
// HMC5883L register model on I2C (Honeywell HMC5883L datasheet rev E), driven by a
// trajectory's body-frame field.
//
// Host-only, no simavr: the simavr harness and the host replay tool drive the same
// object. The bus side (address match at 7-bit hmc5883::kAddress7, START/STOP) is the
// caller's; this class sees a transaction as start(read?), bytes, stop().
//
// What is modelled:
// - Register pointer: the first byte written after an address+write sets it; further
//   written bytes go to Config A, Config B, Mode (others are read-only and ignored).
//   Reads auto-increment; after register 8 the pointer returns to 3, after 12 to 0.
// - Config A: averaging 1/2/4/8 (bits 6:5), output rate (bits 4:2), measurement bias
//   (bits 1:0; with the positive self-test bias the reading is the bias field alone,
//   1.16 Ga on X and Y, 1.08 Ga on Z: datasheet "Self Test Operation", the chip
//   subtracts the external field itself).
// - Config B gain (bits 7:5) and its LSB/Ga (datasheet table 9); a channel outside
//   [-2048, 2047] counts reads -4096.
// - Mode: continuous (first sample ~6 ms after the write, then at the output rate),
//   single (one sample ~6 ms later, then idle: MD bits read 11), idle. Power-on: idle
//   with the registers at their defaults (Config A 0x10, Config B 0x20, Mode 0x01).
// - Data X, Z, Y big-endian; status RDY (bit 0) and LOCK (bit 1); ID 'H','4','3'.
// - Data lock: once a data register is read, a new sample is dropped until all six
//   were read (or Config A / Mode is written).
// - DRDY pin: high when a new sample is in, low once a data register is read. (This
//   follows the project's board notes; the datasheet describes a 250 us low pulse.)
//
// Axis mapping: the inverse of the driver's, hmc5883::body_to_chip (lib/HMC5883).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "TimeWindow.h"
#include "Trajectory.h"

namespace sim {

struct Hmc5883Faults {
    TimeWindows absent;          // NACKs its address (and any byte), DRDY low
    TimeWindows drdy_stuck_low;  // DRDY pin low whatever the data
    TimeWindows drdy_stuck_high; // DRDY pin high whatever the data
    TimeWindows overflow;        // every channel of every sample reads -4096
    TimeWindows spike;           // absurd in-range counts
    int id[3] = {-1, -1, -1};    // >= 0: the ID registers read these instead of 'H','4','3'
};

struct Hmc5883Counters {
    uint32_t transactions = 0;        // address acknowledged
    uint32_t bytes_written = 0;
    uint32_t bytes_read = 0;
    uint32_t samples = 0;             // measurements placed in the data registers
    uint32_t samples_dropped_by_lock = 0;
    uint32_t nacked_while_absent = 0;
    uint32_t writes_to_read_only = 0;
    uint32_t reads_of_invalid_register = 0;  // pointer beyond 12
    uint32_t bytes_without_start = 0;
};

class Hmc5883Model {
public:
    // The samples the model reads; the physics link appends to them as states come.
    Trajectory& trajectory() { return trajectory_; }
    static constexpr double kMeasurementDelay_s = 0.006;  // datasheet: ~6 ms after a mode write
    static constexpr double kAveragedSampleSpacing_s = 0.0007;

    explicit Hmc5883Model(const Trajectory& trajectory);  // copies (own interpolation cursor)

    void advance_to(double t_s);
    double time_s() const { return time_s_; }
    double next_event_s() const;  // when a measurement lands next (infinity when idle)

    // I2C transaction after the bus matched hmc5883::kAddress7. Each returns the chip's
    // ACK (true) or NACK. read() returns the byte the chip drives.
    bool start(bool read);
    bool write(uint8_t byte);
    uint8_t read();
    void stop();

    // Convenience for the host replay tool: whole transactions through the same path.
    bool write_register(uint8_t reg, uint8_t value);
    bool read_registers(uint8_t first_reg, uint8_t* out, size_t count);

    bool drdy_pin_high() const;
    bool answering() const { return !faults_.absent.active(time_s_); }
    uint8_t peek_register(uint8_t reg) const { return reg < 13 ? regs_[reg] : 0; }

    Hmc5883Faults& faults() { return faults_; }
    const Hmc5883Counters& counters() const { return counters_; }

private:
    void measure(double t_s);
    void schedule_after_mode_write();
    double continuous_rate_hz() const;
    uint8_t register_value(uint8_t reg) const;

    Trajectory trajectory_;
    Hmc5883Faults faults_;
    Hmc5883Counters counters_;
    uint8_t regs_[13];
    double time_s_ = 0.0;
    double next_measurement_s_;
    bool ready_ = false;
    uint8_t data_read_mask_ = 0;  // bit i: data register 3 + i read since the last sample
    uint8_t pointer_ = 0;
    bool in_transaction_ = false;
    bool reading_ = false;
    bool pointer_set_ = false;
};

}  // namespace sim
