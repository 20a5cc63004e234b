// SPDX-License-Identifier: GPL-3.0-or-later
// build/score: the BROAD dataset's orientation error metric for one estimate file.
//
//   build/score --trajectory FILE.csv[.gz] --estimate EST.csv [--skip S] [--all] [--csv]
//               [--series OUT.csv]
//
// EST.csv: header naming at least the columns t, roll, pitch, yaw (any order, more
// columns allowed), degrees, aerospace Z-Y-X Euler angles of the body -> earth (NED)
// rotation, yaw = heading: the output of build/replay. `-` reads standard input.
// Lines starting with '#' are ignored.
//
// For each estimate row the truth is the trajectory's nearest sample. A row counts when
// t >= S, t lies within the trajectory, the truth is finite and its movement flag is 1.
// The metric is in ScoreMetric.h. Output, one line:
//   total_rmse_deg=… incl_rmse_deg=… heading_rmse_deg=… samples=N max_total_deg=…
// --csv prints a header line and one row with the same fields instead.
// --series writes the per-row errors (t,total_deg,incl_deg,heading_deg) of the rows that count.
// Exit status: 0 on success, 1 on a usage error, 2 on unreadable or bad input, 3 when no
// row counts.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "ScoreMetric.h"
#include "Trajectory.h"

