// SPDX-License-Identifier: GPL-3.0-or-later
// The orientation error metric of the BROAD dataset (Laidig et al., "BROAD - A
// Benchmark for Robust Inertial Orientation Estimation", Data 6(7):72, 2021), as
// used by build/score and the benchmark. Host-only, header-only, double precision.
//
// Quaternions are scalar first (w, x, y, z) and rotate body -> earth (north-east-
// down). For a true orientation q_t and an estimate q_e:
//   e_body  = q_t^-1 * q_e          the error seen in the (true) body frame
//   e_earth = q_t * e_body * q_t^-1 = q_e * q_t^-1, the same rotation seen in the earth frame
// total error       = rotation angle of e (the same in either frame)
// heading error     = the part of e_earth about the earth's vertical:
//                     2 atan(|z| / |w|) of e_earth
// inclination error = the rest, 2 acos(sqrt(w^2 + z^2)) of e_earth: the angle between the
//                     estimated and the true vertical (gravity direction) in the body frame.
// The split does not depend on whether the vertical points up (ENU) or down (NED).
#pragma once

#include <cmath>

#include "Constants.h"

namespace score {

struct Quat {
    double w, x, y, z;
};

inline Quat quat_mul(const Quat& a, const Quat& b) {
    return Quat{a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
                a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

inline Quat quat_conj(const Quat& q) { return Quat{q.w, -q.x, -q.y, -q.z}; }

inline double quat_norm(const Quat& q) {
    return std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}

inline Quat quat_normalized(const Quat& q) {
    const double n = quat_norm(q);
    return Quat{q.w / n, q.x / n, q.y / n, q.z / n};
}

inline bool quat_finite(const Quat& q) {
    return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) &&
           quat_norm(q) > 1e-9;
}

inline double deg2rad(double d) { return d * linalg::dbl::kRadPerDeg; }
inline double rad2deg(double r) { return r * linalg::dbl::kDegPerRad; }

// Body -> earth quaternion of aerospace Z-Y-X Euler angles: R = Rz(yaw) Ry(pitch) Rx(roll),
// i.e. q = q_z(yaw) * q_y(pitch) * q_x(roll).
inline Quat quat_from_euler_deg(double roll_deg, double pitch_deg, double yaw_deg) {
    const double hr = 0.5 * deg2rad(roll_deg), hp = 0.5 * deg2rad(pitch_deg),
                 hy = 0.5 * deg2rad(yaw_deg);
    const Quat qz{std::cos(hy), 0.0, 0.0, std::sin(hy)};
    const Quat qy{std::cos(hp), 0.0, std::sin(hp), 0.0};
    const Quat qx{std::cos(hr), std::sin(hr), 0.0, 0.0};
    return quat_mul(quat_mul(qz, qy), qx);
}

// Rotation angle of a unit quaternion, radians, 0..pi (q and -q are the same rotation).
inline double rotation_angle_rad(const Quat& q) {
    double c = std::fabs(q.w) / quat_norm(q);
    if (c > 1.0) c = 1.0;
    return 2.0 * std::acos(c);
}

struct ErrorAngles {
    double total_rad;
    double inclination_rad;
    double heading_rad;
};

// The dataset's error split for one sample; both quaternions body -> earth.
inline ErrorAngles error_angles(const Quat& q_true, const Quat& q_est) {
    const Quat e = quat_normalized(quat_mul(quat_normalized(q_est), quat_conj(quat_normalized(q_true))));
    ErrorAngles out;
    out.total_rad = rotation_angle_rad(e);
    const double aw = std::fabs(e.w), az = std::fabs(e.z);
    // heading: rotation about the vertical; atan2 keeps w = 0 finite (pi).
    out.heading_rad = 2.0 * std::atan2(az, aw);
    double c = std::sqrt(e.w * e.w + e.z * e.z);
    if (c > 1.0) c = 1.0;
    out.inclination_rad = 2.0 * std::acos(c);
    return out;
}

// Root mean square of the three error angles over the samples that count.
class RmseAccumulator {
public:
    void add(const ErrorAngles& e) {
        sum_total_ += e.total_rad * e.total_rad;
        sum_incl_ += e.inclination_rad * e.inclination_rad;
        sum_heading_ += e.heading_rad * e.heading_rad;
        if (e.total_rad > max_total_) max_total_ = e.total_rad;
        ++n_;
    }
    long samples() const { return n_; }
    double total_rmse_deg() const { return rms_deg(sum_total_); }
    double incl_rmse_deg() const { return rms_deg(sum_incl_); }
    double heading_rmse_deg() const { return rms_deg(sum_heading_); }
    double max_total_deg() const { return rad2deg(max_total_); }

private:
    double rms_deg(double sum) const { return n_ ? rad2deg(std::sqrt(sum / n_)) : NAN; }
    double sum_total_ = 0, sum_incl_ = 0, sum_heading_ = 0, max_total_ = 0;
    long n_ = 0;
};

}  // namespace score
