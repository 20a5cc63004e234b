// SPDX-License-Identifier: GPL-3.0-or-later
// The settings record's two EEPROM slots (lib/Settings/RecordSlots): the choice at start,
// and a power cut after every byte of a save, on a host image of the chip.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "RecordSlots.h"

using settings::LoadResult;
using settings::Settings;

namespace {

constexpr uint16_t kChipSize = 4096;
std::vector<uint8_t> g_chip;  // what slots::load reads

void read_chip(uint16_t address, uint8_t* out, uint16_t n) {
    ASSERT_LE((size_t)address + n, g_chip.size());
    std::memcpy(out, g_chip.data() + address, n);
}

std::vector<uint8_t> record_of(const Settings& s) {
    std::vector<uint8_t> r(settings::kRecordSize);
    settings::encode(s, r.data());
    return r;
}

Settings numbered(uint8_t n) {
    Settings s = settings::defaults();
    s.rate_hz = (uint8_t)(10 + n);
    settings::set_declination_centideg(s, (int16_t)(-1000 + 137 * n));
    s.mode = n % 2 ? fmt::OutputMode::Csv : fmt::OutputMode::Plot;
    s.flags = settings::kFlagMagCalibrated;
    s.cal.mag_offset_uT = linalg::Vector3f(1.5f * n, -2.0f * n, 0.25f * n);
    s.cal.mag_scale = linalg::Vector3f(1.0f + 0.01f * n, 0.99f, 1.01f);
    s.cal.mag_cross = linalg::Vector3f(0.001f * n, -0.002f, 0.003f);
    return s;
}

slots::Loaded load(Settings& s) { return slots::load(read_chip, s); }

// A save as SettingsStore makes it after a start on this chip: the slot load() says,
// byte by byte in order (unchanged bytes skipped as eeprom_update_byte does), the power
// cut after `bytes` of them.
void save(const Settings& s, uint16_t bytes = slots::kSlotSize) {
    Settings ignored;
    const slots::Loaded l = load(ignored);
    uint8_t slot[slots::kSlotSize];
    slots::encode(record_of(s).data(), l.next_sequence, slot);
    for (uint16_t i = 0; i < bytes && i < slots::kSlotSize; ++i) g_chip[slots::slot_address(l.write) + i] = slot[i];
}

bool same(const Settings& a, const Settings& b) { return record_of(a) == record_of(b); }

TEST(RecordSlots, SlotsLieApartAndAboveTheLegacyRecord) {
    EXPECT_GE(slots::slot_address(0), settings::kEepromAddress + 256u);  // any earlier record length
    EXPECT_GE(slots::slot_address(1), slots::slot_address(0) + slots::kMaxSlotSize);
    EXPECT_LE(slots::slot_address(1) + slots::kMaxSlotSize, kChipSize);
}

TEST(RecordSlots, EncodedSlotInspectsValid) {
    uint8_t bytes[slots::kMaxSlotSize];
    std::memset(bytes, 0xFF, sizeof bytes);
    slots::encode(record_of(numbered(3)).data(), 0x1234, bytes);
    slots::SlotInfo info = slots::inspect(bytes);
    EXPECT_EQ(info.state, slots::SlotState::Valid);
    EXPECT_EQ(info.sequence, 0x1234);
    EXPECT_EQ(info.record_length, settings::kRecordSize);
    for (uint16_t i = 0; i < slots::kSlotSize; ++i) {
        bytes[i] ^= 0x04u;
        EXPECT_EQ(slots::inspect(bytes).state, slots::SlotState::Bad) << "byte " << i;
        bytes[i] ^= 0x04u;
    }
    std::memset(bytes, 0xFF, sizeof bytes);
    EXPECT_EQ(slots::inspect(bytes).state, slots::SlotState::Blank);
}

TEST(RecordSlots, PlanLoadsTheNewerValidSlotAndWritesTheOther) {
    using slots::SlotState;
    const slots::SlotInfo blank{SlotState::Blank, 0xFFFF, 0xFF};
    const slots::SlotInfo bad{SlotState::Bad, 900, 71};
    struct Case {
        slots::SlotInfo a, b;
        int8_t load;
        uint8_t write;
        uint16_t next;
        bool cut;
    };
    const Case cases[] = {
        {blank, blank, -1, 0, 1, false},
        {bad, blank, -1, 0, 1, true},
        {{SlotState::Valid, 5, 71}, blank, 0, 1, 6, false},
        {{SlotState::Valid, 5, 71}, {SlotState::Valid, 6, 71}, 1, 0, 7, false},
        {{SlotState::Valid, 7, 71}, {SlotState::Valid, 6, 71}, 0, 1, 8, false},
        {{SlotState::Valid, 7, 71}, bad, 0, 1, 8, true},
        {bad, {SlotState::Valid, 2, 71}, 1, 0, 3, true},
        // The counter wraps: 0 follows 0xFFFF.
        {{SlotState::Valid, 0xFFFF, 71}, {SlotState::Valid, 0, 71}, 1, 0, 1, false},
        {{SlotState::Valid, 0, 71}, {SlotState::Valid, 0xFFFF, 71}, 0, 1, 1, false},
    };
    for (const Case& c : cases) {
        const slots::SlotInfo info[2] = {c.a, c.b};
        const slots::Plan p = slots::plan(info);
        EXPECT_EQ(p.load, c.load) << c.a.sequence << " " << c.b.sequence;
        EXPECT_EQ(p.write, c.write) << c.a.sequence << " " << c.b.sequence;
        EXPECT_EQ(p.next_sequence, c.next) << c.a.sequence << " " << c.b.sequence;
        EXPECT_EQ(p.newest_cut, c.cut) << c.a.sequence << " " << c.b.sequence;
    }
}

TEST(RecordSlots, BlankChipGivesDefaults) {
    g_chip.assign(kChipSize, 0xFF);
    Settings s = numbered(1);
    const slots::Loaded l = load(s);
    EXPECT_EQ(l.result, LoadResult::Blank);
    EXPECT_TRUE(same(s, settings::defaults()));
}

// Saves one after the other, each cut after every byte: the chip then loads either the
// settings before the save or the ones it wrote, whole; never defaults once a save has
// been whole, never a mixture.
TEST(RecordSlots, PowerCutAfterAnyByteLeavesTheOldOrTheNewSettings) {
    g_chip.assign(kChipSize, 0xFF);
    Settings before = settings::defaults();
    bool any_saved = false;
    int old_boots = 0, new_boots = 0;
    for (uint8_t n = 1; n <= 5; ++n) {
        const Settings next = numbered(n);
        const std::vector<uint8_t> chip_before = g_chip;
        for (uint16_t cut = 0; cut <= slots::kSlotSize; ++cut) {
            g_chip = chip_before;
            save(next, cut);
            Settings loaded;
            const slots::Loaded l = load(loaded);
            const bool is_new = same(loaded, next), is_old = same(loaded, before);
            ASSERT_TRUE(is_new || is_old) << "save " << int(n) << " cut after " << cut << " bytes";
            EXPECT_EQ(is_new, cut == slots::kSlotSize) << "save " << int(n) << " cut after " << cut;
            if (any_saved) {
                EXPECT_EQ(l.result, LoadResult::Ok) << "save " << int(n) << " cut after " << cut;
            } else if (cut < slots::kSlotSize) {
                // The first save, cut: defaults, and said to be a cut (not a blank chip)
                // once anything of the slot is written.
                EXPECT_EQ(l.result, cut == 0 ? LoadResult::Blank : LoadResult::BadCrc) << cut;
            }
            EXPECT_EQ(l.newest_cut, cut > 0 && cut < slots::kSlotSize) << "save " << int(n) << " cut " << cut;
            (is_new ? new_boots : old_boots)++;
        }
        g_chip = chip_before;
        save(next);
        before = next;
        any_saved = true;
    }
    EXPECT_EQ(new_boots, 5);
    EXPECT_EQ(old_boots, 5 * slots::kSlotSize);
}

// A board upgraded from the firmware before the slots: its single record at address 0
// loads (this version) or is refused (another version), and a first save cut short
// leaves it.
TEST(RecordSlots, LegacyRecordLoadsUntilASlotIsWhole) {
    g_chip.assign(kChipSize, 0xFF);
    const std::vector<uint8_t> legacy = record_of(numbered(4));
    std::copy(legacy.begin(), legacy.end(), g_chip.begin() + slots::kLegacyAddress);
    Settings s;
    slots::Loaded l = load(s);
    EXPECT_EQ(l.result, LoadResult::Ok);
    EXPECT_TRUE(l.from_legacy);
    EXPECT_TRUE(same(s, numbered(4)));
    const std::vector<uint8_t> upgraded = g_chip;
    for (uint16_t cut = 1; cut < slots::kSlotSize; ++cut) {
        g_chip = upgraded;
        save(numbered(6), cut);
        l = load(s);
        EXPECT_EQ(l.result, LoadResult::Ok) << cut;
        EXPECT_TRUE(l.from_legacy && l.newest_cut) << cut;
        EXPECT_TRUE(same(s, numbered(4))) << cut;
    }
    g_chip = upgraded;
    save(numbered(6));
    l = load(s);
    EXPECT_EQ(l.result, LoadResult::Ok);
    EXPECT_FALSE(l.from_legacy);
    EXPECT_TRUE(same(s, numbered(6)));
}

TEST(RecordSlots, LegacyRecordOfAnotherVersionIsRefused) {
    g_chip.assign(kChipSize, 0xFF);
    std::vector<uint8_t> legacy = record_of(numbered(4));
    legacy[2] = (uint8_t)(settings::kSettingsVersion + 1u);  // Settings.h: magic, magic, version
    const uint16_t crc = settings::crc16(legacy.data(), (uint16_t)(settings::kRecordSize - 2u));
    legacy[settings::kRecordSize - 2] = (uint8_t)(crc & 0xFFu);
    legacy[settings::kRecordSize - 1] = (uint8_t)(crc >> 8);
    std::copy(legacy.begin(), legacy.end(), g_chip.begin() + slots::kLegacyAddress);
    Settings s = numbered(2);
    EXPECT_EQ(load(s).result, LoadResult::OldVersion);
    EXPECT_TRUE(same(s, settings::defaults()));
}

// A slot written by a firmware whose record has another length: whole, but refused.
TEST(RecordSlots, SlotOfAnotherRecordLengthIsRefused) {
    g_chip.assign(kChipSize, 0xFF);
    const uint8_t other_length = (uint8_t)(settings::kRecordSize + 20u);
    uint8_t* slot = g_chip.data() + slots::slot_address(0);
    slot[0] = 9;
    slot[1] = 0;
    slot[2] = other_length;
    for (uint8_t i = 0; i < other_length; ++i) slot[3 + i] = (uint8_t)(i * 7u);
    const uint16_t crc = settings::crc16(slot, (uint16_t)(3u + other_length));
    slot[3 + other_length] = (uint8_t)(crc & 0xFFu);
    slot[4 + other_length] = (uint8_t)(crc >> 8);
    Settings s = numbered(2);
    const slots::Loaded l = load(s);
    EXPECT_EQ(l.result, LoadResult::OldVersion);
    EXPECT_TRUE(same(s, settings::defaults()));
    EXPECT_EQ(l.write, 1);  // that slot is kept for a downgrade; the next save goes to the other
    EXPECT_EQ(l.next_sequence, 10);
    EXPECT_EQ(l.vehicle, record2::Result::NotRead);  // the second record only beside a first one loaded
}

}  // namespace

