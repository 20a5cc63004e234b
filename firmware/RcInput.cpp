// SPDX-License-Identifier: GPL-3.0-or-later
#include "Features.h"
#if APM25_FLIGHT  // the attitude-only build has no receiver and no outputs

#include "RcInput.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/atomic.h>

namespace rc_input {

namespace {

// Edges come at least 0.8 ms apart and the loop polls between its steps (a step and a
// console reply part take under 8 ms together): 8 hold what comes meanwhile.
constexpr uint8_t kRing = 8;  // a power of two
volatile uint16_t ring[kRing];
volatile uint8_t head;  // captures stored (wraps)
uint8_t tail;           // captures taken

}  // namespace

void begin() {
    DDRL &= (uint8_t)~_BV(PL1);  // ICP5 an input
    // TOP written in normal mode (not double buffered there), then mode 15 (WGM5 =
    // 1111: TOP = OCR5A) and the clock (prescaler 8).
    TCCR5A = 0;
    TCCR5B = 0;
    OCR5A = 39999;
    TCNT5 = 0;
    TCCR5A = _BV(WGM50) | _BV(WGM51);
    TCCR5B = _BV(WGM53) | _BV(WGM52) | _BV(CS51) | _BV(ICES5);  // rising edge
    TIFR5 = _BV(ICF5);
    TIMSK5 = _BV(ICIE5);
}

bool poll(flight::PpmDecoder& decoder) {
    const uint8_t h = head;  // one byte: read at once
    if ((uint8_t)(h - tail) > kRing) {  // the interrupt went round the ring: captures lost
        decoder.reset();
        tail = h;
        return false;
    }
    while (tail != h) {
        uint16_t c;
        ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { c = ring[tail & (kRing - 1u)]; }
        ++tail;
        if (decoder.feed(c)) return true;
    }
    return false;
}

}  // namespace rc_input

ISR(TIMER5_CAPT_vect) {
    const uint8_t h = rc_input::head;
    rc_input::ring[h & (rc_input::kRing - 1u)] = ICR5;
    rc_input::head = (uint8_t)(h + 1u);
}

#endif  // APM25_FLIGHT
