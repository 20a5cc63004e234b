; SPDX-License-Identifier: GPL-3.0-or-later
; Code space, to build the firmware past 128 KB as the features to come will (the e2e test
; e2e.Beyond128K links it with the firmware's objects: `make big`; test/sketch/arduino_builder.sh
; drops it into the sketch's folder, as a user's extra file, for arduino-builder).
;
; apm25_padding is one function of APM25_PAD_BYTES bytes in .text. The linker script (avr6,
; `avr-ld --verbose`) puts .text after the vectors, the PROGMEM data (.progmem*), the
; trampolines and the start-up code, and before every -ffunction-sections function
; (.text.*): the firmware's own code moves up by that much, its last part past 0x20000,
; where the AVR reaches it through EIND and the linker's trampolines for indirect calls.
; The PROGMEM data stays where it was, below 64 KB, as it does when real code grows.
;
; The start-up code calls it once (.init8, which the linker script keeps and runs before
; main): it jumps over its body and returns. Nothing in the sketch refers to it.
;
; With APM25_PAD_BELOW_PROGMEM (a control the test must see fail) the same function goes in
; a .progmem.gcc section, which the linker script puts before the PROGMEM data: that data
; then lies above 64 KB, where LPM (pgm_read_byte) does not reach.

#ifndef APM25_PAD_BYTES
#define APM25_PAD_BYTES 65536
#endif

    .section .init8,"ax",@progbits
    call    apm25_padding

#ifdef APM25_PAD_BELOW_PROGMEM
    .section .progmem.gcc_apm25_padding,"ax",@progbits
#else
    .section .text,"ax",@progbits
#endif
    .global apm25_padding
    .type   apm25_padding, @function
apm25_padding:
    jmp     1f
#if APM25_PAD_BYTES > 6
    .fill   (APM25_PAD_BYTES - 6) / 2, 2, 0x0000    ; nop
#endif
1:  ret
    .size   apm25_padding, . - apm25_padding