// The store writes a slot a byte at a time from the live settings (firmware/SettingsStore):
// record_byte and header_byte are encode's bytes, the CRCs run to slot_crc's.
TEST(RecordSlots, ByteAtATimeIsTheEncodedSlot) {
    for (uint8_t n = 0; n < 3; ++n) {
        Settings s = numbered(n);
        s.flight.elevon_output = n == 1 ? 1 : 0;
        s.flight.roll.p = 0.5f + 0.25f * n;
        s.flight.servo[7].trim_us = (uint16_t)(1400 + n);
        const std::vector<uint8_t> record = record_of(s);
        const uint16_t sequence = (uint16_t)(0xFFFEu + n);
        std::vector<uint8_t> slot(slots::kSlotSize);
        slots::encode(record.data(), sequence, slot.data());
        uint16_t crc = settings::kCrc16Init;
        for (uint8_t i = 0; i < slots::kHeaderSize; ++i) {
            EXPECT_EQ(slots::header_byte(sequence, i), slot[i]) << "header byte " << (int)i;
            crc = settings::crc16_update(crc, slot[i]);
        }
        for (uint8_t i = 0; i + 2u < settings::kRecordSize; ++i) {
            for (uint8_t n = 1; n <= 17 && i + n + 2u <= settings::kRecordSize; n = (uint8_t)(n + 8)) {
                uint8_t part[17];
                settings::record_part(s, i, n, part);
                ASSERT_EQ(0, std::memcmp(part, record.data() + i, n)) << "record bytes " << (int)i << "+" << (int)n;
            }
            crc = settings::crc16_update(crc, record[i]);
        }
        const uint16_t covered = (uint16_t)(slots::kHeaderSize + settings::kRecordSize);
        crc = settings::crc16_update(settings::crc16_update(crc, slot[covered - 2u]), slot[covered - 1u]);
        EXPECT_EQ(crc, slots::slot_crc(record.data(), sequence));
        EXPECT_EQ(crc, (uint16_t)(slot[covered] | slot[covered + 1u] << 8));
    }
}

