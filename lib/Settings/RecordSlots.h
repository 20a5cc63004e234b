// SPDX-License-Identifier: GPL-3.0-or-later
// The settings record (Settings.h) kept in two EEPROM slots, so that a power cut while
// `save` writes loses nothing: a save writes the slot that does NOT hold the newest
// valid record, so that one stays whole until the new one is; at start the newer valid
// slot wins. Each slot:
//
//   offset 0  sequence          little-endian, one more than the slot it supersedes
//          2  record length     kRecordSize of the firmware that wrote it
//          3  record            the settings record, as settings::encode makes it
//          3+len  CRC-16/CCITT-FALSE of bytes 0 .. 2+len, little-endian
//
// The slot's CRC is written last (bytes go out in order), so a slot cut short anywhere
// fails it. Slots sit at fixed addresses whatever the record's length (a firmware with
// another record length finds them, sees the length and refuses the record with a
// message), above the single record at address 0 that firmware before the slots wrote
// (read when no slot is valid: loaded when its version is this one's, else refused).
// Pure: the caller reads and writes the EEPROM; here are the bytes and the choice.
#pragma once

#include <stdint.h>

#include "Settings.h"
#include "VehicleRecord.h"

namespace slots {

constexpr uint8_t kSlots = 2;
constexpr uint8_t kHeaderSize = 3;  // sequence (2), record length (1)
constexpr uint16_t kMaxSlotSize = kHeaderSize + 255u + 2u;  // any record length
constexpr uint16_t kSlotSize = kHeaderSize + settings::kRecordSize + 2u;  // this firmware's slots
// Slot i at kSlotStride * (i + 1): past the earlier firmware's record at address 0 and
// room for a slot of any record length.
constexpr uint16_t kSlotStride = 512;
constexpr uint16_t slot_address(uint8_t slot) { return (uint16_t)(kSlotStride * (slot + 1u)); }
constexpr uint16_t kLegacyAddress = settings::kEepromAddress;

enum class SlotState : uint8_t {
    Blank,  // never written (its header erased)
    Bad,    // CRC wrong: a save cut short, or worn cells
    Valid,  // whole: its record may still be of another version (settings::decode says)
};

struct SlotInfo {
    SlotState state;
    uint16_t sequence;
    uint8_t record_length;
};

// One slot's bytes, at least kMaxSlotSize of them (the slot's CRC covers the length it
// states).
SlotInfo inspect(const uint8_t* slot_bytes);

// What the store does: load one slot (or none: -1) and write the next save where.
struct Plan {
    int8_t load;            // the newer valid slot; -1 when none is valid
    uint8_t write;          // never the slot loaded: it stays whole until the new one is
    uint16_t next_sequence;
    bool newest_cut;        // a slot newer than the one loaded (or than nothing) is Bad
};
// sequence a is newer than b (serial-number arithmetic: a 16-bit counter that wraps).
bool newer(uint16_t a, uint16_t b);
Plan plan(const SlotInfo info[kSlots]);

// Reads n bytes of the EEPROM from address (the firmware: eeprom_read_block).
using ReadBlock = void (*)(uint16_t address, uint8_t* out, uint16_t n);

struct Loaded {
    settings::LoadResult result;
    bool from_legacy;  // the record at address 0 of a firmware before the slots
    bool newest_cut;   // Plan::newest_cut: the last save was cut short
    uint8_t write;     // Plan::write and next_sequence: where the next save goes (both records'
    uint16_t next_sequence;  // slot `write`: VehicleRecord.h)
    record2::Result vehicle;  // the second record, when the first loaded Ok from a slot
};
// The settings at start: the newer valid slot's record or, with no valid slot, the
// legacy record; `s` is defaults() unless the result is Ok. A slot of another record
// length is OldVersion. Nothing valid but a slot cut short is BadCrc, not Blank. With
// the first record Ok from slot i, the second record's slot i when it pairs with it
// (record2::load). Uses ~kMaxSlotSize bytes of stack.
Loaded load(ReadBlock read, settings::Settings& s);

// Header byte i (< kHeaderSize) of a slot of this firmware with `sequence`.
uint8_t header_byte(uint16_t sequence, uint8_t i);
// The CRC that ends a slot holding `record` with `sequence` (encode's last two bytes).
uint16_t slot_crc(const uint8_t record[settings::kRecordSize], uint16_t sequence);

// A slot holding `record` (this firmware's kRecordSize) with `sequence`: kSlotSize bytes.
void encode(const uint8_t record[settings::kRecordSize], uint16_t sequence, uint8_t out[kSlotSize]);

}  // namespace slots
