// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated board itself, checked with a probe AVR program (test/e2e/support/avr/probe.cpp)
// rather than the firmware: sensors answer on the real buses, faults reach the bus,
// bus timing is the board's, the chip-select rule is enforced, console input arrives.
#include "e2e_support.h"

namespace {

#define REQUIRE_PROBE(dir)                         \
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");     \
    E2E_REQUIRE_AVR_PROGRAMS(dir)

const e2e::Line* find_text(const std::vector<e2e::Line>& lines, const std::string& text) {
    for (const e2e::Line& l : lines)
        if (l.text.find(text) != std::string::npos) return &l;
    return nullptr;
}

TEST(Harness, HelpDocumentsTheFaultLanguage) {
    E2E_REQUIRE_TOOLS("apm25sim");
    const e2e::CommandResult r = e2e::run_command(e2e::tool("apm25sim") + " --help");
    EXPECT_EQ(r.exit_code, 0);
    for (const char* spec : {"mpu:absent", "mpu:whoami=", "mag:absent", "mag:drdy-stuck-low", "mag:overflow",
                             "gyro:saturate", "accel:saturate", "imu:spike", "i2c:sda-low", "--profile", "--input",
                             "--eeprom", "overlap",
                             // the receiver and the servo outputs (test_harness_io.cpp)
                             "--rc FILE", "t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8", "12.0,,,,,,,,", "PL1", "22.5 ms",
                             "400 us", "--servo-log FILE", "t,out,width_us", "OC1B/PB6", "OC3A/PE3",
                             // the live board and the physics link (test_harness_serial/physics.cpp)
                             "--serial tcp:PORT", "--speed X", "--physics json[:HOST[:PORT]]", "18458",
                             "--physics-rate HZ", "--physics-timeout S", "--earth-field N,E,D"})
        EXPECT_NE(r.out.find(spec), std::string::npos) << spec;
    const e2e::CommandResult bad = e2e::run_command(e2e::tool("apm25sim") + " --elf x --trajectory " +
                                                    e2e::scenario_csv("rest", 1) + " --fault mpu:melted");
    EXPECT_EQ(bad.exit_code, 1);
    EXPECT_NE(bad.err.find("mpu:melted"), std::string::npos) << bad.err;
}

// Every --fault of one kind holds: two gyro saturation windows, each seen by the probe's
// reads (every 100 ms), with a healthy read between them.
TEST(Harness, EveryWindowOfOneKindReachesTheBus) {
    REQUIRE_PROBE(dir);
    const e2e::SimRun run = e2e::run_sim(dir + "/probe.elf", "rest", 0.5,
                                         "--fault gyro:saturate@0.2-0.25 --fault gyro:saturate@0.4-0.45");
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    std::vector<std::pair<double, bool>> reads;  // (time, every gyro axis at an end of its range)
    for (const e2e::Line& l : run.lines) {
        if (l.text.rfind("ax:", 0) != 0 || l.t_s < 0.15) continue;
        bool ends = true;
        for (const char* axis : {"gx", "gy", "gz"}) {
            const double v = e2e::field(l.text, axis);
            ends = ends && (v == 32767 || v == -32768);
        }
        reads.emplace_back(l.t_s, ends);
    }
    int in_first = 0, between = 0, in_second = 0;
    for (const auto& r : reads) {
        if (r.first >= 0.2 && r.first < 0.25) in_first += r.second ? 1 : -100;
        if (r.first >= 0.26 && r.first < 0.39) between += r.second ? 100 : 1;
        if (r.first >= 0.4 && r.first < 0.45) in_second += r.second ? 1 : -100;
    }
    EXPECT_GE(in_first, 1) << e2e::dump(run);
    EXPECT_GE(between, 1) << e2e::dump(run);
    EXPECT_LT(between, 100) << e2e::dump(run);
    EXPECT_GE(in_second, 1) << e2e::dump(run);
}

// An overlap of two windows of one kind, or a malformed SPEC, stops apm25sim before the
// run: exit status 1 and the SPEC named on stderr, nothing on stdout.
TEST(Harness, OverlappingOrMalformedFaultsAreRefused) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario", "firmware.elf");
    const std::string base = e2e::tool("apm25sim") + " --elf " + e2e::firmware_elf() + " --trajectory " +
                             e2e::scenario_csv("rest", 1) + " ";
    for (const std::string& faults : {std::string("--fault mpu:absent@2-3 --fault mpu:absent@2.5-4"),
                                      std::string("--fault mag:overflow@1 --fault mag:overflow@3-4"),
                                      std::string("--fault mpu:absent@nan"), std::string("--fault mpu:absent@3-2"),
                                      std::string("--fault mpu:absent=1@2-3"), std::string("--fault mpu:whoami=0x70@1-2")}) {
        const e2e::CommandResult r = e2e::run_command(base + faults);
        EXPECT_EQ(r.exit_code, 1) << faults;
        EXPECT_TRUE(r.out.empty()) << faults << ": " << r.out.substr(0, 200);
        const std::string last = faults.substr(faults.rfind("--fault ") + 8);
        EXPECT_NE(r.err.find(last), std::string::npos) << faults << ": " << r.err;
    }
}

