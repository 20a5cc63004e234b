#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The sketch as the Arduino IDE builds it: Debian's arduino-builder compiles
# firmware/firmware.ino with lib/ and the MAVLink headers (build/mavlink, as a library
# named MAVLink, as the README installs them) as its libraries (and, in a second build, with
# test/sketch/user_extension.ino in place of user.ino), then each ELF runs in apm25sim
# for 4 simulated seconds and must print angle lines. A third build adds
# test/sketch/padding.S to the sketch's folder, as a user's extra file, sized to take the
# image to the 200 KB budget: past 128 KB, it must run as the first build does
# (test/e2e/beyond_128k.py, as e2e.Beyond128K runs the Makefile's images).
#   arduino_builder.sh PROJECT_DIR TOOLS_DIR OUT_DIR
set -u
project=${1:?usage: arduino_builder.sh PROJECT_DIR TOOLS_DIR OUT_DIR}
tools=${2:?}
out=${3:?}
passed=0
failed=0
fail() { echo "FAIL: $*"; failed=$((failed + 1)); }
pass() { echo "ok: $*"; passed=$((passed + 1)); }

command -v arduino-builder >/dev/null || { echo "FAIL: arduino-builder not installed (make deps)"; echo "0 passed, 1 failed"; exit 1; }

build() {  # build NAME SKETCH_DIR [-prefs=...]: arduino-builder into $out/NAME, log in $out/NAME.log
  name=$1 dir=$2
  shift 2
  rm -rf "$out/$name" && mkdir -p "$out/$name"
  arduino-builder -compile -hardware /usr/share/arduino/hardware -tools /usr/share/arduino-builder \
    -libraries "$project/lib" -fqbn arduino:avr:mega:cpu=atmega2560 -build-path "$out/$name" \
    -libraries "$out/libraries" -prefs=compiler.cpp.extra_flags=-DDECIMAL_DIG=__DECIMAL_DIG__ \
    -prefs=tools.ctags.path=/usr/bin -prefs=tools.ctags.cmd.path=/usr/bin/arduino-ctags \
    '-prefs=tools.ctags.pattern="{cmd.path}" -u --language-force=c++ -f - --c++-kinds=svpf --fields=KSTtzns --line-directives "{source_file}"' \
    "$@" "$dir/firmware.ino" > "$out/$name.log" 2>&1
}

run() {  # run NAME: 4 s of the rest scenario; prints the serial output to $out/NAME.out
  "$tools/apm25sim" --elf "$out/$1/firmware.ino.elf" --trajectory "$out/rest.csv" --seconds 4 > "$out/$1.out" 2> "$out/$1.err"
}

mkdir -p "$out"
# The MAVLink headers (make mavlink) as the README installs them for the Arduino IDE: a
# library folder named MAVLink.
[ -f "$tools/mavlink/common/mavlink.h" ] || { echo "FAIL: $tools/mavlink missing (make mavlink)"; echo "0 passed, 1 failed"; exit 1; }
rm -rf "$out/libraries" && mkdir -p "$out/libraries" && ln -s "$tools/mavlink" "$out/libraries/MAVLink"
"$tools/scenario" rest --seconds 4 > "$out/rest.csv" || { echo "FAIL: build/scenario"; exit 1; }

# 1. The sketch as it is.
if build sketch "$project/firmware"; then pass "arduino-builder compiled firmware/firmware.ino"
else fail "arduino-builder on firmware/firmware.ino:"; tail -30 "$out/sketch.log"; fi
if [ -f "$out/sketch/firmware.ino.elf" ] && run sketch && [ "$(grep -c '^roll:' "$out/sketch.out")" -ge 50 ]; then
  pass "the arduino-builder ELF prints angles in apm25sim"
else fail "no angle lines from the arduino-builder ELF"; head -20 "$out/sketch.out" "$out/sketch.err" 2>/dev/null; fi

# 2. A user's second sketch file using Serial2, Serial, Wire and SPI beside the firmware.
ext="$out/extended/firmware"
rm -rf "$out/extended" && mkdir -p "$ext" && cp "$project"/firmware/* "$ext"/
cp "$project/test/sketch/user_extension.ino" "$ext/user.ino"
if build extended-build "$ext"; then pass "the sketch with a user file calling Serial2.begin, Serial.print, Wire.setClock, SPI.usingInterrupt links"
else fail "the sketch with the user file:"; tail -30 "$out/extended-build.log"; fi
if [ -f "$out/extended-build/firmware.ino.elf" ] && run extended-build &&
   grep -q '^# user code: Serial2 at 57600 baud' "$out/extended-build.out" &&
   [ "$(grep -c '^roll:' "$out/extended-build.out")" -ge 50 ]; then
  pass "with the user's code the angles still flow, and its message is printed"
else fail "the extended sketch in apm25sim"; head -20 "$out/extended-build.out" "$out/extended-build.err" 2>/dev/null; fi

# 3. Past 128 KB: the padding as a user's extra file (assembly, which the IDE builds from the
# sketch's folder too), sized from the first build's flash; -Wl,-q keeps the relocations for
# the check of every function pointer (the flash bytes are the same without it).
big="$out/big/firmware"
rm -rf "$out/big" && mkdir -p "$big" && cp "$project"/firmware/* "$big"/ && cp "$project/test/sketch/padding.S" "$big"/
if [ -f "$out/sketch/firmware.ino.elf" ]; then
  flash=$(avr-size -A "$out/sketch/firmware.ino.elf" | awk '/^\.text|^\.data/ {s+=$2} END {print s}')
  pad=$((204800 - flash)); [ "$pad" -gt 0 ] || pad=0
  if build big-build "$big" "-prefs=compiler.S.extra_flags=-DAPM25_PAD_BYTES=$pad" "-prefs=compiler.c.elf.extra_flags=-Wl,-q"
  then pass "the sketch with $pad bytes of padding in a user's padding.S links"
  else fail "the sketch with padding.S:"; tail -30 "$out/big-build.log"; fi
  if [ -f "$out/big-build/firmware.ino.elf" ] &&
     python3 "$project/test/e2e/beyond_128k.py" run --tools "$tools" --work "$out/beyond_128k" --no-controls \
       --base "$out/sketch/firmware.ino.elf" --big "$out/big-build/firmware.ino.elf" > "$out/beyond_128k.log" 2>&1
  then pass "past 128 KB, the arduino-builder image runs as the first build does"; grep '^#' "$out/beyond_128k.log" | head -12
  else fail "the arduino-builder image past 128 KB (test/e2e/beyond_128k.py):"; grep -E '^(FAIL|#)' "$out/beyond_128k.log" | head -40; fi
else
  fail "no first build to pad"
fi

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
