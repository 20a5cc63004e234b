#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Builds the AVR programs the e2e tests run in apm25sim, against the Arduino core
# archive the project's Makefile builds, into OUT_DIR:
#   test/e2e/support/avr/build.sh OUT_DIR   ->  OUT_DIR/probe.elf, OUT_DIR/probe_violation.elf,
#                                       OUT_DIR/selftest.elf, OUT_DIR/io_probe.elf
# probe: the simulated board without the firmware; io_probe: its servo pins and PPM
# receiver without the firmware; selftest: the host unit tests' checks
# on the ATmega2560, compiled from the same lib/ sources as the firmware.
# Flags follow the Makefile's firmware flags (../shared/SIM.md, "Building with Debian's
# Arduino core"). Each ELF is linked to a temporary name and renamed into place, so a
# test that is running an ELF never sees it half written (ctest runs tests in parallel;
# the tests also serialise this script with flock).
set -e
here=$(cd "$(dirname "$0")" && pwd)
project=$(cd "$here/../../../.." && pwd)
out=${1:?usage: build.sh OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
avr=/usr/share/arduino/hardware/arduino/avr
make --no-print-directory -s -C "$project" -f mk/build.mk BUILD="$out/core" "$out/core/avr/core.a" >/dev/null
flags="-mmcu=atmega2560 -DF_CPU=16000000L -DARDUINO=10819 -DARDUINO_AVR_MEGA2560 -DARDUINO_ARCH_AVR
  -Os -flto -std=gnu++11 -fno-exceptions -fno-threadsafe-statics -fno-rtti -DDECIMAL_DIG=__DECIMAL_DIG__
  -I$avr/cores/arduino -I$avr/variants/mega -I$avr/libraries/Wire/src -I$avr/libraries/SPI/src"
# True when $1 exists and none of the other files is newer (each test process calls
# this script; relinking unchanged programs would only cost time).
up_to_date() {
  target=$1
  shift
  [ -f "$target" ] || return 1
  for dep in "$@"; do [ "$dep" -nt "$target" ] && return 1; done
  return 0
}
link() {  # link OUTPUT.elf ARGS...: to a temporary file, then renamed into place
  target=$1
  shift
  avr-g++ $flags "$@" "$out/core/avr/core.a" -Wl,--gc-sections -fuse-linker-plugin -lm -o "$target.tmp.$$"
  mv -f "$target.tmp.$$" "$target"
}
probe_deps="$here/probe.cpp $here/build.sh $out/core/avr/core.a"
up_to_date "$out/probe.elf" $probe_deps || link "$out/probe.elf" "$here/probe.cpp"
up_to_date "$out/probe_violation.elf" $probe_deps ||
  link "$out/probe_violation.elf" -DPROBE_BUS_VIOLATION "$here/probe.cpp"
io_probe_deps="$here/io_probe.cpp $here/build.sh $out/core/avr/core.a"
up_to_date "$out/io_probe.elf" $io_probe_deps || link "$out/io_probe.elf" "$here/io_probe.cpp"
if [ -f "$here/selftest.cpp" ]; then
  lib_inc=""
  for d in "$project"/lib/*/; do lib_inc="$lib_inc -I$d"; done
  # lib/MavLink includes the headers `make mavlink` generates; without them it is left out
  # (the selftest does not use it, and the host build says what is missing).
  mavlink_dir=${MAVLINK_DIR:-$project/build/mavlink}
  lib_src=""
  for f in "$project"/lib/*/*.cpp; do
    case "$f" in */lib/MavLink/*) [ -f "$mavlink_dir/common/mavlink.h" ] || continue ;; esac
    lib_src="$lib_src $f"
  done
  [ -f "$mavlink_dir/common/mavlink.h" ] && lib_inc="$lib_inc -I$mavlink_dir"
  # the firmware's code generation (Makefile AVR_OPT), so the checks run the code that flies
  up_to_date "$out/selftest.elf" "$here/selftest.cpp" $probe_deps "$project"/lib/*/*.cpp "$project"/lib/*/*.h ||
  link "$out/selftest.elf" -ffunction-sections -fdata-sections -mcall-prologues -mrelax \
    -Wall -Wextra -Wdouble-promotion $lib_inc "$here/selftest.cpp" $lib_src
fi
