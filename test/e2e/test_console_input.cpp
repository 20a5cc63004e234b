// SPDX-License-Identifier: GPL-3.0-or-later
// Console input at the full 115200 baud (issue 11): an eight-command paste, and a 20 KB
// stream of random bytes with valid commands between them. What must happen is computed
// on the host with the firmware's own console code (lib/Console: LineReader, parse_line,
// apply_setting, print_error): every line answered in order, the last values in force,
// no sample lost (no "loop overrun"), the angle lines flowing throughout.
#include <random>

#include "Console.h"
#include "Settings.h"
#include "e2e_support.h"

namespace {

void append(void* ctx, const char* data, uint8_t len) { static_cast<std::string*>(ctx)->append(data, len); }

struct Expected {
    std::vector<std::string> replies;  // the first line of each answer, in order
    size_t errors = 0;                 // "# error:" answers
    settings::Settings final_settings = settings::defaults();
};

// What the firmware must answer to `input`, by the host build of its console. Commands
// with board-side answers (status, save, cal) are matched by their first words.
Expected expected_replies(const std::string& input) {
    Expected e;
    console::LineReader reader;
    for (const char ch : input) {
        const console::Command c = reader.feed((uint8_t)ch);
        std::string out;
        const text::Sink sink{&out, append};
        switch (c.id) {
            case console::CommandId::None: continue;
            case console::CommandId::Error: console::print_error(c, &sink); ++e.errors; break;
            case console::CommandId::Help: console::print_help(&sink); break;
            case console::CommandId::Status: out = "# status:\n"; break;
            case console::CommandId::Save: out = "# saving\n"; break;
            default: console::apply_setting(c, e.final_settings, &sink); break;
        }
        e.replies.push_back(out.substr(0, out.find('\n')));
    }
    return e;
}

bool is_data_line(const e2e::Line& l) {
    if (l.text.empty() || l.text[0] == '#') return false;
    return l.is_angle || (l.text[0] >= '0' && l.text[0] <= '9');  // plot or csv row
}

struct Outcome {
    e2e::SimRun run;
    double input_start_s = 0.0;       // the first answer's time, a bound for the start
    std::vector<std::string> missing;  // expected replies not found in order
    size_t errors = 0;
    size_t overrun_lines = 0;
    double longest_data_gap_s = 0.0;  // between data lines, from input start to the end
};

Outcome run_input(const std::string& name, const std::string& input, const Expected& e, double seconds) {
    Outcome o;
    const std::string path = e2e::input_file(name, input);
    o.run = e2e::run_sim(e2e::firmware_elf(), "rest", seconds, "--input " + path + " --input-at 2");
    unlink(path.c_str());
    o.input_start_s = 2.0;
    std::vector<const e2e::Line*> answers;
    for (const e2e::Line& l : o.run.lines) {
        if (l.t_s < o.input_start_s) continue;
        if (l.text.rfind("# warn: loop overrun", 0) == 0) ++o.overrun_lines;
        else if (l.text.rfind("# ", 0) == 0) answers.push_back(&l);
        if (l.text.rfind("# error:", 0) == 0) ++o.errors;
    }
    // In order, other '#' lines (warnings, help's further lines) allowed between.
    size_t k = 0;
    for (const std::string& want : e.replies) {
        size_t j = k;
        while (j < answers.size() && answers[j]->text.rfind(want, 0) != 0) ++j;
        if (j == answers.size()) {
            o.missing.push_back(want);
        } else {
            k = j + 1;
        }
    }
    double last = -1.0;
    for (const e2e::Line& l : o.run.lines) {
        if (!is_data_line(l) || l.t_s < o.input_start_s - 0.1) continue;
        if (last >= 0.0 && l.t_s - last > o.longest_data_gap_s) o.longest_data_gap_s = l.t_s - last;
        last = l.t_s;
    }
    if (last >= 0.0 && seconds - last > o.longest_data_gap_s) o.longest_data_gap_s = seconds - last;
    return o;
}

std::string list(const std::vector<std::string>& v) {
    std::string s;
    for (const std::string& x : v) s += "  " + x + "\n";
    return s;
}

// The rate, declination and mode in force at the end: data lines per second over the
// last 2 s, the mean heading at rest facing north (the declination), the line format.
void expect_in_force(const e2e::SimRun& run, const settings::Settings& s, double seconds) {
    std::vector<e2e::Line> tail;
    size_t data = 0;
    for (const e2e::Line& l : run.lines) {
        if (l.t_s < seconds - 2.0 || !is_data_line(l)) continue;
        ++data;
        if (l.is_angle) tail.push_back(l);
    }
    EXPECT_NEAR((double)data / 2.0, s.rate_hz, 1.0) << "rate in force";
    if (s.mode == fmt::OutputMode::Plot) {
        ASSERT_EQ(tail.size(), data) << "plot mode: every data line is label:value";
        ASSERT_FALSE(tail.empty());
        EXPECT_NEAR(e2e::heading_diff_deg(e2e::mean_heading(tail), s.declination_deg()), 0.0, 1.0)
            << "declination in force (the board faces north)";
    }
}

// The paste: eight commands, 82 bytes at once.
const char* const kPaste = "mode quiet\r\nrate 100\r\nhelp\r\ndecl -120.125\r\nstatus\r\ndecl 8.50\r\nmode plot\r\nrate 25\r\n";

TEST(ConsoleInput, EightCommandPasteAnsweredLineByLineWithoutOverrun) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    ASSERT_EQ(std::string(kPaste).size(), 82u);
    const Expected e = expected_replies(kPaste);
    ASSERT_EQ(e.replies.size(), 8u);
    const double seconds = 6.0;
    const Outcome o = run_input("paste", kPaste, e, seconds);
    ASSERT_EQ(o.run.result.exit_code, 0) << e2e::dump(o.run);
    EXPECT_TRUE(o.missing.empty()) << "answers missing or out of order:\n" << list(o.missing) << e2e::dump(o.run, 80);
    EXPECT_EQ(o.errors, 0u) << e2e::dump(o.run, 80);
    EXPECT_EQ(o.overrun_lines, 0u) << "samples lost while answering\n" << e2e::dump(o.run, 80);
    EXPECT_FALSE(e2e::has_non_finite(o.run.lines));
    expect_in_force(o.run, e.final_settings, seconds);
}

