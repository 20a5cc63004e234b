// SPDX-License-Identifier: GPL-3.0-or-later
#include "BatteryModel.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace sim {

namespace {

// A LiPo cell's open-circuit voltage by state of charge (a typical low-rate discharge
// curve: steep at both ends, a plateau near 3.8 V), linear in between.
struct OcvPoint {
    double charge, volts;
};
constexpr OcvPoint kOcvTable[] = {
    {0.00, 3.27}, {0.05, 3.50}, {0.10, 3.69}, {0.15, 3.73}, {0.25, 3.77}, {0.45, 3.80},
    {0.55, 3.87}, {0.80, 3.98}, {0.85, 4.02}, {0.90, 4.08}, {0.95, 4.14}, {1.00, 4.20},
};

constexpr double kPinMaxMv = 5000.0;  // the ADC's reference (AVcc)

double clamp_mv(double mv) { return std::min(std::max(mv, 0.0), kPinMaxMv); }

}  // namespace

double BatteryModel::cell_ocv_v(double charge) {
    const size_t n = sizeof kOcvTable / sizeof kOcvTable[0];
    if (charge <= kOcvTable[0].charge) return kOcvTable[0].volts;
    for (size_t i = 1; i < n; ++i) {
        if (charge <= kOcvTable[i].charge) {
            const OcvPoint& a = kOcvTable[i - 1];
            const OcvPoint& b = kOcvTable[i];
            return a.volts + (b.volts - a.volts) * (charge - a.charge) / (b.charge - a.charge);
        }
    }
    return kOcvTable[n - 1].volts;
}

double BatteryModel::open_circuit_v() const { return o_.cells * cell_ocv_v(charge_); }

double BatteryModel::current_a(uint16_t throttle_width_us) const {
    if (o_.fixed_a >= 0.0) return o_.fixed_a;
    if (throttle_width_us == 0) return o_.idle_a;
    const double thr = std::min(std::max((throttle_width_us - 1000.0) / 1000.0, 0.0), 1.0);
    return o_.idle_a + (o_.max_a - o_.idle_a) * std::pow(thr, 1.5);
}

void BatteryModel::step(double dt_s, double amps) {
    current_a_ = amps;
    if (dt_s > 0.0) {
        const double used_mah = amps * dt_s / 3.6;  // A s -> mAh
        consumed_mah_ += used_mah;
        charge_ = std::max(charge_ - used_mah / o_.capacity_mah, 0.0);
    }
    voltage_v_ = std::max(open_circuit_v() - amps * o_.r_ohm, 0.0);
    stepped_ = true;
}

double BatteryModel::volt_pin_mV() const {
    const double v = stepped_ ? voltage_v_ : open_circuit_v();
    return clamp_mv(v / o_.volt_mult * 1000.0);
}

double BatteryModel::curr_pin_mV() const {
    return clamp_mv((current_a_ / o_.amp_per_volt + o_.amp_offset_v) * 1000.0);
}

bool parse_battery_spec(const std::string& spec, BatteryOptions& out, std::string& error) {
    BatteryOptions o;
    std::stringstream ss(spec);
    std::string item;
    while (std::getline(ss, item, ',')) {
        if (item.empty()) continue;
        const size_t eq = item.find('=');
        if (eq == std::string::npos) {
            error = "--battery: '" + item + "' is not KEY=VALUE";
            return false;
        }
        const std::string key = item.substr(0, eq), text = item.substr(eq + 1);
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !std::isfinite(v)) {
            error = "--battery: " + key + "='" + text + "' is not a number";
            return false;
        }
        struct Key {
            const char* name;
            double* field;
            double min, max;
        };
        double cells = o.cells;
        const Key keys[] = {
            {"cells", &cells, 1, 12},          {"mah", &o.capacity_mah, 1, 1e6},
            {"charge", &o.charge, 0, 1},       {"r_ohm", &o.r_ohm, 0, 10},
            {"amps", &o.fixed_a, 0, 1000},     {"max_a", &o.max_a, 0, 1000},
            {"idle_a", &o.idle_a, 0, 1000},    {"volt_mult", &o.volt_mult, 0.1, 100},
            {"amp_per_volt", &o.amp_per_volt, 0.1, 1000}, {"amp_offset", &o.amp_offset_v, 0, 5},
        };
        bool known = false;
        for (const Key& k : keys) {
            if (key != k.name) continue;
            known = true;
            if (v < k.min || v > k.max) {
                std::ostringstream why;
                why << "--battery: " << key << "=" << text << " is outside " << k.min << ".." << k.max;
                error = why.str();
                return false;
            }
            *k.field = v;
        }
        if (!known) {
            error = "--battery: unknown key '" + key + "' (cells, mah, charge, r_ohm, amps, max_a, idle_a, volt_mult, "
                    "amp_per_volt, amp_offset)";
            return false;
        }
        if (key == "cells") {
            if (cells != std::floor(cells)) {
                error = "--battery: cells=" + text + " is not a whole number";
                return false;
            }
            o.cells = (int)cells;
        }
    }
    out = o;
    return true;
}

}  // namespace sim
