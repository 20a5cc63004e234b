// SPDX-License-Identifier: GPL-3.0-or-later
// apm25sim's receiver and servo pins (--rc, --servo-log), checked with a probe AVR program
// (test/e2e/support/avr/io_probe.cpp) that drives the outputs and captures the PPM as
// ArduPilot's APM2 HAL does, rather than with the firmware.
#include <cstring>
#include <map>

#include "e2e_support.h"

namespace {

struct PulseRow {
    double t_s;
    int out;
    double width_us;
};

// The servo log's rows; false when a row or the header is not the contract's.
bool read_servo_log(const std::string& path, std::vector<PulseRow>& rows, std::string& why) {
    std::istringstream in(e2e::read_text(path));
    std::string line;
    if (!std::getline(in, line) || line != "t,out,width_us") {
        why = "header '" + line + "'";
        return false;
    }
    while (std::getline(in, line)) {
        PulseRow r;
        char t_text[32], w_text[32];
        if (std::sscanf(line.c_str(), "%31[^,],%d,%31s", t_text, &r.out, w_text) != 3) {
            why = "row '" + line + "'";
            return false;
        }
        // Six decimals of seconds, two of microseconds.
        const char* t_dot = std::strchr(t_text, '.');
        const char* w_dot = std::strchr(w_text, '.');
        if (!t_dot || std::strlen(t_dot + 1) != 6 || !w_dot || std::strlen(w_dot + 1) != 2) {
            why = "decimals in '" + line + "'";
            return false;
        }
        r.t_s = std::atof(t_text);
        r.width_us = std::atof(w_text);
        rows.push_back(r);
    }
    return true;
}

// The probe writes output k's width, 900 + 100 k + 25 j us with j = (overflows / 10) mod 8,
// in TIMERn_OVF (OCRn = 2 x width: the pin is high for OCRn + 1 ticks, width + 0.5 us) and
// toggles the servo pins' PORT bits (no effect while the timer owns them) and other bits of
// the same ports all the time. Every pulse of every output is in the
// log, in rising-edge order, at 50 Hz, within 1 us of a width the probe wrote, each width
// held for 10 periods: no glitched pulse, and no PORT write taken for an edge.
TEST(HarnessIo, ServoLogMeasuresEveryOutputsPulsesFromItsPin) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    E2E_REQUIRE_AVR_PROGRAMS(dir);
    const std::string log = e2e::work_dir() + "/servo_log." + std::to_string(getpid()) + ".csv";
    const e2e::SimRun run = e2e::run_sim(dir + "/io_probe.elf", "rest", 2.5, "--servo-log " + log);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    std::vector<PulseRow> rows;
    std::string why;
    ASSERT_TRUE(read_servo_log(log, rows, why)) << why;
    unlink(log.c_str());
    std::map<int, std::vector<PulseRow>> by_output;
    for (size_t i = 0; i < rows.size(); ++i) {
        if (i > 0) {
            EXPECT_GE(rows[i].t_s, rows[i - 1].t_s) << "row " << i + 2;
        }
        by_output[rows[i].out].push_back(rows[i]);
    }
    ASSERT_EQ(by_output.size(), 8u);
    for (int out = 1; out <= 8; ++out) {
        const std::vector<PulseRow>& pulses = by_output[out];
        ASSERT_GE(pulses.size(), 124u) << "OUT" << out;  // 2.5 s at 50 Hz
        std::vector<int> steps;
        int off_schedule = 0;
        for (size_t i = 0; i < pulses.size(); ++i) {
            if (i > 0) {
                EXPECT_NEAR(pulses[i].t_s - pulses[i - 1].t_s, 0.020, 1.5e-6) << "OUT" << out << " " << i;
            }
            const double written_us = pulses[i].width_us - 0.5;
            const int step = (int)std::lround((written_us - 900.0 - 100.0 * out) / 25.0);
            const double expected_us = 900.0 + 100.0 * out + 25.0 * step;
            if (step < 0 || step > 7 || std::fabs(written_us - expected_us) > 1.0) ++off_schedule;
            steps.push_back(step);
        }
        EXPECT_EQ(off_schedule, 0) << "OUT" << out;
        // Runs of one width: 10 periods each, but the first and the last (cut by the run).
        std::vector<int> runs(1, 1);
        for (size_t i = 1; i < steps.size(); ++i) {
            if (steps[i] == steps[i - 1]) {
                ++runs.back();
            } else {
                EXPECT_EQ(steps[i], (steps[i - 1] + 1) % 8) << "OUT" << out << " pulse " << i;
                runs.push_back(1);
            }
        }
        ASSERT_GE(runs.size(), 10u) << "OUT" << out;
        for (size_t r = 1; r + 1 < runs.size(); ++r) EXPECT_EQ(runs[r], 10) << "OUT" << out << " run " << r;
    }
}

// One `ppm` line of the probe: whole frames, captures and the last frame's 8 intervals.
struct PpmLine {
    double t_s;
    double frames, captures;
    double ticks[8];
};

std::vector<PpmLine> ppm_lines(const std::vector<e2e::Line>& lines) {
    std::vector<PpmLine> out;
    for (const e2e::Line& l : lines) {
        if (l.text.rfind("ppm ", 0) != 0) continue;
        PpmLine p;
        p.t_s = l.t_s;
        p.frames = e2e::field(l.text, "f");
        p.captures = e2e::field(l.text, "e");
        for (int c = 0; c < 8; ++c) p.ticks[c] = e2e::field(l.text, "w" + std::to_string(c + 1));
        out.push_back(p);
    }
    return out;
}

