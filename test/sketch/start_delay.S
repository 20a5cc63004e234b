; SPDX-License-Identifier: GPL-3.0-or-later
; A longer start-up, to show that the firmware's timeline does not depend on how long the C
; runtime's start takes (the ctest e2e.StartupVariants links it with the firmware's
; objects: `make startup-variants`).
;
; APM25_START_DELAY_CYCLES: a busy loop of that many cycles (within 4) in .init7, after the
; static constructors (.init6), before main (.init9), as a heavier constructor would cost.
; APM25_START_DATA_BYTES: that many bytes of initialised static data (.data), which the
; start-up copies from flash (avr-libc's __do_copy_data, .init4) and which moves the end of
; the static data up (less RAM for firmware/StackPaint.cpp to paint). Referenced from the
; .init7 code so that --gc-sections keeps them.

#ifndef APM25_START_DELAY_CYCLES
#define APM25_START_DELAY_CYCLES 0
#endif
#ifndef APM25_START_DATA_BYTES
#define APM25_START_DATA_BYTES 0
#endif

    .section .init7,"ax",@progbits
#if APM25_START_DATA_BYTES > 0
    lds     r24, apm25_start_data       ; keeps the data (a load: 2 cycles)
#endif
#if APM25_START_DELAY_CYCLES >= 8
    ldi     r24, lo8((APM25_START_DELAY_CYCLES - 2) / 4)
    ldi     r25, hi8((APM25_START_DELAY_CYCLES - 2) / 4)
1:  sbiw    r24, 1                      ; 2 cycles
    brne    1b                          ; 2 taken, 1 at the end
#endif

#if APM25_START_DATA_BYTES > 0
    .section .data.apm25_start_data,"aw",@progbits
    .global apm25_start_data
apm25_start_data:
    .fill   APM25_START_DATA_BYTES, 1, 0x5A
#endif
