# SPDX-License-Identifier: GPL-3.0-or-later
# Mutation testing, included by mk/build.mk: `make mutate`.
#
#   make mutate                 a seeded sample of universalmutator's mutants of lib/DCM,
#                               lib/LinAlg/Fixed, lib/Calibration and lib/Flight, each
#                               compiled into a test binary of the unit tests that include
#                               those libraries and run (tools/mutate.py); prints the kill
#                               score per library and the survivors (build/mutate/report.txt)
#   MUTANTS=400                 viable mutants in the sample, split evenly over the libraries
#   MUTANTS=all                 every mutant (hours)
#   LIBS="Flight DCM"           only these libraries (lib/ names: DCM, Fixed, Calibration, Flight)
#   SEED=1                      another sample (each library shuffled apart: its sample does
#                               not depend on the others run beside it)
#   MUTATE_JOBS=2               mutants compiled and run at once
#
# Equivalent mutants (no behaviour can tell them apart) are listed with a reason in
# test/mutants_equivalent.txt, keyed by file, line text and replacement.
MUTANTS     ?= 400
SEED        ?= 1
MUTATE_JOBS ?= 2
LIBS        ?=

.PHONY: mutate
mutate: venv
	@test -x $(BUILD)/venv/bin/mutate || { echo "# mutate: universalmutator missing (make venv)"; exit 1; }
	nice python3 tools/mutate.py --build $(BUILD) --mutants $(MUTANTS) --seed $(SEED) -j $(MUTATE_JOBS) \
	  $(foreach l,$(LIBS),--library $(l))