namespace {

void usage(FILE* out) {
    fprintf(out,
            "usage: score --trajectory FILE.csv[.gz] --estimate EST.csv|- [--skip S] [--csv]\n"
            "             [--series OUT.csv]\n"
            "  Scores an estimate (CSV with columns t,roll,pitch,yaw in degrees, Z-Y-X Euler,\n"
            "  body->earth NED) against the trajectory's true orientation with the BROAD metric:\n"
            "  total, inclination and heading RMSE over the rows with movement = 1 and finite truth.\n"
            "  --skip S     ignore rows with t < S seconds\n"
            "  --all        count rows whatever their movement flag (still needs a finite truth)\n"
            "  --csv        print a CSV header and one row instead of key=value\n"
            "  --series F   write per-row errors (t,total_deg,incl_deg,heading_deg) to F\n");
}

std::vector<std::string> split_csv(const std::string& line) {
    std::vector<std::string> out;
    std::string field;
    std::istringstream ss(line);
    while (std::getline(ss, field, ',')) {
        while (!field.empty() && (field.back() == '\r' || field.back() == ' ')) field.pop_back();
        size_t b = 0;
        while (b < field.size() && field[b] == ' ') ++b;
        out.push_back(field.substr(b));
    }
    return out;
}

bool parse_number(const std::string& s, double& v) {
    if (s.empty()) return false;
    char* end = nullptr;
    v = strtod(s.c_str(), &end);
    return end && *end == '\0';
}

struct Options {
    std::string trajectory, estimate, series;
    double skip_s = 0.0;
    bool csv = false;
    bool all_rows = false;  // --all: ignore the movement flag
};

// Returns 0 when the command line is usable, otherwise the exit status to use.
int parse_args(int argc, char** argv, Options& o) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&](const char* name) -> const char* {
            if (i + 1 >= argc) {
                fprintf(stderr, "score: %s needs a value\n", name);
                return nullptr;
            }
            return argv[++i];
        };
        if (a == "--trajectory") {
            const char* v = value("--trajectory");
            if (!v) return 1;
            o.trajectory = v;
        } else if (a == "--estimate") {
            const char* v = value("--estimate");
            if (!v) return 1;
            o.estimate = v;
        } else if (a == "--series") {
            const char* v = value("--series");
            if (!v) return 1;
            o.series = v;
        } else if (a == "--skip") {
            const char* v = value("--skip");
            if (!v) return 1;
            if (!parse_number(v, o.skip_s)) {
                fprintf(stderr, "score: --skip needs a number of seconds, got '%s'\n", v);
                return 1;
            }
        } else if (a == "--all") {
            o.all_rows = true;
        } else if (a == "--csv") {
            o.csv = true;
        } else if (a == "--help" || a == "-h") {
            usage(stdout);
            exit(0);
        } else {
            fprintf(stderr, "score: unknown argument '%s'\n", a.c_str());
            usage(stderr);
            return 1;
        }
    }
    if (o.trajectory.empty() || o.estimate.empty()) {
        fprintf(stderr, "score: --trajectory and --estimate are required\n");
        usage(stderr);
        return 1;
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    if (int rc = parse_args(argc, argv, opt)) return rc;

    sim::Trajectory traj;
    if (!traj.load(opt.trajectory)) {
        fprintf(stderr, "score: %s\n", traj.error().c_str());
        return 2;
    }
    // Rows past the end of the trajectory have no truth: allow half a sample period.
    const double period = traj.size() > 1 ? traj.duration_s() / double(traj.size() - 1) : 0.0;
    const double t_first = traj[0].t_s, t_last = traj.duration_s() + 0.5 * period;

    std::ifstream file;
    std::istream* in = &std::cin;
    if (opt.estimate != "-") {
        file.open(opt.estimate);
        if (!file) {
            fprintf(stderr, "score: cannot open estimate '%s'\n", opt.estimate.c_str());
            return 2;
        }
        in = &file;
    }
    FILE* series = nullptr;
    if (!opt.series.empty()) {
        series = fopen(opt.series.c_str(), "w");
        if (!series) {
            fprintf(stderr, "score: cannot write '%s'\n", opt.series.c_str());
            return 2;
        }
        fprintf(series, "t,total_deg,incl_deg,heading_deg\n");
    }

    std::string line;
    long line_no = 0;
    int col_t = -1, col_roll = -1, col_pitch = -1, col_yaw = -1;
    size_t n_cols = 0;
    long rows = 0;
    score::RmseAccumulator acc;
    while (std::getline(*in, line)) {
        ++line_no;
        if (line.empty() || line == "\r" || line[0] == '#') continue;
        const std::vector<std::string> f = split_csv(line);
        if (col_t < 0) {  // header
            for (size_t i = 0; i < f.size(); ++i) {
                if (f[i] == "t") col_t = int(i);
                if (f[i] == "roll") col_roll = int(i);
                if (f[i] == "pitch") col_pitch = int(i);
                if (f[i] == "yaw") col_yaw = int(i);
            }
            if (col_t < 0 || col_roll < 0 || col_pitch < 0 || col_yaw < 0) {
                fprintf(stderr,
                        "score: %s: line %ld: header must name the columns t,roll,pitch,yaw, got '%s'\n",
                        opt.estimate.c_str(), line_no, line.c_str());
                return 2;
            }
            n_cols = f.size();
            continue;
        }
        double t, roll, pitch, yaw;
        if (f.size() < n_cols || !parse_number(f[col_t], t) || !parse_number(f[col_roll], roll) ||
            !parse_number(f[col_pitch], pitch) || !parse_number(f[col_yaw], yaw)) {
            fprintf(stderr, "score: %s: line %ld: expected %zu comma-separated numbers, got '%s'\n",
                    opt.estimate.c_str(), line_no, n_cols, line.c_str());
            return 2;
        }
        if (!std::isfinite(t) || !std::isfinite(roll) || !std::isfinite(pitch) || !std::isfinite(yaw)) {
            fprintf(stderr, "score: %s: line %ld: the estimate is not finite: '%s'\n",
                    opt.estimate.c_str(), line_no, line.c_str());
            return 2;
        }
        ++rows;
        if (t < opt.skip_s || t < t_first || t > t_last) continue;
        const sim::TrajectorySample truth = traj.at(t);
        const score::Quat q_true{truth.quat[0], truth.quat[1], truth.quat[2], truth.quat[3]};
        if ((!truth.movement && !opt.all_rows) || !score::quat_finite(q_true)) continue;
        const score::ErrorAngles e =
            score::error_angles(q_true, score::quat_from_euler_deg(roll, pitch, yaw));
        acc.add(e);
        if (series)
            fprintf(series, "%.4f,%.4f,%.4f,%.4f\n", t, score::rad2deg(e.total_rad),
                    score::rad2deg(e.inclination_rad), score::rad2deg(e.heading_rad));
    }
    if (series) fclose(series);
    if (col_t < 0) {
        fprintf(stderr, "score: %s: empty, no header t,roll,pitch,yaw\n", opt.estimate.c_str());
        return 2;
    }
    if (acc.samples() == 0) {
        fprintf(stderr,
                "score: none of the %ld estimate rows counts (t >= %.3f within 0..%.3f s, finite truth, "
                "movement = 1)\n",
                rows, opt.skip_s, traj.duration_s());
        return 3;
    }
    if (opt.csv) {
        printf("total_rmse_deg,incl_rmse_deg,heading_rmse_deg,samples,max_total_deg\n");
        printf("%.4f,%.4f,%.4f,%ld,%.4f\n", acc.total_rmse_deg(), acc.incl_rmse_deg(),
               acc.heading_rmse_deg(), acc.samples(), acc.max_total_deg());
    } else {
        printf("total_rmse_deg=%.3f incl_rmse_deg=%.3f heading_rmse_deg=%.3f samples=%ld max_total_deg=%.3f\n",
               acc.total_rmse_deg(), acc.incl_rmse_deg(), acc.heading_rmse_deg(), acc.samples(),
               acc.max_total_deg());
    }
    return 0;
}
