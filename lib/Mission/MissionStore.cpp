// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionStore.h"

#include "RecordSlots.h"
#include "Settings.h"

namespace mission {

uint16_t MissionStore::crc_start(uint16_t sequence, uint8_t count) const {
    uint16_t crc = settings::kCrc16Init;
    crc = settings::crc16_update(crc, (uint8_t)(sequence & 0xFFu));
    crc = settings::crc16_update(crc, (uint8_t)(sequence >> 8));
    return settings::crc16_update(crc, count);
}

uint16_t MissionStore::crc_commands(uint16_t crc, uint8_t area, uint16_t from, uint16_t to) const {
    const uint16_t start = (uint16_t)(area_address(area) + kHeaderBytes);
    for (uint16_t i = from; i < to; ++i) crc = settings::crc16_update(crc, byte_at((uint16_t)(start + i)));
    return crc;
}

uint16_t MissionStore::area_crc(uint8_t area, uint16_t sequence, uint8_t count) const {
    return crc_commands(crc_start(sequence, count), area, 0, (uint16_t)count * kCommandBytes);
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
    commit_count_ = count;
    commit_done_ = 0;
    commit_crc_ = crc_start((uint16_t)(sequence_ + 1u), count);
    commit_ = Commit::kSum;
    if (!stepped_)
        while (!commit_step()) {}
}

bool MissionStore::commit_step() {
    const uint8_t area = (uint8_t)(1u - area_);
    const uint16_t a = area_address(area);
    const uint16_t sequence = (uint16_t)(sequence_ + 1u);
    const uint16_t n = (uint16_t)commit_count_ * kCommandBytes;
    switch (commit_) {
    case Commit::kNone: return true;
    case Commit::kHeader: {
        // The CRC over what the EEPROM holds (read back: a bad write fails it now, not at
        // the next start).
        const uint8_t header[kHeaderBytes - 1] = {(uint8_t)(sequence & 0xFFu), (uint8_t)(sequence >> 8), commit_count_,
                                                  (uint8_t)(commit_crc_ & 0xFFu), (uint8_t)(commit_crc_ >> 8)};
        for (uint8_t i = 0; i < kHeaderBytes - 1; ++i) put((uint16_t)(a + 1u + i), header[i]);
        commit_ = Commit::kMarker;
        return false;
    }
    case Commit::kMarker:
        put(a, kMarker);
        commit_ = Commit::kCheck;
        commit_done_ = 0;
        return false;
    default: break;
    }
    // kSum, kCheck: the commands' CRC, kStepBytes a step (the check's from a fresh start
    // over what the EEPROM holds now, against the CRC written).
    if (commit_done_ == 0 && commit_ == Commit::kCheck) check_crc_ = crc_start(sequence, commit_count_);
    uint16_t& crc = commit_ == Commit::kSum ? commit_crc_ : check_crc_;
    const uint16_t to = (uint16_t)(n - commit_done_ > kStepBytes ? commit_done_ + kStepBytes : n);
    crc = crc_commands(crc, area, commit_done_, to);
    commit_done_ = to;
    if (to < n) return false;
    if (commit_ == Commit::kSum) {
        commit_ = Commit::kHeader;
        return false;
    }
    commit_ = Commit::kNone;
    // In use now only if it reads back whole.
    const uint16_t stored_crc = (uint16_t)(byte_at((uint16_t)(a + 4)) | ((uint16_t)byte_at((uint16_t)(a + 5)) << 8));
    const uint16_t stored_seq = (uint16_t)(byte_at((uint16_t)(a + 1)) | ((uint16_t)byte_at((uint16_t)(a + 2)) << 8));
    if (byte_at(a) == kMarker && stored_seq == sequence && byte_at((uint16_t)(a + 3)) == commit_count_ &&
        stored_crc == check_crc_ && check_crc_ == commit_crc_) {
        area_ = area;
        sequence_ = sequence;
        count_ = commit_count_;
    }
    return true;
}

}  // namespace mission
