# APM 2.5 attitude firmware: build, simulate, test, benchmark.
#
#   make            firmware (build/firmware.elf, .hex; prints flash and RAM use) and the
#                   host tools build/apm25sim, build/replay, build/scenario, build/score
#   make sim        the firmware in simavr on a default scenario, shown as a serial monitor would
#   make test       every test: host GoogleTest units and the simavr end-to-end suite
#   make bench      cycles, size and accuracy against the peers (build/bench/report.md)
#   make deps       install what is missing (apt-get; through sudo when not root)
#   make upload PORT=/dev/ttyACM0    flash with avrdude (wiring protocol, 115200)
#   make monitor PORT=/dev/ttyACM0   watch the serial output (115200)

BUILD       := build
ARDUINO_AVR ?= /usr/share/arduino/hardware/arduino/avr
PORT        ?= /dev/ttyACM0
BAUD        := 115200
SCENARIO    ?= tilt_tour
SECONDS     ?=

# ---------------------------------------------------------------------------
# Dependencies: a quick check, apt-get only when something is missing.
DEB_PACKAGES := gcc-avr avr-libc binutils-avr arduino-core-avr simavr libsimavr-dev libelf-dev \
                avrdude cmake libgtest-dev g++ make zlib1g-dev pkg-config python3 python3-venv
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
MISSING = $(shell for p in $(DEB_PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; done)

.PHONY: all deps firmware tools sim test unit e2e bench upload monitor clean size
all: firmware tools

deps:
	@missing="$(MISSING)"; \
	if [ -n "$$missing" ]; then \
	  echo "# installing: $$missing"; \
	  $(SUDO) apt-get update -qq && DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing; \
	else echo "# dependencies present"; fi

# ---------------------------------------------------------------------------
# Firmware (avr-gcc 5.4 and Debian's Arduino core; facts in ../shared/SIM.md)
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

AVR_DEFS  := -mmcu=$(MCU) -DF_CPU=$(F_CPU) -DARDUINO=10819 -DARDUINO_AVR_MEGA2560 -DARDUINO_ARCH_AVR
AVR_INC   := -I$(CORE_DIR) -I$(ARDUINO_AVR)/variants/mega -I$(WIRE_DIR) -I$(WIRE_DIR)/utility \
             -I$(SPI_DIR) -I$(EEPROM_DIR) $(addprefix -I,$(LIB_DIRS)) -Ifirmware
# -mcall-prologues -mrelax: 1.5 KB less flash for +0.4 % loop cycles (measured with --profile)
AVR_OPT   := -Os -flto -ffunction-sections -fdata-sections -mcall-prologues -mrelax
AVR_CFLAGS   := $(AVR_DEFS) $(AVR_OPT) -std=gnu11
AVR_CXXFLAGS := $(AVR_DEFS) $(AVR_OPT) -std=gnu++11 -fno-exceptions -fno-threadsafe-statics \
                -fno-rtti -DDECIMAL_DIG=__DECIMAL_DIG__
# The project's own files: every warning is an error.
PROJECT_WARN := -Wall -Wextra -Werror -Wdouble-promotion
AVR_LDFLAGS  := -mmcu=$(MCU) -Os -flto -fuse-linker-plugin -Wl,--gc-sections -mcall-prologues -mrelax

CORE_SRC := $(wildcard $(CORE_DIR)/*.c) $(wildcard $(CORE_DIR)/*.cpp) $(CORE_DIR)/wiring_pulse.S \
            $(WIRE_DIR)/Wire.cpp $(WIRE_DIR)/utility/twi.c $(SPI_DIR)/SPI.cpp
CORE_OBJ := $(patsubst $(ARDUINO_AVR)/%,$(BUILD)/avr/arduino/%.o,$(CORE_SRC))
FW_SRC   := $(wildcard firmware/*.cpp) $(foreach d,$(LIB_DIRS),$(wildcard $(d)*.cpp))
FW_OBJ   := $(patsubst %,$(BUILD)/avr/%.o,$(FW_SRC))
FW_HDR   := $(wildcard firmware/*.h) $(foreach d,$(LIB_DIRS),$(wildcard $(d)*.h))

firmware: $(BUILD)/firmware.hex size

$(BUILD)/avr/arduino/%.c.o: $(ARDUINO_AVR)/%.c
	@mkdir -p $(dir $@)
	$(AVR_CC) $(AVR_CFLAGS) $(AVR_INC) -w -c $< -o $@
$(BUILD)/avr/arduino/%.cpp.o: $(ARDUINO_AVR)/%.cpp
	@mkdir -p $(dir $@)
	$(AVR_CXX) $(AVR_CXXFLAGS) $(AVR_INC) -w -c $< -o $@
$(BUILD)/avr/arduino/%.S.o: $(ARDUINO_AVR)/%.S
	@mkdir -p $(dir $@)
	$(AVR_CC) $(AVR_DEFS) -x assembler-with-cpp $(AVR_INC) -c $< -o $@
$(BUILD)/avr/core.a: $(CORE_OBJ)
	@rm -f $@
	$(AVR_AR) rcs $@ $^

$(BUILD)/avr/%.cpp.o: %.cpp $(FW_HDR)
	@mkdir -p $(dir $@)
	$(AVR_CXX) $(AVR_CXXFLAGS) $(PROJECT_WARN) $(AVR_INC) -c $< -o $@

$(BUILD)/firmware.elf: $(FW_OBJ) $(BUILD)/avr/core.a
	$(AVR_CXX) $(AVR_LDFLAGS) $(FW_OBJ) $(BUILD)/avr/core.a -lm -o $@

$(BUILD)/firmware.hex: $(BUILD)/firmware.elf
	avr-objcopy -O ihex -R .eeprom $< $@

size: $(BUILD)/firmware.elf
	@avr-size -A $< | awk '/^\.text|^\.data|^\.bss/ {s[$$1]=$$2} END { \
	  printf "# firmware: flash %d bytes (of 253952), static RAM %d bytes (of 8192)\n", \
	  s[".text"]+s[".data"], s[".data"]+s[".bss"] }'

# ---------------------------------------------------------------------------
# Host tools and tests (CMake + GoogleTest)
HOST_BUILD := $(BUILD)/host
# CMake is configured every time (a second or so): its source globs and the
# optional tools are read at configure time, so a new file is never missed.
tools:
	@cmake -S . -B $(HOST_BUILD) -DCMAKE_BUILD_TYPE=Release -DTOOLS_DIR=$(abspath $(BUILD)) > /dev/null
	@$(MAKE) --no-print-directory -C $(HOST_BUILD) -j2

sim: deps firmware tools
	@mkdir -p $(BUILD)/scenarios
	@$(BUILD)/scenario $(SCENARIO) > $(BUILD)/scenarios/$(SCENARIO).csv
	@echo "# simavr: build/firmware.elf on scenario '$(SCENARIO)' (SCENARIO=name, SECONDS=s to change)"
	@$(BUILD)/apm25sim --elf $(BUILD)/firmware.elf --trajectory $(BUILD)/scenarios/$(SCENARIO).csv \
	  $(if $(SECONDS),--seconds $(SECONDS))

test: deps firmware tools
	cd $(HOST_BUILD) && ctest --output-on-failure -j$$(nproc 2>/dev/null || echo 2)

bench: deps firmware tools
	python3 bench/bench.py --build $(BUILD)

upload: firmware
	avrdude -p $(MCU) -c wiring -P $(PORT) -b $(BAUD) -D -U flash:w:$(BUILD)/firmware.hex:i

monitor:
	@stty -F $(PORT) $(BAUD) raw -echo && cat $(PORT)

clean:
	rm -rf $(BUILD)
