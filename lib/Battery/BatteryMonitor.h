// SPDX-License-Identifier: GPL-3.0-or-later
// The battery monitor: a power module's two analog outputs (the 3DR power module on the
// APM 2.5: the pack's voltage through a 10.1:1 divider on A13, the current as 17 A per
// volt on A12) as volts and amps, the charge used, the capacity left, and ArduPlane's
// low-battery failsafe rule. ArduPilot's AP_BattMonitor (ArduPlane 3.x) is the reference:
//
//   pin volts    = the mean of the ADC conversions since the last update x 5 V / 1024
//                  (AVcc reference, ATmega2560 datasheet 26.7: ADC = Vin x 1024 / Vref;
//                  ArduPilot's voltage_average() on APM2: the mean of its samples since
//                  the last read)
//   voltage      = volt pin x BATT_VOLT_MULT
//   current      = (curr pin - BATT_AMP_OFFSET) x BATT_AMP_PERVOLT
//   consumed mAh += current x dt / 3.6 (A s to mAh), when dt < 2 s (a longer gap is a stall)
//   remaining %  = 100 (BATT_CAPACITY - consumed) / BATT_CAPACITY, held within 0..100
//   failsafe     = the voltage (not 0: no battery) below FS_BATT_VOLTAGE for more than
//                  10 s (AP_BATT_LOW_VOLT_TIMEOUT_MS), or, measuring current, less than
//                  FS_BATT_MAH left (AP_BattMonitor::exhausted); once entered it stays
//                  (ArduPlane's failsafe.low_battery), until reset().
//
// Updated at 10 Hz, as ArduPlane's read_battery task. Units in the names; no clock read:
// the caller gives dt_s and now_ms.
#pragma once

#include <stdint.h>

#include "BatterySettings.h"

namespace battery {

constexpr float kAdcRefV = 5.0f;                        // AVcc on the APM 2.5
constexpr float kVoltsPerCount = kAdcRefV / 1024.0f;    // datasheet 26.7
constexpr uint32_t kLowVoltageMs = 10000u;              // AP_BATT_LOW_VOLT_TIMEOUT_MS
constexpr float kMaxIntegrateDtS = 2.0f;                // AP_BattMonitor: dt < 2 s
constexpr uint16_t kUpdatePeriodMs = 100u;              // ArduPlane's read_battery: 10 Hz

// The mean pin voltage of n conversions that sum to `sum` counts; 0 when n is 0.
float pin_volts(uint32_t sum_counts, uint16_t n);

enum class Failsafe : uint8_t { kNone, kVoltage, kCapacity };

class Monitor {
public:
    // One update: the pins' mean volts since the last one, dt_s since it (0 on the
    // first: nothing integrated), now_ms for the low-voltage timer. True when the
    // failsafe has just been entered (once).
    bool update(const Settings& s, float volt_pin_v, float curr_pin_v, float dt_s, uint32_t now_ms);

    // BATT_MONITOR 3 or 4.
    static bool enabled(const Settings& s) {
        return s.monitor == kMonitorVoltage || s.monitor == kMonitorVoltageAndCurrent;
    }
    static bool has_current(const Settings& s) { return s.monitor == kMonitorVoltageAndCurrent; }

    float voltage_v() const { return voltage_v_; }
    float current_a() const { return current_a_; }
    float consumed_mah() const { return consumed_mah_; }
    // 0..100, or -1 when not measuring current or BATT_CAPACITY is 0.
    int8_t remaining_pct(const Settings& s) const;
    Failsafe failsafe() const { return failsafe_; }
    // The voltage is below FS_BATT_VOLTAGE now (the 10 s are running).
    bool voltage_low() const { return low_timing_; }

    // A new pack: nothing consumed, no failsafe.
    void reset();

private:
    Failsafe exhausted(const Settings& s, uint32_t now_ms);

    float voltage_v_ = 0.0f;
    float current_a_ = 0.0f;
    float consumed_mah_ = 0.0f;
    uint32_t low_since_ms_ = 0;
    bool low_timing_ = false;
    Failsafe failsafe_ = Failsafe::kNone;
};

}  // namespace battery