// The PPM on ICP5 read by Timer5's rising-edge capture as the APM2 HAL reads it: nothing
// before the first row, each row's widths within 1 us (0.5 us ticks) while it holds, 8
// channels in a 22.5 ms frame, no edge at all while the receiver is dead, and the signal
// back with the next full row.
TEST(HarnessIo, PpmOnIcp5CarriesTheRcScript) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    E2E_REQUIRE_AVR_PROGRAMS(dir);
    const std::string rc = e2e::write_work_file("io_rc." + std::to_string(getpid()) + ".csv",
                                                "t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n"
                                                "0.5,1100,1200,1300,1400,1500,1600,1700,1800\n"
                                                "1.0,1500,1500,1000,1500,1500,1500,1500,1900\n"
                                                "1.5,,,,,,,,\n"
                                                "2.0,2000,1000,1500,1500,1500,1500,1500,2200\n");
    const e2e::SimRun run = e2e::run_sim(dir + "/io_probe.elf", "rest", 2.5, "--rc " + rc);
    unlink(rc.c_str());
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const std::vector<PpmLine> lines = ppm_lines(run.lines);
    ASSERT_GE(lines.size(), 45u) << e2e::dump(run);
    const double rows[3][8] = {{1100, 1200, 1300, 1400, 1500, 1600, 1700, 1800},
                               {1500, 1500, 1000, 1500, 1500, 1500, 1500, 1900},
                               {2000, 1000, 1500, 1500, 1500, 1500, 1500, 2200}};
    const PpmLine* dead_first = nullptr;
    const PpmLine* first_of_row0 = nullptr;
    const PpmLine* last_of_row0 = nullptr;
    int checked[3] = {0, 0, 0};
    for (const PpmLine& p : lines) {
        if (p.t_s < 0.5) {
            EXPECT_EQ(p.captures, 0) << p.t_s;
            continue;
        }
        int row = -1;  // the row whose frames the line must show (a frame's time after a change)
        if (p.t_s > 0.55 && p.t_s < 1.0) row = 0;
        if (p.t_s > 1.05 && p.t_s < 1.5) row = 1;
        if (p.t_s > 2.05) row = 2;
        if (row == 0) {
            if (!first_of_row0) first_of_row0 = &p;
            last_of_row0 = &p;
        }
        if (row >= 0) {
            ++checked[row];
            for (int c = 0; c < 8; ++c)
                EXPECT_NEAR(p.ticks[c] / 2.0, rows[row][c], 1.0) << "t=" << p.t_s << " ch" << c + 1;
        }
        // Dead from 1.5 s (the frame in progress ends by 1.52 s) to 2.0 s: no edge at all.
        if (p.t_s > 1.53 && p.t_s < 2.0) {
            if (!dead_first) dead_first = &p;
            EXPECT_EQ(p.captures, dead_first->captures) << p.t_s;
            EXPECT_EQ(p.frames, dead_first->frames) << p.t_s;
        }
    }
    for (int r = 0; r < 3; ++r) EXPECT_GE(checked[r], 6) << "row " << r;
    ASSERT_TRUE(dead_first && first_of_row0 && last_of_row0);
    // 22.5 ms frames: 44.4 a second.
    const double rate = (last_of_row0->frames - first_of_row0->frames) / (last_of_row0->t_s - first_of_row0->t_s);
    EXPECT_NEAR(rate, 1.0 / 0.0225, 2.5);
    EXPECT_GT(lines.back().frames, dead_first->frames + 15) << "the signal came back";
}

// A script that is not the contract's stops the run before it starts: exit 1, the file
// and the line named, nothing on stdout.
TEST(HarnessIo, BadRcFilesAreRefused) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    E2E_REQUIRE_AVR_PROGRAMS(dir);
    const std::string header = "t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n";
    int n = 0;
    for (const std::string& body : {std::string("t,ch1,ch2\n"), header + "1,1500,,,,,,,\n",
                                    header + "1,1500,1500,1500,1500,1500,1500,1500,9000\n",
                                    header + "2,,,,,,,,\n1,,,,,,,,\n"}) {
        const std::string rc = e2e::write_work_file("bad_rc." + std::to_string(getpid()) + "." +
                                                        std::to_string(n++) + ".csv", body);
        const e2e::SimRun run = e2e::run_sim(dir + "/io_probe.elf", "rest", 0.2, "--rc " + rc);
        EXPECT_EQ(run.result.exit_code, 1) << body;
        EXPECT_TRUE(run.result.out.empty()) << body;
        EXPECT_NE(run.result.err.find(rc), std::string::npos) << run.result.err;
        unlink(rc.c_str());
    }
    const e2e::CommandResult missing = e2e::run_command(e2e::tool("apm25sim") + " --elf " + dir +
                                                        "/io_probe.elf --trajectory " +
                                                        e2e::scenario_csv("rest", 0.2) + " --rc /nonexistent.csv");
    EXPECT_EQ(missing.exit_code, 1);
    EXPECT_NE(missing.err.find("/nonexistent.csv"), std::string::npos) << missing.err;
}

}  // namespace
