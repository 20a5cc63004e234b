// SPDX-License-Identifier: GPL-3.0-or-later
// The serial console parser and the settings commands (lib/Console/Console).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "Console.h"

using console::Command;
using console::CommandId;
using console::Error;

namespace {

void sink_write(void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }

Command parse(const char* s) { return console::parse_line(s); }

// Feeds bytes through a LineReader and returns the last non-None command.
Command feed(console::LineReader& r, const std::string& bytes) {
    Command last{CommandId::None, Error::None, 0, fmt::OutputMode::Plot};
    for (char c : bytes) {
        const Command cmd = r.feed((uint8_t)c);
        if (cmd.id != CommandId::None) last = cmd;
    }
    return last;
}

bool same(const settings::Settings& a, const settings::Settings& b) {
    return a.rate_hz == b.rate_hz && a.declination_centideg == b.declination_centideg && a.mode == b.mode &&
           a.flags == b.flags && a.cal.mag_offset_uT == b.cal.mag_offset_uT;
}

}  // namespace

TEST(Console, PlainCommands) {
    EXPECT_EQ(parse("help").id, CommandId::Help);
    EXPECT_EQ(parse("?").id, CommandId::Help);
    EXPECT_EQ(parse("status").id, CommandId::Status);
    EXPECT_EQ(parse("save").id, CommandId::Save);
    EXPECT_EQ(parse("defaults").id, CommandId::Defaults);
    EXPECT_EQ(parse("cal gyro").id, CommandId::CalGyro);
    EXPECT_EQ(parse("cal mag").id, CommandId::CalMag);
    EXPECT_EQ(parse("  STATUS\t ").id, CommandId::Status);  // case and blanks do not matter
    EXPECT_EQ(parse("").id, CommandId::None);
    EXPECT_EQ(parse("   ").id, CommandId::None);
}

TEST(Console, Rate) {
    Command c = parse("rate 10");
    EXPECT_EQ(c.id, CommandId::Rate);
    EXPECT_EQ(c.value, 10);
    EXPECT_EQ(parse("rate 1").value, 1);
    EXPECT_EQ(parse("rate 100").value, 100);
    EXPECT_EQ(parse("rate 25.0").value, 25);
    EXPECT_EQ(parse("rate 0").error, Error::RateRange);
    EXPECT_EQ(parse("rate 101").error, Error::RateRange);
    EXPECT_EQ(parse("rate -5").error, Error::RateRange);
    EXPECT_EQ(parse("rate 2.5").error, Error::RateRange);
    EXPECT_EQ(parse("rate abc").error, Error::BadNumber);
    EXPECT_EQ(parse("rate 5x").error, Error::BadNumber);
    EXPECT_EQ(parse("rate 1e2").error, Error::BadNumber);
    EXPECT_EQ(parse("rate 99999999999").error, Error::BadNumber);
    EXPECT_EQ(parse("rate").error, Error::MissingArgument);
    EXPECT_EQ(parse("rate 5 6").error, Error::ExtraArgument);
}

TEST(Console, Decl) {
    Command c = parse("decl -12.34");
    EXPECT_EQ(c.id, CommandId::Decl);
    EXPECT_EQ(c.value, -1234);
    EXPECT_EQ(parse("decl 2").value, 200);
    EXPECT_EQ(parse("decl +2.5").value, 250);
    EXPECT_EQ(parse("decl .5").value, 50);
    EXPECT_EQ(parse("decl 1.005").value, 101);  // third decimal rounds
    EXPECT_EQ(parse("decl -1.005").value, -101);
    EXPECT_EQ(parse("decl 180").value, 18000);
    EXPECT_EQ(parse("decl -180").value, -18000);
    EXPECT_EQ(parse("decl 180.01").error, Error::DeclRange);
    EXPECT_EQ(parse("decl -200").error, Error::DeclRange);
    EXPECT_EQ(parse("decl nan").error, Error::BadNumber);
    EXPECT_EQ(parse("decl inf").error, Error::BadNumber);
    EXPECT_EQ(parse("decl -").error, Error::BadNumber);
    EXPECT_EQ(parse("decl .").error, Error::BadNumber);
    EXPECT_EQ(parse("decl 1.2.3").error, Error::BadNumber);
    EXPECT_EQ(parse("decl 0x10").error, Error::BadNumber);
    EXPECT_EQ(parse("decl").error, Error::MissingArgument);
}

