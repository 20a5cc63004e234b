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
    settings_loaded_ = r == settings::LoadResult::Ok || r == settings::LoadResult::Blank;
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
    source_ = &s;
    begin();
    Writer(out_).str(TXT("# saving to " TXT_EEPROM)).end();
}

void SettingsStore::begin() {
    uint8_t record[settings::kRecordSize];
    settings::encode(*source_, record);
    expected_crc_ = slots::slot_crc(record, next_sequence_);
    record_crc_ = settings::kCrc16Init;
    slot_crc_ = settings::kCrc16Init;
    index_ = 0;
    part_from_ = 0xFFu;
    verify_index_ = slots::kSlotSize;
}

uint8_t SettingsStore::next_byte() {
    constexpr uint16_t kRecordEnd = slots::kHeaderSize + settings::kRecordSize;
    constexpr uint16_t kRecordCrcAt = kRecordEnd - 2u;
    uint8_t b;
    if (index_ < slots::kHeaderSize) {
        b = slots::header_byte(next_sequence_, (uint8_t)index_);
    } else if (index_ < kRecordCrcAt) {
        const uint8_t i = (uint8_t)(index_ - slots::kHeaderSize);
        if (part_from_ == 0xFFu || i < part_from_ || i >= part_from_ + kPartSize) {
            constexpr uint8_t kEnd = settings::kRecordSize - 2u;
            part_from_ = i;
            settings::record_part(*source_, i, (uint8_t)(kEnd - i < kPartSize ? kEnd - i : kPartSize), part_);
        }
        b = part_[i - part_from_];
        record_crc_ = settings::crc16_update(record_crc_, b);
    } else if (index_ < kRecordEnd) {
        b = index_ == kRecordCrcAt ? (uint8_t)(record_crc_ & 0xFFu) : (uint8_t)(record_crc_ >> 8);
    } else {
        return index_ == kRecordEnd ? (uint8_t)(slot_crc_ & 0xFFu) : (uint8_t)(slot_crc_ >> 8);
    }
    slot_crc_ = settings::crc16_update(slot_crc_, b);
    return b;
}

void SettingsStore::service() {
    if (!eeprom_is_ready()) return;
    if (index_ < slots::kSlotSize) {
        // A setting changed since `save`: the bytes written are not one record; start
        // again before the slot's CRC could make them valid.
        if (index_ == slots::kHeaderSize + settings::kRecordSize && slot_crc_ != expected_crc_) begin();
        // In order: the CRC last, so a slot cut short fails it.
        eeprom_update_byte((uint8_t*)(slot_address() + index_), next_byte());
        if (++index_ == slots::kSlotSize) {
            verify_index_ = 0;
            verify_crc_ = settings::kCrc16Init;
        }
        return;
    }
    if (verify_index_ < slots::kSlotSize) verify_some();
}

void SettingsStore::verify_some() {
    // A part at a time: the CRC of the whole slot read back at once would stretch one
    // loop iteration.
    constexpr uint16_t kCovered = slots::kHeaderSize + settings::kRecordSize;
    constexpr uint8_t kBytesPerCall = 64;
    for (uint8_t n = 0; n < kBytesPerCall && verify_index_ < kCovered; ++n, ++verify_index_)
        verify_crc_ = settings::crc16_update(verify_crc_, eeprom_read_byte((const uint8_t*)(slot_address() + verify_index_)));
    if (verify_index_ < kCovered) return;
    verify_index_ = slots::kSlotSize;
    const uint16_t stored = (uint16_t)(eeprom_read_byte((const uint8_t*)(slot_address() + kCovered)) |
                                       (uint16_t)eeprom_read_byte((const uint8_t*)(slot_address() + kCovered + 1u)) << 8);
    if (verify_crc_ != expected_crc_ || stored != expected_crc_) {
        // The slot is not valid; the other one still holds the newest record, and the
        // next save tries this slot again.
        Writer(out_).str(TXT(TXT_ERROR TXT_EEPROM " write did not verify: not saved")).end();
        return;
    }
    // This slot is now the newest: the next save goes to the other one.
    write_slot_ = (uint8_t)(1u - write_slot_);
    ++next_sequence_;
    settings_loaded_ = true;
    Writer(out_).str(TXT("# saved")).end();
}
