// SPDX-License-Identifier: GPL-3.0-or-later
// The settings record (lib/Console/Settings.h) in the ATmega2560's EEPROM, in two slots
// (lib/Console/RecordSlots.h): a power cut during `save` leaves the previous settings.
//
// Loading happens once at start. Saving writes one byte per loop iteration while the
// EEPROM is ready (a byte takes 3.4 ms to program: writing all of them at once would
// stall the loop for ~250 ms) into the slot not holding the newest record, then reads
// the slot back and says whether it verified.
#pragma once

#include <stdint.h>

#include "RecordSlots.h"
#include "Settings.h"
#include "Text.h"

class SettingsStore {
public:
    explicit SettingsStore(const text::Sink* out) : out_(out) {}

    // Reads the newer valid slot (or, with none, an earlier firmware's single record)
    // into `s` (defaults when blank, corrupted, or from another version) and says which.
    void load(settings::Settings& s);
    // Starts writing `s` (a copy is taken: later changes are not part of this save).
    void start_save(const settings::Settings& s);
    // Every loop iteration: the next byte, or the verification at the end.
    void service();

private:
    uint16_t slot_address() const { return slots::slot_address(write_slot_); }

    const text::Sink* out_;
    uint8_t slot_[slots::kSlotSize];
    uint16_t index_ = slots::kSlotSize;
    uint16_t next_sequence_ = 1;
    uint8_t write_slot_ = 0;
    bool verify_pending_ = false;
};
