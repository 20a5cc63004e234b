// SPDX-License-Identifier: GPL-3.0-or-later
#include "SettingsStore.h"

#include <avr/eeprom.h>

#include "Params.h"
#include "VehicleRecord.h"

using text::Flash;
using text::Writer;

static void read_eeprom(uint16_t address, uint8_t* out, uint16_t n) {
    eeprom_read_block(out, (const void*)address, n);
}

void SettingsStore::load(settings::Settings& s) {
    vehicle_bytes_ = (uint8_t)params::vehicle_bytes();
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
    if (r != settings::LoadResult::Ok) return;  // everything at its defaults: said
    // The second record (VehicleRecord.h): its parameters at their defaults unless paired.
    switch (loaded.vehicle) {
        case record2::Result::Paired: return;
        case record2::Result::NotRead:
        case record2::Result::Missing:
            m = TXT("# settings: saved by an earlier firmware: the newer parameters at their defaults (save to keep)");
            break;
        case record2::Result::BadCrc: m = TXT(TXT_WARN TXT_EEPROM " second record corrupted (CRC): its parameters at their defaults"); break;
        case record2::Result::OldVersion: m = TXT(TXT_WARN TXT_EEPROM " second record from another version: its parameters at their defaults"); break;
        default: m = TXT(TXT_WARN TXT_EEPROM " second record's values out of range: its parameters at their defaults"); break;
    }
    Writer(out_).str(m).end();
}

void SettingsStore::start_save(const settings::Settings& s) {
    source_ = &s;
    begin();
    Writer(out_).str(TXT("# saving to " TXT_EEPROM)).end();
}

void SettingsStore::begin() {
    expected2_crc_ = record2::slot_crc(*source_, next_sequence_, vehicle_bytes_);
    start(kWriteSecond);
}

void SettingsStore::start(Stage stage) {
    stage_ = stage;
    index_ = 0;
    record_crc_ = settings::kCrc16Init;
    slot_crc_ = settings::kCrc16Init;
    part_from_ = 0xFFu;
}

uint8_t SettingsStore::part_byte(Part part, uint8_t i, uint8_t end) {
    if (part_from_ == 0xFFu || i < part_from_ || i >= part_from_ + kPartSize) {
        part_from_ = i;
        part(*source_, i, (uint8_t)(end - i < kPartSize ? end - i : kPartSize), part_);
    }
    return part_[i - part_from_];
}

uint8_t SettingsStore::second_byte() {
    const uint16_t values_end = record2::kHeaderSize + vehicle_bytes_;
    uint8_t b;
    if (index_ < record2::kHeaderSize) {
        b = record2::header_byte(next_sequence_, vehicle_bytes_, (uint8_t)index_);
    } else if (index_ < values_end) {
        b = part_byte(params::vehicle_part, (uint8_t)(index_ - record2::kHeaderSize), vehicle_bytes_);
    } else {
        return index_ == values_end ? (uint8_t)(slot_crc_ & 0xFFu) : (uint8_t)(slot_crc_ >> 8);
    }
    slot_crc_ = settings::crc16_update(slot_crc_, b);
    return b;
}

uint8_t SettingsStore::first_byte() {
    constexpr uint16_t kRecordEnd = slots::kHeaderSize + settings::kRecordSize;
    constexpr uint16_t kRecordCrcAt = kRecordEnd - 2u;
    uint8_t b;
    if (index_ < slots::kHeaderSize) {
        b = slots::header_byte(next_sequence_, (uint8_t)index_);
    } else if (index_ < kRecordCrcAt) {
        b = part_byte(settings::record_part, (uint8_t)(index_ - slots::kHeaderSize), settings::kRecordSize - 2u);
        record_crc_ = settings::crc16_update(record_crc_, b);
    } else if (index_ < kRecordEnd) {
        b = index_ == kRecordCrcAt ? (uint8_t)(record_crc_ & 0xFFu) : (uint8_t)(record_crc_ >> 8);
    } else {
        return index_ == kRecordEnd ? (uint8_t)(slot_crc_ & 0xFFu) : (uint8_t)(slot_crc_ >> 8);
    }
    slot_crc_ = settings::crc16_update(slot_crc_, b);
    return b;
}

