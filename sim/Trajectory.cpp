// SPDX-License-Identifier: GPL-3.0-or-later
#include "Trajectory.h"

#include <cstdio>

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace sim {

static bool parse_double(const char*& p, double& out) {
    while (*p == ' ') ++p;
    if (strncmp(p, "nan", 3) == 0 || strncmp(p, "NaN", 3) == 0) {
        out = NAN;
        p += 3;
        return true;
    }
    char* end = nullptr;
    out = strtod(p, &end);
    if (end == p) return false;
    p = end;
    return true;
}

namespace {

// The columns after qz, by their header names: index into the row's values, or -1.
struct OptionalColumns {
    int movement = -1;
    int ned[3] = {-1, -1, -1};
    int count = 14;  // numbers read from a row: up to the last column used (the rest ignored)
};

// Reads the header's names after the 14 fixed ones. False with `why` on a bad header.
bool parse_optional_columns(const char* header, OptionalColumns& out, std::string& why) {
    std::string text(header);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    std::vector<std::string> names;
    size_t start = 0;
    for (;;) {
        const size_t comma = text.find(',', start);
        names.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    out = OptionalColumns();
    static const char* const kNed[3] = {"n", "e", "d"};
    for (int i = 14; i < (int)names.size(); ++i) {
        std::string name = names[(size_t)i];
        while (!name.empty() && name.front() == ' ') name.erase(0, 1);
        while (!name.empty() && name.back() == ' ') name.pop_back();
        int* slot = nullptr;
        if (name == "movement") slot = &out.movement;
        for (int k = 0; k < 3; ++k)
            if (name == kNed[k]) slot = &out.ned[k];
        if (!slot) continue;  // a column of someone else's: skipped
        if (*slot >= 0) {
            why = "column '" + name + "' twice";
            return false;
        }
        *slot = i;
        if (i + 1 > out.count) out.count = i + 1;
    }
    const int ned_given = (out.ned[0] >= 0) + (out.ned[1] >= 0) + (out.ned[2] >= 0);
    if (ned_given != 0 && ned_given != 3) {
        why = "the position needs all three columns n,e,d";
        return false;
    }
    return true;
}

}  // namespace

bool Trajectory::load(const std::string& path) {
    samples_.clear();
    cursor_ = 0;
    has_position_ = false;
    gzFile f = gzopen(path.c_str(), "rb");  // reads plain files too
    if (!f) {
        error_ = "cannot open trajectory '" + path + "'";
        return false;
    }
    char line[4096];
    size_t line_no = 0;
    OptionalColumns columns;
    std::vector<double> v;
    bool ok = true;
    while (gzgets(f, line, sizeof line)) {
        ++line_no;
        if (line_no == 1) {
            if (strncmp(line, "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz", 40) != 0) {
                error_ = path + ": line 1: header is not t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz[,movement][,n,e,d]";
                ok = false;
                break;
            }
            std::string why;
            if (!parse_optional_columns(line, columns, why)) {
                error_ = path + ": line 1: " + why;
                ok = false;
                break;
            }
            has_position_ = columns.ned[0] >= 0;
            v.assign((size_t)columns.count, 0.0);
            continue;
        }
        if (line[0] == '\n' || line[0] == '\r' || line[0] == 0) continue;
        TrajectorySample s;
        const int n = columns.count;
        const char* p = line;
        for (int i = 0; i < n; ++i) {
            if (!parse_double(p, v[(size_t)i]) || (i + 1 < n && *p++ != ',')) {
                error_ = path + ": line " + std::to_string(line_no) + ": expected " +
                         std::to_string(n) + " numbers";
                ok = false;
                break;
            }
        }
        if (!ok) break;
        s.t_s = v[0];
        for (int i = 0; i < 3; ++i) {
            s.gyro_rad_s[i] = v[(size_t)(1 + i)];
            s.accel_m_s2[i] = v[(size_t)(4 + i)];
            s.mag_uT[i] = v[(size_t)(7 + i)];
            if (has_position_) s.ned_m[i] = v[(size_t)columns.ned[i]];
        }
        for (int i = 0; i < 4; ++i) s.quat[i] = v[(size_t)(10 + i)];
        s.movement = columns.movement >= 0 ? v[(size_t)columns.movement] != 0.0 : true;
        if (has_position_ && !(std::isfinite(s.ned_m[0]) && std::isfinite(s.ned_m[1]) && std::isfinite(s.ned_m[2]))) {
            error_ = path + ": line " + std::to_string(line_no) + ": n,e,d must be numbers";
            ok = false;
            break;
        }
        if (!samples_.empty() && !(s.t_s >= samples_.back().t_s)) {
            error_ = path + ": line " + std::to_string(line_no) + ": time goes backwards";
            ok = false;
            break;
        }
        samples_.push_back(s);
    }
    gzclose(f);
    if (ok && samples_.empty()) {
        error_ = path + ": no samples";
        ok = false;
    }
    if (!ok) samples_.clear();
    if (ok && has_position_) derive_velocity();
    return ok;
}

// The velocity of a file's positions: the central difference between the neighbours
// (the one-sided one at the ends; zero where two samples share a time).
void Trajectory::derive_velocity() {
    const size_t n = samples_.size();
    for (size_t k = 0; k < n; ++k) {
        const TrajectorySample& a = samples_[k > 0 ? k - 1 : k];
        const TrajectorySample& b = samples_[k + 1 < n ? k + 1 : k];
        const double span = b.t_s - a.t_s;
        for (int i = 0; i < 3; ++i) samples_[k].vel_ned_m_s[i] = span > 0.0 ? (b.ned_m[i] - a.ned_m[i]) / span : 0.0;
    }
}

void Trajectory::drop_before(double t_s) {
    size_t keep_from = 0;
    while (keep_from + 1 < samples_.size() && samples_[keep_from + 1].t_s <= t_s) ++keep_from;
    if (keep_from == 0) return;
    samples_.erase(samples_.begin(), samples_.begin() + (long)keep_from);
    cursor_ = 0;
}

std::string format_trajectory_row(const TrajectorySample& s) {
    const double sign = s.quat[0] < 0 ? -1.0 : 1.0;  // q and -q are one orientation
    char row[320];
    std::snprintf(row, sizeof row, "%.6f,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.9f,%.9f,%.9f,%.9f,%d\n", s.t_s,
                  s.gyro_rad_s[0], s.gyro_rad_s[1], s.gyro_rad_s[2], s.accel_m_s2[0], s.accel_m_s2[1],
                  s.accel_m_s2[2], s.mag_uT[0], s.mag_uT[1], s.mag_uT[2], sign * s.quat[0], sign * s.quat[1],
                  sign * s.quat[2], sign * s.quat[3], s.movement ? 1 : 0);
    return row;
}

std::string format_trajectory_row_ned(const TrajectorySample& s) {
    std::string row = format_trajectory_row(s);
    row.pop_back();  // the newline
    char ned[96];
    std::snprintf(ned, sizeof ned, ",%.3f,%.3f,%.3f\n", s.ned_m[0], s.ned_m[1], s.ned_m[2]);
    return row + ned;
}

TrajectorySample Trajectory::at(double t_s) const {
    if (samples_.empty()) return TrajectorySample{};
    if (t_s <= samples_.front().t_s) return samples_.front();
    if (t_s >= samples_.back().t_s) return samples_.back();
    if (cursor_ >= samples_.size() || samples_[cursor_].t_s > t_s) cursor_ = 0;
    while (cursor_ + 1 < samples_.size() && samples_[cursor_ + 1].t_s <= t_s) ++cursor_;
    const TrajectorySample& a = samples_[cursor_];
    const TrajectorySample& b = samples_[cursor_ + 1];
    const double span = b.t_s - a.t_s;
    const double w = span > 0.0 ? (t_s - a.t_s) / span : 0.0;
    TrajectorySample s = (w < 0.5) ? a : b;  // quaternion and movement: nearest
    s.t_s = t_s;
    for (int i = 0; i < 3; ++i) {
        s.gyro_rad_s[i] = a.gyro_rad_s[i] + w * (b.gyro_rad_s[i] - a.gyro_rad_s[i]);
        s.accel_m_s2[i] = a.accel_m_s2[i] + w * (b.accel_m_s2[i] - a.accel_m_s2[i]);
        s.mag_uT[i] = a.mag_uT[i] + w * (b.mag_uT[i] - a.mag_uT[i]);
        s.ned_m[i] = a.ned_m[i] + w * (b.ned_m[i] - a.ned_m[i]);
        s.vel_ned_m_s[i] = a.vel_ned_m_s[i] + w * (b.vel_ned_m_s[i] - a.vel_ned_m_s[i]);
    }
    return s;
}

}  // namespace sim