TEST(Console, Mode) {
    EXPECT_EQ(parse("mode plot").mode, fmt::OutputMode::Plot);
    EXPECT_EQ(parse("mode CSV").mode, fmt::OutputMode::Csv);
    EXPECT_EQ(parse("mode quiet").mode, fmt::OutputMode::Quiet);
    EXPECT_EQ(parse("mode quat").mode, fmt::OutputMode::Quat);
    EXPECT_EQ(parse("mode RAW").mode, fmt::OutputMode::Raw);
    EXPECT_EQ(parse("mode mavlink").mode, fmt::OutputMode::Mavlink);
    EXPECT_EQ(parse("mode mav").error, Error::BadMode);
    EXPECT_EQ(parse("mode quaternion").error, Error::BadMode);
    EXPECT_EQ(parse("mode loud").error, Error::BadMode);
    EXPECT_EQ(parse("mode").error, Error::MissingArgument);
}

TEST(Console, UnknownAndMalformed) {
    EXPECT_EQ(parse("hello").error, Error::Unknown);
    EXPECT_EQ(parse("help me").error, Error::ExtraArgument);
    EXPECT_EQ(parse("status now").error, Error::ExtraArgument);
    EXPECT_EQ(parse("cal").error, Error::MissingArgument);
    EXPECT_EQ(parse("cal baro").error, Error::BadCalTarget);
    EXPECT_EQ(parse("cal gyro mag").error, Error::ExtraArgument);
    EXPECT_EQ(parse("a b c d e").error, Error::ExtraArgument);
    EXPECT_EQ(parse("ratee 5").error, Error::Unknown);
}

TEST(Console, LineReaderEndings) {
    console::LineReader r;
    EXPECT_EQ(feed(r, "status\n").id, CommandId::Status);
    EXPECT_EQ(feed(r, "status\r").id, CommandId::Status);
    // "\r\n" is one line ending: exactly one command.
    int commands = 0;
    for (char c : std::string("rate 5\r\nrate 6\r\n")) {
        if (r.feed((uint8_t)c).id != CommandId::None) ++commands;
    }
    EXPECT_EQ(commands, 2);
    EXPECT_EQ(feed(r, "\n\n\r\n").id, CommandId::None);  // empty lines: nothing
}

TEST(Console, Backspace) {
    console::LineReader r;
    EXPECT_EQ(feed(r, "ratx\x08" "e 7\n").value, 7);
    EXPECT_EQ(feed(r, "\x7f\x7f" "help\n").id, CommandId::Help);
}

TEST(Console, OverLongLineIsRejectedWhole) {
    console::LineReader r;
    const std::string longline = "rate " + std::string(60, '5') + "\n";
    Command c = feed(r, longline);
    EXPECT_EQ(c.id, CommandId::Error);
    EXPECT_EQ(c.error, Error::TooLong);
    // The reader recovers at the next line.
    EXPECT_EQ(feed(r, "rate 5\n").value, 5);
    // Exactly the capacity is fine.
    const std::string fits = "decl " + std::string(console::kLineCapacity - 7, ' ') + "12";
    ASSERT_EQ(fits.size(), console::kLineCapacity);
    EXPECT_EQ(feed(r, fits + "\n").value, 1200);
    EXPECT_EQ(feed(r, fits + "3\n").error, Error::TooLong);
}

TEST(Console, BinaryGarbage) {
    console::LineReader r;
    std::string garbage;
    for (int i = 0; i < 256; ++i)
        if (i != '\n' && i != '\r' && i != 0x08 && i != 0x7F) garbage.push_back((char)i);
    Command c = feed(r, garbage + "\n");
    EXPECT_EQ(c.error, Error::Garbage);
    EXPECT_EQ(feed(r, std::string("rate\0 5\n", 8)).error, Error::Garbage);
    EXPECT_EQ(feed(r, "mode csv\xff\n").error, Error::Garbage);
    EXPECT_EQ(feed(r, "mode csv\n").mode, fmt::OutputMode::Csv);
}

