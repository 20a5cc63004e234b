// SPDX-License-Identifier: GPL-3.0-or-later
// Settings in the ATmega2560's EEPROM through a simulated power cycle (apm25sim --eeprom):
// `save` then a new run from the same chip brings the settings back; a flipped byte, a
// half-written slot, a record of another version or a first save cut short by power loss
// give the defaults and a message, never garbage; a slot cut short beside a whole one
// gives the whole one's settings. A board upgraded from the firmware before the slots
// (one record at address 0) keeps its settings. The second record (the vehicle settings,
// lib/Settings/VehicleRecord.h) pairs with the first: a power cut at any instant of a save
// leaves both of the save before or both new ones; a board saved by a firmware without it
// keeps the first and says so. The chips are built on the host with the firmware's own
// settings::encode, slots::encode and record2::encode (lib/Settings), not from fixed offsets.
#include <cstring>
#include <map>

#include "Params.h"
#include "RecordSlots.h"
#include "Settings.h"
#include "VehicleRecord.h"
#include "e2e_support.h"

namespace {

using settings::kRecordSize;

const char* const kDefaultsLine = "# settings: rate 50 Hz, decl 0.00 deg, mode plot, compass cal none";

std::string eeprom_path(const std::string& name) {
    const std::string path = e2e::work_dir() + "/eeprom_" + name + "." + std::to_string(getpid()) + ".bin";
    unlink(path.c_str());
    return path;
}

// A 4096-byte chip, erased but for `bytes` at `address`.
void write_chip(const std::string& path, const std::vector<std::pair<uint16_t, std::vector<uint8_t>>>& parts) {
    std::string chip(4096, '\xFF');
    for (const auto& part : parts)
        for (size_t i = 0; i < part.second.size(); ++i) chip[part.first + i] = (char)part.second[i];
    std::ofstream(path, std::ios::binary) << chip;
}

// The slot `slot` of the chip file (empty when the file is short).
std::vector<uint8_t> read_slot(const std::string& path, uint8_t slot) {
    const std::string chip = e2e::read_text(path);
    const uint16_t at = slots::slot_address(slot);
    if (chip.size() < at + slots::kSlotSize) return {};
    return std::vector<uint8_t>(chip.begin() + at, chip.begin() + at + slots::kSlotSize);
}

// What the firmware's load (the same lib/Console code) makes of the chip file.
std::string g_chip_bytes;
void read_chip_bytes(uint16_t address, uint8_t* out, uint16_t n) {
    for (uint16_t i = 0; i < n; ++i) out[i] = address + i < g_chip_bytes.size() ? (uint8_t)g_chip_bytes[address + i] : 0xFFu;
}
slots::Loaded load_chip(const std::string& path, settings::Settings& s) {
    g_chip_bytes = e2e::read_text(path);
    return slots::load(read_chip_bytes, s);
}

std::vector<uint8_t> encoded(const settings::Settings& s) {
    std::vector<uint8_t> r(kRecordSize);
    settings::encode(s, r.data());
    return r;
}

// A slot holding `record` with `sequence`, as the firmware writes it.
std::vector<uint8_t> slot_of(const std::vector<uint8_t>& record, uint16_t sequence) {
    std::vector<uint8_t> slot(slots::kSlotSize);
    slots::encode(record.data(), sequence, slot.data());
    return slot;
}

// The second record's slot of `s` paired with the first record's slot of `sequence`.
std::vector<uint8_t> slot2_of(const settings::Settings& s, uint16_t sequence) {
    std::vector<uint8_t> slot(record2::slot_size((uint8_t)params::vehicle_bytes()));
    record2::encode(s, sequence, slot.data());
    return slot;
}

// Both records' bytes, the first's and the vehicle settings': what a start must give
// wholly from one save.
std::vector<uint8_t> pair_of(const settings::Settings& s) {
    std::vector<uint8_t> bytes = encoded(s);
    const uint8_t n = (uint8_t)params::vehicle_bytes();
    bytes.resize(kRecordSize + n);
    params::vehicle_part(s, 0, n, bytes.data() + kRecordSize);
    return bytes;
}

// A slot's bytes padded to kMaxSlotSize for slots::inspect.
std::vector<uint8_t> slot_bytes(std::vector<uint8_t> slot) {
    slot.resize(slots::kMaxSlotSize, 0xFF);
    return slot;
}

settings::Settings stored_sample() {
    settings::Settings s = settings::defaults();
    s.rate_hz = 25;
    settings::set_declination_centideg(s, 850);
    s.mode = fmt::OutputMode::Csv;
    return s;
}

const e2e::Line* find_line(const std::vector<e2e::Line>& lines, const std::string& text) {
    for (const e2e::Line& l : lines)
        if (l.text.find(text) != std::string::npos) return &l;
    return nullptr;
}

// The start-up of the firmware on `chip`: 0.5 s is past the banner and the settings line.
e2e::SimRun boot(const std::string& chip) { return e2e::run_sim(e2e::firmware_elf(), "rest", 0.5, "--eeprom " + chip); }

// Defaults in force and said so: a "# warn: EEPROM ...: default settings" line, then the
// defaults' settings line; never "settings loaded".
void expect_defaults_and_message(const e2e::SimRun& run, const std::string& why) {
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const e2e::Line* warn = e2e::find_report(run.lines, "# warn:", {"EEPROM"});
    ASSERT_TRUE(warn) << why << "\n" << e2e::dump(run);
    EXPECT_NE(warn->text.find("default settings"), std::string::npos) << why << ": " << warn->text;
    EXPECT_TRUE(find_line(run.lines, kDefaultsLine)) << why << "\n" << e2e::dump(run);
    EXPECT_FALSE(find_line(run.lines, "settings loaded")) << why << "\n" << e2e::dump(run);
}

TEST(Eeprom, SavedSettingsSurviveAPowerCycle) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::string chip = eeprom_path("save");
    const std::string input = e2e::input_file(
        "eeprom_save", "rate 25\r\ndecl 8.5\r\nmode csv\r\nset ARMING_REQUIRE 0\r\nset COMPASS_DEC 0.2\r\nsave\r\n");
    const e2e::SimRun first = e2e::run_sim(e2e::firmware_elf(), "rest", 3.0, "--eeprom " + chip + " --input " + input);
    unlink(input.c_str());
    ASSERT_EQ(first.result.exit_code, 0) << e2e::dump(first);
    EXPECT_TRUE(find_line(first.lines, "EEPROM blank")) << e2e::dump(first);
    ASSERT_TRUE(find_line(first.lines, "# saved")) << e2e::dump(first, 200);

