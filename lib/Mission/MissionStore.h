// SPDX-License-Identifier: GPL-3.0-or-later
// The mission in EEPROM, power-safe: two areas in the bytes kMissionStart..4095 (the
// settings live below, lib/Settings), each a header and kMaxCommands commands of
// kCommandBytes (MissionCommand.h):
//
//   area 0 at 1284, area 1 at 2690, kAreaSize 1406 bytes each:
//   offset 0  marker kMarker         written LAST: it commits the area
//          1  sequence              little-endian, one more than the area it supersedes
//          3  count                 commands (home, MAVLink's seq 0, is not stored)
//          4  CRC-16/CCITT-FALSE    of bytes 1..3 and the count's commands, little-endian
//          6  command 0 (seq 1), command 1 (seq 2), ...
//
// An upload writes the area NOT in use: begin_upload() erases its marker first, the
// commands go in as they arrive, and commit() writes the sequence, count and CRC, then the
// marker. The area in use is never written, so a power cut at any byte, or a ground
// station that stops half way, leaves it whole and current; the area half written has no
// marker (or, cut within the marker's byte, a garbage one, or a CRC that fails). At start
// the valid area with the newer sequence is the mission (serial-number arithmetic, as
// the settings' slots). Clearing the mission is committing an empty one.
//
// The EEPROM through two callbacks (the firmware: avr-libc's eeprom_read_byte and a
// write queue; host tests: an array that can lose power at any byte). The AVR takes
// ~3.4 ms to write a byte: a command is 14 bytes, 48 ms. A commit reads the area twice
// (its CRC, then the read-back): 2800 bytes for 100 commands, ~10 ms on the AVR, so the
// firmware commits in steps (set_stepped): each step reads at most kStepBytes.
#pragma once

#include <stdint.h>

#include "MissionCommand.h"

namespace mission {

constexpr uint16_t kMissionStart = 1284;
constexpr uint16_t kEepromSize = 4096;
constexpr uint8_t kMaxCommands = 100;
constexpr uint8_t kHeaderBytes = 6;
constexpr uint16_t kAreaSize = kHeaderBytes + (uint16_t)kMaxCommands * kCommandBytes;
constexpr uint8_t kMarker = 0xA5;
static_assert(kMissionStart + 2u * kAreaSize <= kEepromSize, "two mission areas fit the EEPROM");

struct Eeprom {
    void* ctx;
    uint8_t (*read)(void* ctx, uint16_t address);
    void (*write)(void* ctx, uint16_t address, uint8_t value);
};

constexpr uint16_t area_address(uint8_t area) { return (uint16_t)(kMissionStart + area * kAreaSize); }

class MissionStore {
public:
    // constexpr: a static store is initialised data, not start-up code.
    constexpr explicit MissionStore(Eeprom eeprom) : eeprom_(eeprom) {}

    // Finds the current area (at start); false when neither is valid (no mission).
    bool load();
    // Commands in the current mission (MAVLink's count is this + 1: home).
    uint8_t count() const { return count_; }
    // Command `index` (0 = MAVLink's seq 1); false past the end or for unreadable bytes.
    bool read(uint8_t index, Command& c) const;
    uint8_t current_area() const { return area_; }
    uint16_t sequence() const { return sequence_; }

    // An upload into the other area: begin, write each command (index 0 first), commit.
    // Until commit() the current mission is unchanged. begin_upload() again starts over.
    void begin_upload();
    void write(uint8_t index, const Command& c);
    // Makes the uploaded `count` commands (<= kMaxCommands) the mission. Stepped: only
    // starts the commit, commit_step() does it.
    void commit(uint8_t count);
    // The commit a step a call: the CRC kStepBytes at a time, the header, the marker, the
    // read-back kStepBytes at a time; true when done (or none runs). The same writes in
    // the same order as commit() at once; until done the mission before is current.
    bool commit_step();
    bool committing() const { return commit_ != Commit::kNone; }
    void set_stepped(bool stepped) { stepped_ = stepped; }
    static constexpr uint8_t kStepBytes = 64;

private:
    enum class Commit : uint8_t { kNone, kSum, kHeader, kMarker, kCheck };
    // CRC of sequence and count, then of the area's command bytes from..to.
    uint16_t crc_start(uint16_t sequence, uint8_t count) const;
    uint16_t crc_commands(uint16_t crc, uint8_t area, uint16_t from, uint16_t to) const;
    bool area_valid(uint8_t area, uint16_t& sequence, uint8_t& count) const;
    uint16_t area_crc(uint8_t area, uint16_t sequence, uint8_t count) const;
    uint8_t byte_at(uint16_t address) const { return eeprom_.read(eeprom_.ctx, address); }
    void put(uint16_t address, uint8_t v) { eeprom_.write(eeprom_.ctx, address, v); }

    Eeprom eeprom_;
    uint16_t sequence_ = 0;
    uint8_t count_ = 0;
    uint8_t area_ = 1;  // none valid: the first upload goes to area 0
    // The commit under way (stepped): its count, the command bytes summed, their CRC.
    Commit commit_ = Commit::kNone;
    bool stepped_ = false;
    uint8_t commit_count_ = 0;
    uint16_t commit_done_ = 0;
    uint16_t commit_crc_ = 0;
    uint16_t check_crc_ = 0;
};

}  // namespace mission
