// SPDX-License-Identifier: GPL-3.0-or-later
// The stack's high-water mark: at start-up, the RAM between the static data's end and the
// top of the stack is painted with profile::kStackPaint; the stack overwrites it as it
// grows, so the painted bytes left untouched are the RAM the stack has never needed.
// apm25sim --profile counts them at the end of a run (`make bench`: "stack high-water
// mark"); on a board a debugger can read them the same way.
//
// The usual AVR way (avr-libc's start-up runs the .initN sections in order, falling
// through from one to the next): in .init3, after .init2 has set the stack pointer and
// __zero_reg__, before .init4 copies .data and clears .bss (both below _end, untouched
// here). Naked and called by nobody, in assembly so that no register is assumed and no
// stack is used while it paints: the stack pointer is RAMEND, nothing is on it yet.
#include <stdint.h>

#include "Profile.h"

extern "C" __attribute__((naked, used, section(".init3"))) void apm25_paint_stack() {
    __asm__ __volatile__(
        "ldi r30, lo8(_end)\n\t"
        "ldi r31, hi8(_end)\n\t"
        "ldi r24, lo8(__stack)\n\t"
        "ldi r25, hi8(__stack)\n\t"
        "ldi r18, 0xC5\n"
        "1:\n\t"
        "st Z+, r18\n\t"
        "cp r30, r24\n\t"
        "cpc r31, r25\n\t"
        "brlo 1b\n\t"
        "st Z, r18\n\t"  // RAMEND itself
        ::: "r18", "r24", "r25", "r30", "r31", "memory");
}
static_assert(profile::kStackPaint == 0xC5, "the painting's ldi writes 0xC5");