// A byte written; after the slot's last, the next stage (its read-back) from the start.
void SettingsStore::written(uint16_t size, Stage next) {
    if (++index_ == size) start(next);
}

void SettingsStore::service() {
    if (stage_ == kIdle || !eeprom_is_ready()) return;
    constexpr uint16_t kFirstCovered = slots::kHeaderSize + settings::kRecordSize;
    const uint16_t second_covered = record2::kHeaderSize + vehicle_bytes_;
    switch (stage_) {
        case kWriteSecond:
            // A setting changed since `save`: the bytes written are not one record; start
            // again before the slot's CRC could make them valid.
            if (index_ == second_covered && slot_crc_ != expected2_crc_) begin();
            // In order: the CRC last, so a slot cut short fails it.
            eeprom_update_byte((uint8_t*)(record2::slot_address(write_slot_) + index_), second_byte());
            written(record2::slot_size(vehicle_bytes_), kVerifySecond);
            return;
        case kVerifySecond: {
            const uint8_t v = verify_some(record2::slot_address(write_slot_), second_covered, expected2_crc_);
            if (v == 1) start(kNoteFirst);
            if (v != 2) return;
            break;  // not verified: the first record's slot stays as it is
        }
        case kNoteFirst:
            // The bytes the write will make, their CRC: a few a pass, so that a pass that
            // walks the parameter table for a part costs what a writing one does (the whole
            // record at once took ~4.8 ms, a part's walk takes ~1.1 ms).
            for (uint8_t n = 0; n < kNoteBytesPerPass && index_ < kFirstCovered; ++n, ++index_) first_byte();
            if (index_ < kFirstCovered) return;
            expected_crc_ = slot_crc_;
            start(kWriteFirst);
            return;
        case kWriteFirst:
            if (index_ == kFirstCovered) {
                stage_ = kCheckSecond;  // before the CRC that makes the new pair the loaded one
                return;
            }
            eeprom_update_byte((uint8_t*)(slots::slot_address(write_slot_) + index_), first_byte());
            ++index_;
            return;
        case kCheckSecond:
            // Either record changed since its CRC was noted: both again, of the settings now.
            if (slot_crc_ != expected_crc_ ||
                record2::slot_crc(*source_, next_sequence_, vehicle_bytes_) != expected2_crc_) {
                begin();
            } else {
                stage_ = kCommitFirst;
            }
            return;
        case kCommitFirst:
            eeprom_update_byte((uint8_t*)(slots::slot_address(write_slot_) + index_), first_byte());
            written(slots::kSlotSize, kVerifyFirst);
            return;
        case kVerifyFirst: {
            const uint8_t v = verify_some(slots::slot_address(write_slot_), kFirstCovered, expected_crc_);
            if (v == 0) return;
            stage_ = kIdle;
            if (v == 2) break;
            // Both slots `write_slot_` now hold the newest pair: the next save goes to the others.
            write_slot_ = (uint8_t)(1u - write_slot_);
            ++next_sequence_;
            settings_loaded_ = true;
            Writer(out_).str(TXT("# saved")).end();
            return;
        }
        default: return;
    }
    // A slot not valid: the other pair still holds the newest settings, and the next save
    // tries these slots again.
    stage_ = kIdle;
    Writer(out_).str(TXT(TXT_ERROR TXT_EEPROM " write did not verify: not saved")).end();
}

uint8_t SettingsStore::verify_some(uint16_t address, uint16_t covered, uint16_t expected) {
    // A part at a time: the CRC of the whole slot read back at once would stretch one
    // loop iteration.
    constexpr uint8_t kBytesPerCall = 64;
    for (uint8_t n = 0; n < kBytesPerCall && index_ < covered; ++n, ++index_)
        slot_crc_ = settings::crc16_update(slot_crc_, eeprom_read_byte((const uint8_t*)(address + index_)));
    if (index_ < covered) return 0;
    const uint16_t stored = (uint16_t)(eeprom_read_byte((const uint8_t*)(address + covered)) |
                                       (uint16_t)eeprom_read_byte((const uint8_t*)(address + covered + 1u)) << 8);
    return slot_crc_ == expected && stored == expected ? 1 : 2;
}
