// SPDX-License-Identifier: GPL-3.0-or-later
// millis() starts a fixed time after reset (pipeline::kBootMs), whatever the C runtime's
// start-up costs: the copy of .data, the clearing of .bss, the stack's paint (StackPaint.cpp)
// and the static constructors take time that grows with the static RAM and the constructors'
// work (about 4.5 ms today), and Arduino's init() starts millis() only after them. The
// sensors' clocks are their own: the MPU6000 samples on its own 5 ms grid from power-up, so
// the sample the loop took first (at pipeline::kLoopStartMs of millis()) depended on that
// duration, and a few microseconds more moved it to the next sample: replay, whose timeline
// counts from reset, then ran a step apart. setup() waits for each stage's time less kBootMs
// (firmware.ino), so its timeline counts from reset too.
//
// Timer1 counts from the start of the C runtime (.init1, before anything else runs) at
// clk/8 (0.5 us ticks); .init8 (after the constructors, before main) waits until it reads
// kBootMs, then puts Timer1 back as reset leaves it for Arduino's init() to configure.
// Every register is written explicitly: behind a bootloader, Timer1 may not be at its reset
// state. A start-up longer than kBootMs (or than the counter's 32 ms) waits for nothing.
// Naked and called by nobody, in assembly so that no register is assumed and no stack
// is used (as StackPaint.cpp).
#include <avr/io.h>
#include <stdint.h>

#include "Pipeline.h"

namespace {
constexpr uint32_t kTicksPerMs = F_CPU / 8u / 1000u;  // clk/8: 2000 ticks a millisecond
constexpr uint32_t kBootTicks = (uint32_t)pipeline::kBootMs * kTicksPerMs;
static_assert(kBootTicks > 0u && kBootTicks < 65536u, "kBootMs fits Timer1's 16 bits at clk/8");
}  // namespace

extern "C" __attribute__((naked, used, section(".init1"))) void apm25_start_boot_clock() {
    // __zero_reg__ is not cleared yet (.init2): r24 carries the zero.
    __asm__ __volatile__(
        "ldi r24, 0\n\t"
        "sts %[tccr1b], r24\n\t"  // stopped
        "sts %[tccr1a], r24\n\t"  // normal mode, no outputs
        "sts %[tccr1c], r24\n\t"
        "sts %[timsk1], r24\n\t"  // no interrupts
        "sts %[tcnt1h], r24\n\t"  // high byte first (the TEMP register)
        "sts %[tcnt1l], r24\n\t"
        "ldi r24, 0x2F\n\t"        // every flag cleared (written 1)
        "out %[tifr1], r24\n\t"
        "ldi r24, %[cs11]\n\t"     // clk/8: counting from here
        "sts %[tccr1b], r24\n\t"
        ::[tccr1a] "n"(_SFR_MEM_ADDR(TCCR1A)), [tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)),
          [tccr1c] "n"(_SFR_MEM_ADDR(TCCR1C)), [timsk1] "n"(_SFR_MEM_ADDR(TIMSK1)),
          [tcnt1h] "n"(_SFR_MEM_ADDR(TCNT1H)), [tcnt1l] "n"(_SFR_MEM_ADDR(TCNT1L)),
          [tifr1] "n"(_SFR_IO_ADDR(TIFR1)), [cs11] "n"(_BV(CS11))
        : "r24", "memory");
}

extern "C" __attribute__((naked, used, section(".init8"))) void apm25_wait_boot_clock() {
    __asm__ __volatile__(
        "1:\n\t"
        "sbic %[tifr1], %[tov1]\n\t"  // wrapped (a start-up past 32 ms): no wait
        "rjmp 2f\n\t"
        "lds r24, %[tcnt1l]\n\t"      // low byte first: the high byte is latched with it
        "lds r25, %[tcnt1h]\n\t"
        "cpi r24, lo8(%[ticks])\n\t"
        "ldi r26, hi8(%[ticks])\n\t"
        "cpc r25, r26\n\t"
        "brlo 1b\n"
        "2:\n\t"
        "sts %[tccr1b], __zero_reg__\n\t"  // Timer1 as reset leaves it
        "sts %[tcnt1h], __zero_reg__\n\t"
        "sts %[tcnt1l], __zero_reg__\n\t"
        "ldi r24, 0x2F\n\t"
        "out %[tifr1], r24\n\t"
        ::[tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)), [tcnt1h] "n"(_SFR_MEM_ADDR(TCNT1H)),
          [tcnt1l] "n"(_SFR_MEM_ADDR(TCNT1L)), [tifr1] "n"(_SFR_IO_ADDR(TIFR1)), [tov1] "n"(TOV1),
          [ticks] "n"(kBootTicks)
        : "r24", "r25", "r26", "memory");
}