// 20 KB: random bytes (any value, line ends included) with a valid command after each
// chunk; the last rate, decl and mode given are the ones in force at the end.
std::string random_stream(std::vector<std::string>& commands) {
    std::mt19937 rng(20261123u);
    std::string s;
    const char* const kRates[] = {"10", "20", "25", "50"};
    const char* const kDecls[] = {"-45.5", "3.25", "12", "-7.75"};
    int k = 0;
    while (s.size() < 20000) {
        const size_t chunk = 20 + rng() % 200;
        for (size_t i = 0; i < chunk; ++i) s.push_back((char)(rng() & 0xFF));
        std::string cmd;
        switch (k++ % 3) {
            case 0: cmd = std::string("rate ") + kRates[rng() % 4]; break;
            case 1: cmd = std::string("decl ") + kDecls[rng() % 4]; break;
            default: cmd = (rng() % 2) ? "mode csv" : "mode plot"; break;
        }
        commands.push_back(cmd);
        s += "\r\n" + cmd + "\r\n";
    }
    s += "\r\nrate 20\r\ndecl -45.5\r\nmode plot\r\n";  // the final state is known
    return s;
}

TEST(ConsoleInput, RandomBytesStreamWithCommandsBetween) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    std::vector<std::string> commands;
    const std::string stream = random_stream(commands);
    ASSERT_GE(stream.size(), 20000u);
    const Expected e = expected_replies(stream);
    ASSERT_EQ(e.final_settings.rate_hz, 20);
    ASSERT_EQ(e.final_settings.declination_centideg, -4550);
    ASSERT_GT(e.errors, 50u);  // the premise: much of it is garbage
    // 20 KB at 11.5 KB/s is 1.8 s; the answers (~10 KB) follow within about as long.
    const double seconds = 10.0;
    const Outcome o = run_input("stream", stream, e, seconds);
    ASSERT_EQ(o.run.result.exit_code, 0) << e2e::dump(o.run);
    EXPECT_FALSE(e2e::has_non_finite(o.run.lines));
    EXPECT_LT(o.longest_data_gap_s, 0.25) << "the angle lines stopped";
    EXPECT_EQ(o.errors, e.errors) << "every garbage line answered once";
    EXPECT_TRUE(o.missing.empty()) << o.missing.size() << " of " << e.replies.size()
                                   << " answers missing or out of order, e.g.:\n"
                                   << list(std::vector<std::string>(o.missing.begin(),
                                                                    o.missing.begin() + (long)std::min<size_t>(5, o.missing.size())));
    EXPECT_EQ(o.overrun_lines, 0u) << "samples lost while reading the stream";
    expect_in_force(o.run, e.final_settings, seconds);
}

}  // namespace