    // The chip holds, in its first slot, the record the host library encodes for these
    // settings; the firmware's load (the same code on the host) finds it.
    settings::Settings on_chip;
    const std::vector<uint8_t> slot = read_slot(chip, 0);
    ASSERT_EQ(slot.size(), slots::kSlotSize);
    EXPECT_EQ(slots::inspect(slot_bytes(slot).data()).state, slots::SlotState::Valid);
    EXPECT_EQ(slots::inspect(slot_bytes(slot).data()).sequence, 1);
    const slots::Loaded loaded = load_chip(chip, on_chip);
    ASSERT_EQ(loaded.result, settings::LoadResult::Ok);
    EXPECT_FALSE(loaded.from_legacy);
    EXPECT_EQ(on_chip.rate_hz, 25);
    EXPECT_EQ(on_chip.mode, fmt::OutputMode::Csv);
    // The second record beside it, of the same save: ARMING_REQUIRE and COMPASS_DEC as set
    // (the float sent; the first record keeps its hundredths).
    EXPECT_EQ(loaded.vehicle, record2::Result::Paired);
    EXPECT_EQ(on_chip.vehicle.arming_require, 0);
    EXPECT_EQ(on_chip.declination_rad(), 0.2f);
    EXPECT_EQ(on_chip.declination_centideg, 1146);

