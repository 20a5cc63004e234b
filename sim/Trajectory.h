// SPDX-License-Identifier: GPL-3.0-or-later
// Trajectory files (../shared/SIM.md): CSV, optionally gzip-compressed, header
// `t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz[,movement][,n,e,d]`, body frame x forward,
// y right, z down; rad/s, m/s^2, uT; quaternion body->earth (NED), scalar first.
// The optional columns after qz are found by their names in the header, in any order:
// `movement`, and `n,e,d` (all three or none), the position in metres north, east and
// down from the origin (apm25sim --home), for the GPS and barometer models; the velocity
// is their central difference. Other named columns after qz are skipped.
// Host-only (simulator, replay, scorer); read once into memory.
#pragma once

#include <stddef.h>
#include <string>
#include <vector>

namespace sim {

struct TrajectorySample {
    double t_s;
    double gyro_rad_s[3];
    double accel_m_s2[3];
    double mag_uT[3];
    double quat[4];   // w, x, y, z; NaN where unknown
    bool movement;    // counts in error metrics
    // Position from the origin and velocity, NED (m, m/s): the `n,e,d` columns or the
    // physics backend's `position` and `velocity`; zero (at rest at the origin) without.
    double ned_m[3] = {0.0, 0.0, 0.0};
    double vel_ned_m_s[3] = {0.0, 0.0, 0.0};
};

// The header and one row as the project writes them (scenario, apm25sim --physics-log):
// t to six decimals, the sensor values to seven significant digits, the quaternion to nine
// decimals with its scalar part made >= 0.
constexpr const char* kTrajectoryHeader = "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,movement\n";
std::string format_trajectory_row(const TrajectorySample& s);
// The same with the position (apm25sim --physics-log): `...,movement,n,e,d`, metres to 3
// decimals.
constexpr const char* kTrajectoryHeaderNed = "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,movement,n,e,d\n";
std::string format_trajectory_row_ned(const TrajectorySample& s);

class Trajectory {
public:
    // Loads FILE (.csv or .csv.gz, detected by content). On failure returns false and
    // sets error() to a sentence naming the file and the line.
    bool load(const std::string& path);
    const std::string& error() const { return error_; }
    size_t size() const { return samples_.size(); }
    const TrajectorySample& operator[](size_t i) const { return samples_[i]; }
    double duration_s() const { return samples_.empty() ? 0.0 : samples_.back().t_s; }

    // Linear interpolation of the physical values at time t (held at both ends), the
    // position and velocity included. The quaternion is taken from the nearest sample
    // (not interpolated).
    TrajectorySample at(double t_s) const;

    std::vector<TrajectorySample>& samples() { return samples_; }
    // The file had n,e,d columns.
    bool has_position() const { return has_position_; }

    // Appends a sample at or after the last one (the physics link's states as they come).
    void append(const TrajectorySample& s) { samples_.push_back(s); }
    // Forgets the samples before t_s but the last one before it (still needed to
    // interpolate at t_s), so that a long live run keeps a bounded history.
    void drop_before(double t_s);

private:
    void derive_velocity();

    std::vector<TrajectorySample> samples_;
    std::string error_;
    bool has_position_ = false;
    mutable size_t cursor_ = 0;  // speeds up monotonic at() calls
};

}  // namespace sim
