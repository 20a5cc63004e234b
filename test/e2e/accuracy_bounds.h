// SPDX-License-Identifier: GPL-3.0-or-later
// The per-file accuracy bounds the e2e tests hold replay to: test/e2e/accuracy_bounds.txt,
// written by `make bench` (bench/bench.py --write-bounds) from today's figures plus a
// small margin, and changed only with a reason in the commit.
#pragma once

#include <map>
#include <sstream>
#include <string>

#include "e2e_support.h"

namespace e2e {

struct AccuracyBound {
    std::string name, kind;   // kind: broad, mean, scenario
    double total_deg = NAN;   // the figure when the table was written
    double bound_deg = NAN;   // what the test allows
    std::string options;      // the scenario tool's options (a scenario variant)
};

// The table by name; empty when the file is missing (a test then fails, never skips).
inline std::map<std::string, AccuracyBound> accuracy_bounds() {
    std::map<std::string, AccuracyBound> rows;
    std::istringstream in(read_text(project_dir() + "/test/e2e/accuracy_bounds.txt"));
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream f(line);
        AccuracyBound b;
        double incl, heading;
        if (!(f >> b.name >> b.kind >> b.total_deg >> incl >> heading >> b.bound_deg)) continue;
        std::getline(f, b.options);
        const size_t start = b.options.find_first_not_of(' ');
        b.options = start == std::string::npos ? "" : b.options.substr(start);
        rows[b.name] = b;
    }
    return rows;
}

// A scenario variant's CSV at its default length, as `make bench` generates it
// (generated once, atomically for parallel ctest).
inline std::string scenario_variant_csv(const AccuracyBound& b) {
    const std::string path = work_dir() + "/bound_" + b.name + ".csv";
    if (file_exists(path)) return path;
    const std::string tmp = path + ".tmp." + std::to_string(getpid());
    const CommandResult r = run_command(tool("scenario") + " " + b.name.substr(0, b.name.find('+')) + " " +
                                        b.options + " > " + tmp);
    if (r.exit_code != 0) return "";
    std::rename(tmp.c_str(), path.c_str());
    return path;
}

}  // namespace e2e
