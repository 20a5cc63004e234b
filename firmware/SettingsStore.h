// SPDX-License-Identifier: GPL-3.0-or-later
// The settings record (lib/Console/Settings.h) in the ATmega2560's EEPROM.
//
// Loading happens once at start. Saving writes one byte per loop iteration while the
// EEPROM is ready (a byte takes 3.4 ms to program: writing all of them at once would
// stall the loop for ~160 ms), then reads the record back and says whether it verified.
#pragma once

#include <stdint.h>

#include "Settings.h"
#include "Text.h"

class SettingsStore {
public:
    explicit SettingsStore(const text::Sink* out) : out_(out) {}

    // Reads the record into `s` (defaults when blank, corrupted, or from another
    // version) and says which.
    void load(settings::Settings& s);
    // Starts writing `s` (a copy is taken: later changes are not part of this save).
    void start_save(const settings::Settings& s);
    // Every loop iteration: the next byte, or the verification at the end.
    void service();

private:
    const text::Sink* out_;
    uint8_t record_[settings::kRecordSize];
    uint8_t index_ = settings::kRecordSize;
    bool verify_pending_ = false;
};
