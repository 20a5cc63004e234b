# SPDX-License-Identifier: GPL-3.0-or-later
# The build, run by the Makefile once the toolchain is installed (make -f mk/build.mk GOAL
# works too when it is). V=1 shows every command.

BUILD       ?= build
ARDUINO_AVR ?= /usr/share/arduino/hardware/arduino/avr
PORT        ?= /dev/ttyACM0
BAUD        := 115200
SCENARIO    ?= tilt_tour
SECONDS     ?=
SERIAL      ?=
# APM25_FLIGHT=0: the attitude-only build (firmware/Features.h), in build/attitude-only.
APM25_FLIGHT ?= 1

ifeq ($(V),1)
Q :=
say = @:
else
Q := @
say = @printf '  %-8s %s\n' '$(1)' '$(2)'
endif

.PHONY: all firmware tools unit sim fly test bench tune upload size attitude-only big progmem-control docs startup-variants
all: firmware tools

# ---------------------------------------------------------------------------
# Firmware: the sketch firmware/firmware.ino (+ the folder's other .ino and .cpp files),
# the project's libraries lib/*, and the Arduino core with SPI and Wire, as the Arduino
# IDE builds them (../shared/SIM.md: Debian's avr-gcc 5.4 and arduino-core-avr).
# APM25_FLIGHT=0 builds the same sketch without the flight features into FW_BUILD
# (build/attitude-only/firmware.elf, .hex), the Arduino core's objects shared.
ifeq ($(APM25_FLIGHT),0)
FW_BUILD := $(BUILD)/attitude-only
FW_DEFS  := -DAPM25_FLIGHT=0
else
FW_BUILD := $(BUILD)
FW_DEFS  :=
endif
MCU   := atmega2560
F_CPU := 16000000L
AVR_CC  := avr-gcc
AVR_CXX := avr-g++
AVR_AR  := avr-gcc-ar
CORE_DIR := $(ARDUINO_AVR)/cores/arduino
WIRE_DIR := $(ARDUINO_AVR)/libraries/Wire/src
SPI_DIR  := $(ARDUINO_AVR)/libraries/SPI/src
EEPROM_DIR := $(ARDUINO_AVR)/libraries/EEPROM/src
LIB_DIRS := $(sort $(dir $(wildcard lib/*/)))

# The flags: mk/avr-flags.mk, shared with platformio.ini. The link takes the optimisation
# and the target's flags too: with LTO it compiles the program.
include mk/avr-flags.mk
AVR_DEFS  := -mmcu=$(MCU) -DF_CPU=$(F_CPU) -DARDUINO=10819 -DARDUINO_AVR_MEGA2560 -DARDUINO_ARCH_AVR \
             $(AVR_SHARED_DEFS)
AVR_INC   := -I$(CORE_DIR) -I$(ARDUINO_AVR)/variants/mega -I$(WIRE_DIR) -I$(WIRE_DIR)/utility \
             -I$(SPI_DIR) -I$(EEPROM_DIR) $(addprefix -I,$(LIB_DIRS)) -Ifirmware
AVR_OPT   := $(AVR_SHARED_OPT)
AVR_CFLAGS   := $(AVR_DEFS) $(AVR_OPT) -std=gnu11
# DECIMAL_DIG: WString.cpp needs it, which Debian's gcc 5.4 leaves undefined in C++11.
AVR_CXXFLAGS := $(AVR_DEFS) $(AVR_OPT) -std=gnu++11 $(AVR_SHARED_CXX) -DDECIMAL_DIG=__DECIMAL_DIG__
# The project's own files: every warning is an error.
PROJECT_WARN := $(AVR_SHARED_WARN) -Werror
# ... and their own optimisation flags (mk/avr-flags.mk).
PROJECT_OPT  := $(AVR_SHARED_PROJECT_OPT)
AVR_LDFLAGS  := -mmcu=$(MCU) $(filter -O% -flto,$(AVR_SHARED_OPT)) $(AVR_SHARED_LINK) \
                $(filter -m%,$(AVR_SHARED_OPT))

CORE_SRC := $(wildcard $(CORE_DIR)/*.c) $(wildcard $(CORE_DIR)/*.cpp) $(wildcard $(CORE_DIR)/*.S) \
            $(WIRE_DIR)/Wire.cpp $(WIRE_DIR)/utility/twi.c $(SPI_DIR)/SPI.cpp
CORE_OBJ := $(patsubst $(ARDUINO_AVR)/%,$(BUILD)/avr/arduino/%.o,$(CORE_SRC))
# The sketch's .ino files as the Arduino IDE joins them: the main one, then the others
# in alphabetical order, after #include <Arduino.h>. (They need no generated prototypes:
# every function is declared before use.)
SKETCH_INO := firmware/firmware.ino $(sort $(filter-out firmware/firmware.ino,$(wildcard firmware/*.ino)))
SKETCH_CPP := $(FW_BUILD)/avr/sketch/firmware.ino.cpp
FW_SRC   := $(wildcard firmware/*.cpp) $(foreach d,$(LIB_DIRS),$(wildcard $(d)*.cpp))
FW_OBJ   := $(patsubst %,$(FW_BUILD)/avr/%.o,$(FW_SRC)) $(SKETCH_CPP).o
FW_HDR   := $(wildcard firmware/*.h) $(foreach d,$(LIB_DIRS),$(wildcard $(d)*.h))

firmware: $(FW_BUILD)/firmware.hex size

# The attitude-only build beside the full one: `make test` checks that it builds.
attitude-only:
	@$(MAKE) --no-print-directory -f mk/build.mk APM25_FLIGHT=0 firmware

# The core's objects follow this file's flags (TWI_BUFFER_LENGTH ...), every object the
# shared flags.
$(CORE_OBJ): mk/build.mk
$(CORE_OBJ) $(FW_OBJ): mk/avr-flags.mk

$(BUILD)/avr/arduino/%.c.o: $(ARDUINO_AVR)/%.c
	@mkdir -p $(dir $@)
	$(Q)$(AVR_CC) $(AVR_CFLAGS) $(AVR_INC) -w -c $< -o $@
$(BUILD)/avr/arduino/%.cpp.o: $(ARDUINO_AVR)/%.cpp
	@mkdir -p $(dir $@)
	$(Q)$(AVR_CXX) $(AVR_CXXFLAGS) $(AVR_INC) -w -c $< -o $@
$(BUILD)/avr/arduino/%.S.o: $(ARDUINO_AVR)/%.S
	@mkdir -p $(dir $@)
	$(Q)$(AVR_CC) $(AVR_DEFS) -x assembler-with-cpp $(AVR_INC) -c $< -o $@
$(BUILD)/avr/core.a: $(CORE_OBJ)
	$(call say,CORE,Arduino core + SPI + Wire ($(words $(CORE_OBJ)) files) -> $@)
	@rm -f $@
	$(Q)$(AVR_AR) rcs $@ $^

$(SKETCH_CPP): $(SKETCH_INO)
	@mkdir -p $(dir $@)
	$(Q){ echo '#include <Arduino.h>'; for f in $^; do echo "#line 1 \"$$f\""; cat "$$f"; done; } > $@
$(SKETCH_CPP).o: $(SKETCH_CPP) $(FW_HDR)
	$(call say,AVR-CXX,$(SKETCH_INO))
	$(Q)$(AVR_CXX) $(AVR_CXXFLAGS) $(PROJECT_OPT) $(FW_DEFS) $(PROJECT_WARN) $(AVR_INC) -c $< -o $@
$(FW_BUILD)/avr/%.cpp.o: %.cpp $(FW_HDR)
	$(call say,AVR-CXX,$<)
	@mkdir -p $(dir $@)
	$(Q)$(AVR_CXX) $(AVR_CXXFLAGS) $(PROJECT_OPT) $(FW_DEFS) $(PROJECT_WARN) $(AVR_INC) -c $< -o $@

# The commit's hash for AUTOPILOT_VERSION (firmware/Version.h: git_version.h when the build
# has one), rewritten only when HEAD moves, so that only GcsLink is compiled again.
GIT_VERSION_H := $(FW_BUILD)/avr/gen/git_version.h
$(GIT_VERSION_H): FORCE
	@mkdir -p $(dir $@)
	@h=$$(git rev-parse --short=8 HEAD 2>/dev/null); line="#define APM25_GIT_HASH \"$$h\""; \
	  [ -n "$$h" ] || line="/* not built from a git checkout */"; \
	  [ -f $@ ] && [ "$$(cat $@)" = "$$line" ] || echo "$$line" > $@
$(FW_BUILD)/avr/firmware/GcsLink.cpp.o: $(GIT_VERSION_H)
$(FW_BUILD)/avr/firmware/GcsLink.cpp.o: AVR_INC += -I$(FW_BUILD)/avr/gen
.PHONY: FORCE
FORCE:

$(FW_BUILD)/firmware.elf: $(FW_OBJ) $(BUILD)/avr/core.a
	$(call say,LINK,$@)
	$(Q)$(AVR_CXX) $(AVR_LDFLAGS) $(FW_OBJ) $(BUILD)/avr/core.a -lm -o $@

$(FW_BUILD)/firmware.hex: $(FW_BUILD)/firmware.elf
	$(Q)avr-objcopy -O ihex -R .eeprom $< $@

size: $(FW_BUILD)/firmware.elf
	@avr-size -A $< | awk '/^\.text|^\.data|^\.bss/ {s[$$1]=$$2} END { \
	  printf "# %s: flash %d bytes (of 253952), static RAM %d bytes (of 8192)\n", \
	  "$(if $(FW_DEFS),attitude-only firmware,firmware)", s[".text"]+s[".data"], s[".data"]+s[".bss"] }'

# ---------------------------------------------------------------------------
# The firmware with a longer C runtime start-up (make startup-variants ->
# build/startup/*.elf, for the test e2e.Equivalence.WhateverTheStartUpTakes): the same objects
# linked after test/sketch/start_delay.S, a busy loop of N cycles after the static
# constructors (dN) or N bytes more of initialised static data (rN). kBootMs
# (firmware/StartTime.cpp) absorbs them all but late-d200000 (12.5 ms more, past kBootMs: the
# control the test must see fail).
STARTUP_BUILD    := $(BUILD)/startup
STARTUP_VARIANTS := d0 d20 d80 d500 d2000 d20000 d80000 r33 r400 late-d200000
startup-variants: $(patsubst %,$(STARTUP_BUILD)/%.elf,$(STARTUP_VARIANTS))
.PRECIOUS: $(STARTUP_BUILD)/%.S.o
$(STARTUP_BUILD)/%.S.o: test/sketch/start_delay.S
	@mkdir -p $(dir $@)
	$(Q)n=$$(echo $* | sed 's/^late-//; s/^[a-z]//'); \
	  case $* in *d*) defs="-DAPM25_START_DELAY_CYCLES=$$n";; *) defs="-DAPM25_START_DATA_BYTES=$$n";; esac; \
	  $(AVR_CC) $(AVR_DEFS) $$defs -x assembler-with-cpp -c $< -o $@
$(STARTUP_BUILD)/%.elf: $(STARTUP_BUILD)/%.S.o $(FW_OBJ) $(BUILD)/avr/core.a
	$(call say,LINK,$@ (start-up variant))
	$(Q)$(AVR_CXX) $(AVR_LDFLAGS) $< $(FW_OBJ) $(BUILD)/avr/core.a -lm -o $@

# ---------------------------------------------------------------------------
# The firmware past 128 KB (make big -> build/big/firmware.elf, for the test e2e.Beyond128K):
# the same objects linked after test/sketch/padding.S, a function of FLASH_BUDGET bytes less
# the firmware's flash in .text, which the linker script puts after the PROGMEM data and the
# start-up code and before every function of the firmware: their code moves up by that much,
# past 0x20000 for its last part (where EIND and the linker's trampolines reach it), as the
# features to come will move it. -q keeps the relocations in the ELF, for the test to follow
# every function pointer (the flash bytes are the same with or without it).
# Beside it, two controls that the test must see fail: the image linked without trampolines
# (--no-stubs: a word address of code above 128 KB wraps round), and padding before the
# PROGMEM data that lifts its end past LPM's 64 KB (that one from the attitude-only build).
FLASH_BUDGET := 204800
BIG_BUILD    := $(FW_BUILD)/big
BIG_LINK      = $(AVR_CXX) $(AVR_LDFLAGS) -Wl,-q $(BIG_LDFLAGS) $< $(FW_OBJ) $(BUILD)/avr/core.a -lm -o $@
big: $(BIG_BUILD)/firmware.elf $(BIG_BUILD)/no-trampolines.elf
	@$(MAKE) --no-print-directory -f mk/build.mk APM25_FLIGHT=0 progmem-control
# The PROGMEM control from the attitude-only objects (build/attitude-only/big): the full
# firmware and 51 KB of padding no longer fit the 2560's 256 KB.
progmem-control: $(BIG_BUILD)/progmem-high.elf
$(BIG_BUILD)/firmware.elf: BIG_LDFLAGS := -Wl,-Map,$(BIG_BUILD)/firmware.map
$(BIG_BUILD)/no-trampolines.elf: BIG_LDFLAGS := -Wl,--no-stubs
$(BIG_BUILD)/padding.S.o: test/sketch/padding.S $(FW_BUILD)/firmware.elf
	@mkdir -p $(dir $@)
	$(Q)flash=$$(avr-size -A $(FW_BUILD)/firmware.elf | awk '/^\.text|^\.data/ {s+=$$2} END {print s}'); \
	  pad=$$(($(FLASH_BUDGET) - flash)); [ $$pad -gt 0 ] || pad=0; \
	  $(AVR_CC) $(AVR_DEFS) -DAPM25_PAD_BYTES=$$pad -x assembler-with-cpp -c $< -o $@
# The control's padding: enough to lift the end of the PROGMEM data (__ctors_start follows
# it) 256 bytes past 64 KB, so that the firmware with it still fits the 2560's flash.
$(BIG_BUILD)/padding-low.S.o: test/sketch/padding.S $(FW_BUILD)/firmware.elf
	@mkdir -p $(dir $@)
	$(Q)end=$$(avr-nm $(FW_BUILD)/firmware.elf | awk '$$3 == "__ctors_start" {print $$1}'); \
	  pad=$$((65536 + 256 - 0x$$end)); \
	  $(AVR_CC) $(AVR_DEFS) -DAPM25_PAD_BYTES=$$pad -DAPM25_PAD_BELOW_PROGMEM -x assembler-with-cpp -c $< -o $@
$(BIG_BUILD)/firmware.elf: $(BIG_BUILD)/padding.S.o $(FW_OBJ) $(BUILD)/avr/core.a
	$(call say,LINK,$@ (padded to the $(FLASH_BUDGET)-byte budget))
	$(Q)$(BIG_LINK)
	@avr-size -A $@ | awk '/^\.text|^\.data/ {s+=$$2} END { printf "# padded firmware: flash %d bytes (of 253952)\n", s }'
$(BIG_BUILD)/no-trampolines.elf: $(BIG_BUILD)/padding.S.o $(FW_OBJ) $(BUILD)/avr/core.a
	$(call say,LINK,$@ (a control))
	$(Q)$(BIG_LINK)
$(BIG_BUILD)/progmem-high.elf: $(BIG_BUILD)/padding-low.S.o $(FW_OBJ) $(BUILD)/avr/core.a
	$(call say,LINK,$@ (a control))
	$(Q)$(BIG_LINK)

# Flash per library (make bench, bench/flash.py): the firmware built again with -g, whose
# debug lines (stabs, avr-gcc 5.4's -g) name the source file of every instruction as LTO
# inlined it, linked with a map (which names the libgcc, libc and libm members and the
# start-up code); and linked once more with -q, for its relocations (which code uses each
# PROGMEM string or table; binutils reads no stabs lines from an ELF that keeps them).
# Its flash bytes are the firmware's: flash.py checks it.
ATTR_BUILD := $(BUILD)/flash-attr
ATTR_OBJ   := $(patsubst $(FW_BUILD)/%,$(ATTR_BUILD)/%,$(FW_OBJ))
.PHONY: flash-attr
flash-attr: $(FW_BUILD)/firmware.elf
	@$(MAKE) --no-print-directory -f mk/build.mk BUILD=$(ATTR_BUILD) MAVLINK_DIR=$(MAVLINK_DIR) VENV=$(VENV) \
	  AVR_OPT="$(AVR_OPT) -g" AVR_LDFLAGS="$(AVR_LDFLAGS) -g -Wl,-Map,$(ATTR_BUILD)/firmware.map" \
	  $(ATTR_BUILD)/firmware.elf
	@[ $(ATTR_BUILD)/firmware-relocs.elf -nt $(ATTR_BUILD)/firmware.elf ] || \
	  $(AVR_CXX) $(AVR_LDFLAGS) -g -Wl,-q $(ATTR_OBJ) $(ATTR_BUILD)/avr/core.a -lm -o $(ATTR_BUILD)/firmware-relocs.elf

# ---------------------------------------------------------------------------
# Host tools and tests (CMake + GoogleTest). CMake is configured every time (a second or
# so): its source globs and the optional tools are read at configure time, so a new file
# is never missed. The compiler's output goes to a log, shown when something fails.
HOST_BUILD := $(BUILD)/host
HOST_LOG   := $(HOST_BUILD)/build.log
NPROC      := $(shell nproc 2>/dev/null || echo 2)
tools:
	$(call say,HOST,tools and tests in $(HOST_BUILD) (log: $(HOST_LOG)))
	@mkdir -p $(HOST_BUILD)
ifeq ($(V),1)
	cmake -S . -B $(HOST_BUILD) -DCMAKE_BUILD_TYPE=Release -DTOOLS_DIR=$(abspath $(BUILD))
	$(MAKE) --no-print-directory -C $(HOST_BUILD) -j$(NPROC)
else
	@{ cmake -S . -B $(HOST_BUILD) -DCMAKE_BUILD_TYPE=Release -DTOOLS_DIR=$(abspath $(BUILD)) && \
	   $(MAKE) --no-print-directory -C $(HOST_BUILD) -j$(NPROC); } > $(HOST_LOG) 2>&1 || \
	 { grep -E -B2 -A12 'error|Error' $(HOST_LOG) | head -80; echo "# host build failed: see $(HOST_LOG)"; exit 1; }
endif

# The host unit tests alone (test/<Library>/ and test/sim/): their target built (and the
# libraries it links, none of the simulator's tools) and run once, in seconds. CMake is
# configured first, as for tools, so that a new test file is never missed.
# FILTER='Mixer.*:PpmDecoder.*' runs only those (GoogleTest's --gtest_filter).
FILTER ?=
unit:
	$(call say,UNIT,host unit tests in $(HOST_BUILD) (build log: $(HOST_LOG)))
	@mkdir -p $(HOST_BUILD)
	@{ cmake -S . -B $(HOST_BUILD) -DCMAKE_BUILD_TYPE=Release -DTOOLS_DIR=$(abspath $(BUILD)) && \
	   $(MAKE) --no-print-directory -C $(HOST_BUILD) -j$(NPROC) unit_tests; } > $(HOST_LOG) 2>&1 || \
	 { grep -E -B2 -A12 'error|Error' $(HOST_LOG) | head -80; echo "# unit tests' build failed: see $(HOST_LOG)"; exit 1; }
	@cd $(HOST_BUILD) && start=$$(date +%s%N) && \
	  { ./unit_tests --gtest_brief=1 $(if $(FILTER),--gtest_filter='$(FILTER)') > unit_tests.log 2>&1; status=$$?; }; \
	  grep -v '^Running main()' unit_tests.log; \
	  echo "# unit: run in $$(( ($$(date +%s%N) - start) / 1000000 )) ms (output: $(HOST_BUILD)/unit_tests.log)"; \
	  exit $$status

# The parameter reference, docs/parameters.md, printed from the parameter table
# (lib/Settings/Params.cpp) by build/paramdoc; the ctest docs.parameters_current fails when
# the committed file is not what the table says.
docs: tools
	$(call say,DOCS,docs/parameters.md from lib/Settings/Params.cpp)
	$(Q)$(BUILD)/paramdoc > docs/parameters.md.tmp && mv docs/parameters.md.tmp docs/parameters.md || \
	  { rm -f docs/parameters.md.tmp; exit 1; }

# SERIAL=tcp:5760: a live board, UART0 served on TCP 127.0.0.1:5760 in real time (as
# ArduPilot's SITL) until Ctrl-C, the scenario's last state held after its end.
# MODE=mavlink (any output mode) types `mode NAME` into the board as it starts.
sim: firmware tools
	@mkdir -p $(BUILD)/scenarios
	@$(BUILD)/scenario $(SCENARIO) > $(BUILD)/scenarios/$(SCENARIO).csv
	$(if $(MODE),@printf 'mode $(MODE)\n' > $(BUILD)/scenarios/sim-input.txt)
	@echo "# simavr: $(FW_BUILD)/firmware.elf on scenario '$(SCENARIO)' (SCENARIO=name, SECONDS=s, SERIAL=tcp:5760 to change)"
	@$(BUILD)/apm25sim --elf $(FW_BUILD)/firmware.elf --trajectory $(BUILD)/scenarios/$(SCENARIO).csv \
	  $(if $(SECONDS),--seconds $(SECONDS)) $(if $(SERIAL),--serial $(SERIAL)) \
	  $(if $(MODE),--input $(BUILD)/scenarios/sim-input.txt)

# make fly [FLIGHT=cruise|gusty|upset|turn|figure8|climb|mission] [GUST=0|1|2] [SECONDS=s] [STAMP=1]
# [VIEW=1] [SERIAL=tcp:5760] [SPEED=x]: the firmware flies the JSBSim Rascal
# (sim/flight/closed_loop.py: the backend with the flight's stick script, apm25sim
# --physics json in lock-step), the board's serial output shown as a serial monitor would
# (STAMP=1: after its simulated time); VIEW=1 (or make view FLIGHT=...) draws it on the
# live horizon. SERIAL=tcp:5760 (or GCS=tcp:5760) attaches a ground station: the board's
# UART0 also on TCP 127.0.0.1:5760, as make sim SERIAL=... and ArduPilot's SITL, flown in
# real time (SPEED=x: x times real time). MODE=mavlink (plot, csv, quat, raw, quiet) types
# `mode NAME` into the board as it starts, as make view MODE=... does: in MAVLink from then
# on, a ground station that only listens hears it. The board is armed on the stand
# (closed_loop.py --arm: `arm` typed, the throttle at zero meanwhile). Both processes end by themselves, or
# after FLY_TIMEOUT wall seconds.
# FLIGHT=mission flies a mission in AUTO from a hand launch (sim/flight/mission_flight.py;
# MISSION=FILE.waypoints or FILE.plan, default sim/flight/missions/thesis.waypoints; light
# gusts unless GUST=), prints its figures and draws it into PLOT (build/flight/mission.png;
# docs/mission.png is this picture).
FLY_TIMEOUT ?= 1800
FLY_SERIAL = $(or $(GCS),$(SERIAL))
MISSION ?= sim/flight/missions/thesis.waypoints
PLOT ?= $(BUILD)/flight/mission.png
fly: firmware tools venv
ifeq ($(FLIGHT),mission)
	@echo "# flight 'mission': build/firmware.elf flies $(MISSION) in AUTO from a hand launch (MISSION=file.waypoints|.plan, GUST=0-2, SECONDS=s, SERIAL=tcp:5760)"
	@$(VENV_PY) sim/flight/mission_flight.py --mission $(MISSION) --plot $(PLOT) $(if $(GUST),--gust $(GUST)) \
	  $(if $(SECONDS),--seconds $(SECONDS)) --sim $(BUILD)/apm25sim --elf $(BUILD)/firmware.elf \
	  --timeout $(FLY_TIMEOUT) $(if $(FLY_SERIAL),--serial $(FLY_SERIAL)) $(if $(SPEED),--speed $(SPEED))
else
	@echo "# flight '$(or $(FLIGHT),cruise)': build/firmware.elf in simavr flies the JSBSim Rascal 110 (FLIGHT=name, GUST=0-2, SECONDS=s, SERIAL=tcp:5760 for a ground station; flights: fly.py --list)"
	$(if $(MODE),@mkdir -p $(BUILD)/flight && printf 'mode $(MODE)\n' > $(BUILD)/flight/fly-input.txt)
	@$(VENV_PY) sim/flight/closed_loop.py --flight $(or $(FLIGHT),cruise) $(if $(GUST),--gust $(GUST)) \
	  $(if $(SECONDS),--seconds $(SECONDS)) $(if $(STAMP),--stamp) --sim $(BUILD)/apm25sim \
	  --elf $(BUILD)/firmware.elf --timeout $(FLY_TIMEOUT) --arm \
	  $(if $(FLY_SERIAL),--serial $(FLY_SERIAL)) $(if $(SPEED),--speed $(SPEED)) \
	  $(if $(MODE),--input $(BUILD)/flight/fly-input.txt) \
	  $(if $(VIEW),| $(VENV_PY) tools/view.py --file /dev/stdin $(VIEW_FLAGS))
endif

test: firmware attitude-only big startup-variants tools venv
	@cd $(HOST_BUILD) && ctest --output-on-failure -j$(NPROC)

bench: firmware attitude-only tools flash-attr
	python3 bench/bench.py --build $(BUILD)

# Cross-validation of the estimator's settings on the BROAD recordings (bench/tune.py).
TUNE_ARGS ?= --cv
tune: tools
	python3 bench/tune.py --build $(BUILD) $(TUNE_ARGS)

upload: firmware
	avrdude -p $(MCU) -c wiring -P $(PORT) -b $(BAUD) -D -U flash:w:$(FW_BUILD)/firmware.hex:i

# ---------------------------------------------------------------------------
# The Python environment, MAVLink headers and live view, fuzzing and sanitizers.
include mk/python.mk
include mk/mavlink.mk
include mk/fuzz.mk
include mk/mutate.mk
include mk/navcost.mk
