// SPDX-License-Identifier: GPL-3.0-or-later
#include "Mpu6000Model.h"

#include <cmath>
#include <cstring>

#include "Bytes.h"
#include "Mpu6000Registers.h"

namespace sim {

using linalg::Vector3f;

namespace {

constexpr uint8_t kPwrSleep = 0x40;          // PWR_MGMT_1 bit 6
constexpr uint8_t kIntLevelActiveLow = 0x80; // INT_PIN_CFG bit 7
constexpr uint8_t kIntLatch = 0x20;          // INT_PIN_CFG bit 5
constexpr uint8_t kIntRdClear = 0x10;        // INT_PIN_CFG bit 4
constexpr uint8_t kRegTempOutH = 0x41;
constexpr uint8_t kRegGyroXoutH = 0x43;
constexpr uint8_t kLastDataReg = 0x48;
using linalg::dbl::kPi;

// DLPF bandwidths in Hz by DLPF_CFG (Register Map 4.3 table); 0 and 7 are "off".
constexpr float kGyroBandwidth_hz[8] = {256, 188, 98, 42, 20, 10, 5, 256};
constexpr float kAccelBandwidth_hz[8] = {260, 184, 94, 44, 21, 10, 5, 260};

bool is_data_register(uint8_t reg) { return reg >= mpu6000::REG_ACCEL_XOUT_H && reg <= kLastDataReg; }

bool is_read_only(uint8_t reg) {
    return is_data_register(reg) || reg == mpu6000::REG_INT_STATUS || reg == mpu6000::REG_WHO_AM_I ||
           reg == mpu6000::REG_FIFO_COUNTH || reg == mpu6000::REG_FIFO_COUNTH + 1;
}

int16_t end_of_range(double truth) { return truth >= 0.0 ? 32767 : -32768; }

}  // namespace

Mpu6000Model::Mpu6000Model(const Trajectory& trajectory) : trajectory_(trajectory) {
    reset_registers();
    std::memcpy(snapshot_, regs_, sizeof regs_);
}

void Mpu6000Model::reset_registers() {
    // Register Map section 3: every register resets to 0 except PWR_MGMT_1 (0x40, asleep)
    // and WHO_AM_I (0x68).
    std::memset(regs_, 0, sizeof regs_);
    regs_[mpu6000::REG_PWR_MGMT_1] = kPwrSleep;
    regs_[mpu6000::REG_WHO_AM_I] = mpu6000::kWhoAmIValue;
    data_ready_ = false;
    filter_primed_ = false;
    int_pulse_end_s_ = -1.0;
    fifo_.clear();
}

bool Mpu6000Model::asleep() const { return (regs_[mpu6000::REG_PWR_MGMT_1] & kPwrSleep) != 0; }

double Mpu6000Model::internal_rate_hz() const {
    const uint8_t dlpf = regs_[mpu6000::REG_CONFIG] & 0x07;
    return (dlpf == 0 || dlpf == 7) ? 8000.0 : 1000.0;
}

float Mpu6000Model::gyro_lsb_per_dps() const {
    return mpu6000::gyro_lsb_per_dps((mpu6000::GyroRange)(regs_[mpu6000::REG_GYRO_CONFIG] & 0x18));
}

float Mpu6000Model::accel_lsb_per_g() const {
    return mpu6000::accel_lsb_per_g((mpu6000::AccelRange)(regs_[mpu6000::REG_ACCEL_CONFIG] & 0x18));
}

void Mpu6000Model::advance_to(double t_s) {
    if (t_s < time_s_) return;
    while (next_internal_s_ <= t_s) {
        const double t_sample_s = next_internal_s_;
        // The next point of the internal rate's grid (anchored at t = 0; the rate
        // changes from 8 to 1 kHz when the DLPF is switched on).
        const double rate_hz = internal_rate_hz();
        next_internal_s_ = (std::floor(t_sample_s * rate_hz + 0.5) + 1.0) / rate_hz;
        if (t_sample_s < reset_until_s_ || asleep()) {
            filter_primed_ = false;
            continue;
        }
        internal_sample(t_sample_s);
    }
    time_s_ = t_s;
}

double Mpu6000Model::next_event_s() const {
    double next_s = next_internal_s_;
    if (int_pulse_end_s_ > time_s_ && int_pulse_end_s_ < next_s) next_s = int_pulse_end_s_;
    return next_s;
}

void Mpu6000Model::internal_sample(double t_s) {
    const TrajectorySample s = trajectory_.at(t_s);
    const Vector3f gyro_body((float)s.gyro_rad_s[0], (float)s.gyro_rad_s[1], (float)s.gyro_rad_s[2]);
    const Vector3f accel_body((float)s.accel_m_s2[0], (float)s.accel_m_s2[1], (float)s.accel_m_s2[2]);
    const Vector3f gyro_chip_dps = mpu6000::body_to_chip(gyro_body) * linalg::kDegPerRad;
    const Vector3f accel_chip_g = mpu6000::body_to_chip(accel_body) * (1.0f / linalg::kGravity_m_s2);
    // The ADCs convert within the configured full scale and the DLPF filters what they
    // converted (Product Specification 3.1/3.2: the low-pass is digital): a shock beyond
    // the range is clipped before it is filtered.
    const float gyro_fs_dps = 32768.0f / gyro_lsb_per_dps();
    const float accel_fs_g = 32768.0f / accel_lsb_per_g();
    auto within = [](float v, float fs) { return v > fs ? fs : (v < -fs ? -fs : v); };
    const float gyro_in[3] = {within(gyro_chip_dps.x, gyro_fs_dps), within(gyro_chip_dps.y, gyro_fs_dps),
                              within(gyro_chip_dps.z, gyro_fs_dps)};
    const float accel_in[3] = {within(accel_chip_g.x, accel_fs_g), within(accel_chip_g.y, accel_fs_g),
                               within(accel_chip_g.z, accel_fs_g)};

    // First-order low-pass at the configured bandwidth, one step per internal sample.
    const uint8_t dlpf = regs_[mpu6000::REG_CONFIG] & 0x07;
    const double rate_hz = internal_rate_hz();
    const float gyro_alpha = (float)(1.0 - std::exp(-2.0 * kPi * kGyroBandwidth_hz[dlpf] / rate_hz));
    const float accel_alpha = (float)(1.0 - std::exp(-2.0 * kPi * kAccelBandwidth_hz[dlpf] / rate_hz));
    for (int i = 0; i < 3; ++i) {
        if (!filter_primed_) {
            gyro_dps_filtered_[i] = gyro_in[i];
            accel_g_filtered_[i] = accel_in[i];
        } else {
            gyro_dps_filtered_[i] += gyro_alpha * (gyro_in[i] - gyro_dps_filtered_[i]);
            accel_g_filtered_[i] += accel_alpha * (accel_in[i] - accel_g_filtered_[i]);
        }
    }
    filter_primed_ = true;

    // Output every (1 + SMPLRT_DIV)-th internal sample, counted on the absolute grid
    // (see advance_to): the same instants whenever the chip was configured.
    const long index = std::lround(t_s * rate_hz);
    if (index % (1L + regs_[mpu6000::REG_SMPLRT_DIV]) == 0) publish_sample(t_s);
}

void Mpu6000Model::publish_sample(double t_s) {
    if (faults_.frozen.active(t_s)) return;
    const float gyro_lsb = gyro_lsb_per_dps();
    const float accel_lsb = accel_lsb_per_g();
    int16_t accel[3], gyro[3];
    for (int i = 0; i < 3; ++i) {
        accel[i] = linalg::saturate_int16(accel_g_filtered_[i] * accel_lsb);
        gyro[i] = linalg::saturate_int16(gyro_dps_filtered_[i] * gyro_lsb);
        if (faults_.accel_saturate.active(t_s)) accel[i] = end_of_range(accel_g_filtered_[i]);
        if (faults_.gyro_saturate.active(t_s)) gyro[i] = end_of_range(gyro_dps_filtered_[i]);
    }
    if (faults_.spike.active(t_s)) {
        // Absurd but not saturated: a glitch, not a range problem.
        const int16_t accel_spike[3] = {-31000, 29000, 30500};
        const int16_t gyro_spike[3] = {30000, -29500, 31000};
        for (int i = 0; i < 3; ++i) {
            accel[i] = accel_spike[i];
            gyro[i] = gyro_spike[i];
        }
    }
    const int16_t temp = linalg::saturate_int16((kTemperature_c - 36.53f) * 340.0f);
    for (int i = 0; i < 3; ++i) {
        regs_[mpu6000::REG_ACCEL_XOUT_H + 2 * i] = linalg::high_byte(accel[i]);
        regs_[mpu6000::REG_ACCEL_XOUT_H + 2 * i + 1] = linalg::low_byte(accel[i]);
        regs_[kRegGyroXoutH + 2 * i] = linalg::high_byte(gyro[i]);
        regs_[kRegGyroXoutH + 2 * i + 1] = linalg::low_byte(gyro[i]);
    }
    regs_[kRegTempOutH] = linalg::high_byte(temp);
    regs_[kRegTempOutH + 1] = linalg::low_byte(temp);

    ++counters_.samples;
    if (!sample_read_ && counters_.samples > 1) ++counters_.samples_not_read;
    push_fifo_sample();
    sample_read_ = false;
    data_ready_ = true;
    regs_[mpu6000::REG_INT_STATUS] |= mpu6000::kIntStatusDataReady;
    int_pulse_end_s_ = t_s + kIntPulse_s;
}

void Mpu6000Model::push_fifo_sample() {
    if (!(regs_[mpu6000::REG_USER_CTRL] & mpu6000::kUserCtrlFifoEn)) return;
    const uint8_t en = regs_[mpu6000::REG_FIFO_EN];
    // Register order (Register Map 4.6): ACCEL (bit 3), TEMP (bit 7), XG, YG, ZG (bits 6..4).
    struct Source { uint8_t bit, reg, bytes; };
    const Source kSources[] = {{0x08, mpu6000::REG_ACCEL_XOUT_H, 6}, {0x80, kRegTempOutH, 2},
                               {0x40, kRegGyroXoutH, 2}, {0x20, kRegGyroXoutH + 2, 2}, {0x10, kRegGyroXoutH + 4, 2}};
    bool overflowed = false;
    for (const Source& src : kSources) {
        if (!(en & src.bit)) continue;
        for (uint8_t i = 0; i < src.bytes; ++i) {
            if (fifo_.size() >= mpu6000::kFifoSize) {
                fifo_.pop_front();
                overflowed = true;
            }
            fifo_.push_back(regs_[src.reg + i]);
        }
    }
    if (overflowed) {
        ++counters_.fifo_overflows;
        regs_[mpu6000::REG_INT_STATUS] |= mpu6000::kIntStatusFifoOverflow;
    }
    update_fifo_count();
}

void Mpu6000Model::update_fifo_count() {
    const int16_t count = (int16_t)fifo_.size();
    regs_[mpu6000::REG_FIFO_COUNTH] = linalg::high_byte(count);
    regs_[mpu6000::REG_FIFO_COUNTH + 1] = linalg::low_byte(count);
}

void Mpu6000Model::clear_data_ready() {
    data_ready_ = false;
    regs_[mpu6000::REG_INT_STATUS] &= (uint8_t)~mpu6000::kIntStatusDataReady;
}

bool Mpu6000Model::int_asserted() const {
    if (!data_ready_ || !(regs_[mpu6000::REG_INT_ENABLE] & mpu6000::kIntEnableDataReady)) return false;
    if (regs_[mpu6000::REG_INT_PIN_CFG] & kIntLatch) return true;
    return time_s_ < int_pulse_end_s_;
}

bool Mpu6000Model::int_pin_high() const {
    if (faults_.absent.active(time_s_) || faults_.int_stuck_low.active(time_s_)) return false;
    const bool active_low = (regs_[mpu6000::REG_INT_PIN_CFG] & kIntLevelActiveLow) != 0;
    return int_asserted() != active_low;
}

void Mpu6000Model::set_chip_select(bool selected) {
    if (selected && !selected_) {
        byte_index_ = 0;
        std::memcpy(snapshot_, regs_, sizeof regs_);
    }
    if (!selected && selected_ && byte_index_ > 0) ++counters_.transactions;
    selected_ = selected;
}

uint8_t Mpu6000Model::transfer(uint8_t mosi, double sck_hz) {
    if (!selected_) {
        ++counters_.bytes_without_select;
        return 0x00;
    }
    ++counters_.bytes;
    const unsigned index = byte_index_++;
    if (faults_.absent.active(time_s_)) {
        ++counters_.access_while_absent;
        return 0x00;
    }
    if (time_s_ < reset_until_s_) {
        ++counters_.access_during_reset;
        return 0x00;
    }
    if (index == 0) {
        reading_ = (mosi & mpu6000::kReadFlag) != 0;
        address_ = mosi & 0x7F;
        return 0x00;
    }
    const uint8_t reg = address_;
    if (reg != mpu6000::REG_FIFO_R_W) address_ = (uint8_t)((address_ + 1) & 0x7F);  // burst auto-increment
    if (reading_) return read_register_for_spi(reg);
    write_register_from_spi(reg, mosi, sck_hz);
    return 0x00;
}

uint8_t Mpu6000Model::read_register_for_spi(uint8_t reg) {
    if (reg == mpu6000::REG_FIFO_R_W) {
        if (fifo_.empty()) {
            ++counters_.fifo_underruns;
            return 0x00;
        }
        const uint8_t b = fifo_.front();
        fifo_.pop_front();
        update_fifo_count();
        sample_read_ = true;
        return b;
    }
    uint8_t value = snapshot_[reg];
    if (reg == mpu6000::REG_WHO_AM_I && faults_.who_am_i >= 0) value = (uint8_t)faults_.who_am_i;
    if (is_data_register(reg)) {
        if (asleep()) {
            ++counters_.data_read_while_asleep;
            value = 0x00;
        }
        sample_read_ = true;
    }
    if (reg == mpu6000::REG_INT_STATUS) regs_[reg] &= (uint8_t)~mpu6000::kIntStatusFifoOverflow;
    if (reg == mpu6000::REG_INT_STATUS || (regs_[mpu6000::REG_INT_PIN_CFG] & kIntRdClear)) clear_data_ready();
    return value;
}

void Mpu6000Model::write_register_from_spi(uint8_t reg, uint8_t value, double sck_hz) {
    ++counters_.register_writes;
    if (sck_hz > 1.05e6) ++counters_.writes_above_1mhz;
    if (is_read_only(reg)) {
        ++counters_.writes_to_read_only;
        return;
    }
    if (reg == mpu6000::REG_PWR_MGMT_1 && (value & mpu6000::kPwrDeviceReset)) {
        reset_registers();
        reset_until_s_ = time_s_ + kResetDuration_s;
        return;
    }
    if (reg == mpu6000::REG_USER_CTRL && (value & mpu6000::kUserCtrlFifoReset)) {
        fifo_.clear();
        update_fifo_count();
        value = (uint8_t)(value & ~mpu6000::kUserCtrlFifoReset);  // self-clearing
    }
    regs_[reg] = value;
    if (reg == mpu6000::REG_PWR_MGMT_1 && !(value & kPwrSleep)) {
        // Waking: sampling resumes at the next point of the internal rate's grid,
        // anchored at t = 0 (a model choice: the chip's own phase is arbitrary, and
        // a fixed one makes simavr runs and the host replay sample the same instants).
        if (next_internal_s_ < time_s_) next_internal_s_ = std::ceil(time_s_ * internal_rate_hz()) / internal_rate_hz();
    }
}

void Mpu6000Model::write_register(uint8_t reg, uint8_t value) {
    set_chip_select(true);
    transfer((uint8_t)(reg & 0x7F));
    transfer(value);
    set_chip_select(false);
}

void Mpu6000Model::read_registers(uint8_t first_reg, uint8_t* out, size_t count) {
    set_chip_select(true);
    transfer((uint8_t)(first_reg | mpu6000::kReadFlag), 8e6);
    for (size_t i = 0; i < count; ++i) out[i] = transfer(0x00, 8e6);
    set_chip_select(false);
}

}  // namespace sim
