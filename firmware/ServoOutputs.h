// SPDX-License-Identifier: GPL-3.0-or-later
// The eight servo outputs as the APM 2.5 wires them (ArduPilot's APM2 HAL,
// ../shared/APM25.md "Flying"):
//
//   OUT1 OC1B/PB6, OUT2 OC1A/PB5                 Timer1
//   OUT3 OC4C/PH5, OUT4 OC4B/PH4, OUT5 OC4A/PH3  Timer4
//   OUT6 OC3C/PE5, OUT7 OC3B/PE4, OUT8 OC3A/PE3  Timer3
//
// Hardware fast PWM (ATmega2560 datasheet 17.9.3, mode 14: TOP = ICRn), prescaler 8:
// 0.5 us ticks, ICRn = 39999: a 20.000 ms period (ArduPilot wrote 40000, 20.0005 ms).
// The pin is set at BOTTOM and cleared one tick after the compare match, so a width of
// w us is OCRn = 2w - 1. The pulse comes from the timer: no jitter from the loop or the
// interrupts. A new width takes effect at the start of a period, never mid-pulse: the
// loop fills a buffer and each timer's overflow interrupt copies it to the OCRn
// registers at TOP (the chip double-buffers OCRn in this mode; simavr 1.6 applies a
// write at once, so writing them anywhere else cuts pulses there).
//
// Safe from the first pulse: begin() loads the first widths before any pin is an output,
// and the widths given are always within the outputs' limits (lib/Flight's mixer clamps
// them to SERVOn_MIN..MAX).
#pragma once

#include <stdint.h>

namespace servo_outputs {

constexpr uint8_t kOutputs = 8;

// Timers 1, 3 and 4 in mode 14 with these widths from the first period, then the pins.
void begin(const uint16_t width_us[kOutputs]);
// The widths from the next period on.
void set(const uint16_t width_us[kOutputs]);
// The width output (0..7) has from the next period on, us.
uint16_t width_us(uint8_t output);

}  // namespace servo_outputs
