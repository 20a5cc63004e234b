// SPDX-License-Identifier: GPL-3.0-or-later
#include "Adc.h"

#include "ArduinoCore.h"

namespace adc {

// What the ADC converts now: A0 for the airspeed, or a battery pin (its slot).
enum Slot : uint8_t { kVolt = 0, kCurr = 1, kA0 = 2 };
static uint8_t converting = kA0;
static uint8_t pins[2] = {kNoPin, kNoPin};
static uint8_t next_battery = kVolt;
static Sums sums = {0u, 0u, 0u, 0u};

static void start(uint8_t channel, uint8_t slot) {
    ADMUX = (uint8_t)(_BV(REFS0) | (channel & 0x07u));  // AVcc reference
    if (channel & 0x08u)
        ADCSRB |= _BV(MUX5);
    else
        ADCSRB &= (uint8_t)~_BV(MUX5);
    ADCSRA |= _BV(ADSC);
    converting = slot;
}

static bool busy() { return (ADCSRA & _BV(ADSC)) != 0; }

void begin() {
    ADMUX = _BV(REFS0);  // AVcc reference, channel 0
    ADCSRB &= (uint8_t)~_BV(MUX5);
    converting = kA0;
    ADCSRA |= _BV(ADEN) | _BV(ADSC);
}

// The battery pin whose turn it is (kNoPin: none set).
static uint8_t battery_turn(uint8_t& slot) {
    for (uint8_t tries = 0; tries < 2; ++tries) {
        slot = next_battery;
        next_battery = next_battery == kVolt ? kCurr : kVolt;
        if (pins[slot] != kNoPin) return pins[slot];
    }
    return kNoPin;
}

bool take_a0(uint16_t& counts) {
    if (busy()) return false;
    if (converting != kA0) {  // the loop task has not taken the battery's yet: now, and A0's next
        take_battery_conversion();
        return false;
    }
    counts = ADC;
    uint8_t slot;
    const uint8_t pin = battery_turn(slot);
    if (pin != kNoPin)
        start(pin, slot);
    else
        start(0, kA0);
    return true;
}

bool battery_conversion_due() { return converting != kA0 && !busy(); }

static void add(uint16_t& sum, uint8_t& n, uint16_t counts) {
    if (n >= 63u) {
        sum = (uint16_t)(sum / 2u);
        n = (uint8_t)(n / 2u);
    }
    sum = (uint16_t)(sum + counts);
    ++n;
}

void take_battery_conversion() {
    const uint16_t counts = ADC;
    if (converting == kVolt)
        add(sums.volt_counts, sums.volt_n, counts);
    else if (converting == kCurr)
        add(sums.curr_counts, sums.curr_n, counts);
    start(0, kA0);
}

void convert_battery_pins_now() {
    while (busy()) {
    }
    if (converting != kA0) take_battery_conversion();  // hands it on, starts A0's
    while (busy()) {
    }
    for (uint8_t slot = kVolt; slot <= kCurr; ++slot) {
        if (pins[slot] == kNoPin) continue;
        start(pins[slot], slot);
        while (busy()) {
        }
        take_battery_conversion();  // and A0's started again
        while (busy()) {
        }
    }
}

void set_battery_pins(uint8_t volt_pin, uint8_t curr_pin) {
    pins[kVolt] = volt_pin;
    pins[kCurr] = curr_pin;
}

void take_battery_sums(Sums& out) {
    out = sums;
    sums = Sums{0u, 0u, 0u, 0u};
}

}  // namespace adc
