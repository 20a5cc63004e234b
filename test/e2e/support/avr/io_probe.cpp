// SPDX-License-Identifier: GPL-3.0-or-later
// A tiny AVR program that checks apm25sim's receiver and servo pins without the firmware
// (test/e2e/test_harness_io.cpp). Built by test/e2e/support/avr/build.sh.
//
// Servo outputs as ArduPilot's APM2 HAL drives them: Timers 1, 4 and 3 in fast PWM mode 14
// (TOP = ICRn = 40000, prescaler 8: 0.5 us ticks, 50 Hz), OCRn written in TIMERn_OVF. Output
// k (1..8) pulses 900 + 100 k + 25 j us, j = (overflows / 10) mod 8: each width held for 10
// periods, then the next. The main loop toggles the PORT bits of the servo pins and of
// other pins of the same ports all the time: while COMnx connects a pin to its timer, PORT
// has no effect on it (ATmega2560 datasheet, 16-bit Timer/Counter, "Compare Match Output
// Unit").
//
// Receiver as the APM2 HAL reads it: Timer5 mode 15 (TOP = OCR5A = 39999), prescaler 8,
// input capture on the rising edge (ICES5) of ICP5 = PL1; a rising-to-rising interval over
// 8000 ticks (4 ms) is the frame sync. Every 50 ms it prints
//   ppm f:<whole 8-channel frames> e:<captures> w1:<ticks> ... w8:<ticks>
// with the last whole frame's intervals in 0.5 us ticks, then ` a0:<counts>`, analog input A0
// (the airspeed sensor's) against the 5 V reference.
#include <Arduino.h>

static volatile uint16_t overflows[3];  // Timer1, Timer4, Timer3

static uint16_t width_ticks(uint8_t output, uint16_t overflow) {
    const uint16_t step = (uint16_t)((overflow / 10u) % 8u);
    return (uint16_t)(2u * (900u + 100u * output + 25u * step));
}

ISR(TIMER1_OVF_vect) {
    const uint16_t k = ++overflows[0];
    OCR1B = width_ticks(1, k);
    OCR1A = width_ticks(2, k);
}
ISR(TIMER4_OVF_vect) {
    const uint16_t k = ++overflows[1];
    OCR4C = width_ticks(3, k);
    OCR4B = width_ticks(4, k);
    OCR4A = width_ticks(5, k);
}
ISR(TIMER3_OVF_vect) {
    const uint16_t k = ++overflows[2];
    OCR3C = width_ticks(6, k);
    OCR3B = width_ticks(7, k);
    OCR3A = width_ticks(8, k);
}

static volatile uint16_t ppm_last;
static volatile uint8_t ppm_channel = 255;  // 255: waiting for a sync
static volatile uint16_t ppm_widths[8];
static volatile uint16_t ppm_frame[8];
static volatile uint16_t ppm_frames;
static volatile uint16_t ppm_captures;

ISR(TIMER5_CAPT_vect) {
    const uint16_t now = ICR5;
    const uint16_t interval = now >= ppm_last ? now - ppm_last : (uint16_t)(now + 40000u - ppm_last);
    ppm_last = now;
    ++ppm_captures;
    if (interval > 8000u) {
        if (ppm_channel == 8) {
            for (uint8_t c = 0; c < 8; ++c) ppm_frame[c] = ppm_widths[c];
            ++ppm_frames;
        }
        ppm_channel = 0;
    } else if (ppm_channel < 8) {
        ppm_widths[ppm_channel++] = interval;
    } else {
        ppm_channel = 255;  // too many channels: wait for the next sync
    }
}

static void start_servo_timer(volatile uint8_t& tccra, volatile uint8_t& tccrb, volatile uint16_t& icr,
                              volatile uint8_t& timsk, uint8_t com_bits) {
    icr = 40000;                                   // TOP first: simavr reads it when the clock starts
    tccra = (uint8_t)(com_bits | (1 << WGM11));    // non-inverting on the outputs, WGM 14 (WGMn1)
    tccrb = (1 << WGM13) | (1 << WGM12) | (1 << CS11);  // WGMn3:2, clk/8
    timsk = 1 << TOIE1;
}

void setup() {
    Serial.begin(115200);
    Serial.println(F("# io probe: servo outputs and PPM capture"));
    DDRB |= (1 << 5) | (1 << 6) | (1 << 7);
    DDRH |= (1 << 3) | (1 << 4) | (1 << 5) | (1 << 6);
    DDRE |= (1 << 3) | (1 << 4) | (1 << 5) | (1 << 7);
    DDRL &= (uint8_t)~(1 << 1);
    OCR1B = width_ticks(1, 0);
    OCR1A = width_ticks(2, 0);
    OCR4C = width_ticks(3, 0);
    OCR4B = width_ticks(4, 0);
    OCR4A = width_ticks(5, 0);
    OCR3C = width_ticks(6, 0);
    OCR3B = width_ticks(7, 0);
    OCR3A = width_ticks(8, 0);
    const uint8_t abc = (1 << COM1A1) | (1 << COM1B1) | (1 << COM1C1);
    start_servo_timer(TCCR1A, TCCR1B, ICR1, TIMSK1, (1 << COM1A1) | (1 << COM1B1));
    start_servo_timer(TCCR4A, TCCR4B, ICR4, TIMSK4, abc);
    start_servo_timer(TCCR3A, TCCR3B, ICR3, TIMSK3, abc);

    OCR5A = 39999;
    TCCR5A = (1 << WGM51) | (1 << WGM50);
    TCCR5B = (1 << WGM53) | (1 << WGM52) | (1 << CS51) | (1 << ICES5);
    TIMSK5 = 1 << ICIE5;
}

static uint32_t last_ms = 0;

void loop() {
    PORTB ^= (1 << 5) | (1 << 6) | (1 << 7);
    PORTH ^= (1 << 3) | (1 << 4) | (1 << 5) | (1 << 6);
    PORTE ^= (1 << 3) | (1 << 4) | (1 << 5) | (1 << 7);
    const uint32_t now = millis();
    if (now - last_ms < 50) return;
    last_ms = now;
    uint16_t frame[8], frames, captures;
    noInterrupts();
    for (uint8_t c = 0; c < 8; ++c) frame[c] = ppm_frame[c];
    frames = ppm_frames;
    captures = ppm_captures;
    interrupts();
    Serial.print(F("ppm f:"));
    Serial.print(frames);
    Serial.print(F(" e:"));
    Serial.print(captures);
    for (uint8_t c = 0; c < 8; ++c) {
        Serial.print(F(" w"));
        Serial.print(c + 1);
        Serial.print(':');
        Serial.print(frame[c]);
    }
    Serial.print(F(" a0:"));
    Serial.println(analogRead(A0));
}
