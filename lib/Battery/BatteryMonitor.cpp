// SPDX-License-Identifier: GPL-3.0-or-later
#include "BatteryMonitor.h"

namespace battery {

float pin_volts(uint32_t sum_counts, uint16_t n) {
    if (n == 0u) return 0.0f;
    return (float)sum_counts * kVoltsPerCount / (float)n;
}

bool Monitor::update(const Settings& s, float volt_pin_v, float curr_pin_v, float dt_s, uint32_t now_ms) {
    if (!enabled(s)) {
        voltage_v_ = 0.0f;
        current_a_ = 0.0f;
        low_timing_ = false;
        return false;
    }
    voltage_v_ = volt_pin_v * s.volt_mult;
    if (has_current(s)) {
        current_a_ = (curr_pin_v - s.amp_offset_v) * s.amp_per_volt;
        // A s -> mAh: x 1000 / 3600.
        if (dt_s > 0.0f && dt_s < kMaxIntegrateDtS) consumed_mah_ += current_a_ * dt_s * (1.0f / 3.6f);
    } else {
        current_a_ = 0.0f;
    }
    const Failsafe now = exhausted(s, now_ms);
    if (failsafe_ != Failsafe::kNone || now == Failsafe::kNone) return false;
    failsafe_ = now;
    return true;
}

// AP_BattMonitor::exhausted: the low-voltage timer runs while the voltage is low (a reading
// of 0 is no battery, never low); the capacity rule needs the current measured.
Failsafe Monitor::exhausted(const Settings& s, uint32_t now_ms) {
    if (voltage_v_ > 0.0f && s.fs_voltage_v > 0.0f && voltage_v_ < s.fs_voltage_v) {
        if (!low_timing_) {
            low_timing_ = true;
            low_since_ms_ = now_ms;
        } else if (now_ms - low_since_ms_ > kLowVoltageMs) {
            return Failsafe::kVoltage;
        }
    } else {
        low_timing_ = false;
    }
    if (has_current(s) && s.fs_mah > 0u && (float)s.capacity_mah - consumed_mah_ < (float)s.fs_mah)
        return Failsafe::kCapacity;
    return Failsafe::kNone;
}

int8_t Monitor::remaining_pct(const Settings& s) const {
    if (!has_current(s) || s.capacity_mah == 0u) return -1;
    const float pct = 100.0f * ((float)s.capacity_mah - consumed_mah_) / (float)s.capacity_mah;
    if (!(pct > 0.0f)) return 0;  // NaN too
    if (pct >= 100.0f) return 100;
    return (int8_t)pct;
}

void Monitor::reset() {
    consumed_mah_ = 0.0f;
    low_timing_ = false;
    failsafe_ = Failsafe::kNone;
}

}  // namespace battery
