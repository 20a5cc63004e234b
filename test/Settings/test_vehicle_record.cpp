// SPDX-License-Identifier: GPL-3.0-or-later
// The second settings record (lib/Settings/VehicleRecord) and its pairing with the first
// record's slots (RecordSlots::load): the EEPROM map, the bytes the store writes, and a
// power cut after every byte of a save of both records, on a host image of the chip.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "Params.h"
#include "RecordSlots.h"
#include "VehicleRecord.h"

using settings::LoadResult;
using settings::Settings;

namespace {

constexpr uint16_t kChipSize = 4096;
constexpr uint16_t kMissionStart = 1284;  // the mission's storage: 1284..4095 stays free
std::vector<uint8_t> g_chip;

void read_chip(uint16_t address, uint8_t* out, uint16_t n) {
    ASSERT_LE((size_t)address + n, g_chip.size());
    std::memcpy(out, g_chip.data() + address, n);
}

slots::Loaded load(Settings& s) { return slots::load(read_chip, s); }

std::vector<uint8_t> record1_of(const Settings& s) {
    std::vector<uint8_t> r(settings::kRecordSize);
    settings::encode(s, r.data());
    return r;
}

std::vector<uint8_t> slot1_of(const Settings& s, uint16_t sequence) {
    std::vector<uint8_t> slot(slots::kSlotSize);
    slots::encode(record1_of(s).data(), sequence, slot.data());
    return slot;
}

uint8_t payload() { return (uint8_t)params::vehicle_bytes(); }

std::vector<uint8_t> slot2_of(const Settings& s, uint16_t sequence) {
    std::vector<uint8_t> slot(record2::slot_size(payload()));
    record2::encode(s, sequence, slot.data());
    return slot;
}

// Both records' bytes: what a start must give wholly from one save.
struct Pair {
    std::vector<uint8_t> first, second;
    bool operator==(const Pair& o) const { return first == o.first && second == o.second; }
};
Pair pair_of(const Settings& s) {
    Pair p{record1_of(s), std::vector<uint8_t>(payload())};
    params::vehicle_part(s, 0, payload(), p.second.data());
    return p;
}

void put(uint16_t address, const std::vector<uint8_t>& bytes) {
    std::copy(bytes.begin(), bytes.end(), g_chip.begin() + address);
}

// Settings that differ in both records from one n to the next, and from the defaults.
Settings numbered(uint8_t n) {
    Settings s = settings::defaults();
    s.rate_hz = (uint8_t)(10 + n);
    s.mode = n % 2 ? fmt::OutputMode::Csv : fmt::OutputMode::Plot;
    s.cal.mag_offset_uT = linalg::Vector3f(1.5f * n, -2.0f * n, 0.25f * n);
    s.flight.roll.p = 0.5f + 0.125f * n;
    settings::set_declination_rad(s, 0.2f + 0.01f * n);  // not a whole hundredth of a degree
    s.vehicle.arming_require = (uint8_t)(n % 2);
    return s;
}

// A save as SettingsStore makes it after a start on this chip: the second record's slot
// `write` with the sequence the first record's slot `write` is about to get, then that
// slot, each byte by byte in order; the power cut after `bytes` of them.
uint16_t save_bytes() { return (uint16_t)(record2::slot_size(payload()) + slots::kSlotSize); }
void save(const Settings& s, uint16_t bytes) {
    Settings ignored;
    const slots::Loaded l = load(ignored);
    std::vector<uint8_t> all = slot2_of(s, l.next_sequence);
    const std::vector<uint8_t> first = slot1_of(s, l.next_sequence);
    all.insert(all.end(), first.begin(), first.end());
    const uint16_t n2 = record2::slot_size(payload());
    for (uint16_t i = 0; i < bytes && i < all.size(); ++i)
        g_chip[i < n2 ? record2::slot_address(l.write) + i : slots::slot_address(l.write) + (i - n2)] = all[i];
}

TEST(VehicleRecord, FitsItsSlotsAndTheEepromMapLeavesTheMissionArea) {
    // The rows after GND_ABS_PRESS fit the smaller gap (docs/storage.md).
    EXPECT_LE(params::vehicle_bytes(), record2::kMaxPayload);
    EXPECT_LE(record2::slot_size(record2::kMaxPayload), record2::kSlotSpace);
    struct Area {
        uint16_t from, size;
    };
    const Area areas[] = {{slots::kLegacyAddress, 256},
                          {slots::slot_address(0), slots::kMaxSlotSize},
                          {slots::slot_address(1), slots::kMaxSlotSize},
                          {record2::slot_address(0), record2::kSlotSpace},
                          {record2::slot_address(1), record2::kSlotSpace}};
    for (const Area& a : areas) {
        EXPECT_LE(a.from + a.size, kMissionStart) << a.from;
        for (const Area& b : areas)
            if (&a != &b) EXPECT_TRUE(a.from + a.size <= b.from || b.from + b.size <= a.from) << a.from << " " << b.from;
    }
}

// The store writes the slot a byte at a time from the live settings: header_byte and
// vehicle_part in parts are encode's bytes, and slot_crc (one walk) its CRC.
TEST(VehicleRecord, ByteAtATimeIsTheEncodedSlot) {
    for (uint8_t n = 0; n < 3; ++n) {
        const Settings s = numbered(n);
        const uint16_t sequence = (uint16_t)(0xFFFEu + n);
        const std::vector<uint8_t> slot = slot2_of(s, sequence);
        for (uint8_t i = 0; i < record2::kHeaderSize; ++i)
            EXPECT_EQ(record2::header_byte(sequence, payload(), i), slot[i]) << (int)i;
        for (uint8_t i = 0; i < payload(); ++i) {
            uint8_t b;
            params::vehicle_part(s, i, 1, &b);
            EXPECT_EQ(b, slot[record2::kHeaderSize + i]) << (int)i;
        }
        const uint16_t crc = record2::slot_crc(s, sequence, payload());
        EXPECT_EQ(crc, settings::crc16(slot.data(), (uint16_t)(record2::kHeaderSize + payload())));
        EXPECT_EQ(crc, (uint16_t)(slot[slot.size() - 2] | slot[slot.size() - 1] << 8));
    }
}

// The hundredths `decl` sets come back from the float they give; any float's hundredths
// are its rounding.
TEST(VehicleRecord, DeclinationHundredthsAndFloatAgree) {
    Settings s = settings::defaults();
    for (int32_t cd = settings::kDeclMinCentideg; cd <= settings::kDeclMaxCentideg; ++cd) {
        settings::set_declination_centideg(s, (int16_t)cd);
        ASSERT_EQ(settings::centideg_of_rad(s.declination_rad()), cd);
        ASSERT_NEAR(s.declination_deg(), 0.01f * (float)cd, 1e-4f);
    }
    settings::set_declination_rad(s, 0.2f);
    EXPECT_EQ(s.declination_rad(), 0.2f);
    EXPECT_EQ(s.declination_centideg, 1146);
    settings::set_declination_rad(s, -3.1416f);  // COMPASS_DEC's range ends a little past 180 deg
    EXPECT_EQ(s.declination_centideg, settings::kDeclMinCentideg);
    EXPECT_TRUE(settings::is_valid(s));
    s.declination_centideg = 0;  // a copy that disagrees is not valid
    EXPECT_FALSE(settings::is_valid(s));
}

// Saves one after the other, each cut after every byte of both slots: a start gives both
// records of the save before, or both of the new one; never one of each, never defaults
// once a save has been whole. The declination comes back as the float saved.
TEST(VehicleRecord, PowerCutAfterAnyByteLeavesTheOldOrTheNewPair) {
    g_chip.assign(kChipSize, 0xFF);
    Settings before = settings::defaults();
    bool any_saved = false;
    int old_boots = 0, new_boots = 0;
    for (uint8_t n = 1; n <= 4; ++n) {
        const Settings next = numbered(n);
        ASSERT_FALSE(pair_of(next).first == pair_of(before).first);
        ASSERT_FALSE(pair_of(next).second == pair_of(before).second);
        const std::vector<uint8_t> chip_before = g_chip;
        for (uint16_t cut = 0; cut <= save_bytes(); ++cut) {
            g_chip = chip_before;
            save(next, cut);
            Settings loaded;
            const slots::Loaded l = load(loaded);
            const Pair got = pair_of(loaded);
            const bool is_new = got == pair_of(next), is_old = got == pair_of(before);
            ASSERT_TRUE(is_new || is_old) << "save " << int(n) << " cut after " << cut << " bytes";
            EXPECT_EQ(is_new, cut == save_bytes()) << "save " << int(n) << " cut after " << cut;
            EXPECT_EQ(loaded.declination_rad(), (is_new ? next : before).declination_rad());
            if (any_saved) {
                EXPECT_EQ(l.result, LoadResult::Ok) << "save " << int(n) << " cut after " << cut;
                EXPECT_EQ(l.vehicle, record2::Result::Paired) << "save " << int(n) << " cut after " << cut;
            } else if (cut < save_bytes()) {
                EXPECT_NE(l.result, LoadResult::Ok) << cut;
            }
            (is_new ? new_boots : old_boots)++;
        }
        g_chip = chip_before;
        save(next, save_bytes());
        before = next;
        any_saved = true;
    }
    EXPECT_EQ(new_boots, 4);
    EXPECT_EQ(old_boots, 4 * save_bytes());
}

// A board saved by a firmware before the second record: the first record loads, the
// vehicle settings are the defaults but the declination, which comes from the first
// record's hundredths; a save cut anywhere keeps that, a whole one pairs.
TEST(VehicleRecord, BoardWithoutTheSecondRecordKeepsTheFirstAndPairsAfterASave) {
    g_chip.assign(kChipSize, 0xFF);
    Settings old = numbered(3);
    settings::set_declination_centideg(old, -345);
    old.vehicle.arming_require = settings::defaults().vehicle.arming_require;
    put(slots::slot_address(1), slot1_of(old, 9));
    Settings s;
    slots::Loaded l = load(s);
    ASSERT_EQ(l.result, LoadResult::Ok);
    EXPECT_EQ(l.vehicle, record2::Result::Missing);
    EXPECT_TRUE(pair_of(s) == pair_of(old));
    EXPECT_EQ(s.declination_rad(), old.declination_rad());
    EXPECT_EQ(s.declination_centideg, -345);
    EXPECT_EQ(l.write, 0);
    const std::vector<uint8_t> upgraded = g_chip;
    for (uint16_t cut = 1; cut < save_bytes(); ++cut) {
        g_chip = upgraded;
        save(numbered(6), cut);
        l = load(s);
        ASSERT_EQ(l.result, LoadResult::Ok) << cut;
        EXPECT_EQ(l.vehicle, record2::Result::Missing) << cut;
        EXPECT_TRUE(pair_of(s) == pair_of(old)) << cut;
    }
    g_chip = upgraded;
    save(numbered(6), save_bytes());
    l = load(s);
    EXPECT_EQ(l.vehicle, record2::Result::Paired);
    EXPECT_TRUE(pair_of(s) == pair_of(numbered(6)));
}

// After a downgrade an older firmware saved the first record alone (sequence 11 over the
// slot of 9): the second record beside it is of 9, the other one of 10: neither pairs.
TEST(VehicleRecord, FirstRecordSavedAloneSinceDoesNotPairWithAnOlderSecond) {
    g_chip.assign(kChipSize, 0xFF);
    put(slots::slot_address(0), slot1_of(numbered(1), 11));
    put(slots::slot_address(1), slot1_of(numbered(2), 10));
    put(record2::slot_address(0), slot2_of(numbered(1), 9));
    put(record2::slot_address(1), slot2_of(numbered(2), 10));
    Settings s;
    const slots::Loaded l = load(s);
    ASSERT_EQ(l.result, LoadResult::Ok);
    EXPECT_EQ(l.vehicle, record2::Result::Missing);
    EXPECT_TRUE(pair_of(s).first == pair_of(numbered(1)).first);
    EXPECT_EQ(s.vehicle.arming_require, settings::defaults().vehicle.arming_require);
    EXPECT_EQ(s.declination_centideg, numbered(1).declination_centideg);  // the first record's copy
}

// The paired slot holding something else: another version, a flipped bit, a value out of
// range: the first record stands, the vehicle settings take their defaults.
TEST(VehicleRecord, PairedSlotOfAnotherVersionCorruptedOrOutOfRangeGivesDefaults) {
    const Settings saved = numbered(1);
    Settings expected = saved;  // the first record's, the vehicle's at defaults
    const uint16_t cd = (uint16_t)saved.declination_centideg;
    const Settings d = settings::defaults();
    expected.vehicle = d.vehicle;
    settings::set_declination_centideg(expected, (int16_t)cd);
    struct Case {
        const char* what;
        uint8_t at, value;  // the byte changed, before the CRC is made again (at 0xFF: not made)
        bool recrc;
        record2::Result result;
    };
    const uint8_t arming_at = record2::kHeaderSize;  // ARMING_REQUIRE: the table's first vehicle row
    const Case cases[] = {
        {"version 2", 2, 2, true, record2::Result::OldVersion},
        {"flipped bit", record2::kHeaderSize, 0x10, false, record2::Result::BadCrc},
        {"ARMING_REQUIRE 7", arming_at, 7, true, record2::Result::BadValue},
        {"magic", 0, 'X', true, record2::Result::BadCrc},
        {"payload too long", 3, (uint8_t)(record2::kMaxPayload + 1u), true, record2::Result::BadCrc},
    };
    for (const Case& c : cases) {
        g_chip.assign(kChipSize, 0xFF);
        std::vector<uint8_t> slot = slot2_of(saved, 5);
        if (c.recrc) {
            slot[c.at] = c.value;
        } else {
            slot[c.at] ^= c.value;
        }
        if (c.recrc) {
            const uint16_t crc = settings::crc16(slot.data(), (uint16_t)(slot.size() - 2u));
            slot[slot.size() - 2] = (uint8_t)(crc & 0xFFu);
            slot[slot.size() - 1] = (uint8_t)(crc >> 8);
        }
        put(slots::slot_address(0), slot1_of(saved, 5));
        put(record2::slot_address(0), slot);
        Settings s;
        const slots::Loaded l = load(s);
        ASSERT_EQ(l.result, LoadResult::Ok) << c.what;
        EXPECT_EQ(l.vehicle, c.result) << c.what;
        EXPECT_TRUE(pair_of(s) == pair_of(expected)) << c.what;
        EXPECT_TRUE(settings::is_valid(s)) << c.what;
    }
}

// A second record with fewer rows (an earlier firmware's) is this one's first part; one
// with more (a later firmware's, after a downgrade) is refused as another version is.
TEST(VehicleRecord, ShorterPayloadLoadsAsTheFirstPartALongerIsRefused) {
    const Settings saved = numbered(1);  // ARMING_REQUIRE 1 ... declination 0.21 rad
    Settings zero_arming = saved;
    zero_arming.vehicle.arming_require = 0;
    for (const uint8_t n : {(uint8_t)1, (uint8_t)(payload() + 7u)}) {
        g_chip.assign(kChipSize, 0xFF);
        std::vector<uint8_t> full = slot2_of(zero_arming, 5);
        std::vector<uint8_t> slot(full.begin(), full.begin() + record2::kHeaderSize);
        for (uint8_t i = 0; i < n; ++i)
            slot.push_back(i < payload() ? full[record2::kHeaderSize + i] : (uint8_t)(0xA0u + i));
        slot[3] = n;
        const uint16_t crc = settings::crc16(slot.data(), (uint16_t)slot.size());
        slot.push_back((uint8_t)(crc & 0xFFu));
        slot.push_back((uint8_t)(crc >> 8));
        put(slots::slot_address(0), slot1_of(saved, 5));
        put(record2::slot_address(0), slot);
        Settings s;
        const slots::Loaded l = load(s);
        // The declination the earlier record lacked, or of the record refused: the first
        // record's hundredths.
        EXPECT_EQ(s.declination_centideg, saved.declination_centideg);
        EXPECT_NEAR(s.declination_rad(), saved.declination_rad(), 1e-4f);
        if (n == 1) {
            EXPECT_EQ(l.vehicle, record2::Result::Paired);
            EXPECT_EQ(s.vehicle.arming_require, 0);
        } else {
            EXPECT_EQ(l.vehicle, record2::Result::OldVersion);
            EXPECT_EQ(s.vehicle.arming_require, settings::defaults().vehicle.arming_require);
        }
    }
}

// The first record loaded from the legacy address, or not at all: the second is not read.
TEST(VehicleRecord, NotReadWithoutAFirstRecordFromASlot) {
    g_chip.assign(kChipSize, 0xFF);
    put(record2::slot_address(0), slot2_of(numbered(1), 1));
    Settings s;
    slots::Loaded l = load(s);
    EXPECT_EQ(l.result, LoadResult::Blank);
    EXPECT_EQ(l.vehicle, record2::Result::NotRead);
    EXPECT_TRUE(pair_of(s) == pair_of(settings::defaults()));
    put(slots::kLegacyAddress, record1_of(numbered(2)));
    l = load(s);
    EXPECT_EQ(l.result, LoadResult::Ok);
    EXPECT_TRUE(l.from_legacy);
    EXPECT_EQ(l.vehicle, record2::Result::NotRead);
    EXPECT_EQ(s.vehicle.arming_require, settings::defaults().vehicle.arming_require);
}

}  // namespace
