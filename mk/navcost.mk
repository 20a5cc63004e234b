# SPDX-License-Identifier: GPL-3.0-or-later
# What the navigation costs on the 2560 (make nav-cost, part of make bench):
# bench/nav_cost.cpp with lib/Nav, lib/Mission and lib/LinAlg, built with the firmware's
# flags (mk/avr-flags.mk), run in apm25sim --profile; bench/nav.py prints each piece's
# cycles and the whole 10 Hz step's against its budget (and fails over it), and the RAM.
NAVCOST_DIR   := $(BUILD)/nav-cost
NAVCOST_FLAGS := -mmcu=$(MCU) -DF_CPU=$(F_CPU) $(AVR_SHARED_OPT) -std=gnu++11 $(AVR_SHARED_CXX) \
                 $(AVR_SHARED_WARN) -Werror $(addprefix -I,$(LIB_DIRS)) $(AVR_SHARED_LINK)
NAVCOST_SRC   := bench/nav_cost.cpp lib/Nav/L1Control.cpp lib/Nav/Tecs.cpp lib/Nav/Location.cpp \
                 lib/Mission/MissionCommand.cpp lib/Mission/MissionExecutor.cpp lib/Mission/MissionStore.cpp \
                 lib/Settings/RecordSlots.cpp lib/Settings/Settings.cpp lib/LinAlg/LinAlg.cpp

.PHONY: nav-cost
bench: nav-cost
nav-cost: tools
	@mkdir -p $(NAVCOST_DIR)
	$(call say,AVR-CXX,bench/nav_cost.cpp -> $(NAVCOST_DIR)/cost.elf)
	$(Q)$(AVR_CXX) $(NAVCOST_FLAGS) $(NAVCOST_SRC) -lm -o $(NAVCOST_DIR)/cost.elf
	@python3 bench/nav.py --build $(BUILD)
