#!/bin/sh
# Builds the probe AVR program (and its bus-violation variant) against the Arduino core
# archive the project's Makefile builds, into OUT_DIR:
#   test/e2e/avr/build.sh OUT_DIR   ->  OUT_DIR/probe.elf, OUT_DIR/probe_violation.elf
# Flags follow the Makefile's firmware flags (../shared/SIM.md, "Building with Debian's
# Arduino core").
set -e
here=$(cd "$(dirname "$0")" && pwd)
project=$(cd "$here/../../.." && pwd)
out=${1:?usage: build.sh OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
avr=/usr/share/arduino/hardware/arduino/avr
make --no-print-directory -s -C "$project" BUILD="$out/core" "$out/core/avr/core.a" >/dev/null
flags="-mmcu=atmega2560 -DF_CPU=16000000L -DARDUINO=10819 -DARDUINO_AVR_MEGA2560 -DARDUINO_ARCH_AVR
  -Os -flto -std=gnu++11 -fno-exceptions -fno-threadsafe-statics -fno-rtti -DDECIMAL_DIG=__DECIMAL_DIG__
  -I$avr/cores/arduino -I$avr/variants/mega -I$avr/libraries/Wire/src -I$avr/libraries/SPI/src"
avr-g++ $flags "$here/probe.cpp" "$out/core/avr/core.a" -Wl,--gc-sections -fuse-linker-plugin -o "$out/probe.elf"
avr-g++ $flags -DPROBE_BUS_VIOLATION "$here/probe.cpp" "$out/core/avr/core.a" -Wl,--gc-sections \
  -fuse-linker-plugin -o "$out/probe_violation.elf"
