// SPDX-License-Identifier: GPL-3.0-or-later
#include "RecordSlots.h"

#include <string.h>

namespace slots {

static_assert(kSlots == 2, "plan() writes the slot it does not load");
static_assert(slot_address(1) >= slot_address(0) + kMaxSlotSize, "slots of any length apart");
static_assert(record2::kSlotSpace <= kMaxSlotSize, "load reads the second record into the first's buffer");
// The second record's slots in the gaps: after the legacy record (at most 256 bytes), before
// slot 0; after slot 0, before slot 1.
static_assert(record2::slot_address(0) >= kLegacyAddress + 256u &&
                  record2::slot_address(0) + record2::kSlotSpace <= slot_address(0) &&
                  record2::slot_address(1) >= slot_address(0) + kMaxSlotSize &&
                  record2::slot_address(1) + record2::kSlotSpace <= slot_address(1),
              "the second record's slots overlap no first record of any length");

SlotInfo inspect(const uint8_t* b) {
    SlotInfo info;
    info.sequence = (uint16_t)(b[0] | (uint16_t)((uint16_t)b[1] << 8));
    info.record_length = b[2];
    const uint16_t covered = (uint16_t)(kHeaderSize + info.record_length);
    const uint16_t crc = (uint16_t)(b[covered] | (uint16_t)((uint16_t)b[covered + 1u] << 8));
    if (b[0] == 0xFFu && b[1] == 0xFFu && b[2] == 0xFFu && crc == 0xFFFFu) info.state = SlotState::Blank;
    else info.state = crc == settings::crc16(b, covered) ? SlotState::Valid : SlotState::Bad;
    return info;
}

bool newer(uint16_t a, uint16_t b) { return (int16_t)(uint16_t)(a - b) > 0; }

Plan plan(const SlotInfo info[kSlots]) {
    Plan p;
    p.load = -1;
    for (uint8_t i = 0; i < kSlots; ++i) {
        if (info[i].state != SlotState::Valid) continue;
        if (p.load < 0 || newer(info[i].sequence, info[(uint8_t)p.load].sequence)) p.load = (int8_t)i;
    }
    // Two slots: the other one. (A Bad slot's sequence means nothing: its bytes may be
    // any mixture of two saves.)
    p.write = p.load < 0 ? 0 : (uint8_t)(1 - p.load);
    p.next_sequence = p.load < 0 ? 1u : (uint16_t)(info[(uint8_t)p.load].sequence + 1u);
    // The slot written last is the one not loaded (any, when none is valid); when it is
    // Bad the last save was cut.
    p.newest_cut = false;
    for (uint8_t i = 0; i < kSlots; ++i)
        if ((int8_t)i != p.load && info[i].state == SlotState::Bad) p.newest_cut = true;
    return p;
}

Loaded load(ReadBlock read, settings::Settings& s) {
    uint8_t bytes[kMaxSlotSize];
    SlotInfo info[kSlots];
    for (uint8_t i = 0; i < kSlots; ++i) {
        read(slot_address(i), bytes, kMaxSlotSize);
        info[i] = inspect(bytes);
    }
    const Plan p = plan(info);
    Loaded out;
    out.from_legacy = p.load < 0;
    out.newest_cut = p.newest_cut;
    out.write = p.write;
    out.next_sequence = p.next_sequence;
    out.vehicle = record2::Result::NotRead;
    // This firmware's record, or version 3's or 4's (Settings.h: they load, the newer rows at defaults).
    if (p.load >= 0 && info[(uint8_t)p.load].record_length != settings::kRecordSize &&
        info[(uint8_t)p.load].record_length != settings::kV3RecordSize &&
        info[(uint8_t)p.load].record_length != settings::kV4RecordSize) {
        s = settings::defaults();
        out.result = settings::LoadResult::OldVersion;  // another firmware's record layout
        return out;
    }
    read(p.load >= 0 ? (uint16_t)(slot_address((uint8_t)p.load) + kHeaderSize) : kLegacyAddress, bytes,
         settings::kRecordSize);
    out.result = settings::decode(bytes, s);
    if (out.from_legacy && out.result == settings::LoadResult::Blank && p.newest_cut)
        out.result = settings::LoadResult::BadCrc;
    if (!out.from_legacy && out.result == settings::LoadResult::Ok) {
        read(record2::slot_address((uint8_t)p.load), bytes, record2::kSlotSpace);
        out.vehicle = record2::load(bytes, info[(uint8_t)p.load].sequence, s);
    }
    return out;
}

uint8_t header_byte(uint16_t sequence, uint8_t i) {
    return i == 0 ? (uint8_t)(sequence & 0xFFu) : i == 1 ? (uint8_t)(sequence >> 8) : settings::kRecordSize;
}

uint16_t slot_crc(const uint8_t record[settings::kRecordSize], uint16_t sequence) {
    uint16_t crc = settings::kCrc16Init;
    for (uint8_t i = 0; i < kHeaderSize; ++i) crc = settings::crc16_update(crc, header_byte(sequence, i));
    for (uint8_t i = 0; i < settings::kRecordSize; ++i) crc = settings::crc16_update(crc, record[i]);
    return crc;
}

void encode(const uint8_t record[settings::kRecordSize], uint16_t sequence, uint8_t out[kSlotSize]) {
    for (uint8_t i = 0; i < kHeaderSize; ++i) out[i] = header_byte(sequence, i);
    memcpy(out + kHeaderSize, record, settings::kRecordSize);
    const uint16_t crc = slot_crc(record, sequence);
    out[kHeaderSize + settings::kRecordSize] = (uint8_t)(crc & 0xFFu);
    out[kHeaderSize + settings::kRecordSize + 1u] = (uint8_t)(crc >> 8);
}

}  // namespace slots
