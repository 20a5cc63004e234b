# SPDX-License-Identifier: GPL-3.0-or-later
# The AVR flags of the build, one list for the Makefile (mk/build.mk includes this file)
# and PlatformIO (platformio.ini: build_flags = !python3 tools/avr_flags.py, which prints
# them). Plain `NAME := flags` lines, a comment line above each: the script reads them.
# The board's own defines (F_CPU, ARDUINO_AVR_MEGA2560 ...) are each build's: PlatformIO
# takes them from its board and framework.

# Defines for every file, the Arduino core's too. TWI_BUFFER_LENGTH: twi.c's three buffers
# hold one transfer; the longest here is the HMC5883L's six data bytes (the core's default,
# 32, spends 72 bytes of RAM on nothing). SERIAL_RX_BUFFER_SIZE: the USB port's receive ring
# (HardwareSerial's 64 by default) holds 128 bytes, three PARAM_SET frames: a ground station's
# burst arrives at 11.5 bytes/ms while a request takes ~0.7 ms and the loop's other work as
# much again; with 64 a 20-frame burst lost 2 (the Arduino IDE's build keeps 64: docs/mavlink.md).
AVR_SHARED_DEFS := -DTWI_BUFFER_LENGTH=8 -DSERIAL_RX_BUFFER_SIZE=128

# Code generation: the compiler's and, with LTO, the link's (which compiles the program).
# -mcall-prologues -mrelax: 1.5 KB less flash for +0.4 % loop cycles (measured with
# --profile); -mrelax also lets the linker turn calls into rcall (--relax).
# -mstrict-X: the X register only where the AVR can address through it (it has no
# displacement): smaller, and the estimator step no slower (README "Performance").
AVR_SHARED_OPT := -Os -flto -ffunction-sections -fdata-sections -mcall-prologues -mrelax -mstrict-X

# The project's own files (lib/, firmware/), after AVR_SHARED_OPT: passes that trade flash
# for speed even at -Os, left out: 1.3 KB less flash, the estimator step and the loop
# iteration within 0.3 % of their cycles (docs/performance.md, "Size"). Not on the Arduino
# core: its interrupt handlers run inside every profiled section, and with these flags
# they add 1.5 % to the estimator step. (PlatformIO's build_flags reach the core too.)
AVR_SHARED_PROJECT_OPT := -fno-jump-tables -fno-move-loop-invariants -fno-gcse -fno-tree-loop-im

# C++ only: no exceptions, no RTTI, no guards on function-local statics (avr-libc has no
# __cxa_guard_*).
AVR_SHARED_CXX := -fno-exceptions -fno-threadsafe-statics -fno-rtti

# The link. -flto-partition=one: the whole program in one LTO unit, which inlines and
# clones with every caller in view (the link is one job here anyway).
AVR_SHARED_LINK := -flto-partition=one -fuse-linker-plugin -Wl,--gc-sections

# The project's warnings (the Makefile makes them errors in the project's own files).
AVR_SHARED_WARN := -Wall -Wextra -Wdouble-promotion
