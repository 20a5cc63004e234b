// SPDX-License-Identifier: GPL-3.0-or-later
#include "Features.h"
#if APM25_FLIGHT  // the attitude-only build has no receiver and no outputs

#include "ServoOutputs.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

namespace servo_outputs {

namespace {

constexpr uint16_t kTop = 39999;  // 40000 ticks of 0.5 us: 20 ms

// The compare values for the next period, in output order (OUT1 .. OUT8).
volatile uint16_t next_ocr[kOutputs];

uint16_t ocr_of(uint16_t width_us) { return (uint16_t)(2u * width_us - 1u); }

void fill(const uint16_t width_us[kOutputs]) {
    uint16_t v[kOutputs];
    for (uint8_t i = 0; i < kOutputs; ++i) v[i] = ocr_of(width_us[i]);
    // A 16-bit value is two byte writes: the overflow interrupts must not see half of one.
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
        for (uint8_t i = 0; i < kOutputs; ++i) next_ocr[i] = v[i];
    }
}

}  // namespace

void set(const uint16_t width_us[kOutputs]) { fill(width_us); }

uint16_t width_us(uint8_t output) {
    uint16_t ocr;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { ocr = next_ocr[output]; }
    return (uint16_t)((ocr + 1u) / 2u);
}

void begin(const uint16_t width_us[kOutputs]) {
    fill(width_us);
    // Stopped in normal mode, the first widths and TOP are written (OCRn is not double
    // buffered in mode 0: they are the compare values of the first period, where in a
    // PWM mode they would wait in the buffer for TOP and the first period would compare
    // at 0, a 0.5 us pulse; simavr 1.6 says "avr_timer_write_ocr mode 0 UNSUPPORTED" and
    // keeps them). Then mode 14 (WGMn3:0 = 1110) with COMnx1 (clear on match, set at
    // BOTTOM) so that each pin is the waveform's, low; the pins outputs; the clocks
    // (prescaler 8, CSn1) last: the first level change is the first pulse's rising edge.
    TCCR1A = 0;
    TCCR1B = 0;
    OCR1B = next_ocr[0];
    OCR1A = next_ocr[1];
    ICR1 = kTop;
    TCNT1 = 0;
    TCCR1A = _BV(COM1A1) | _BV(COM1B1) | _BV(WGM11);
    TCCR1B = _BV(WGM13) | _BV(WGM12);
    TCCR4A = 0;
    TCCR4B = 0;
    OCR4C = next_ocr[2];
    OCR4B = next_ocr[3];
    OCR4A = next_ocr[4];
    ICR4 = kTop;
    TCNT4 = 0;
    TCCR4A = _BV(COM4A1) | _BV(COM4B1) | _BV(COM4C1) | _BV(WGM41);
    TCCR4B = _BV(WGM43) | _BV(WGM42);
    TCCR3A = 0;
    TCCR3B = 0;
    OCR3C = next_ocr[5];
    OCR3B = next_ocr[6];
    OCR3A = next_ocr[7];
    ICR3 = kTop;
    TCNT3 = 0;
    TCCR3A = _BV(COM3A1) | _BV(COM3B1) | _BV(COM3C1) | _BV(WGM31);
    TCCR3B = _BV(WGM33) | _BV(WGM32);

    TIFR1 = _BV(TOV1);
    TIFR4 = _BV(TOV4);
    TIFR3 = _BV(TOV3);
    TIMSK1 = _BV(TOIE1);
    TIMSK4 = _BV(TOIE4);
    TIMSK3 = _BV(TOIE3);
    DDRB |= _BV(PB6) | _BV(PB5);
    DDRH |= _BV(PH5) | _BV(PH4) | _BV(PH3);
    DDRE |= _BV(PE5) | _BV(PE4) | _BV(PE3);
    TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11);
    TCCR4B = _BV(WGM43) | _BV(WGM42) | _BV(CS41);
    TCCR3B = _BV(WGM33) | _BV(WGM32) | _BV(CS31);
}

}  // namespace servo_outputs

// At TOP (the overflow), for the period that starts now.
ISR(TIMER1_OVF_vect) {
    OCR1B = servo_outputs::next_ocr[0];
    OCR1A = servo_outputs::next_ocr[1];
}
ISR(TIMER4_OVF_vect) {
    OCR4C = servo_outputs::next_ocr[2];
    OCR4B = servo_outputs::next_ocr[3];
    OCR4A = servo_outputs::next_ocr[4];
}
ISR(TIMER3_OVF_vect) {
    OCR3C = servo_outputs::next_ocr[5];
    OCR3B = servo_outputs::next_ocr[6];
    OCR3A = servo_outputs::next_ocr[7];
}

#endif  // APM25_FLIGHT
