// SPDX-License-Identifier: GPL-3.0-or-later
// The settings in the ATmega2560's EEPROM: the first record (lib/Settings/Settings.h) in two
// slots (lib/Settings/RecordSlots.h) and the second, the vehicle settings, in two slots of
// its own paired with them (lib/Settings/VehicleRecord.h): a power cut during `save`
// leaves both records of the save before, or both new ones.
//
// Loading happens once at start. Saving writes one byte per loop iteration while the
// EEPROM is ready (a byte takes 3.4 ms to program: writing all of them at once would
// stall the loop for ~1 s), in this order, each step a loop iteration or more:
//   1. the second record's slot (the one beside the first record's slot not holding the
//      newest), with the sequence the first record's slot is about to get; read back;
//   2. the first record's slot, its CRC last; read back; "# saved".
// The first slot's CRC makes the new pair the one a start loads; a second record that did
// not verify stops the save before the first slot is touched. No copy of a record is kept
// (RAM): each byte is encoded from the live settings when it is written, and the CRCs run
// along. Each record's CRC is noted before its slot is written (the second's at `save`, in
// one walk of the parameter table; the first's a part a pass, as its write encodes it), and
// the second's checked against the live settings again before the first slot's CRC: if a
// setting changed meanwhile, the save starts again (of the settings then) before that
// CRC is written, so the pair is the settings of one instant. No pass takes more than one
// walk of the parameter table.
#pragma once

#include <stdint.h>

#include "RecordSlots.h"
#include "Settings.h"
#include "Text.h"

class SettingsStore {
public:
    explicit constexpr SettingsStore(const text::Sink* out) : out_(out), part_{} {}  // no start-up code

    // Reads the newer valid slot (or, with none, an earlier firmware's single record) and
    // the second record paired with it into `s` (defaults when blank, corrupted, or from
    // another version) and says which.
    void load(settings::Settings& s);
    // Starts writing `s`, which must stay alive (the pipeline's settings): a change to it
    // before the save's end starts the save again.
    void start_save(const settings::Settings& s);
    // Every loop iteration: the next byte, or a part of a verification or of a CRC's note.
    void service();
    // A save is under way (a reboot waits for its end).
    bool busy() const { return stage_ != kIdle; }
    // The settings in use are the user's: loaded, or the EEPROM blank (a new board's
    // defaults), or saved since; false while the board runs on defaults because the
    // record was unreadable (corrupt, another firmware's, out of range): the pre-arm
    // check "Settings not loaded" until the user saves.
    bool settings_loaded() const { return settings_loaded_; }

private:
    enum Stage : uint8_t {
        kIdle,
        kWriteSecond,   // the second record's slot, byte index_
        kVerifySecond,  // ... read back
        kNoteFirst,     // the first record's slot CRC noted, a part a pass
        kWriteFirst,    // the first record's slot up to its CRC
        kCheckSecond,   // the second record still the live settings' (a pass)
        kCommitFirst,   // the first record's slot CRC
        kVerifyFirst,   // ... read back
    };
    using Part = void (*)(const settings::Settings&, uint8_t from, uint8_t n, uint8_t* out);
    // The second record's slot CRC noted: writing it from byte 0.
    void begin();
    // A stage from its first byte, the running CRCs and the part anew.
    void start(Stage stage);
    uint8_t second_byte();
    uint8_t first_byte();
    // Byte i (< end) of a record's values, encoded a part at a time by `part`.
    uint8_t part_byte(Part part, uint8_t i, uint8_t end);
    // Reads a part of the slot at `address` back; 0 until its end, then 1 when its
    // `covered` bytes and its stored CRC are `expected`'s, else 2.
    uint8_t verify_some(uint16_t address, uint16_t covered, uint16_t expected);
    void written(uint16_t size, Stage next);

    const text::Sink* out_;
    const settings::Settings* source_ = nullptr;
    Stage stage_ = kIdle;
    uint8_t write_slot_ = 0;       // both records' slot the save writes
    uint8_t vehicle_bytes_ = 0;    // the second record's payload: params::vehicle_bytes()
    uint16_t index_ = 0;           // the next byte of the slot the stage writes or reads
    uint16_t expected_crc_ = 0;    // the first record's slot CRC, noted at kNoteFirst
    uint16_t expected2_crc_ = 0;   // the second record's slot CRC, noted at `save`
    uint16_t record_crc_ = 0;      // the running CRCs of the bytes written (or read back)
    uint16_t slot_crc_ = 0;
    // The record's values from part_from_ on, encoded a part at a time (the parameter
    // table is walked once a part, not once a byte).
    static constexpr uint8_t kPartSize = 12;
    static constexpr uint8_t kNoteBytesPerPass = 4;
    uint8_t part_[kPartSize];
    uint8_t part_from_ = 0xFFu;
    uint16_t next_sequence_ = 1;
    bool settings_loaded_ = true;
};
