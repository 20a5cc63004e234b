// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the end-to-end tests: run the project's tools (TOOLS_DIR: firmware.elf,
// apm25sim, replay, scenario, score), generate scenarios, parse the serial output.
// A test whose tool is missing skips (GTEST_SKIP), it does not fail.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <vector>

namespace e2e {

inline std::string tools_dir() { return TOOLS_DIR; }
inline std::string project_dir() { return PROJECT_DIR; }
inline std::string tool(const std::string& name) { return tools_dir() + "/" + name; }
inline std::string firmware_elf() { return tool("firmware.elf"); }

inline bool file_exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Work directory for generated files, shared by the test processes ctest runs.
inline std::string work_dir() {
    const std::string dir = tools_dir() + "/e2e";
    mkdir(dir.c_str(), 0755);
    return dir;
}

inline std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct CommandResult {
    int exit_code = -1;
    std::string out;  // stdout
    std::string err;  // stderr
};

// Runs a shell command, capturing stdout and stderr.
inline CommandResult run_command(const std::string& command) {
    CommandResult result;
    char err_path[] = "/tmp/e2e_stderr_XXXXXX";
    const int fd = mkstemp(err_path);
    if (fd >= 0) close(fd);
    FILE* pipe = popen((command + " 2>" + err_path).c_str(), "r");
    if (!pipe) return result;
    char buffer[65536];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, pipe)) > 0) result.out.append(buffer, n);
    const int status = pclose(pipe);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.err = read_text(err_path);
    unlink(err_path);
    return result;
}

// The scenario's CSV (generated once by build/scenario, atomically for parallel ctest).
inline std::string scenario_csv(const std::string& name, double seconds) {
    char file[128];
    std::snprintf(file, sizeof file, "/%s_%gs.csv", name.c_str(), seconds);
    const std::string path = work_dir() + file;
    if (file_exists(path)) return path;
    const std::string tmp = path + ".tmp." + std::to_string(getpid());
    char seconds_text[32];
    std::snprintf(seconds_text, sizeof seconds_text, "%g", seconds);
    const CommandResult r = run_command(tool("scenario") + " " + name + " --seconds " + seconds_text + " > " + tmp);
    if (r.exit_code != 0) return "";
    std::rename(tmp.c_str(), path.c_str());
    return path;
}

// One line of stamped serial output.
struct Line {
    double t_s = 0.0;
    std::string text;
    bool is_angle = false;
    double roll = NAN, pitch = NAN, yaw = NAN;
};

// Value after `label:` in an angle line; NaN when absent or not a number.
inline double field(const std::string& text, const std::string& label) {
    const std::string key = label + ":";
    size_t pos = 0;
    while ((pos = text.find(key, pos)) != std::string::npos) {
        if (pos == 0 || text[pos - 1] == ' ') {
            const char* start = text.c_str() + pos + key.size();
            char* end = nullptr;
            const double v = std::strtod(start, &end);
            return end == start ? NAN : v;
        }
        pos += key.size();
    }
    return NAN;
}

// Splits `--stamp` output into lines; angle lines are those that do not begin with '#'.
inline std::vector<Line> parse_stamped(const std::string& out) {
    std::vector<Line> lines;
    // The run can stop in the middle of a line (e.g. "12.34 roll:0.00 pi" at the end):
    // only lines that ended with a newline are whole, so a final unterminated one is dropped.
    const size_t last_newline = out.rfind('\n');
    std::istringstream in(last_newline == std::string::npos ? std::string() : out.substr(0, last_newline + 1));
    std::string raw;
    while (std::getline(in, raw)) {
        if (!raw.empty() && raw.back() == '\r') raw.pop_back();
        Line line;
        const size_t space = raw.find(' ');
        if (space == std::string::npos) continue;
        line.t_s = std::atof(raw.substr(0, space).c_str());
        line.text = raw.substr(space + 1);
        if (line.text.rfind("#", 0) != 0 && line.text.find("roll:") != std::string::npos) {
            line.is_angle = true;
            line.roll = field(line.text, "roll");
            line.pitch = field(line.text, "pitch");
            line.yaw = field(line.text, "yaw");
        }
        lines.push_back(line);
    }
    return lines;
}

