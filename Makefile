# SPDX-License-Identifier: GPL-3.0-or-later
# APM 2.5 attitude firmware: build, simulate, test, benchmark.
#
#   make            the firmware (build/firmware.elf, .hex; prints flash and RAM use) and
#                   the host tools build/apm25sim, build/replay, build/scenario, build/score
#   make APM25_FLIGHT=0   the attitude-only firmware, without the flight features
#                   (build/attitude-only/firmware.elf; with sim, upload too; README "Builds")
#   make startup-variants  the firmware linked with longer C runtime start-ups
#                   (build/startup/*.elf: the test e2e.Equivalence.WhateverTheStartUpTakes)
#   make big        the firmware padded past 128 KB to the 200 KB budget (build/big/firmware.elf:
#                   the test e2e.Beyond128K runs it beside the firmware)
#   make sim        the firmware in simavr on a default scenario, shown as a serial monitor would
#   make fly        the firmware in simavr flies a JSBSim aeroplane (FLIGHT=turn GUST=1 SECONDS=30;
#                   SERIAL=tcp:5760: a ground station watches it, in real time)
#   make test       every test: host GoogleTest units, the simavr end-to-end suite, the
#                   sketch built by arduino-builder
#   make unit       the host unit tests alone (test/<Library>/, test/sim/): built and run in
#                   seconds (FILTER='Mixer.*' for some)
#   make bench      cycles, size and accuracy against the peers (build/bench/report.md)
#   make nav-cost   the navigation step's cycles on the 2560 alone (bench/nav_cost.cpp in
#                   apm25sim; part of make bench; fails when the guidance is over 20 000)
#   make tune       cross-validation of the estimator's gains on the BROAD recordings
#   make docs       docs/parameters.md from the parameter table (lib/Settings/Params.cpp)
#   make deps       install what is missing (apt-get; through sudo when not root)
#   make upload PORT=/dev/ttyACM0    flash with avrdude (wiring protocol, 115200)
#   make monitor PORT=/dev/ttyACM0   watch the serial output (115200)
#   V=1             show every command
#
# This file only makes sure the toolchain is there, then runs the build (mk/build.mk)
# in a new make: the build lists the Arduino core's files when it is read, which on a
# fresh machine is only possible after the packages are installed.

DEB_PACKAGES := gcc-avr avr-libc binutils-avr arduino-core-avr arduino-builder simavr libsimavr-dev \
                libelf-dev avrdude cmake libgtest-dev g++ make zlib1g-dev pkg-config python3 python3-venv python3-tk clang libclang-rt-dev
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
BUILD_GOALS := all firmware attitude-only big startup-variants tools docs sim fly test unit bench tune upload size venv mavlink view mavlink-cost nav-cost fuzz fuzz-smoke asan-unit mutate

.DEFAULT_GOAL := all
.PHONY: deps $(BUILD_GOALS) monitor clean
# Each goal is a make of its own (below): two at once (make -j2 all venv) would both
# build what they share, the venv at the same time. Goals run one after the other here;
# each build is parallel inside with the -j given.
.NOTPARALLEL:

# A quick check (dpkg-query), apt-get only when something is missing.
deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "# installing with apt-get:" $$missing; \
	  $(SUDO) apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq $$missing > /dev/null || exit 1; \
	  echo "# installed"; \
	fi

$(BUILD_GOALS): deps
	@$(MAKE) --no-print-directory -f mk/build.mk $@

PORT ?= /dev/ttyACM0
monitor:
	@stty -F $(PORT) 115200 raw -echo && cat $(PORT)

clean:
	rm -rf build