    // Power cycle: the next run starts from the same chip.
    const std::string gets = e2e::input_file("eeprom_get", "get ARMING_REQUIRE\r\nget COMPASS_DEC\r\n");
    const e2e::SimRun second =
        e2e::run_sim(e2e::firmware_elf(), "rest", 2.5, "--eeprom " + chip + " --input " + gets + " --input-at 2.0");
    unlink(gets.c_str());
    ASSERT_EQ(second.result.exit_code, 0) << e2e::dump(second);
    EXPECT_TRUE(find_line(second.lines, "# settings loaded from EEPROM")) << e2e::dump(second);
    EXPECT_FALSE(find_line(second.lines, "earlier firmware")) << e2e::dump(second);
    EXPECT_TRUE(find_line(second.lines, "# settings: rate 25 Hz, decl 11.46 deg, mode csv")) << e2e::dump(second);
    EXPECT_TRUE(find_line(second.lines, "# ARMING_REQUIRE 0")) << e2e::dump(second, 200);
    EXPECT_TRUE(find_line(second.lines, "# COMPASS_DEC 0.2000")) << e2e::dump(second, 200);
    // In force: csv rows at 25 Hz after the header.
    EXPECT_TRUE(find_line(second.lines, "t_ms,roll,pitch,yaw")) << e2e::dump(second);
    int rows = 0;
    for (const e2e::Line& l : second.lines)
        if (l.t_s >= 1.5 && l.t_s < 2.5 && !l.text.empty() && l.text[0] >= '0' && l.text[0] <= '9') ++rows;
    EXPECT_NEAR(rows, 25, 2) << e2e::dump(second, 200);
    unlink(chip.c_str());
}

// A flipped byte in the only slot: the slot's CRC fails it.
TEST(Eeprom, FlippedByteGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::vector<uint8_t> good = slot_of(encoded(stored_sample()), 1);
    // The first byte, one in the middle of the record, the last (the slot CRC's high byte).
    for (const size_t i : {size_t{0}, size_t{slots::kSlotSize / 2}, size_t{slots::kSlotSize - 1}}) {
        std::vector<uint8_t> bad = good;
        bad[i] = (uint8_t)(bad[i] ^ 0x10u);
        const std::string chip = eeprom_path("flip");
        write_chip(chip, {{slots::slot_address(0), bad}});
        settings::Settings s;
        ASSERT_NE(load_chip(chip, s).result, settings::LoadResult::Ok) << i;  // the premise
        expect_defaults_and_message(boot(chip), "byte " + std::to_string(i) + " flipped");
        unlink(chip.c_str());
    }
}

// A save interrupted half way (the firmware writes a slot byte by byte from the start):
// over an erased chip, the defaults and a message; beside a whole slot with the settings
// before, those settings and a word that the last save was cut.
TEST(Eeprom, HalfWrittenSlotGivesThePreviousSettingsOrDefaults) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    settings::Settings old_settings = settings::defaults();
    old_settings.rate_hz = 10;
    settings::set_declination_centideg(old_settings, -4500);
    const std::vector<uint8_t> old_slot = slot_of(encoded(old_settings), 4);
    const std::vector<uint8_t> new_slot = slot_of(encoded(stored_sample()), 5);
    std::vector<uint8_t> half(new_slot.begin(), new_slot.begin() + (long)(slots::kSlotSize / 2));
    const std::string chip = eeprom_path("half");
    write_chip(chip, {{slots::slot_address(0), half}});
    expect_defaults_and_message(boot(chip), "half a slot on an erased chip");

    // The new slot half over an older record (what the firmware overwrites: not the newest).
    std::vector<uint8_t> over_older = slot_of(encoded(settings::defaults()), 3);
    std::copy(half.begin(), half.end(), over_older.begin());
    write_chip(chip, {{slots::slot_address(0), over_older}, {slots::slot_address(1), old_slot}});
    const e2e::SimRun run = boot(chip);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, "# warn: the last save to EEPROM was cut short")) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, "# settings loaded from EEPROM")) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, "# settings: rate 10 Hz, decl -45.00 deg, mode plot")) << e2e::dump(run);
    unlink(chip.c_str());
}

