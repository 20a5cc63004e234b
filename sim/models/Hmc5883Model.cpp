// SPDX-License-Identifier: GPL-3.0-or-later
#include "Hmc5883Model.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "Bytes.h"
#include "Hmc5883Registers.h"

namespace sim {

using linalg::Vector3f;

namespace {

constexpr double kNever_s = std::numeric_limits<double>::infinity();
constexpr uint8_t kModeMask = 0x03;
constexpr uint8_t kModeIdle = 0x03;
constexpr uint8_t kStatusLock = 0x02;
constexpr uint8_t kLastRegister = 12;
constexpr uint8_t kLastDataRegister = 8;
// Datasheet "Self Test Operation": positive bias field per chip axis, gauss.

int16_t counts_or_overflow(float gauss, float lsb_per_gauss) {
    const int16_t counts = linalg::saturate_int16(gauss * lsb_per_gauss);
    // Datasheet, data output registers: an ADC over/underflow reads -4096.
    if (counts < -2048 || counts > 2047) return hmc5883::kOverflow;
    return counts;
}

}  // namespace

Hmc5883Model::Hmc5883Model(const Trajectory& trajectory)
    : trajectory_(trajectory), next_measurement_s_(kNever_s) {
    // Datasheet table 2 defaults; power-on leaves no measurement pending.
    std::memset(regs_, 0, sizeof regs_);
    regs_[hmc5883::REG_CONFIG_A] = 0x10;
    regs_[hmc5883::REG_CONFIG_B] = 0x20;
    regs_[hmc5883::REG_MODE] = 0x01;
    regs_[hmc5883::REG_ID_A] = hmc5883::kId[0];
    regs_[hmc5883::REG_ID_A + 1] = hmc5883::kId[1];
    regs_[hmc5883::REG_ID_A + 2] = hmc5883::kId[2];
}

void Hmc5883Model::advance_to(double t_s) {
    if (t_s < time_s_) return;
    while (next_measurement_s_ <= t_s) {
        const double t_m = next_measurement_s_;
        const uint8_t mode = regs_[hmc5883::REG_MODE] & kModeMask;
        if (mode == hmc5883::kModeContinuous) {
            // The output rate's grid anchored at t = 0 (a model choice: simavr runs and
            // the host replay then sample the same instants), at least half a period on.
            const double rate_hz = continuous_rate_hz();
            next_measurement_s_ = std::ceil((t_m + 0.5 / rate_hz) * rate_hz) / rate_hz;
        } else {
            next_measurement_s_ = kNever_s;
            regs_[hmc5883::REG_MODE] = (uint8_t)((regs_[hmc5883::REG_MODE] & ~kModeMask) | kModeIdle);
        }
        measure(t_m);
    }
    time_s_ = t_s;
}

double Hmc5883Model::next_event_s() const { return next_measurement_s_; }

double Hmc5883Model::continuous_rate_hz() const {
    const float rate_hz = hmc5883::output_rate_hz(regs_[hmc5883::REG_CONFIG_A]);
    return rate_hz > 0.0f ? rate_hz : 75.0;  // reserved DO code: the fastest listed rate
}

void Hmc5883Model::measure(double t_s) {
    // Data lock: part of the last sample was read, not all of it.
    if (data_read_mask_ != 0 && data_read_mask_ != 0x3F) {
        ++counters_.samples_dropped_by_lock;
        return;
    }
    const unsigned averaged = 1u << ((regs_[hmc5883::REG_CONFIG_A] >> 5) & 0x03);
    Vector3f sum_uT;
    for (unsigned i = 0; i < averaged; ++i) {
        const TrajectorySample s = trajectory_.at(t_s - (double)(averaged - 1 - i) * kAveragedSampleSpacing_s);
        sum_uT += Vector3f((float)s.mag_uT[0], (float)s.mag_uT[1], (float)s.mag_uT[2]);
    }
    const Vector3f chip_Ga =
        hmc5883::body_to_chip(sum_uT * (1.0f / (float)averaged)) * (1.0f / linalg::kMicroteslaPerGauss);
    float field_Ga[3] = {chip_Ga.x, chip_Ga.y, chip_Ga.z};
    // Self-test (datasheet "Self Test Operation"): the chip measures the external
    // field, then the field with the offset straps on, and outputs the difference:
    // the bias field alone, whatever the external field.
    const uint8_t bias = regs_[hmc5883::REG_CONFIG_A] & hmc5883::kConfigA_BiasMask;
    if (bias == hmc5883::kConfigA_PositiveBias || bias == hmc5883::kConfigA_NegativeBias) {
        const float sign = bias == hmc5883::kConfigA_PositiveBias ? 1.0f : -1.0f;
        for (int i = 0; i < 3; ++i) field_Ga[i] = sign * hmc5883::kSelfTestField_Ga[i];
    }
    const float lsb = hmc5883::lsb_per_gauss((hmc5883::Gain)(regs_[hmc5883::REG_CONFIG_B] & 0xE0));
    int16_t x = counts_or_overflow(field_Ga[0], lsb);
    int16_t y = counts_or_overflow(field_Ga[1], lsb);
    int16_t z = counts_or_overflow(field_Ga[2], lsb);
    if (faults_.overflow.active(t_s)) x = y = z = hmc5883::kOverflow;
    if (faults_.spike.active(t_s)) {
        x = 2000;
        y = -1990;
        z = 2040;
    }
    // Register order X, Z, Y (datasheet table 2).
    const int16_t ordered[3] = {x, z, y};
    for (int i = 0; i < 3; ++i) {
        regs_[hmc5883::REG_DATA_X_MSB + 2 * i] = linalg::high_byte(ordered[i]);
        regs_[hmc5883::REG_DATA_X_MSB + 2 * i + 1] = linalg::low_byte(ordered[i]);
    }
    ++counters_.samples;
    ready_ = true;
    data_read_mask_ = 0;
}

void Hmc5883Model::schedule_after_mode_write() {
    data_read_mask_ = 0;  // a mode write releases the lock
    const uint8_t mode = regs_[hmc5883::REG_MODE] & kModeMask;
    if (mode == hmc5883::kModeContinuous || mode == hmc5883::kModeSingle)
        next_measurement_s_ = time_s_ + kMeasurementDelay_s;
    else
        next_measurement_s_ = kNever_s;
}

uint8_t Hmc5883Model::register_value(uint8_t reg) const {
    if (reg == hmc5883::REG_STATUS) {
        const bool locked = data_read_mask_ != 0 && data_read_mask_ != 0x3F;
        return (uint8_t)((ready_ ? hmc5883::kStatusReady : 0) | (locked ? kStatusLock : 0));
    }
    if (reg >= hmc5883::REG_ID_A && reg <= kLastRegister) {
        const int fault_id = faults_.id[reg - hmc5883::REG_ID_A];
        if (fault_id >= 0) return (uint8_t)fault_id;
    }
    return regs_[reg];
}

bool Hmc5883Model::start(bool read) {
    if (faults_.absent.active(time_s_)) {
        ++counters_.nacked_while_absent;
        in_transaction_ = false;
        return false;
    }
    ++counters_.transactions;
    in_transaction_ = true;
    reading_ = read;
    pointer_set_ = false;
    return true;
}

bool Hmc5883Model::write(uint8_t byte) {
    if (!in_transaction_ || reading_) {
        ++counters_.bytes_without_start;
        return false;
    }
    if (faults_.absent.active(time_s_)) {
        ++counters_.nacked_while_absent;
        return false;
    }
    ++counters_.bytes_written;
    if (!pointer_set_) {
        pointer_ = byte;
        pointer_set_ = true;
        return true;
    }
    const uint8_t reg = pointer_;
    pointer_ = (uint8_t)(pointer_ + 1);
    if (reg > hmc5883::REG_MODE) {
        ++counters_.writes_to_read_only;  // datasheet: ignored
        return true;
    }
    regs_[reg] = byte;
    if (reg == hmc5883::REG_MODE) schedule_after_mode_write();
    if (reg == hmc5883::REG_CONFIG_A) {
        // A new measurement configuration releases the lock and restarts continuous sampling.
        data_read_mask_ = 0;
        if ((regs_[hmc5883::REG_MODE] & kModeMask) == hmc5883::kModeContinuous) schedule_after_mode_write();
    }
    return true;
}

uint8_t Hmc5883Model::read() {
    if (!in_transaction_ || !reading_) {
        ++counters_.bytes_without_start;
        return 0xFF;
    }
    if (faults_.absent.active(time_s_)) {
        ++counters_.nacked_while_absent;
        return 0xFF;  // nobody pulls SDA low
    }
    ++counters_.bytes_read;
    const uint8_t reg = pointer_;
    uint8_t value = 0x00;
    if (reg > kLastRegister) {
        ++counters_.reads_of_invalid_register;
    } else {
        value = register_value(reg);
    }
    if (reg >= hmc5883::REG_DATA_X_MSB && reg <= kLastDataRegister) {
        data_read_mask_ |= (uint8_t)(1u << (reg - hmc5883::REG_DATA_X_MSB));
        ready_ = false;
    }
    // Pointer auto-increment: after 8 back to 3 (re-read the data), after 12 to 0.
    if (reg == kLastDataRegister)
        pointer_ = hmc5883::REG_DATA_X_MSB;
    else if (reg >= kLastRegister)
        pointer_ = 0;
    else
        pointer_ = (uint8_t)(reg + 1);
    return value;
}

void Hmc5883Model::stop() { in_transaction_ = false; }

bool Hmc5883Model::drdy_pin_high() const {
    if (faults_.drdy_stuck_low.active(time_s_)) return false;
    if (faults_.drdy_stuck_high.active(time_s_)) return true;
    if (faults_.absent.active(time_s_)) return false;
    return ready_;
}

bool Hmc5883Model::write_register(uint8_t reg, uint8_t value) {
    const bool ok = start(false) && write(reg) && write(value);
    stop();
    return ok;
}

bool Hmc5883Model::read_registers(uint8_t first_reg, uint8_t* out, size_t count) {
    bool ok = start(false) && write(first_reg);
    stop();
    ok = ok && start(true);
    for (size_t i = 0; i < count; ++i) out[i] = ok ? read() : 0xFF;
    stop();
    return ok;
}

}  // namespace sim
