// SPDX-License-Identifier: GPL-3.0-or-later
// A 4 KB EEPROM for the mission's host tests: erased to 0xFF, counting writes, and able
// to lose power after a given number of byte writes (the byte being written then holds
// `garbage`, later writes are lost).
#pragma once

#include <stdint.h>
#include <string.h>

#include "MissionStore.h"

namespace testeeprom {

struct FakeEeprom {
    uint8_t bytes[mission::kEepromSize];
    uint32_t writes = 0;
    uint32_t power_after = UINT32_MAX;  // writes that complete before the cut
    int garbage = -1;                   // the byte cut mid-write: -1 keeps the old value

    FakeEeprom() { memset(bytes, 0xFF, sizeof bytes); }

    static uint8_t read(void* ctx, uint16_t a) { return static_cast<FakeEeprom*>(ctx)->bytes[a]; }
    static void write(void* ctx, uint16_t a, uint8_t v) {
        FakeEeprom& e = *static_cast<FakeEeprom*>(ctx);
        if (e.writes < e.power_after) {
            e.bytes[a] = v;
        } else if (e.writes == e.power_after && e.garbage >= 0) {
            e.bytes[a] = (uint8_t)e.garbage;
        }
        ++e.writes;
    }
    mission::Eeprom port() { return mission::Eeprom{this, &FakeEeprom::read, &FakeEeprom::write}; }
};

}  // namespace testeeprom