// A record with another version byte and a CRC right for it. The version's place is the
// one the record's own layout gives (Settings.h: magic, magic, version).
std::vector<uint8_t> record_of_version(uint8_t version) {
    std::vector<uint8_t> rec = encoded(stored_sample());
    const size_t version_at = 2;
    EXPECT_EQ(rec[0], settings::kMagic0);
    EXPECT_EQ(rec[1], settings::kMagic1);
    EXPECT_EQ(rec[version_at], settings::kSettingsVersion);
    rec[version_at] = version;
    const uint16_t crc = settings::crc16(rec.data(), (uint16_t)(kRecordSize - 2u));
    rec[kRecordSize - 2] = (uint8_t)(crc & 0xFFu);
    rec[kRecordSize - 1] = (uint8_t)(crc >> 8);
    return rec;
}

// A record that another firmware version wrote into a slot.
TEST(Eeprom, RecordOfAnotherVersionGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::vector<uint8_t> rec = record_of_version((uint8_t)(settings::kSettingsVersion - 1u));
    settings::Settings s;
    ASSERT_EQ(settings::decode(rec.data(), s), settings::LoadResult::OldVersion);
    const std::string chip = eeprom_path("version");
    write_chip(chip, {{slots::slot_address(0), slot_of(rec, 1)}});
    const e2e::SimRun run = boot(chip);
    expect_defaults_and_message(run, "older version");
    EXPECT_TRUE(find_line(run.lines, "another version")) << e2e::dump(run);
    unlink(chip.c_str());
}

// A board saved by a firmware before the second record: its first record loads, the
// vehicle settings take their defaults and the start says so once; COMPASS_DEC is the
// first record's hundredths. A second record of another version: the same, with a warning.
TEST(Eeprom, FirstRecordWithoutItsSecondLoadsAndSaysSo) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    settings::Settings saved = stored_sample();  // rate 25, decl 8.50, mode csv
    saved.vehicle.arming_require = 0;
    std::vector<uint8_t> other_version = slot2_of(saved, 1);
    other_version[2] = (uint8_t)(record2::kVersion + 1u);  // VehicleRecord.h: magic, magic, version
    const uint16_t crc = settings::crc16(other_version.data(), (uint16_t)(other_version.size() - 2u));
    other_version[other_version.size() - 2] = (uint8_t)(crc & 0xFFu);
    other_version[other_version.size() - 1] = (uint8_t)(crc >> 8);
    struct Case {
        const char* what;
        std::vector<uint8_t> second;  // at the second record's slot 0 (empty: none)
        record2::Result result;
        const char* said;
    };
    const Case cases[] = {
        {"no second record", {}, record2::Result::Missing,
         "# settings: saved by an earlier firmware: the newer parameters at their defaults (save to keep)"},
        {"second record of another version", other_version, record2::Result::OldVersion,
         "# warn: EEPROM second record from another version: its parameters at their defaults"},
        {"second record of another save", slot2_of(saved, 2), record2::Result::Missing,
         "# settings: saved by an earlier firmware"},
    };
    for (const Case& c : cases) {
        const std::string chip = eeprom_path("first_only");
        std::vector<std::pair<uint16_t, std::vector<uint8_t>>> parts = {{slots::slot_address(0), slot_of(encoded(saved), 1)}};
        if (!c.second.empty()) parts.push_back({record2::slot_address(0), c.second});
        write_chip(chip, parts);
        settings::Settings s;
        const slots::Loaded l = load_chip(chip, s);
        ASSERT_EQ(l.result, settings::LoadResult::Ok) << c.what;
        EXPECT_EQ(l.vehicle, c.result) << c.what;
        const std::string gets = e2e::input_file("first_only", "get ARMING_REQUIRE\r\nget COMPASS_DEC\r\n");
        const e2e::SimRun run =
            e2e::run_sim(e2e::firmware_elf(), "rest", 2.2, "--eeprom " + chip + " --input " + gets + " --input-at 2.0");
        unlink(gets.c_str());
        ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        EXPECT_TRUE(find_line(run.lines, "# settings loaded from EEPROM")) << c.what << "\n" << e2e::dump(run);
        EXPECT_TRUE(find_line(run.lines, "# settings: rate 25 Hz, decl 8.50 deg, mode csv")) << c.what;
        int said = 0;
        for (const e2e::Line& line : run.lines) said += line.text.find(c.said) == 0 ? 1 : 0;
        EXPECT_EQ(said, 1) << c.what << "\n" << e2e::dump(run);
        EXPECT_TRUE(find_line(run.lines, "# ARMING_REQUIRE 1")) << c.what << "\n" << e2e::dump(run, 200);
        EXPECT_TRUE(find_line(run.lines, "# COMPASS_DEC 0.1484")) << c.what << "\n" << e2e::dump(run, 200);  // 8.5 deg
        unlink(chip.c_str());
    }
}

