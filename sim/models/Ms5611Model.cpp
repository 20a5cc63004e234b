// SPDX-License-Identifier: GPL-3.0-or-later
#include "Ms5611Model.h"

#include <cmath>

#include "Ms5611.h"

namespace sim {

namespace {

using ms5611::kCmdAdcRead;
using ms5611::kCmdPromRead;  // + 2 * word
using ms5611::kCmdReset;
constexpr uint8_t kCmdConvertD1 = 0x40;  // + 2 * OSR index (the firmware uses OSR 4096's)
constexpr uint8_t kCmdConvertD2 = 0x50;
constexpr uint32_t kMaxCode = 0xFFFFFF;  // 24-bit ADC

// The temperature the chip means by D2, in 0.01 degC without the integer rounding (the
// inverse is searched on it, so that D2 is the code nearest the temperature).
double temperature_c100(const uint16_t prom[8], uint32_t d2) {
    const double dt = (double)d2 - (double)prom[5] * 256.0;
    double temp = 2000.0 + dt * prom[6] / 8388608.0;
    if (temp < 2000.0) temp -= dt * dt / 2147483648.0;
    return temp;
}

}  // namespace

constexpr double Ms5611Model::kConversion_s[5];

// Word 0: this model's factory word; 1..6: the datasheet's example C1..C6; 7: a serial
// code, CRC-4 (AN520) = 0x3 in the low 4 bits (test/sim/test_ms5611_model.cpp checks it).
const uint16_t Ms5611Model::kProm[8] = {0x0C4D, 40127, 36924, 23317, 23282, 33464, 28312, 0x5A33};

Ms5611Model::Ms5611Model(const Trajectory& trajectory, const Ms5611Options& options)
    : trajectory_(trajectory), options_(options), noise_(options.seed ^ 0xBB67AE8584CAA73Bull) {}

void Ms5611Model::codes_for(const uint16_t prom[8], double pressure_pa, double temperature_c, uint32_t& d1,
                            uint32_t& d2) {
    // D2: TEMP grows with D2 (dT C6 / 2^23 - dT^2 / 2^31 rises for dT < 0): bisection.
    const double target = temperature_c * 100.0;
    uint32_t lo = 0, hi = kMaxCode;
    if (temperature_c100(prom, lo) >= target) hi = lo;
    while (hi - lo > 1) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (temperature_c100(prom, mid) >= target) hi = mid;
        else lo = mid;
    }
    d2 = (std::fabs(temperature_c100(prom, lo) - target) < std::fabs(temperature_c100(prom, hi) - target)) ? lo : hi;
    // D1: P = (D1 SENS / 2^21 - OFF) / 2^15 with the OFF and SENS this D2 gives.
    const ms5611::Terms c = ms5611::terms(prom, d2);
    const double code = (pressure_pa * 32768.0 + (double)c.off) * 2097152.0 / (double)c.sens;
    d1 = code <= 0.0 ? 0 : code >= (double)kMaxCode ? kMaxCode : (uint32_t)std::llround(code);
}

double Ms5611Model::pressure_pa_at(double t_s) {
    const TrajectorySample s = trajectory_.at(t_s);
    return isa_pressure_pa(options_.home.alt_m - s.ned_m[2]);
}

double Ms5611Model::temperature_c_at(double t_s) {
    if (options_.fixed_temperature) return options_.temperature_c;
    const TrajectorySample s = trajectory_.at(t_s);
    return isa_temperature_c(options_.home.alt_m - s.ned_m[2]);
}

void Ms5611Model::advance_to(double t_s) {
    if (t_s < time_s_) return;
    time_s_ = t_s;
    if (converting_ && conversion_end_s_ <= t_s) finish_conversion();
}

void Ms5611Model::finish_conversion() {
    converting_ = false;
    const double mid_s = 0.5 * (conversion_start_s_ + conversion_end_s_);
    uint32_t d1 = 0, d2 = 0;
    const double noise_pa = options_.noise_pa * noise_.gauss();
    codes_for(kProm, pressure_pa_at(mid_s) + noise_pa, temperature_c_at(mid_s), d1, d2);
    uint32_t code = converting_d1_ ? d1 : d2;
    if (faults_.stuck.active(conversion_end_s_)) {
        const bool have = converting_d1_ ? have_last_d1_ : have_last_d2_;
        if (have) code = converting_d1_ ? last_d1_ : last_d2_;
    } else if (converting_d1_) {
        last_d1_ = code;
        have_last_d1_ = true;
    } else {
        last_d2_ = code;
        have_last_d2_ = true;
    }
    if (converting_d1_ && faults_.spike.active(conversion_end_s_)) code ^= 1u << 19;
    result_ = conversion_spoiled_ ? 0 : code;
    result_ready_ = true;
}

void Ms5611Model::set_chip_select(bool selected) {
    if (selected && !selected_) {
        byte_index_ = 0;
        answer_length_ = 0;
    }
    selected_ = selected;
}

void Ms5611Model::command(uint8_t cmd) {
    if (time_s_ < reset_until_s_) {
        ++counters_.commands_during_reset;
        return;
    }
    if (cmd == kCmdReset) {
        ++counters_.resets;
        reset_until_s_ = time_s_ + kReset_s;
        converting_ = false;
        result_ready_ = false;
        return;
    }
    if (cmd == kCmdAdcRead) {
        ++counters_.adc_reads;
        uint32_t value = 0;
        if (converting_) {
            ++counters_.reads_during_conversion;
            conversion_spoiled_ = true;
        } else if (result_ready_) {
            value = result_;
            result_ready_ = false;
        }
        if (value == 0) ++counters_.adc_reads_zero;
        answer_[0] = (uint8_t)(value >> 16);
        answer_[1] = (uint8_t)(value >> 8);
        answer_[2] = (uint8_t)value;
        answer_length_ = 3;
        return;
    }
    const bool d1 = cmd >= kCmdConvertD1 && cmd <= kCmdConvertD1 + 8 && (cmd & 1) == 0;
    const bool d2 = cmd >= kCmdConvertD2 && cmd <= kCmdConvertD2 + 8 && (cmd & 1) == 0;
    if (d1 || d2) {
        if (converting_) ++counters_.commands_during_conversion;
        ++counters_.conversions;
        converting_ = true;
        converting_d1_ = d1;
        conversion_spoiled_ = false;
        result_ready_ = false;
        conversion_start_s_ = time_s_;
        conversion_end_s_ = time_s_ + kConversion_s[(cmd & 0x0F) >> 1];
        return;
    }
    if (cmd >= kCmdPromRead && cmd <= kCmdPromRead + 14 && (cmd & 1) == 0) {
        ++counters_.prom_reads;
        const uint16_t word = kProm[(cmd - kCmdPromRead) >> 1];
        answer_[0] = (uint8_t)(word >> 8);
        answer_[1] = (uint8_t)word;
        answer_length_ = 2;
        return;
    }
    ++counters_.unknown_commands;
}

uint8_t Ms5611Model::transfer(uint8_t mosi, int spi_mode) {
    if (!selected_) return 0x00;
    ++counters_.bytes;
    if (byte_index_ == 0) ++counters_.transactions;
    if (faults_.absent.active(time_s_)) {
        ++counters_.bytes_while_absent;
        ++byte_index_;
        return 0x00;
    }
    if (spi_mode == 1 || spi_mode == 2) ++counters_.bytes_wrong_spi_mode;
    if (byte_index_++ == 0) {
        answer_length_ = 0;
        command(mosi);
        return 0x00;
    }
    const int index = byte_index_ - 2;
    return index < answer_length_ ? answer_[index] : 0x00;
}

}  // namespace sim