TEST(Console, PseudoRandomBytesNeverChangeSettings) {
    // Every line of random bytes containing a non-text byte is rejected whole.
    console::LineReader r;
    uint32_t x = 12345;
    std::string out;
    const text::Sink sink{&out, sink_write};
    settings::Settings s = settings::defaults();
    const settings::Settings before = s;
    for (int i = 0; i < 20000; ++i) {
        x = x * 1103515245u + 12345u;
        uint8_t b = (uint8_t)(x >> 16);
        if (i % 37 == 36) b = '\n';
        else if (b >= 0x20 && b < 0x7F) b = 0x80;  // keep every line binary
        const Command c = r.feed(b);
        if (c.id != CommandId::None) {
            EXPECT_EQ(c.id, CommandId::Error);
            console::apply_setting(c, s, &sink);
        }
    }
    EXPECT_TRUE(same(s, before));
}

TEST(Console, ApplySettingsAndReplies) {
    std::string out;
    const text::Sink sink{&out, sink_write};
    settings::Settings s = settings::defaults();

    EXPECT_TRUE(console::apply_setting(parse("rate 20"), s, &sink));
    EXPECT_EQ(s.rate_hz, 20);
    EXPECT_EQ(out, "# rate 20 Hz\n");

    out.clear();
    EXPECT_TRUE(console::apply_setting(parse("decl -3.5"), s, &sink));
    EXPECT_EQ(s.declination_centideg, -350);
    EXPECT_EQ(out, "# decl -3.50 deg\n");

    out.clear();
    EXPECT_TRUE(console::apply_setting(parse("mode csv"), s, &sink));
    EXPECT_EQ(s.mode, fmt::OutputMode::Csv);
    EXPECT_EQ(out, "# mode csv\nt_ms,roll,pitch,yaw\n");

    out.clear();
    s.cal.mag_offset_uT = linalg::Vector3f(1.0f, 2.0f, 3.0f);
    EXPECT_TRUE(console::apply_setting(parse("defaults"), s, &sink));
    EXPECT_TRUE(same(s, settings::defaults()));
    EXPECT_EQ(out.rfind("# defaults", 0), 0u);

    // Commands that are not settings are left to the firmware; errors change nothing.
    const settings::Settings before = s;
    EXPECT_FALSE(console::apply_setting(parse("status"), s, &sink));
    EXPECT_FALSE(console::apply_setting(parse("rate 500"), s, &sink));
    EXPECT_FALSE(console::apply_setting(parse("decl x"), s, &sink));
    EXPECT_TRUE(same(s, before));
}

TEST(Console, ErrorMessagesAreHashLines) {
    const char* bad[] = {"bogus", "rate", "rate 1 2", "rate x", "rate 0", "decl 999", "mode x", "cal x"};
    for (const char* line : bad) {
        std::string out;
        const text::Sink sink{&out, sink_write};
        const Command c = parse(line);
        ASSERT_EQ(c.id, CommandId::Error) << line;
        console::print_error(c, &sink);
        EXPECT_EQ(out.rfind("# error: ", 0), 0u) << out;
        EXPECT_EQ(out.back(), '\n');
        EXPECT_EQ(out.find('\n'), out.size() - 1) << "one line";
    }
}

TEST(Console, HelpListsEveryCommandOnHashLines) {
    std::string out;
    const text::Sink sink{&out, sink_write};
    console::print_help(&sink);
    for (const char* word : {"rate", "decl", "mode", "status", "cal gyro", "cal mag", "save", "defaults"})
        EXPECT_NE(out.find(word), std::string::npos) << word;
    size_t start = 0;
    while (start < out.size()) {
        EXPECT_EQ(out.compare(start, 2, "# "), 0) << out.substr(start);
        start = out.find('\n', start) + 1;
    }
}

