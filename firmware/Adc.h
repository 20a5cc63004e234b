// SPDX-License-Identifier: GPL-3.0-or-later
// The ATmega2560's one ADC, shared by the airspeed sensor on A0 and the battery monitor's
// two pins (BATT_VOLT_PIN, BATT_CURR_PIN: A13 and A12 on the APM 2.5's power module port).
// One conversion at a time (13 ADC clocks at 16 MHz / 128: 104 us), never waited for:
//   - on each sample the airspeed task takes A0's conversion (started in the period
//     before) with take_a0(), which starts the next conversion: a battery pin's when one
//     is set (the two in turn), else A0's again, as the airspeed sensor always did;
//   - the `adc` loop task, due once that battery conversion is over (the first loop pass
//     after the sample's tasks, ~0.1 ms after it started), adds it to its pin's sum and
//     starts A0's, over long before the next sample.
// So A0 is still converted once a sample period, and each battery pin every other period
// (100 Hz each); the battery task takes the pins' sums ten times a second, the mean of
// its samples since the last read as ArduPilot's APM2 AnalogIn gives it. With no battery
// pin set (BATT_MONITOR 0) the ADC does exactly what it did for the airspeed alone.
// Reference AVcc (5 V); the channel's MUX5 bit in ADCSRB for A8..A15 (datasheet 26.8.1,
// 26.8.4). The mux is only changed with no conversion running.
#pragma once

#include <stdint.h>

namespace adc {

constexpr uint8_t kNoPin = 0xFF;

// In setup(): the ADC on, A0's first conversion (the ADC's longer first one: 25 clocks).
void begin();
// Sample task (the airspeed's): A0's conversion if it is over (true), and the next started.
bool take_a0(uint16_t& counts);
// Loop task: a battery pin's conversion is over: into its sum, A0's next started.
bool battery_conversion_due();
void take_battery_conversion();

// The battery pins to convert (kNoPin: none), from the battery task.
void set_battery_pins(uint8_t volt_pin, uint8_t curr_pin);
// The sums of the battery pins' conversions since the last call, and their counts. At 63
// conversions a sum and its count are halved, as ArduPilot's APM2 AnalogIn does: the mean
// stays that of the latest ones and 16 bits never overflow (64 x 1023 < 65536).
struct Sums {
    uint16_t volt_counts, curr_counts;
    uint8_t volt_n, curr_n;
};
void take_battery_sums(Sums& out);
// While no sample flows (the MPU6000 down: nobody takes A0), the battery task converts its
// pins itself: each conversion waited for (104 us, three at most: ~0.35 ms, within the
// task's budget), A0's started again after them.
void convert_battery_pins_now();

}  // namespace adc
