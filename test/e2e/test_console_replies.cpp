// SPDX-License-Identifier: GPL-3.0-or-later
// Long replies go out a line at a time (firmware.ino: run_console_command): `status` and
// `help` asked in the output mode with the longest lines (raw, 104 bytes) and in MAVLink
// (STATUSTEXT, two frames a line) are answered whole and in order, while the
// data keeps flowing and no sample is missed.
#include "e2e_support.h"

namespace {

// Every line of `status`, in order (the pipeline's bias and compass lines are two parts).
const std::vector<std::string> kStatusLines = {"status: ", "load ", "gyro bias ", "compass: cal ", "settings: rate "};
// The first words of help's lines.
const std::vector<std::string> kHelpLines = {"rate <Hz>", "decl <deg>", "mode plot", "status:", "cal gyro",
                                             "cal mag", "save | defaults"};

// Where each of `words` starts in `text`, each after the previous one; npos when one is missing.
size_t find_in_order(const std::string& text, const std::vector<std::string>& words, size_t from) {
    for (const std::string& w : words) {
        from = text.find(w, from);
        if (from == std::string::npos) return from;
        from += w.size();
    }
    return from;
}

TEST(ConsoleReplies, StatusAndHelpWholeInRawModeWithoutOverrun) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::string input = e2e::input_file("replies_raw", "mode raw\r\nstatus\r\nhelp\r\nstatus\r\nhelp\r\nstatus\r\n");
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 5.0, "--input " + input + " --input-at 2");
    unlink(input.c_str());
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    std::string replies;  // the "# " lines after the input, in order
    size_t overruns = 0, data = 0;
    double last_data = 2.0, longest_gap = 0.0;
    for (const e2e::Line& l : run.lines) {
        if (l.t_s < 2.0) continue;
        if (l.text.rfind("# ", 0) == 0) {
            replies += l.text + "\n";
            overruns += l.text.find("loop overrun") != std::string::npos;
        } else if (!l.text.empty()) {  // raw lines
            ++data;
            longest_gap = std::max(longest_gap, l.t_s - last_data);
            last_data = l.t_s;
        }
    }
    size_t at = 0;
    for (int k = 0; k < 3 && at != std::string::npos; ++k) {
        at = find_in_order(replies, kStatusLines, at);
        EXPECT_NE(at, std::string::npos) << "status " << k << " incomplete:\n" << replies;
        if (k < 2 && at != std::string::npos) {
            at = find_in_order(replies, kHelpLines, at);
            EXPECT_NE(at, std::string::npos) << "help " << k << " incomplete:\n" << replies;
        }
    }
    EXPECT_EQ(overruns, 0u) << replies;
    EXPECT_GT(data, 100u);
    EXPECT_LT(longest_gap, 0.1) << "the raw lines stopped";
}

TEST(ConsoleReplies, StatusAndHelpWholeInMavlinkModeWithoutOverrun) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    // In MAVLink no text line acts, so the commands are typed in text and a
    // ground station's HEARTBEAT (pymavlink's, system 255) right behind them switches the
    // port while their replies are still queued: they go out as STATUSTEXT.
    static const unsigned char kGcsHeartbeat[] = {0xFD, 0x09, 0x00, 0x00, 0x00, 0xFF, 0xBE, 0x00, 0x00, 0x00, 0x00,
                                                  0x00, 0x00, 0x00, 0x06, 0x08, 0x00, 0x00, 0x03, 0x5C, 0x2B};
    std::string typed = "status\r\nhelp\r\nstatus\r\nhelp\r\nstatus\r\nstatus\r\n";
    typed.append(reinterpret_cast<const char*>(kGcsHeartbeat), sizeof kGcsHeartbeat);
    const std::string input = e2e::input_file("replies_mavlink", typed);
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 6.0, "--input " + input + " --input-at 2");
    unlink(input.c_str());
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    // STATUSTEXT carries each line without "# " in chunks of up to 50 characters: the
    // words looked for are each within one chunk of their line. From the first frame on
    // (the first status may have begun as text): a help, a status, a help, a status whole.
    const std::string& bytes = run.result.out;
    size_t at = bytes.find('\xFD');
    ASSERT_NE(at, std::string::npos) << "the HEARTBEAT did not switch the port to MAVLink";
    for (int k = 0; k < 2 && at != std::string::npos; ++k) {
        at = find_in_order(bytes, kHelpLines, at);
        EXPECT_NE(at, std::string::npos) << "help " << k << " incomplete";
        if (at == std::string::npos) break;
        at = find_in_order(bytes, kStatusLines, at);
        EXPECT_NE(at, std::string::npos) << "status " << k << " incomplete";
    }
    EXPECT_EQ(bytes.find("loop overrun"), std::string::npos) << "a sample was missed while answering";
}

}  // namespace