TEST(CommandQueue, KeepsOrderAndRefusesWhenFull) {
    console::CommandQueue q;
    EXPECT_TRUE(q.empty());
    // Rates take 2 bytes: full (a set, the longest item, might not fit) with 4 bytes left.
    constexpr uint8_t kRates = (console::CommandQueue::kBytes - 4) / 2;
    static_assert(console::CommandQueue::kMaxItem == 6, "a set: id, index, int32");
    for (uint8_t i = 0; i < kRates; ++i) {
        EXPECT_FALSE(q.full());
        console::Command c = console::parse_line("rate 10");
        c.value = 10 + i;
        EXPECT_TRUE(q.push(c));
    }
    EXPECT_TRUE(q.full());
    EXPECT_EQ(q.size(), kRates);
    EXPECT_FALSE(q.push(console::parse_line("set RLL2SRV_P 1")));  // 6 bytes: 4 are left
    // Oldest first, and the ring wraps: pop two, push a rate and a decl, then all in order.
    EXPECT_EQ(q.pop().value, 10);
    EXPECT_EQ(q.pop().value, 11);
    EXPECT_FALSE(q.full());
    console::Command a = console::parse_line("rate 50"), b = console::parse_line("decl -180");
    EXPECT_TRUE(q.push(a));
    EXPECT_TRUE(q.push(b));
    for (int32_t v = 12; v < 10 + kRates; ++v) EXPECT_EQ(q.pop().value, v);
    EXPECT_EQ(q.peek().id, console::CommandId::Rate);
    EXPECT_EQ(q.pop().value, 50);
    const console::Command last = q.pop();
    EXPECT_EQ(last.id, console::CommandId::Decl);
    EXPECT_EQ(last.value, -18000);
    EXPECT_TRUE(q.empty());
}

TEST(CommandQueue, EveryKindComesBackAsParsed) {
    // Each command through the queue, again and again so that items straddle the wrap.
    const char* const lines[] = {"help", "rate 100", "decl 179.99", "decl -0.01", "mode mavlink", "mode quiet",
                                 "status", "cal gyro", "cal mag", "save", "defaults", "frobnicate", "rate 0",
                                 "mode x", "cal x", "\x01"};
    console::CommandQueue q;
    for (int round = 0; round < 20; ++round) {
        for (const char* line : lines) {
            const console::Command c = line[0] == '\x01' ? console::Command{CommandId::Error, console::Error::Garbage,
                                                                                0, fmt::OutputMode::Plot, 0}
                                                            : parse(line);
            ASSERT_TRUE(q.push(c)) << line;
            const console::Command back = q.pop();
            EXPECT_EQ(back.id, c.id) << line;
            EXPECT_EQ(back.error, c.error) << line;
            EXPECT_EQ(back.value, c.value) << line;
            EXPECT_EQ(back.mode, c.mode) << line;
            EXPECT_TRUE(q.empty());
        }
    }
    // The capacity in commands: one byte each for those without a number.
    constexpr uint8_t kHelps = console::CommandQueue::kBytes - console::CommandQueue::kMaxItem + 1;
    for (uint8_t i = 0; i < kHelps; ++i) ASSERT_TRUE(q.push(parse("help")));
    EXPECT_TRUE(q.full());
    EXPECT_EQ(q.size(), kHelps);
}

TEST(CommandQueue, ErrorsBeyondTheirSlotsAreCountedAndCommandsStillFit) {
    console::CommandQueue q;
    const uint8_t slots = console::CommandQueue::kErrorBytes;  // one byte each
    const console::Command bad = parse("frobnicate");
    ASSERT_EQ(bad.id, CommandId::Error);
    for (uint8_t i = 0; i < slots; ++i) EXPECT_TRUE(q.push(bad));
    for (int i = 0; i < 100; ++i) EXPECT_TRUE(q.push(bad));  // merged into the newest
    EXPECT_EQ(q.size(), slots);
    // A command still gets a slot, an error after it takes one of its own, and decls (the
    // longest commands) fill what is left.
    EXPECT_TRUE(q.push(parse("rate 10")));
    EXPECT_TRUE(q.push(bad));
    for (int i = 0; i < 6; ++i) EXPECT_TRUE(q.push(parse("decl 10")));
    uint32_t answered = 0, merged = 0;
    std::string out;
    const text::Sink sink{&out, sink_write};
    while (!q.empty()) {
        const console::Command c = q.pop();
        if (c.id != CommandId::Error) continue;
        EXPECT_EQ(c.error, console::Error::Unknown);
        ++answered;
        merged += (uint32_t)c.value;
        EXPECT_LE(0, c.value);
        out.clear();
        console::print_error(c, &sink);
        if (c.value > 0) {
            EXPECT_NE(out.find("# error: 100 more bad lines"), std::string::npos) << out;
        }
        for (uint8_t part = 0; part < 2; ++part) {  // each part one line within the bound
            out.clear();
            EXPECT_EQ(console::print_error(c, part, &sink), part == 0 || c.value > 0);
            if (out.empty()) continue;
            EXPECT_LE(out.size(), console::kPartReply) << out;
            EXPECT_EQ(out.find('\n'), out.size() - 1) << out;
        }
    }
    EXPECT_EQ(answered + merged, slots + 100u + 1u);  // every bad line accounted for
}

