// SPDX-License-Identifier: GPL-3.0-or-later
// apm25sim --physics json: ArduPilot's SITL JSON interface with apm25sim on ArduPilot's side,
// against a tiny backend (test/e2e/support/fake_physics.py) that holds the board at a fixed
// attitude at rest: the firmware's angles read that attitude, the frames come in lock-step,
// the measured servo widths go out in the packets, the backend's `rc` comes in as PPM, a
// silent backend is said and given up on, and two runs are the same bytes.
#include <map>
#include <regex>

#include "harness_live.h"

namespace {

struct Backend {
    e2e::LiveProcess process;
    std::string port;
    std::string log;  // the backend's packet log: frame_rate,frame_count,pwm1..pwm16

    bool start(const std::vector<std::string>& options) {
        log = e2e::work_dir() + "/physics_packets." + std::to_string(getpid()) + "." +
              std::to_string(++count_) + ".csv";
        std::vector<std::string> args = {"python3", e2e::project_dir() + "/test/e2e/support/fake_physics.py",
                                         "--port", "0", "--log", log};
        args.insert(args.end(), options.begin(), options.end());
        if (!process.start(args, 1, "/dev/null")) return false;
        port = process.wait_line("^port ([0-9]+)$");
        return !port.empty();
    }
    ~Backend() {
        process.stop();
        unlink(log.c_str());
    }
    static int count_;
};
int Backend::count_ = 0;

e2e::SimRun run_physics(const std::string& elf, const Backend& backend, double seconds, const std::string& extra = "") {
    e2e::SimRun run;
    char seconds_text[32];
    std::snprintf(seconds_text, sizeof seconds_text, "%g", seconds);
    run.result = e2e::run_command(e2e::tool("apm25sim") + " --elf " + elf + " --physics json:127.0.0.1:" +
                                  backend.port + " --seconds " + seconds_text + " --stamp " + extra);
    run.lines = e2e::parse_stamped(run.result.out);
    return run;
}

std::vector<std::vector<long>> packets(const std::string& log) {
    std::vector<std::vector<long>> rows;
    std::istringstream in(e2e::read_text(log));
    std::string line;
    while (std::getline(in, line)) {
        std::vector<long> row;
        std::istringstream fields(line);
        std::string f;
        while (std::getline(fields, f, ',')) row.push_back(std::atol(f.c_str()));
        rows.push_back(row);
    }
    return rows;
}

// The firmware on a board the backend holds at roll 20, pitch -10, heading 90 deg (as
// `attitude`, then as `quaternion`): its lines read that attitude, from the earth field
// rotated by the backend's attitude, and score them against --physics-log's file. Every frame once, counting from 0, at 1000 Hz, one a
// millisecond of simulated time; with no receiver the outputs hold their safe values.
TEST(HarnessPhysics, TheFirmwareReadsTheBackendsAttitude) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf");
    for (const char* form : {"attitude", "quaternion"}) {
        Backend backend;
        std::vector<std::string> options = {"--attitude", "20,-10,90"};
        if (std::string(form) == "quaternion") options.push_back("--quaternion");
        ASSERT_TRUE(backend.start(options)) << backend.process.text;
        const std::string log = e2e::work_dir() + "/physics_log." + std::to_string(getpid()) + "." + form + ".csv";
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, 5.0, "--physics-log " + log);
        ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        // The states the sensors read, as a trajectory file: score takes the firmware's lines
        // against it as against any recording.
        const e2e::CommandResult score = e2e::score_lines(run.lines, log);
        unlink(log.c_str());
        ASSERT_EQ(score.exit_code, 0) << score.out << score.err;
        EXPECT_LT(e2e::score_field(score.out, "total_rmse_deg"), 0.5) << score.out;
        EXPECT_GT(e2e::score_field(score.out, "samples"), 150) << score.out;
        const std::vector<e2e::Line> settled = e2e::angle_lines(run.lines, 4.0);
        ASSERT_GE(settled.size(), 20u) << e2e::dump(run);
        for (const e2e::Line& l : settled) {
            EXPECT_NEAR(l.roll, 20.0, 0.3) << form << " " << l.text;
            EXPECT_NEAR(l.pitch, -10.0, 0.3) << form << " " << l.text;
            EXPECT_NEAR(e2e::heading_diff_deg(l.yaw, 90.0), 0.0, 1.0) << form << " " << l.text;
        }
        const std::vector<std::vector<long>> sent = packets(backend.log);
        ASSERT_EQ(sent.size(), 5001u);  // frame 0 for the start, then one a millisecond
        for (size_t i = 0; i < sent.size(); ++i) {
            ASSERT_EQ(sent[i].size(), 18u);
            EXPECT_EQ(sent[i][0], 1000) << i;
            EXPECT_EQ(sent[i][1], (long)i);
            // Without a receiver the firmware holds its safe outputs (issue 21): OUT3, the
            // throttle, at its failsafe 1000 us, the others at their 1500 us trim, from their
            // first pulse on (0 before it: nothing measured yet); OUT9-16 are not wired.
            for (int c = 0; c < 8; ++c) {
                const long neutral_us = c == 2 ? 1000 : 1500;
                const long width_us = sent[i][2 + c];
                if (i >= 100) EXPECT_EQ(width_us, neutral_us) << i << " OUT" << c + 1;
                else EXPECT_TRUE(width_us == 0 || width_us == neutral_us) << i << " OUT" << c + 1 << " " << width_us;
            }
            for (int c = 8; c < 16; ++c) EXPECT_EQ(sent[i][2 + c], 0) << i;
        }
    }
}

