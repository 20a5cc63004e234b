// SPDX-License-Identifier: GPL-3.0-or-later
// The settings record (lib/Settings/Settings.h) in the ATmega2560's EEPROM, in two slots
// (lib/Settings/RecordSlots.h): a power cut during `save` leaves the previous settings.
//
// Loading happens once at start. Saving writes one byte per loop iteration while the
// EEPROM is ready (a byte takes 3.4 ms to program: writing all of them at once would
// stall the loop for ~250 ms) into the slot not holding the newest record, then reads
// the slot back and says whether it verified. No copy of the record is kept (RAM): each
// byte is encoded from the live settings when it is written, and the CRCs run along.
// The slot's CRC noted at `save` says whether the bytes written are that record's: if a
// setting changed meanwhile, the save starts again (of the settings then), before the
// slot's CRC is written, so no slot ever holds a mixture.
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
    // Starts writing `s`, which must stay alive (the pipeline's settings): a change to it
    // before the save's end starts the save again.
    void start_save(const settings::Settings& s);
    // Every loop iteration: the next byte, or a part of the verification at the end.
    void service();
    // The settings in use are the user's: loaded, or the EEPROM blank (a new board's
    // defaults), or saved since; false while the board runs on defaults because the
    // record was unreadable (corrupt, another firmware's, out of range): the pre-arm
    // check "Settings not loaded" until the user saves.
    bool settings_loaded() const { return settings_loaded_; }

private:
    uint16_t slot_address() const { return slots::slot_address(write_slot_); }
    // The note of `save` (again): the slot's CRC of the settings now; writing from byte 0.
    void begin();
    // Slot byte index_ of the settings now, the running CRCs brought up to it.
    uint8_t next_byte();
    void verify_some();

    const text::Sink* out_;
    const settings::Settings* source_ = nullptr;
    uint16_t index_ = slots::kSlotSize;  // the next slot byte written; kSlotSize: none
    uint16_t expected_crc_ = 0;          // the slot's CRC of the record at `save`
    uint16_t record_crc_ = 0;            // the running CRCs of the bytes written
    uint16_t slot_crc_ = 0;
    // The record's bytes from part_from_ on, encoded a part at a time (the parameter
    // table is walked once a part, not once a byte).
    static constexpr uint8_t kPartSize = 12;
    uint8_t part_[kPartSize];
    uint8_t part_from_ = 0xFFu;
    uint16_t verify_index_ = slots::kSlotSize;  // the next byte read back; kSlotSize: none
    uint16_t verify_crc_ = 0;
    uint16_t next_sequence_ = 1;
    uint8_t write_slot_ = 0;
    bool settings_loaded_ = true;
};