TEST(CommandQueue, EveryReplyPartFitsItsBound) {
    // The firmware writes a reply part when its output queue has room for kPartReply
    // bytes and an output line: a longer part would block the loop. A part is one "# "
    // line (`mode csv` adds its header line, not a "# " line).
    std::string out;
    const text::Sink sink{&out, sink_write};
    auto one_line_within_bound = [&](const std::string& what) {
        EXPECT_LE(out.size(), console::kPartReply) << what << ": " << out;
        EXPECT_EQ(out.compare(0, 2, "# "), 0) << what << ": " << out;
        const size_t first = out.find('\n');
        ASSERT_NE(first, std::string::npos) << what;
        if (first + 1 < out.size()) {
            EXPECT_EQ(out.substr(first + 1), "t_ms,roll,pitch,yaw\n") << what;
        }
    };
    std::string help;
    uint8_t parts = 0;
    for (; parts < 20; ++parts) {
        out.clear();
        if (!console::print_help(parts, &sink)) break;
        one_line_within_bound("help part " + std::to_string(parts));
        help += out;
    }
    EXPECT_TRUE(out.empty()) << "nothing written past the last part";
    EXPECT_GT(help.size(), console::kPartReply);  // help needs its parts
    out.clear();
    console::print_help(&sink);
    EXPECT_EQ(out, help) << "the parts make the whole help";
    const char* const lines[] = {"rate 100", "decl -179.99", "mode mavlink", "mode csv", "mode x", "rate 0",
                                 "decl 200", "cal x", "frobnicate", "rate", "rate 5 6", "rate abc", "\x01\x02"};
    for (const char* line : lines) {
        settings::Settings s = settings::defaults();
        const console::Command c = parse(line);
        out.clear();
        if (c.id == CommandId::Error) console::print_error(c, &sink);
        else console::apply_setting(c, s, &sink);
        one_line_within_bound(line);
    }
    out.clear();
    console::print_defaults(&sink);
    one_line_within_bound("defaults");
}

TEST(Console, EveryModeNameParsesBackToItsMode) {
    for (uint8_t m = 0; m <= (uint8_t)fmt::kLastOutputMode; ++m) {
        const fmt::OutputMode mode = (fmt::OutputMode)m;
        const std::string line = std::string("mode ") + console::mode_name(mode).p;
        const console::Command c = parse(line.c_str());
        EXPECT_EQ(c.id, CommandId::Mode) << line;
        EXPECT_EQ(c.mode, mode) << line;
    }
}

TEST(Console, ModeMavlinkIsAppliedAndHelpNamesTheNewModes) {
    settings::Settings s = settings::defaults();
    std::string out;
    const text::Sink sink{&out, sink_write};
    EXPECT_TRUE(console::apply_setting(parse("mode mavlink"), s, &sink));
    EXPECT_EQ(s.mode, fmt::OutputMode::Mavlink);
    EXPECT_EQ(out, "# mode mavlink\n");
    out.clear();
    console::print_help(&sink);
    for (const char* word : {"quat", "raw", "mavlink"}) EXPECT_NE(out.find(word), std::string::npos) << word;
    out.clear();
    console::print_error(parse("mode loud"), &sink);
    EXPECT_EQ(out, "# error: mode must be plot, csv, quat, raw, mavlink or quiet; nothing changed\n");
}
