# SPDX-License-Identifier: GPL-3.0-or-later
# Fuzzing and sanitizers (issue 11). Included by the Makefile (`include mk/fuzz.mk`), or
# on its own: `make -f mk/fuzz.mk fuzz`.
#
#   make fuzz         each libFuzzer target for FUZZ_RUNS inputs (10^7), the count per target
#   make fuzz-smoke   each target for FUZZ_SMOKE_S seconds (30)
#   make asan-unit    the host unit tests built once with ASan+UBSan (build/asan) and run
#
# fuzz-smoke and asan-unit are also ctest tests (CMakeLists.txt, `hardening.*`), so
# `make test` runs them. Targets: test/fuzz/fuzz_<name>.cpp, each built in one clang++
# call from its source and lib/ (no shared objects: two runs in parallel never race).
# A crash leaves build/fuzz/crash-<name>-*: rerun it with build/fuzz/fuzz_<name> FILE.
BUILD        ?= build
FUZZ_DIR     := $(BUILD)/fuzz
FUZZ_RUNS    ?= 10000000
FUZZ_SMOKE_S ?= 30
FUZZ_CXX     ?= clang++
FUZZ_NAMES   := $(patsubst test/fuzz/fuzz_%.cpp,%,$(wildcard test/fuzz/fuzz_*.cpp))
FUZZ_LIB_SRC := $(wildcard lib/*/*.cpp)
FUZZ_LIB_HDR := $(wildcard lib/*/*.h)
FUZZ_FLAGS   := -std=c++14 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
                -fno-omit-frame-pointer $(addprefix -I,$(sort $(dir $(FUZZ_LIB_HDR)))) -I$(BUILD)/mavlink
FUZZ_ENV     := ASAN_OPTIONS=abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Console input is lines of <= 40 characters: 512 bytes hold a dozen lines and keep the
# rate up (libFuzzer's default 4096 runs ~8x slower and finds nothing more).
FUZZ_OPTS_console := -max_len=512
ASAN_BUILD   := $(BUILD)/asan
ASAN_FLAGS   := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer

.PHONY: fuzz fuzz-smoke asan-unit fuzz-build $(addprefix fuzz-smoke-,$(FUZZ_NAMES)) $(addprefix fuzz-run-,$(FUZZ_NAMES))

fuzz-build: $(addprefix $(FUZZ_DIR)/fuzz_,$(FUZZ_NAMES))

$(FUZZ_DIR)/fuzz_%: test/fuzz/fuzz_%.cpp test/fuzz/FuzzAssert.h $(FUZZ_LIB_SRC) $(FUZZ_LIB_HDR)
	@command -v $(FUZZ_CXX) > /dev/null || { echo "# fuzz: $(FUZZ_CXX) missing (Debian package clang)"; exit 1; }
	@mkdir -p $(FUZZ_DIR)
	$(FUZZ_CXX) $(FUZZ_FLAGS) $< $(FUZZ_LIB_SRC) -o $@.tmp && mv $@.tmp $@

# One libFuzzer run: $(1) name, $(2) limit flag, $(3) log tag (a smoke run beside a long one). The corpus grows in build/fuzz/corpus_NAME
# (kept between runs); the dictionary test/fuzz/NAME.dict is used when present. The count
# is libFuzzer's own "Done N runs" line.
define fuzz_run
	@mkdir -p $(FUZZ_DIR)/corpus_$(1)
	@cd $(FUZZ_DIR) && $(FUZZ_ENV) ./fuzz_$(1) $(2) $(FUZZ_OPTS_$(1)) -print_final_stats=1 -artifact_prefix=crash-$(1)- \
	  $(if $(wildcard test/fuzz/$(1).dict),-dict=$(abspath test/fuzz/$(1).dict)) corpus_$(1) > log_$(3)$(1).txt 2>&1; \
	  status=$$?; \
	  runs=$$(sed -n 's/^Done \([0-9]*\) runs in \([0-9]*\) second.*/\1 inputs in \2 s/p' log_$(3)$(1).txt); \
	  if [ $$status -ne 0 ]; then echo "# fuzz $(1): FAILED (exit $$status), see $(FUZZ_DIR)/log_$(3)$(1).txt:"; \
	    grep -m5 -E "ERROR|SUMMARY|runtime error|crash-" log_$(3)$(1).txt; exit 1; fi; \
	  echo "# fuzz $(1): $$runs, no crash"
endef

$(addprefix fuzz-run-,$(FUZZ_NAMES)): fuzz-run-%: $(FUZZ_DIR)/fuzz_%
	$(call fuzz_run,$*,-runs=$(FUZZ_RUNS),)
$(addprefix fuzz-smoke-,$(FUZZ_NAMES)): fuzz-smoke-%: $(FUZZ_DIR)/fuzz_%
	$(call fuzz_run,$*,-max_total_time=$(FUZZ_SMOKE_S),smoke_)

fuzz: $(addprefix fuzz-run-,$(FUZZ_NAMES))
fuzz-smoke: $(addprefix fuzz-smoke-,$(FUZZ_NAMES))

# The unit tests (not the simavr suite) under ASan+UBSan, in their own CMake tree;
# HARDENING_TESTS=OFF there so it does not register itself again.
asan-unit:
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHARDENING_TESTS=OFF \
	  -DTOOLS_DIR=$(abspath $(ASAN_BUILD))/tools -DMAVLINK_DIR=$(abspath $(BUILD))/mavlink -DCMAKE_CXX_FLAGS="$(ASAN_FLAGS)" \
	  -DCMAKE_C_FLAGS="$(ASAN_FLAGS)" -DCMAKE_EXE_LINKER_FLAGS="$(ASAN_FLAGS)" > /dev/null
	@$(MAKE) --no-print-directory -C $(ASAN_BUILD) unit_tests > $(ASAN_BUILD)/build.log 2>&1 || \
	  { tail -30 $(ASAN_BUILD)/build.log; exit 1; }
	@cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ./unit_tests --gtest_brief=1 > unit_tests.log 2>&1; status=$$?; \
	  tail -3 unit_tests.log; \
	  if [ $$status -ne 0 ]; then grep -m20 -E "FAILED|ERROR|runtime error" unit_tests.log; exit 1; fi; \
	  echo "# asan-unit: $$(sed -n 's/^\[  PASSED  \] \([0-9]*\) tests.*/\1/p' unit_tests.log) unit tests passed under ASan+UBSan"