inline std::string lowercase(std::string s) {
    for (char& c : s) c = (char)std::tolower((unsigned char)c);
    return s;
}

// True if any angle line holds a nan or inf (as text, or unparsable angles).
inline bool has_non_finite(const std::vector<Line>& lines) {
    for (const Line& l : lines) {
        if (!l.is_angle) continue;
        const std::string low = lowercase(l.text);
        if (low.find("nan") != std::string::npos || low.find("inf") != std::string::npos) return true;
        if (!std::isfinite(l.roll) || !std::isfinite(l.pitch) || !std::isfinite(l.yaw)) return true;
    }
    return false;
}

inline std::vector<Line> angle_lines(const std::vector<Line>& lines, double from_s = 0.0, double to_s = 1e30) {
    std::vector<Line> out;
    for (const Line& l : lines)
        if (l.is_angle && l.t_s >= from_s && l.t_s < to_s) out.push_back(l);
    return out;
}

// First '#' line after from_s that starts with `prefix` and mentions one of `names`
// (case-insensitive); nullptr when none.
inline const Line* find_report(const std::vector<Line>& lines, const std::string& prefix,
                               const std::vector<std::string>& names, double from_s = 0.0) {
    for (const Line& l : lines) {
        if (l.t_s < from_s || l.text.rfind(prefix, 0) != 0) continue;
        const std::string low = lowercase(l.text);
        for (const std::string& n : names)
            if (low.find(lowercase(n)) != std::string::npos) return &l;
    }
    return nullptr;
}

// Smallest signed difference a - b between two headings, degrees.
// Circular mean of the headings of `lines` (0/360 wrap), degrees.
inline double mean_heading(const std::vector<Line>& lines) {
    double s = 0.0, c = 0.0;
    for (const Line& l : lines) {
        s += std::sin(l.yaw * M_PI / 180.0);
        c += std::cos(l.yaw * M_PI / 180.0);
    }
    return std::atan2(s, c) * 180.0 / M_PI;
}

inline double heading_diff_deg(double a, double b) {
    double d = std::fmod(a - b, 360.0);
    if (d > 180.0) d -= 360.0;
    if (d < -180.0) d += 360.0;
    return d;
}

struct SimRun {
    CommandResult result;
    std::vector<Line> lines;
};

// build/apm25sim on a trajectory file (not a named scenario).
inline SimRun run_sim_file(const std::string& elf, const std::string& csv, double seconds,
                           const std::string& extra_args = "") {
    SimRun run;
    char seconds_text[32];
    std::snprintf(seconds_text, sizeof seconds_text, "%g", seconds);
    run.result = run_command(tool("apm25sim") + " --elf " + elf + " --trajectory " + csv + " --seconds " +
                             seconds_text + " --stamp " + extra_args);
    run.lines = parse_stamped(run.result.out);
    return run;
}

// build/apm25sim --elf ELF --trajectory <scenario> --seconds S --stamp [extra...]
inline SimRun run_sim(const std::string& elf, const std::string& scenario, double seconds,
                      const std::string& extra_args = "") {
    return run_sim_file(elf, scenario_csv(scenario, seconds), seconds, extra_args);
}

// The AVR test programs of test/e2e/support/avr (probe.elf, probe_violation.elf, selftest.elf),
// built once per process; flock serialises the builds of the test processes ctest runs
// in parallel, and build.sh renames each ELF into place so a running one is never
// rewritten under it.
struct AvrPrograms {
    bool toolchain = false;  // avr-g++ and the Arduino core are installed
    bool built = false;
    std::string dir;
    std::string log;         // build.sh's output when it failed
};