// --eeprom: the file's bytes are the EEPROM the program reads, and what it holds at the
// end of the run goes back to the file (a missing file is an erased chip).
TEST(Harness, EepromFileIsTheChip) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario", "firmware.elf");
    const std::string path = e2e::work_dir() + "/harness_eeprom." + std::to_string(getpid()) + ".bin";
    unlink(path.c_str());
    const e2e::SimRun fresh = e2e::run_sim(e2e::firmware_elf(), "rest", 0.1, "--eeprom " + path);
    ASSERT_EQ(fresh.result.exit_code, 0) << e2e::dump(fresh);
    EXPECT_TRUE(find_text(fresh.lines, "EEPROM blank")) << e2e::dump(fresh);
    std::string bytes = e2e::read_text(path);
    ASSERT_EQ(bytes.size(), 4096u);
    EXPECT_EQ(bytes, std::string(4096, '\xFF'));
    // Something else at address 0: the firmware reads those bytes, and leaves them.
    bytes.replace(0, 4, "JUNK");
    std::ofstream(path, std::ios::binary) << bytes;
    const e2e::SimRun junk = e2e::run_sim(e2e::firmware_elf(), "rest", 0.1, "--eeprom " + path);
    EXPECT_TRUE(find_text(junk.lines, "EEPROM holds something else")) << e2e::dump(junk);
    EXPECT_EQ(e2e::read_text(path), bytes);
    // Longer than the chip: refused.
    std::ofstream(path, std::ios::binary) << std::string(4097, '\0');
    const e2e::SimRun longer = e2e::run_sim(e2e::firmware_elf(), "rest", 0.1, "--eeprom " + path);
    EXPECT_EQ(longer.result.exit_code, 1);
    EXPECT_NE(longer.result.err.find("4096"), std::string::npos) << longer.result.err;
    unlink(path.c_str());
}

