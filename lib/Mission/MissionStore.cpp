// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionStore.h"

#include "RecordSlots.h"
#include "Settings.h"

namespace mission {

uint16_t MissionStore::area_crc(uint8_t area, uint16_t sequence, uint8_t count) const {
    uint16_t crc = settings::kCrc16Init;
    crc = settings::crc16_update(crc, (uint8_t)(sequence & 0xFFu));
    crc = settings::crc16_update(crc, (uint8_t)(sequence >> 8));
    crc = settings::crc16_update(crc, count);
    const uint16_t start = (uint16_t)(area_address(area) + kHeaderBytes);
    const uint16_t n = (uint16_t)count * kCommandBytes;
    for (uint16_t i = 0; i < n; ++i) crc = settings::crc16_update(crc, byte_at((uint16_t)(start + i)));
    return crc;
}

bool MissionStore::area_valid(uint8_t area, uint16_t& sequence, uint8_t& count) const {
    const uint16_t a = area_address(area);
    if (byte_at(a) != kMarker) return false;
    sequence = (uint16_t)(byte_at((uint16_t)(a + 1)) | ((uint16_t)byte_at((uint16_t)(a + 2)) << 8));
    count = byte_at((uint16_t)(a + 3));
    if (count > kMaxCommands) return false;
    const uint16_t crc = (uint16_t)(byte_at((uint16_t)(a + 4)) | ((uint16_t)byte_at((uint16_t)(a + 5)) << 8));
    return crc == area_crc(area, sequence, count);
}

bool MissionStore::load() {
    uint16_t seq[2] = {0, 0};
    uint8_t n[2] = {0, 0};
    const bool ok0 = area_valid(0, seq[0], n[0]);
    const bool ok1 = area_valid(1, seq[1], n[1]);
    if (!ok0 && !ok1) {
        count_ = 0;
        sequence_ = 0;
        area_ = 1;
        return false;
    }
    area_ = (ok0 && (!ok1 || slots::newer(seq[0], seq[1]))) ? 0 : 1;
    sequence_ = seq[area_];
    count_ = n[area_];
    return true;
}

bool MissionStore::read(uint8_t index, Command& c) const {
    if (index >= count_) return false;
    uint8_t bytes[kCommandBytes];
    const uint16_t a = (uint16_t)(area_address(area_) + kHeaderBytes + (uint16_t)index * kCommandBytes);
    for (uint8_t i = 0; i < kCommandBytes; ++i) bytes[i] = byte_at((uint16_t)(a + i));
    return unpack(bytes, c);
}

void MissionStore::begin_upload() {
    const uint16_t a = area_address((uint8_t)(1u - area_));
    if (byte_at(a) != 0xFFu) put(a, 0xFFu);  // no marker: not a mission until commit()
}

void MissionStore::write(uint8_t index, const Command& c) {
    if (index >= kMaxCommands) return;
    uint8_t bytes[kCommandBytes];
    pack(c, bytes);
    const uint16_t a = (uint16_t)(area_address((uint8_t)(1u - area_)) + kHeaderBytes + (uint16_t)index * kCommandBytes);
    for (uint8_t i = 0; i < kCommandBytes; ++i) put((uint16_t)(a + i), bytes[i]);
}

void MissionStore::commit(uint8_t count) {
    if (count > kMaxCommands) return;
    const uint8_t area = (uint8_t)(1u - area_);
    const uint16_t a = area_address(area);
    const uint16_t sequence = (uint16_t)(sequence_ + 1u);
    // The CRC over what the EEPROM holds (read back: a bad write fails it now, not at the
    // next start).
    const uint16_t crc = area_crc(area, sequence, count);
    put((uint16_t)(a + 1), (uint8_t)(sequence & 0xFFu));
    put((uint16_t)(a + 2), (uint8_t)(sequence >> 8));
    put((uint16_t)(a + 3), count);
    put((uint16_t)(a + 4), (uint8_t)(crc & 0xFFu));
    put((uint16_t)(a + 5), (uint8_t)(crc >> 8));
    put(a, kMarker);
    // In use now only if it reads back whole.
    uint16_t seq_read;
    uint8_t count_read;
    if (area_valid(area, seq_read, count_read)) {
        area_ = area;
        sequence_ = sequence;
        count_ = count;
    }
}

}  // namespace mission
