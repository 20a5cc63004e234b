// SPDX-License-Identifier: GPL-3.0-or-later
#include "Trajectory.h"

#include <cstdio>

#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <cstring>

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

bool Trajectory::load(const std::string& path) {
    samples_.clear();
    cursor_ = 0;
    gzFile f = gzopen(path.c_str(), "rb");  // reads plain files too
    if (!f) {
        error_ = "cannot open trajectory '" + path + "'";
        return false;
    }
    char line[4096];
    size_t line_no = 0;
    bool has_movement = false;
    bool ok = true;
    while (gzgets(f, line, sizeof line)) {
        ++line_no;
        if (line_no == 1) {
            if (strncmp(line, "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz", 40) != 0) {
                error_ = path + ": line 1: header is not t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz[,movement]";
                ok = false;
                break;
            }
            has_movement = strstr(line, "movement") != nullptr;
            continue;
        }
        if (line[0] == '\n' || line[0] == '\r' || line[0] == 0) continue;
        TrajectorySample s;
        double v[15];
        const int n = has_movement ? 15 : 14;
        const char* p = line;
        for (int i = 0; i < n; ++i) {
            if (!parse_double(p, v[i]) || (i + 1 < n && *p++ != ',')) {
                error_ = path + ": line " + std::to_string(line_no) + ": expected " +
                         std::to_string(n) + " numbers";
                ok = false;
                break;
            }
        }
        if (!ok) break;
        s.t_s = v[0];
        for (int i = 0; i < 3; ++i) {
            s.gyro_rad_s[i] = v[1 + i];
            s.accel_m_s2[i] = v[4 + i];
            s.mag_uT[i] = v[7 + i];
        }
        for (int i = 0; i < 4; ++i) s.quat[i] = v[10 + i];
        s.movement = has_movement ? v[14] != 0.0 : true;
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
    return ok;
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
    }
    return s;
}

}  // namespace sim
