// SPDX-License-Identifier: GPL-3.0-or-later
// The battery monitor's settings, ArduPilot's AP_BattMonitor and ArduPlane's FS_BATT_*
// parameters (ArduPlane 3.x names; the parameter table, lib/Settings/Params.cpp, has their
// ranges, defaults and words). Part of settings::VehicleSettings.
#pragma once

#include <stdint.h>

namespace battery {

// BATT_MONITOR's values (AP_BattMonitor: AP_BATT_MONITOR_*).
constexpr uint8_t kMonitorDisabled = 0;
constexpr uint8_t kMonitorVoltage = 3;
constexpr uint8_t kMonitorVoltageAndCurrent = 4;

struct Settings {
    uint8_t monitor;        // BATT_MONITOR: 0 off, 3 voltage, 4 voltage and current
    uint8_t volt_pin;       // BATT_VOLT_PIN: analog input A0..A15 (13: the 3DR power module on the APM 2.5)
    uint8_t curr_pin;       // BATT_CURR_PIN (12)
    float volt_mult;        // BATT_VOLT_MULT: battery volts per pin volt (10.1)
    float amp_per_volt;     // BATT_AMP_PERVOLT: A per pin volt above the offset (17.0)
    float amp_offset_v;     // BATT_AMP_OFFSET: the current pin's volts at 0 A
    uint16_t capacity_mah;  // BATT_CAPACITY: the full pack's charge
    float fs_voltage_v;     // FS_BATT_VOLTAGE: below it for 10 s is the failsafe (0: off)
    uint16_t fs_mah;        // FS_BATT_MAH: less charge left than this is the failsafe (0: off)
};

}  // namespace battery