TEST(Harness, SensorsAnswerOnSpiAndI2cWithDataReadyLines) {
    REQUIRE_PROBE(dir);
    const e2e::SimRun run = e2e::run_sim(dir + "/probe.elf", "rest", 1.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_TRUE(find_text(run.lines, "# whoami 0x68")) << e2e::dump(run);
    EXPECT_TRUE(find_text(run.lines, "# magid 3 H43")) << e2e::dump(run);
    // Level at rest, +-4 g: accel chip z = +1 g = 8192 counts; 200 Hz data-ready on INT;
    // DRDY seen and the field's chip z (-45 uT at 1090 LSB/Ga) about -490.
    const e2e::Line* last = nullptr;
    for (const e2e::Line& l : run.lines)
        if (l.text.rfind("ax:", 0) == 0) last = &l;
    ASSERT_TRUE(last) << e2e::dump(run);
    EXPECT_NEAR(e2e::field(last->text, "az"), 8192, 60) << last->text;
    EXPECT_NEAR(e2e::field(last->text, "mz"), -490, 15) << last->text;
    const double ints = e2e::field(last->text, "ints");
    EXPECT_NEAR(ints / (last->t_s - 0.11), 200.0, 15.0) << last->text;
}

TEST(Harness, FaultsReachTheBus) {
    REQUIRE_PROBE(dir);
    const e2e::SimRun whoami = e2e::run_sim(dir + "/probe.elf", "rest", 0.3, "--fault mpu:whoami=0x70");
    EXPECT_TRUE(find_text(whoami.lines, "# whoami 0x70")) << e2e::dump(whoami);
    const e2e::SimRun absent = e2e::run_sim(dir + "/probe.elf", "rest", 0.3, "--fault mag:absent --fault mpu:absent");
    EXPECT_TRUE(find_text(absent.lines, "# magid 0")) << e2e::dump(absent);
    EXPECT_TRUE(find_text(absent.lines, "# whoami 0x0")) << e2e::dump(absent);
    const e2e::SimRun sda = e2e::run_sim(dir + "/probe.elf", "rest", 0.3, "--fault i2c:sda-low@0-1");
    EXPECT_TRUE(find_text(sda.lines, "# magid 0")) << e2e::dump(sda);
    const e2e::SimRun sat = e2e::run_sim(dir + "/probe.elf", "rest", 0.35, "--fault gyro:saturate@0.2-1");
    // Every gyro axis at an end of the int16 range (the sign of the true rate), from 0.2 s.
    const e2e::Line* line = nullptr;
    for (const e2e::Line& l : sat.lines) {
        if (l.text.rfind("ax:", 0) != 0) continue;
        bool all_ends = true;
        for (const char* axis : {"gx", "gy", "gz"}) {
            const double v = e2e::field(l.text, axis);
            all_ends = all_ends && (v == 32767 || v == -32768);
        }
        if (all_ends) {
            line = &l;
            break;
        }
    }
    ASSERT_TRUE(line) << e2e::dump(sat);
    EXPECT_GE(line->t_s, 0.2);
}

TEST(Harness, BaroChipSelectLowWhileMpuSelectedFailsTheRun) {
    REQUIRE_PROBE(dir);
    const e2e::SimRun bad = e2e::run_sim(dir + "/probe_violation.elf", "rest", 0.8);
    EXPECT_EQ(bad.result.exit_code, 3) << e2e::dump(bad);
    EXPECT_NE(bad.result.err.find("bus violation"), std::string::npos) << bad.result.err;
    const e2e::SimRun good = e2e::run_sim(dir + "/probe.elf", "rest", 0.8);
    EXPECT_EQ(good.result.exit_code, 0) << e2e::dump(good);
    EXPECT_EQ(good.result.err.find("bus violation"), std::string::npos) << good.result.err;
}

TEST(Harness, BusTransfersTakeTheBoardsTime) {
    REQUIRE_PROBE(dir);
    const std::string profile = e2e::work_dir() + "/probe_profile." + std::to_string(getpid()) + ".csv";
    const e2e::SimRun run = e2e::run_sim(dir + "/probe.elf", "rest", 1.0, "--profile " + profile);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const std::string csv = e2e::read_text(profile);
    std::istringstream in(csv);
    std::string row;
    double spi_avg = 0, twi_avg = 0;
    while (std::getline(in, row)) {
        unsigned id = 0;
        unsigned long long count = 0, avg = 0;
        if (std::sscanf(row.c_str(), "%u,%llu,%llu", &id, &count, &avg) == 3) {
            if (id == 4) spi_avg = (double)avg;
            if (id == 5) twi_avg = (double)avg;
        }
    }
    // 15 SPI bytes at 8 MHz: ~735 cycles on the board (APM25.md); simavr 1.6 alone: 24000.
    EXPECT_GT(spi_avg, 600);
    EXPECT_LT(spi_avg, 1000);
    // Pointer write + 6-byte read at 400 kHz: ~11 bytes x 9 bits x 40 cycles plus Wire's work.
    EXPECT_GT(twi_avg, 3500);
    EXPECT_LT(twi_avg, 7000);
    EXPECT_NE(csv.find("\nrun,1,"), std::string::npos) << csv;
    unlink(profile.c_str());
}

TEST(Harness, InputReachesTheUartAfterTheFirstDataLine) {
    REQUIRE_PROBE(dir);
    const std::string input = e2e::input_file("probe_input", "hi\n");
    const e2e::SimRun run = e2e::run_sim(dir + "/probe.elf", "rest", 0.5, "--input " + input);
    unlink(input.c_str());
    // The probe echoes what it reads (maybe a few characters at a time).
    std::string echoed;
    for (const e2e::Line& l : run.lines) {
        size_t pos = 0;
        while ((pos = l.text.find("# echo ", pos)) != std::string::npos) {
            pos += 7;
            while (pos < l.text.size() && l.text[pos] != '#') echoed += l.text[pos++];
        }
    }
    EXPECT_NE(echoed.find('h'), std::string::npos) << e2e::dump(run);
    EXPECT_NE(echoed.find('i'), std::string::npos) << e2e::dump(run);
}

}  // namespace
