// SPDX-License-Identifier: GPL-3.0-or-later
// The second settings record: the vehicle settings (VehicleSettings.h: the parameter
// table's rows after GND_ABS_PRESS, params::vehicle_part), in two EEPROM slots of its own
// beside the first record's (RecordSlots.h). Each slot:
//
//   offset 0  'A' 'V'           magic
//          2  version           kVersion; any other: these settings at their defaults
//          3  payload length n  params::vehicle_bytes() of the firmware that wrote it
//          4  sequence          the first record's slot it was saved with, little-endian
//          6  payload           params::vehicle_part: the rows' values in table order
//          6+n  CRC-16/CCITT-FALSE of bytes 0 .. 5+n, little-endian
//
// Pairing: a save writes this record's slot i first, with the sequence number the first
// record's slot i is about to get, verifies it, then writes the first record's slot i
// (its CRC last). At start the first record's newer valid slot is loaded, and this
// record's slot of the same index only when it carries that slot's sequence: a power
// cut anywhere in a save leaves the pair of the save before or the new pair, never one
// record of each. No pair (a board saved by a firmware before this record, or by one
// after a downgrade) leaves these settings at their defaults, the declination taken from
// the first record's hundredths.
//
// A payload shorter than this firmware's (an earlier firmware's rows) loads as its first
// part, the rows after it at their defaults; a longer one (a later firmware's, after a
// downgrade) or another version is refused whole, as the first record's other versions
// are. Pure: the caller reads and writes the EEPROM.
#pragma once

#include <stdint.h>

#include "Settings.h"

namespace record2 {

constexpr uint8_t kMagic0 = 'A';
constexpr uint8_t kMagic1 = 'V';
constexpr uint8_t kVersion = 1;
constexpr uint8_t kHeaderSize = 6;  // magic (2), version, payload length, sequence (2)

// The EEPROM map (docs/storage.md): the legacy record at 0..255, the first record's slots
// at 512..771 and 1024..1283 (any record length), the mission from 1284. This record's
// slots fill the gaps: 256..511 and 772..1023, so a slot is at most the smaller gap.
constexpr uint16_t kSlotSpace = 252;
constexpr uint8_t kMaxPayload = (uint8_t)(kSlotSpace - kHeaderSize - 2u);  // 244
constexpr uint16_t slot_address(uint8_t slot) { return slot == 0 ? 256u : 772u; }
constexpr uint16_t slot_size(uint8_t payload) { return (uint16_t)(kHeaderSize + payload + 2u); }

// What the start made of this record (after the first loaded Ok from a slot).
enum class Result : uint8_t {
    Paired,      // loaded
    NotRead,     // the first record did not load from a slot: everything at its defaults or the legacy record
    Missing,     // no slot of the first record's sequence: saved by an earlier firmware
    BadCrc,      // the paired slot is corrupted
    OldVersion,  // another version of this record, or a later firmware's (a longer payload)
    BadValue,    // a value out of range
};

// Header byte i (< kHeaderSize) of a slot with `payload` bytes and `sequence`.
uint8_t header_byte(uint16_t sequence, uint8_t payload, uint8_t i);
// The CRC that ends a slot of s's values (payload: params::vehicle_bytes()) with
// `sequence`, in one walk of the parameter table.
uint16_t slot_crc(const settings::Settings& s, uint16_t sequence, uint8_t payload);
// The whole slot: slot_size(params::vehicle_bytes()) bytes.
void encode(const settings::Settings& s, uint16_t sequence, uint8_t* out);
// The slot's bytes (kSlotSpace of them) paired with the first record's slot of
// `sequence`, into s, whose first record is loaded: Paired changes only s.vehicle and the
// declination; anything else leaves s as it is.
Result load(const uint8_t* slot, uint16_t sequence, settings::Settings& s);

}  // namespace record2
