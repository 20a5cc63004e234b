// SPDX-License-Identifier: GPL-3.0-or-later
// The battery monitor (lib/Battery) on the APM 2.5's power module port: the pins' ADC sums
// (Adc.h) turned into volts, amps and the charge used ten times a second, as ArduPlane's
// read_battery task; the low-battery failsafe said once (ArduPlane's words, STATUSTEXT in
// MAVLink) and its action; BATTERY_STATUS once a second to a ground station; `status`'s
// line. docs/battery.md has the design.
#pragma once

#include <stdint.h>

#include "MavLink.h"
#include "Text.h"

namespace battery_input {

// Loop task, every 100 ms: the new readings, the failsafe rule.
bool due();
void update();
// Loop task in MAVLink, once a second while BATT_MONITOR is 3 or 4: BATTERY_STATUS.
bool status_due();
void send_status();

// SYS_STATUS's battery: BATT_MONITOR 3 or 4 (present and enabled), healthy outside the
// failsafe (as ArduPilot: battery.healthy() && !has_failsafed()); its fields.
bool enabled();
bool healthy();
mav::BatteryReport report();
// The failsafe has been entered (it stays until the next power-up).
bool failsafe();
// `status`'s "# battery: ..." line.
void print_status_line(const text::Sink* out);

}  // namespace battery_input