// A board upgraded from the firmware before the slots: its one record at address 0, of
// version 2. Loaded while the record is still of version 2 here; once the record's
// version is another, refused with a message, never misread. A save then writes a slot.
TEST(Eeprom, UpgradedBoardsSingleVersion2Record) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const uint8_t kSingleRecordVersion = 2;
    const std::string chip = eeprom_path("upgrade");
    write_chip(chip, {{settings::kEepromAddress, record_of_version(kSingleRecordVersion)}});
    const e2e::SimRun run = boot(chip);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    if (settings::kSettingsVersion == kSingleRecordVersion) {
        EXPECT_TRUE(find_line(run.lines, "# settings loaded from EEPROM (an earlier firmware's record)")) << e2e::dump(run);
        EXPECT_TRUE(find_line(run.lines, "# settings: rate 25 Hz, decl 8.50 deg, mode csv")) << e2e::dump(run);
    } else {
        expect_defaults_and_message(run, "version 2 record");
        EXPECT_TRUE(find_line(run.lines, "another version")) << e2e::dump(run);
    }
    unlink(chip.c_str());
}

// The power goes while the first `save` writes (the end of the run is the power cut):
// from an erased chip, a part of the slot is on it, and the next start says so and uses
// the defaults.
TEST(Eeprom, PowerCutDuringFirstSaveGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::string text = "rate 25\r\ndecl 8.5\r\nsave\r\n";
    const std::string input = e2e::input_file("eeprom_cut", text);
    // When does the save start? (simavr is deterministic: the same run twice is the same.)
    const std::string probe_chip = eeprom_path("cut_probe");
    const e2e::SimRun whole = e2e::run_sim(e2e::firmware_elf(), "rest", 3.0, "--eeprom " + probe_chip + " --input " + input);
    const e2e::Line* saving = find_line(whole.lines, "# saving to EEPROM");
    const e2e::Line* saved = find_line(whole.lines, "# saved");
    ASSERT_TRUE(saving && saved) << e2e::dump(whole, 200);
    ASSERT_GT(saved->t_s - saving->t_s, 0.03) << "the save is too quick to cut";
    const double cut_s = 0.5 * (saving->t_s + saved->t_s);
    const std::string chip = eeprom_path("cut");
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.6f", cut_s);
    const e2e::CommandResult cut = e2e::run_command(e2e::tool("apm25sim") + " --elf " + e2e::firmware_elf() +
                                                    " --trajectory " + e2e::scenario_csv("rest", 3.0) + " --seconds " +
                                                    seconds + " --eeprom " + chip + " --input " + input);
    unlink(input.c_str());
    ASSERT_EQ(cut.exit_code, 0) << cut.err;
    const std::vector<uint8_t> partial = read_slot(chip, 0);
    ASSERT_EQ(partial.size(), slots::kSlotSize);
    settings::Settings s;
    EXPECT_NE(load_chip(chip, s).result, settings::LoadResult::Ok);
    EXPECT_NE(partial, std::vector<uint8_t>(slots::kSlotSize, 0xFF)) << "nothing was written before the cut";
    expect_defaults_and_message(boot(chip), "save cut at " + std::string(seconds) + " s");
    unlink(chip.c_str());
    unlink(probe_chip.c_str());
}

// --- a power cut at every 1 ms across a save ------------------------------------------

