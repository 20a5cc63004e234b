// SPDX-License-Identifier: GPL-3.0-or-later
#include "SettingsStore.h"

#include <avr/eeprom.h>

using text::Flash;
using text::Writer;

void SettingsStore::load(settings::Settings& s) {
    uint8_t rec[settings::kRecordSize];
    eeprom_read_block(rec, (const void*)settings::kEepromAddress, settings::kRecordSize);
    Flash m;
    switch (settings::decode(rec, s)) {
        case settings::LoadResult::Ok: m = TXT("# settings loaded from " TXT_EEPROM); break;
        case settings::LoadResult::Blank: m = TXT("# " TXT_EEPROM " blank" TXT_DEFAULTS); break;
        case settings::LoadResult::BadMagic: m = TXT(TXT_WARN TXT_EEPROM " holds something else" TXT_DEFAULTS); break;
        case settings::LoadResult::OldVersion: m = TXT(TXT_WARN TXT_EEPROM " from another version" TXT_DEFAULTS); break;
        case settings::LoadResult::BadCrc: m = TXT(TXT_WARN TXT_EEPROM " corrupted (CRC)" TXT_DEFAULTS); break;
        default: m = TXT(TXT_WARN TXT_EEPROM " values out of range" TXT_DEFAULTS); break;
    }
    Writer(out_).str(m).end();
}

void SettingsStore::start_save(const settings::Settings& s) {
    settings::encode(s, record_);
    index_ = 0;
    verify_pending_ = true;
    Writer(out_).str(TXT("# saving to " TXT_EEPROM)).end();
}

void SettingsStore::service() {
    if (!eeprom_is_ready()) return;
    if (index_ < settings::kRecordSize) {
        eeprom_update_byte((uint8_t*)(settings::kEepromAddress + index_), record_[index_]);
        ++index_;
        return;
    }
    if (!verify_pending_) return;
    verify_pending_ = false;
    bool same = true;
    for (uint8_t i = 0; i < settings::kRecordSize; ++i)
        same = same && eeprom_read_byte((const uint8_t*)(settings::kEepromAddress + i)) == record_[i];
    Writer(out_).str(same ? TXT("# saved") : TXT(TXT_ERROR TXT_EEPROM " write did not verify: not saved")).end();
}