// crc16_update's byte-at-once form is CRC-16/CCITT-FALSE: the check value, and the
// bitwise definition (poly 0x1021, MSB first) for every state and byte.
TEST(RecordSlots, Crc16IsCcittFalse) {
    const uint8_t check[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    EXPECT_EQ(0x29B1u, settings::crc16(check, sizeof check));
    for (uint32_t state = 0; state < 0x10000u; ++state) {
        for (uint16_t byte = 0; byte < 256; ++byte) {
            uint16_t bitwise = (uint16_t)(state ^ (byte << 8));
            for (uint8_t b = 0; b < 8; ++b)
                bitwise = (bitwise & 0x8000u) ? (uint16_t)((uint16_t)(bitwise << 1) ^ 0x1021u) : (uint16_t)(bitwise << 1);
            if (settings::crc16_update((uint16_t)state, (uint8_t)byte) != bitwise) {
                FAIL() << "state " << state << " byte " << byte;
            }
        }
    }
}

// A slot that version 3 or 4 of the firmware wrote (its record is this one's first part,
// Settings.h): loaded, the rows added since at their defaults; the next save writes the other slot.
void expect_older_slot_loads(uint8_t version, uint8_t payload_length, uint8_t record_size) {
    g_chip.assign(kChipSize, 0xFF);
    Settings older = numbered(5);
    older.flight.trim_arspd_cm = 1800;
    std::vector<uint8_t> rec = record_of(older);
    rec[2] = version;
    rec[3] = payload_length;
    const uint16_t rcrc = settings::crc16(rec.data(), (uint16_t)(4u + payload_length));
    rec[4 + payload_length] = (uint8_t)(rcrc & 0xFFu);
    rec[5 + payload_length] = (uint8_t)(rcrc >> 8);
    uint8_t* slot = g_chip.data() + slots::slot_address(0);
    slot[0] = 4;
    slot[1] = 0;
    slot[2] = record_size;
    std::copy(rec.begin(), rec.begin() + record_size, slot + 3);
    const uint16_t crc = settings::crc16(slot, (uint16_t)(3u + record_size));
    slot[3 + record_size] = (uint8_t)(crc & 0xFFu);
    slot[4 + record_size] = (uint8_t)(crc >> 8);
    Settings s;
    const slots::Loaded l = load(s);
    EXPECT_EQ(l.result, LoadResult::Ok) << "version " << (int)version;
    EXPECT_EQ(s.flight.trim_arspd_cm, 1800);
    EXPECT_TRUE(same(s, older));  // the newer rows: numbered() has their defaults
    EXPECT_EQ(l.write, 1);
    EXPECT_EQ(l.next_sequence, 5);
}

TEST(RecordSlots, SlotOfVersion3Loads) {
    expect_older_slot_loads(3, settings::kV3PayloadLength, settings::kV3RecordSize);
}

TEST(RecordSlots, SlotOfVersion4Loads) {
    expect_older_slot_loads(4, settings::kV4PayloadLength, settings::kV4RecordSize);
}