// The "# settings: ..." line a start prints, and whether it said the settings were loaded.
struct Boot {
    std::string settings_line;
    bool loaded = false;
};
// 60 ms: the start-up's lines leave by ~55 ms (millis() starts at pipeline::kBootMs, 10 ms
// after reset: firmware/StartTime.cpp).
Boot boot_line(const std::string& chip) {
    // 0.4 s: past the settings line: the start reads and checks both records (~50 ms) before the
    // MPU6000 is due, so the line finishes in the waits that follow, by the loop at 0.35 s.
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 0.4, "--eeprom " + chip);
    Boot b;
    EXPECT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const e2e::Line* line = find_line(run.lines, "# settings: rate");
    if (line) b.settings_line = line->text;
    EXPECT_TRUE(line) << chip << "\n" << e2e::dump(run);
    b.loaded = find_line(run.lines, "# settings loaded from EEPROM") != nullptr;
    return b;
}

struct SweepResult {
    int cuts = 0, cuts_during_save = 0, distinct_chips = 0, old_boots = 0, new_boots = 0;
    double saving_s = 0.0;                 // when "# saving to EEPROM" came
    std::vector<e2e::Line> lines;          // the run's output
    settings::Settings before, after;      // the chip's settings before and after the save
};

// One simavr run from the chip `start` that types `input` (at input_at_s) ending with a
// save; apm25sim --eeprom-cuts writes the chip as a power cut at every 1 ms from from_s
// to to_s leaves it. Every cut must start with the settings before the save or those
// after it, whole: the firmware's own load, run on the host, gives both records of one
// of the two saves byte for byte (never the first record of one and the second of the
// other), and a start in simavr prints that one's settings line and "settings loaded". Chips alike give the same start (simavr is deterministic): each
// distinct one is started once.
SweepResult sweep(const std::string& name, const std::string& csv, double seconds, const std::string& input_text,
                  double input_at_s, const std::vector<std::pair<uint16_t, std::vector<uint8_t>>>& start, double from_s,
                  double to_s) {
    SweepResult r;
    const std::string chip = eeprom_path(name);
    write_chip(chip, start);
    settings::Settings old_settings, new_settings;
    slots::Loaded l = load_chip(chip, old_settings);
    EXPECT_EQ(l.result, settings::LoadResult::Ok);
    EXPECT_EQ(l.vehicle, record2::Result::Paired);
    const Boot old_boot = boot_line(chip);
    EXPECT_TRUE(old_boot.loaded);

    const std::string input = e2e::input_file(name, input_text);
    char window[96];
    std::snprintf(window, sizeof window, " --eeprom-cuts %.3f:%.3f:0.001 --input-at %.3f", from_s, to_s, input_at_s);
    const e2e::SimRun run = e2e::run_sim_file(e2e::firmware_elf(), csv, seconds,
                                              "--eeprom " + chip + " --input " + input + window);
    unlink(input.c_str());
    EXPECT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const e2e::Line* saving = find_line(run.lines, "# saving to EEPROM");
    const e2e::Line* saved = find_line(run.lines, "# saved");
    EXPECT_TRUE(saving && saved) << e2e::dump(run, 400);
    r.lines = run.lines;
    if (!saving || !saved) return r;
    r.saving_s = saving->t_s;
    EXPECT_GT(saving->t_s, from_s + 0.01) << "the cuts begin before the save";
    EXPECT_LT(saved->t_s, to_s - 0.01) << "the cuts end before the save has ended";
    l = load_chip(chip, new_settings);
    EXPECT_EQ(l.result, settings::LoadResult::Ok);
    EXPECT_EQ(l.vehicle, record2::Result::Paired);
    const std::vector<uint8_t> old_record = pair_of(old_settings), new_record = pair_of(new_settings);
    // The save changes both records.
    EXPECT_NE(encoded(old_settings), encoded(new_settings));
    EXPECT_NE(std::vector<uint8_t>(old_record.begin() + kRecordSize, old_record.end()),
              std::vector<uint8_t>(new_record.begin() + kRecordSize, new_record.end()));
    const Boot new_boot = boot_line(chip);
    EXPECT_TRUE(new_boot.loaded);
    EXPECT_NE(old_boot.settings_line, new_boot.settings_line) << "the starts must tell the two apart";
    std::printf("# %s: save from %.4f to %.4f s; before: %s; after: %s\n", name.c_str(), saving->t_s, saved->t_s,
                old_boot.settings_line.c_str(), new_boot.settings_line.c_str());

    std::map<std::string, bool> is_new_of_chip;  // distinct chip -> booted with the new settings
    const int expected_cuts = (int)std::lround((to_s - from_s) / 0.001) + 1;
    for (int k = 0;; ++k) {
        const std::string cut_path = chip + ".cut" + std::to_string(k);
        if (!e2e::file_exists(cut_path)) break;
        ++r.cuts;
        const double t_s = from_s + 0.001 * k;
        const std::string bytes = e2e::read_text(cut_path);
        auto known = is_new_of_chip.find(bytes);
        if (known == is_new_of_chip.end()) {
            settings::Settings s;
            const slots::Loaded cut_load = load_chip(cut_path, s);
            EXPECT_EQ(cut_load.result, settings::LoadResult::Ok) << "cut at " << t_s;
            EXPECT_EQ(cut_load.vehicle, record2::Result::Paired) << "cut at " << t_s;
            const std::vector<uint8_t> rec = pair_of(s);
            const bool is_new = rec == new_record;
            EXPECT_TRUE(is_new || rec == old_record) << "cut at " << t_s << ": neither pair";
            const Boot b = boot_line(cut_path);
            EXPECT_TRUE(b.loaded) << "cut at " << t_s;
            EXPECT_EQ(b.settings_line, is_new ? new_boot.settings_line : old_boot.settings_line) << "cut at " << t_s;
            known = is_new_of_chip.emplace(bytes, is_new).first;
        }
        (known->second ? r.new_boots : r.old_boots)++;
        if (t_s < saving->t_s) EXPECT_FALSE(known->second) << "cut at " << t_s;
        if (t_s > saved->t_s) EXPECT_TRUE(known->second) << "cut at " << t_s;
        if (t_s >= saving->t_s && t_s <= saved->t_s) ++r.cuts_during_save;
        unlink(cut_path.c_str());
    }
    r.distinct_chips = (int)is_new_of_chip.size();
    r.before = old_settings;
    r.after = new_settings;
    EXPECT_EQ(r.cuts, expected_cuts);
    std::printf("# %s: %d cuts (%d during the save), %d distinct chips started: %d old, %d new settings\n",
                name.c_str(), r.cuts, r.cuts_during_save, r.distinct_chips, r.old_boots, r.new_boots);
    unlink(chip.c_str());
    return r;
}