// The probe (io_probe.elf) writes output k's width 900 + 100 k + 25 j us (j stepping every
// 10 periods) and captures PPM: the packets carry each width as measured on the pin (the
// pin is high width + 0.5 us: within 1 us), OUT9-16 at 0; the backend's rc_1..rc_8 reach
// the capture within 0.5 us, and its empty `rc` (from 1 s) stops the PPM; its `airspeed`
// reaches A0 as the MPXV7002DP's voltage.
TEST(HarnessPhysics, PacketsCarryThePinsWidthsAndRcDrivesThePpm) {
    E2E_REQUIRE_TOOLS("apm25sim");
    E2E_REQUIRE_AVR_PROGRAMS(dir);
    Backend backend;
    ASSERT_TRUE(backend.start({"--rc", "1100,1200,1300,1400,1500,1600,1700,1800", "--rc-dead-from", "1.0",
                               "--airspeed", "20"}))
        << backend.process.text;
    const e2e::SimRun run = run_physics(dir + "/io_probe.elf", backend, 1.6);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const std::vector<std::vector<long>> sent = packets(backend.log);
    ASSERT_GE(sent.size(), 1600u);
    int checked = 0;
    for (size_t i = 100; i < sent.size(); ++i) {  // from 0.1 s: every output has pulsed
        for (int out = 1; out <= 8; ++out) {
            const long w = sent[i][1 + out];
            const long step = std::lround((w - 0.5 - 900.0 - 100.0 * out) / 25.0);
            EXPECT_TRUE(step >= 0 && step <= 7 && std::labs(w - (900 + 100 * out + 25 * step)) <= 1)
                << "frame " << i << " OUT" << out << " " << w;
        }
        for (int c = 9; c <= 16; ++c) EXPECT_EQ(sent[i][1 + c], 0);
        ++checked;
    }
    EXPECT_GT(checked, 1400);
    double frames_at_1_1 = -1, frames_last = -1;
    for (const e2e::Line& l : run.lines) {
        if (l.text.rfind("ppm ", 0) != 0 || l.t_s < 0.1) continue;
        if (l.t_s < 1.0) {
            for (int c = 0; c < 8; ++c)
                EXPECT_NEAR(e2e::field(l.text, "w" + std::to_string(c + 1)) / 2.0, 1100.0 + 100.0 * c, 0.5) << l.text;
        }
        if (l.t_s > 1.05 && frames_at_1_1 < 0) frames_at_1_1 = e2e::field(l.text, "e");
        frames_last = e2e::field(l.text, "e");
    }
    EXPECT_GT(frames_at_1_1, 300) << e2e::dump(run);
    // airspeed 20 m/s: 245 Pa, the MPXV7002DP at 2.5 V + 0.245 V: 562 counts of 5 V by the
    // datasheet's Vin x 1024 / Vref, 561 from simavr 1.6 (it scales by 1023).
    int a0_lines = 0;
    for (const e2e::Line& l : run.lines) {
        if (l.text.rfind("ppm ", 0) != 0) continue;
        EXPECT_NEAR(e2e::field(l.text, "a0"), 2745.0 * 1024.0 / 5000.0, 1.5) << l.text;
        ++a0_lines;
    }
    EXPECT_GT(a0_lines, 25);
    EXPECT_EQ(frames_last, frames_at_1_1) << "captures after the backend's rc went empty";
}

