// SPDX-License-Identifier: GPL-3.0-or-later
#include "SettingsStore.h"

#include <avr/eeprom.h>

using text::Flash;
using text::Writer;

static void read_eeprom(uint16_t address, uint8_t* out, uint16_t n) {
    eeprom_read_block(out, (const void*)address, n);
}

void SettingsStore::load(settings::Settings& s) {
    const slots::Loaded loaded = slots::load(read_eeprom, s);
    write_slot_ = loaded.write;
    next_sequence_ = loaded.next_sequence;
    const settings::LoadResult r = loaded.result;
    if (loaded.newest_cut && r == settings::LoadResult::Ok)
        Writer(out_).str(TXT(TXT_WARN "the last save to " TXT_EEPROM " was cut short: the one before it stands")).end();
    Flash m;
    switch (r) {
        case settings::LoadResult::Ok:
            m = !loaded.from_legacy ? TXT("# settings loaded from " TXT_EEPROM)
                               : TXT("# settings loaded from " TXT_EEPROM " (an earlier firmware's record)");
            break;
        case settings::LoadResult::Blank: m = TXT("# " TXT_EEPROM " blank" TXT_DEFAULTS); break;
        case settings::LoadResult::BadMagic: m = TXT(TXT_WARN TXT_EEPROM " holds something else" TXT_DEFAULTS); break;
        case settings::LoadResult::OldVersion: m = TXT(TXT_WARN TXT_EEPROM " from another version" TXT_DEFAULTS); break;
        case settings::LoadResult::BadCrc: m = TXT(TXT_WARN TXT_EEPROM " corrupted (CRC)" TXT_DEFAULTS); break;
        default: m = TXT(TXT_WARN TXT_EEPROM " values out of range" TXT_DEFAULTS); break;
    }
    Writer(out_).str(m).end();
}

void SettingsStore::start_save(const settings::Settings& s) {
    uint8_t record[settings::kRecordSize];
    settings::encode(s, record);
    slots::encode(record, next_sequence_, slot_);
    index_ = 0;
    verify_pending_ = true;
    Writer(out_).str(TXT("# saving to " TXT_EEPROM)).end();
}

void SettingsStore::service() {
    if (!eeprom_is_ready()) return;
    if (index_ < slots::kSlotSize) {
        // In order: the CRC last, so a slot cut short fails it.
        eeprom_update_byte((uint8_t*)(slot_address() + index_), slot_[index_]);
        ++index_;
        return;
    }
    if (!verify_pending_) return;
    verify_pending_ = false;
    bool same = true;
    for (uint16_t i = 0; i < slots::kSlotSize; ++i)
        same = same && eeprom_read_byte((const uint8_t*)(slot_address() + i)) == slot_[i];
    if (!same) {
        // The slot is not valid; the other one still holds the newest record, and the
        // next save tries this slot again.
        Writer(out_).str(TXT(TXT_ERROR TXT_EEPROM " write did not verify: not saved")).end();
        return;
    }
    // This slot is now the newest: the next save goes to the other one.
    write_slot_ = (uint8_t)(1u - write_slot_);
    ++next_sequence_;
    Writer(out_).str(TXT("# saved")).end();
}