settings::Settings numbered_settings(uint8_t n, bool mag_cal) {
    settings::Settings s = settings::defaults();
    s.rate_hz = (uint8_t)(10 + n);
    settings::set_declination_centideg(s, (int16_t)(-2000 + 333 * n));
    s.vehicle.arming_require = (uint8_t)(n % 2);
    if (mag_cal) {
        s.flags = settings::kFlagMagCalibrated;
        s.cal.mag_offset_uT = linalg::Vector3f(2.5f * n, -1.25f * n, 4.0f);
        s.cal.mag_scale = linalg::Vector3f(1.02f, 0.99f, 0.99f);
        s.cal.mag_cross = linalg::Vector3f(0.01f, -0.005f, 0.002f);
    }
    return s;
}

// `save` of settings changed in both records (the rate and mode in the first,
// ARMING_REQUIRE in the second, the declination in both), with both pairs whole (the
// older one is written over).
TEST(Eeprom, PowerCutAtEveryMillisecondOfASettingsSave) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const SweepResult r = sweep(
        "sweep_settings", e2e::scenario_csv("rest", 2.1), 2.1,
        "rate 40\r\ndecl -3\r\nmode csv\r\nset ARMING_REQUIRE 1\r\nsave\r\n", 1.4,
        {{slots::slot_address(0), slot_of(encoded(numbered_settings(1, false)), 7)},
         {record2::slot_address(0), slot2_of(numbered_settings(1, false), 7)},
         {slots::slot_address(1), slot_of(encoded(numbered_settings(2, true)), 8)},
         {record2::slot_address(1), slot2_of(numbered_settings(2, true), 8)}},
        1.35, 2.05);
    EXPECT_EQ(r.before.vehicle.arming_require, 0);
    EXPECT_EQ(r.after.vehicle.arming_require, 1);
    // The slot's changed bytes at 3.4 ms each.
    EXPECT_GE(r.cuts_during_save, 100);
    EXPECT_GT(r.old_boots, 0);
    EXPECT_GT(r.new_boots, 0);
}

