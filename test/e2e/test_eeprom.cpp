// SPDX-License-Identifier: GPL-3.0-or-later
// Settings in the ATmega2560's EEPROM through a simulated power cycle (apm25sim --eeprom):
// `save` then a new run from the same chip brings the settings back; a flipped byte, a
// half-written record, a record of another version or a save cut short by power loss
// give the defaults and a message, never garbage. The records are built on the host with
// the firmware's own settings::encode (lib/Console/Settings), not from fixed offsets.
#include <cstring>

#include "Settings.h"
#include "e2e_support.h"

namespace {

using settings::kRecordSize;

const char* const kDefaultsLine = "# settings: rate 50 Hz, decl 0.00 deg, mode plot, compass cal none";

std::string eeprom_path(const std::string& name) {
    const std::string path = e2e::work_dir() + "/eeprom_" + name + "." + std::to_string(getpid()) + ".bin";
    unlink(path.c_str());
    return path;
}

// A 4096-byte chip: `record` at settings::kEepromAddress, the rest erased.
void write_chip(const std::string& path, const std::vector<uint8_t>& record) {
    std::string chip(4096, '\xFF');
    for (size_t i = 0; i < record.size(); ++i) chip[settings::kEepromAddress + i] = (char)record[i];
    std::ofstream(path, std::ios::binary) << chip;
}

std::vector<uint8_t> read_record(const std::string& path) {
    const std::string chip = e2e::read_text(path);
    if (chip.size() < settings::kEepromAddress + kRecordSize) return {};
    return std::vector<uint8_t>(chip.begin() + settings::kEepromAddress,
                                chip.begin() + settings::kEepromAddress + kRecordSize);
}

std::vector<uint8_t> encoded(const settings::Settings& s) {
    std::vector<uint8_t> r(kRecordSize);
    settings::encode(s, r.data());
    return r;
}

settings::Settings stored_sample() {
    settings::Settings s = settings::defaults();
    s.rate_hz = 25;
    s.declination_centideg = 850;
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
    const std::string input = e2e::input_file("eeprom_save", "rate 25\r\ndecl 8.5\r\nmode csv\r\nsave\r\n");
    const e2e::SimRun first = e2e::run_sim(e2e::firmware_elf(), "rest", 3.0, "--eeprom " + chip + " --input " + input);
    unlink(input.c_str());
    ASSERT_EQ(first.result.exit_code, 0) << e2e::dump(first);
    EXPECT_TRUE(find_line(first.lines, "EEPROM blank")) << e2e::dump(first);
    ASSERT_TRUE(find_line(first.lines, "# saved")) << e2e::dump(first, 200);

    // The chip holds the record the host library encodes for these settings.
    settings::Settings on_chip;
    const std::vector<uint8_t> record = read_record(chip);
    ASSERT_EQ(record.size(), kRecordSize);
    ASSERT_EQ(settings::decode(record.data(), on_chip), settings::LoadResult::Ok);
    EXPECT_EQ(on_chip.rate_hz, 25);
    EXPECT_EQ(on_chip.declination_centideg, 850);
    EXPECT_EQ(on_chip.mode, fmt::OutputMode::Csv);

    // Power cycle: the next run starts from the same chip.
    const e2e::SimRun second = e2e::run_sim(e2e::firmware_elf(), "rest", 2.5, "--eeprom " + chip);
    ASSERT_EQ(second.result.exit_code, 0) << e2e::dump(second);
    EXPECT_TRUE(find_line(second.lines, "# settings loaded from EEPROM")) << e2e::dump(second);
    EXPECT_TRUE(find_line(second.lines, "# settings: rate 25 Hz, decl 8.50 deg, mode csv")) << e2e::dump(second);
    // In force: csv rows at 25 Hz after the header.
    EXPECT_TRUE(find_line(second.lines, "t_ms,roll,pitch,yaw")) << e2e::dump(second);
    int rows = 0;
    for (const e2e::Line& l : second.lines)
        if (l.t_s >= 1.5 && l.t_s < 2.5 && !l.text.empty() && l.text[0] >= '0' && l.text[0] <= '9') ++rows;
    EXPECT_NEAR(rows, 25, 2) << e2e::dump(second, 200);
    unlink(chip.c_str());
}

TEST(Eeprom, FlippedByteGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::vector<uint8_t> good = encoded(stored_sample());
    // The first byte, one in the middle of the payload, the last (the CRC's high byte).
    for (const size_t i : {size_t{0}, size_t{kRecordSize / 2}, size_t{kRecordSize - 1}}) {
        std::vector<uint8_t> bad = good;
        bad[i] = (uint8_t)(bad[i] ^ 0x10u);
        settings::Settings s;
        ASSERT_NE(settings::decode(bad.data(), s), settings::LoadResult::Ok) << i;  // the premise
        const std::string chip = eeprom_path("flip");
        write_chip(chip, bad);
        expect_defaults_and_message(boot(chip), "byte " + std::to_string(i) + " flipped");
        unlink(chip.c_str());
    }
}

// A save interrupted half way: the first half of the new record over the old one (the
// firmware writes byte by byte from the start), and over an erased chip.
TEST(Eeprom, HalfWrittenRecordGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    settings::Settings old_settings = settings::defaults();
    old_settings.rate_hz = 10;
    old_settings.declination_centideg = -4500;
    const std::vector<uint8_t> old_record = encoded(old_settings);
    const std::vector<uint8_t> new_record = encoded(stored_sample());
    const size_t half = kRecordSize / 2;
    std::vector<uint8_t> over_old = old_record, over_erased(kRecordSize, 0xFF);
    std::copy(new_record.begin(), new_record.begin() + (long)half, over_old.begin());
    std::copy(new_record.begin(), new_record.begin() + (long)half, over_erased.begin());
    for (const auto& c : {std::make_pair(std::string("over the old record"), over_old),
                          std::make_pair(std::string("over an erased chip"), over_erased)}) {
        const std::string chip = eeprom_path("half");
        write_chip(chip, c.second);
        expect_defaults_and_message(boot(chip), c.first);
        unlink(chip.c_str());
    }
}

// A record that another firmware version wrote: its version byte differs and its CRC is
// right for it. The version's place is the one the record's own layout gives
// (Settings.h: magic, magic, version), found in the encoded bytes.
TEST(Eeprom, RecordOfAnotherVersionGivesDefaultsAndAMessage) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    std::vector<uint8_t> rec = encoded(stored_sample());
    const size_t version_at = 2;
    ASSERT_EQ(rec[0], settings::kMagic0);
    ASSERT_EQ(rec[1], settings::kMagic1);
    ASSERT_EQ(rec[version_at], settings::kSettingsVersion);
    rec[version_at] = (uint8_t)(settings::kSettingsVersion - 1u);
    const uint16_t crc = settings::crc16(rec.data(), (uint16_t)(kRecordSize - 2u));
    rec[kRecordSize - 2] = (uint8_t)(crc & 0xFFu);
    rec[kRecordSize - 1] = (uint8_t)(crc >> 8);
    settings::Settings s;
    ASSERT_EQ(settings::decode(rec.data(), s), settings::LoadResult::OldVersion);
    const std::string chip = eeprom_path("version");
    write_chip(chip, rec);
    const e2e::SimRun run = boot(chip);
    expect_defaults_and_message(run, "older version");
    EXPECT_TRUE(find_line(run.lines, "another version")) << e2e::dump(run);
    unlink(chip.c_str());
}

// The power goes while `save` writes (the end of the run is the power cut): from an erased
// chip, a part of the record is on it, and the next start says so and uses the defaults.
TEST(Eeprom, PowerCutDuringSaveGivesDefaultsAndAMessage) {
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
    const std::vector<uint8_t> partial = read_record(chip);
    ASSERT_EQ(partial.size(), kRecordSize);
    settings::Settings s;
    EXPECT_NE(settings::decode(partial.data(), s), settings::LoadResult::Ok);
    EXPECT_NE(partial, std::vector<uint8_t>(kRecordSize, 0xFF)) << "nothing was written before the cut";
    expect_defaults_and_message(boot(chip), "save cut at " + std::string(seconds) + " s");
    unlink(chip.c_str());
    unlink(probe_chip.c_str());
}

}  // namespace