inline const AvrPrograms& avr_programs() {
    static const AvrPrograms programs = [] {
        AvrPrograms p;
        p.toolchain = run_command("command -v avr-g++").exit_code == 0 &&
                      file_exists("/usr/share/arduino/hardware/arduino/avr/cores/arduino/Arduino.h");
        if (!p.toolchain) return p;
        p.dir = work_dir() + "/probe";
        const CommandResult r = run_command("flock " + work_dir() + "/probe.lock " + project_dir() +
                                            "/test/e2e/support/avr/build.sh " + p.dir + " 2>&1");
        p.built = r.exit_code == 0;
        if (!p.built) p.log = r.out.substr(0, 4000);
        return p;
    }();
    return programs;
}

// Skips without the AVR toolchain; a build that fails with it installed is a failure.
#define E2E_REQUIRE_AVR_PROGRAMS(dir)                                                   \
    const e2e::AvrPrograms& avr_ = e2e::avr_programs();                                 \
    if (!avr_.toolchain) GTEST_SKIP() << "avr-g++ or the Arduino core is missing";     \
    ASSERT_TRUE(avr_.built) << "test/e2e/support/avr/build.sh failed:\n" << avr_.log;          \
    const std::string dir = avr_.dir

// Writes `content` to work_dir()/name through a temporary file and a rename, so that a
// test process running in parallel never reads it half written. Returns the path.
inline std::string write_work_file(const std::string& name, const std::string& content) {
    const std::string path = work_dir() + "/" + name;
    const std::string tmp = path + ".tmp." + std::to_string(getpid());
    {
        std::ofstream out(tmp, std::ios::binary);
        out << content;
        if (!out) return "";
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) return "";
    return path;
}

// A value `key=...` from build/score's one-line output; NaN if absent.
inline double score_field(const std::string& out, const std::string& key) {
    const size_t pos = out.find(key + "=");
    return pos == std::string::npos ? NAN : std::atof(out.c_str() + pos + key.size() + 1);
}

// The angle lines of a simavr run scored against `trajectory` by build/score, as
// replay's output would be (`options`: extra score flags such as --all).
inline CommandResult score_lines(const std::vector<Line>& lines, const std::string& trajectory,
                                 const std::string& options = "") {
    const std::string estimate = work_dir() + "/estimate." + std::to_string(getpid()) + "." +
                                 std::to_string(lines.size()) + ".csv";
    {
        std::ofstream out(estimate);
        out << "t,roll,pitch,yaw\n";
        for (const Line& l : angle_lines(lines)) out << l.t_s << "," << l.roll << "," << l.pitch << "," << l.yaw << "\n";
    }
    const CommandResult r =
        run_command(tool("score") + " " + options + " --trajectory " + trajectory + " --estimate " + estimate);
    unlink(estimate.c_str());
    return r;
}

// Writes `text` to a file under the work directory for --input.
inline std::string input_file(const std::string& name, const std::string& text) {
    const std::string path = work_dir() + "/" + name + "." + std::to_string(getpid()) + ".txt";
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

inline std::string dump(const SimRun& run, size_t max_lines = 40) {
    std::string s = "exit " + std::to_string(run.result.exit_code) + "; stderr:\n" + run.result.err.substr(0, 2000) +
                    "\nstdout (first lines):\n";
    size_t n = 0;
    std::istringstream in(run.result.out);
    std::string line;
    while (n++ < max_lines && std::getline(in, line)) s += line + "\n";
    return s;
}

}  // namespace e2e

// Skips the test unless the named files exist in TOOLS_DIR.
#define E2E_REQUIRE_TOOLS(...)                                                          \
    do {                                                                                \
        for (const char* name_ : {__VA_ARGS__}) {                                       \
            if (!e2e::file_exists(e2e::tool(name_)))                                    \
                GTEST_SKIP() << e2e::tool(name_) << " is missing (build it first)";     \
        }                                                                               \
    } while (0)
