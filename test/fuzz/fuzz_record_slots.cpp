// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: the settings records' EEPROM slots (lib/Settings/RecordSlots and
// VehicleRecord). Built by mk/fuzz.mk with clang -fsanitize=fuzzer,address,undefined.
//
// The input is laid over an erased chip: its first bytes over the legacy record at
// address 0, then over slot 0, then slot 1 (any header, any length byte, any CRC), then
// the second record's slots 0 and 1. load() reads only inside the chip, and either gives
// valid settings (Ok) that some record on the chip holds byte for byte, or exactly
// defaults(); the slot it would write next is never the one it loaded. The vehicle
// settings are a paired second record's (a whole one of this firmware's length: its
// payload byte for byte), or their defaults with the first record's declination.
#include <stddef.h>
#include <stdint.h>

#include <cstring>

#include "FuzzAssert.h"
#include "Params.h"
#include "RecordSlots.h"
#include "VehicleRecord.h"

namespace {

constexpr uint16_t kChip = 4096;
uint8_t g_chip[kChip];

void read_chip(uint16_t address, uint8_t* out, uint16_t n) {
    fuzz_assert((uint32_t)address + n <= kChip);
    std::memcpy(out, g_chip + address, n);
}

bool chip_holds(const uint8_t* record) {
    for (uint32_t at = 0; at + settings::kRecordSize <= kChip; ++at)
        if (std::memcmp(g_chip + at, record, settings::kRecordSize) == 0) return true;
    return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::memset(g_chip, 0xFF, sizeof g_chip);
    const uint16_t regions[5] = {slots::kLegacyAddress, slots::slot_address(0), slots::slot_address(1),
                                 record2::slot_address(0), record2::slot_address(1)};
    const uint16_t lengths[5] = {settings::kRecordSize, slots::kMaxSlotSize, slots::kMaxSlotSize, record2::kSlotSpace,
                                 record2::kSlotSpace};
    for (uint8_t i = 0; i < 5 && size > 0; ++i) {
        const size_t n = size < lengths[i] ? size : lengths[i];
        std::memcpy(g_chip + regions[i], data, n);
        data += n;
        size -= n;
    }
    settings::Settings s;
    std::memset(&s, 0xA5, sizeof s);  // garbage in: load must overwrite it
    const slots::Loaded l = slots::load(read_chip, s);
    uint8_t rec[settings::kRecordSize];
    settings::encode(s, rec);
    if (l.result == settings::LoadResult::Ok) {
        fuzz_assert(settings::is_valid(s));
        fuzz_assert(chip_holds(rec));
    } else {
        uint8_t defaults[settings::kRecordSize];
        settings::encode(settings::defaults(), defaults);
        fuzz_assert(std::memcmp(rec, defaults, sizeof rec) == 0);
    }
    fuzz_assert(l.write < slots::kSlots);

    const uint8_t n = (uint8_t)params::vehicle_bytes();
    uint8_t vehicle[record2::kMaxPayload], expected[record2::kMaxPayload];
    params::vehicle_part(s, 0, n, vehicle);
    if (l.vehicle == record2::Result::Paired) {
        fuzz_assert(l.result == settings::LoadResult::Ok && !l.from_legacy);
        const uint8_t* slot = g_chip + record2::slot_address(l.write == 0 ? 1 : 0);  // beside the slot loaded
        fuzz_assert(slot[0] == record2::kMagic0 && slot[1] == record2::kMagic1 && slot[2] == record2::kVersion);
        if (slot[3] == n) fuzz_assert(std::memcmp(slot + record2::kHeaderSize, vehicle, n) == 0);
    } else {
        settings::Settings d = settings::defaults();
        settings::set_declination_centideg(d, s.declination_centideg);
        params::vehicle_part(d, 0, n, expected);
        fuzz_assert(std::memcmp(vehicle, expected, n) == 0);
    }
    if (l.result != settings::LoadResult::Ok || l.from_legacy) fuzz_assert(l.vehicle == record2::Result::NotRead);
    return 0;
}