// A backend that stops answering: the frame is sent again every second, said on stderr,
// and after --physics-timeout the run stops with exit status 4 (not a hang), or at once on
// SIGTERM (exit 0); one that answers with something else than a state stops it at once,
// saying what is wrong.
TEST(HarnessPhysics, ASilentOrConfusedBackendStopsTheRunWithAReason) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf");
    {
        Backend backend;
        ASSERT_TRUE(backend.start({"--silent-after", "200"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, 5.0, "--physics-timeout 3");
        EXPECT_EQ(run.result.exit_code, 4) << e2e::dump(run);
        EXPECT_NE(run.result.err.find("has not answered frame 201"), std::string::npos) << run.result.err;
        EXPECT_NE(run.result.err.find("sending it again"), std::string::npos) << run.result.err;
        EXPECT_NE(run.result.err.find("no answer from the physics backend at 127.0.0.1:" + backend.port), std::string::npos)
            << run.result.err;
        const std::vector<std::vector<long>> sent = packets(backend.log);
        ASSERT_GE(sent.size(), 203u);
        EXPECT_EQ(sent[201][1], 201);
        EXPECT_EQ(sent[202][1], 201) << "a resend keeps the frame count";
    }
    {
        // SIGTERM while waiting for a silent backend: a clean end at once, not after the timeout.
        Backend backend;
        ASSERT_TRUE(backend.start({"--silent-after", "50"})) << backend.process.text;
        e2e::LiveProcess sim;
        const std::string out = e2e::work_dir() + "/physics_stdout." + std::to_string(getpid()) + ".txt";
        ASSERT_TRUE(sim.start({e2e::tool("apm25sim"), "--elf", e2e::firmware_elf(), "--physics",
                               "json:127.0.0.1:" + backend.port, "--physics-timeout", "600"},
                              2, out));
        EXPECT_FALSE(sim.wait_line("has not answered frame 51").empty()) << sim.text;
        EXPECT_EQ(sim.stop(), 0) << sim.text;
        unlink(out.c_str());
    }
    {
        Backend backend;
        ASSERT_TRUE(backend.start({"--garbage-after", "10"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, 5.0);
        EXPECT_EQ(run.result.exit_code, 4) << e2e::dump(run);
        EXPECT_NE(run.result.err.find("answer to frame 11: not a JSON object"), std::string::npos) << run.result.err;
    }
}

// The count in the summary line "apm25sim: physics backend at ...: F frames, R sent again,
// D late or duplicate replies dropped" (-1 when there is none).
long summary_count(const std::string& err, const std::string& what) {
    const std::regex re("physics backend at [^:]+:[0-9]+: ([0-9]+) frames, ([0-9]+) sent again, ([0-9]+) late or "
                        "duplicate replies dropped");
    std::smatch m;
    if (!std::regex_search(err, m, re)) return -1;
    const int group = what == "frames" ? 1 : what == "sent again" ? 2 : 3;
    return std::atol(m[group].str().c_str());
}

// Issue 46's race on a loaded machine, made deterministic by the backend: frame 1500 is
// answered only after apm25sim's 1 s time-out sent it again, and the answer to that resend
// (the same state) arrives while apm25sim waits for frame 1501. A backend answering every
// packet twice is the same race at every frame. Neither stops the run: the stale replies
// are dropped and counted, and the board sees exactly the states of an undisturbed run
// (lock-step: the same bytes, stamped).
TEST(HarnessPhysics, ALateOrDuplicateReplyIsDroppedAndCounted) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf");
    const double seconds = 2.5;
    std::string clean;
    {
        Backend backend;
        ASSERT_TRUE(backend.start({"--attitude", "5,3,200"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, seconds);
        ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        clean = run.result.out;
        // Every frame once; a frame sent again on a loaded machine (none when idle) is
        // answered twice, and one of the two answers dropped.
        EXPECT_EQ(summary_count(run.result.err, "frames"), 2501) << run.result.err;
        EXPECT_GE(summary_count(run.result.err, "sent again"), 0) << run.result.err;
        EXPECT_EQ(summary_count(run.result.err, "dropped"), summary_count(run.result.err, "sent again"))
            << run.result.err;
    }
    EXPECT_GT(clean.size(), 500u);
    {
        Backend backend;
        ASSERT_TRUE(backend.start({"--attitude", "5,3,200", "--late", "1500"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, seconds);
        EXPECT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        EXPECT_NE(run.result.err.find("has not answered frame 1500"), std::string::npos) << run.result.err;
        EXPECT_EQ(run.result.err.find("is not after"), std::string::npos) << run.result.err;
        EXPECT_EQ(summary_count(run.result.err, "frames"), 2501) << run.result.err;
        EXPECT_GE(summary_count(run.result.err, "sent again"), 1) << run.result.err;  // 1 on an idle machine
        EXPECT_EQ(summary_count(run.result.err, "dropped"), summary_count(run.result.err, "sent again"))
            << run.result.err;
        EXPECT_TRUE(run.result.out == clean) << "the serial output differs from the undisturbed run's";
        const std::vector<std::vector<long>> sent = packets(backend.log);
        ASSERT_GE(sent.size(), 2502u);  // frame 1500 twice
        EXPECT_EQ(sent[1500][1], 1500);
        EXPECT_EQ(sent[1501][1], 1500);
    }
    {
        Backend backend;
        ASSERT_TRUE(backend.start({"--attitude", "5,3,200", "--twice"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, seconds);
        EXPECT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        EXPECT_EQ(summary_count(run.result.err, "frames"), 2501) << run.result.err;
        // Every frame's second answer but the last frame's, read before the run ended (and
        // both answers to a frame sent again on a loaded machine).
        EXPECT_EQ(summary_count(run.result.err, "dropped"), 2500 + 2 * summary_count(run.result.err, "sent again"))
            << run.result.err;
        EXPECT_TRUE(run.result.out == clean) << "the serial output differs from the undisturbed run's";
    }
}

// A backend whose time went back (restarted under the same port) answers every send, but
// never with a state after the last one: a genuine failure, not a late reply. The frame is
// sent again every second, and after --physics-timeout the run stops with exit status 4,
// saying so.
TEST(HarnessPhysics, ABackendWhoseTimeWentBackStopsTheRun) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf");
    Backend backend;
    ASSERT_TRUE(backend.start({"--time-back-after", "200"})) << backend.process.text;
    const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, 5.0, "--physics-timeout 3");
    EXPECT_EQ(run.result.exit_code, 4) << e2e::dump(run);
    EXPECT_NE(run.result.err.find("has not answered frame 201"), std::string::npos) << run.result.err;
    EXPECT_NE(run.result.err.find("no new state from the physics backend at 127.0.0.1:" + backend.port +
                                  " for frame 201"),
              std::string::npos)
        << run.result.err;
    EXPECT_NE(run.result.err.find("its time stands still or went back"), std::string::npos) << run.result.err;
    EXPECT_EQ(summary_count(run.result.err, "frames"), 201) << run.result.err;
    EXPECT_GE(summary_count(run.result.err, "dropped"), 3) << run.result.err;  // the send and its resends
    // The board stopped at the last new state (frame 200, 0.2 s), never ran on a stale one.
    EXPECT_NE(run.result.err.find("stopping at t=0.200000 s"), std::string::npos) << run.result.err;
}

// Lock-step: the same backend twice gives the same bytes on the serial line.
TEST(HarnessPhysics, TwoRunsGiveTheSameBytes) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf");
    std::string outputs[2];
    for (std::string& out : outputs) {
        Backend backend;
        ASSERT_TRUE(backend.start({"--attitude", "5,3,200"})) << backend.process.text;
        const e2e::SimRun run = run_physics(e2e::firmware_elf(), backend, 3.0);
        ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
        out = run.result.out;
    }
    EXPECT_GT(outputs[0].size(), 1000u);
    EXPECT_EQ(outputs[0], outputs[1]);
}

// Exactly one source of motion, and the spec's grammar.
TEST(HarnessPhysics, PhysicsOptionsAreChecked) {
    E2E_REQUIRE_TOOLS("apm25sim", "firmware.elf", "scenario");
    const std::string base = e2e::tool("apm25sim") + " --elf " + e2e::firmware_elf() + " --seconds 0.1 ";
    for (const std::string& args :
         {std::string("--physics json --trajectory ") + e2e::scenario_csv("rest", 1), std::string(""),
          std::string("--physics jsn"), std::string("--physics json:"), std::string("--physics json:127.0.0.1:0"),
          std::string("--physics json --physics-rate 100"), std::string("--physics json --earth-field 1,2")}) {
        const e2e::CommandResult r = e2e::run_command(base + args);
        EXPECT_EQ(r.exit_code, 1) << args << ": " << r.err;
        EXPECT_TRUE(r.out.empty()) << args;
    }
}

}  // namespace