// `cal mag` on a tumble, then `save`: the calibration's floats all change. The console
// waits through the 30 s of turning on empty lines (ignored) before the declination and
// the save (the characters come a little slower than the baud rate: the save starts near
// 36.15 s and ends near 36.69 s, the second record's 102 bytes: the cuts go on to 36.77 s,
// past its end whatever a pass more or less on the way there).
TEST(Eeprom, PowerCutAtEveryMillisecondOfACompassCalibrationSave) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const double input_at_s = 5.5, char_s = 10.0 / 115200.0;
    std::string text = "cal mag\r\n";
    text += std::string((size_t)(28.4 / char_s), '\r');  // past the fit's result (35.5 s)
    text += "decl 12.5\r\nsave\r\n";
    const SweepResult r = sweep("sweep_cal_mag", e2e::scenario_csv("tumble", 37.0), 36.8, text, input_at_s,
                                {{slots::slot_address(1), slot_of(encoded(numbered_settings(3, true)), 3)},
                                 {record2::slot_address(1), slot2_of(numbered_settings(3, true), 3)},
                                 {slots::slot_address(0), slot_of(encoded(numbered_settings(4, false)), 2)},
                                 {record2::slot_address(0), slot2_of(numbered_settings(4, false), 2)}},
                                35.8, 36.77);
    // The save is the new calibration's: the fit's verdict came before it.
    const e2e::Line* fit = find_line(r.lines, "# cal mag: offset");
    ASSERT_TRUE(fit) << "no cal mag result";
    EXPECT_LT(fit->t_s, r.saving_s);
    EXPECT_FALSE(r.after.cal.mag_offset_uT == r.before.cal.mag_offset_uT);
    EXPECT_FALSE(r.after.cal.mag_scale == r.before.cal.mag_scale);
    EXPECT_GE(r.cuts_during_save, 100);
    EXPECT_GT(r.old_boots, 0);
    EXPECT_GT(r.new_boots, 0);
}

}  // namespace

// The pre-arm check "settings loaded" (docs/arming.md): a board running on defaults
// because its record was unreadable refuses `arm` with the reason; a blank chip (a new
// board's defaults) does not give it (the receiver's absence is the other reason both say).
TEST(Eeprom, UnreadableRecordRefusesArmingBlankDoesNot) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    std::vector<uint8_t> bad = slot_of(encoded(stored_sample()), 1);
    bad[slots::kSlotSize / 2] = (uint8_t)(bad[slots::kSlotSize / 2] ^ 0x10u);
    const std::string chip = eeprom_path("arm_flip");
    write_chip(chip, {{slots::slot_address(0), bad}});
    const std::string input = e2e::input_file("arm", "arm\n");
    const std::string kReason = "# PreArm: Settings are defaults (EEPROM unreadable)";
    e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 2.5, "--eeprom " + chip + " --input " + input);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, "# PreArm: RC not found")) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, kReason)) << e2e::dump(run);
    EXPECT_FALSE(find_line(run.lines, "# Throttle armed")) << e2e::dump(run);
    unlink(chip.c_str());
    const std::string blank = eeprom_path("arm_blank");
    run = e2e::run_sim(e2e::firmware_elf(), "rest", 2.5, "--eeprom " + blank + " --input " + input);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_TRUE(find_line(run.lines, "# PreArm: RC not found")) << e2e::dump(run);
    EXPECT_FALSE(find_line(run.lines, kReason)) << e2e::dump(run);
    unlink(blank.c_str());
    unlink(input.c_str());
}
