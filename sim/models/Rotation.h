// SPDX-License-Identifier: GPL-3.0-or-later
// Double-precision quaternions for the host tools (scenario generation, the physics link):
// body -> earth (north-east-down), scalar first, Hamilton product.
#pragma once

#include <cmath>

namespace sim {

// The earth field the scenarios and the physics link place the board in unless told
// otherwise (NED, uT): a Berlin-like 49 uT at 66 deg inclination, declination 0.
constexpr double kEarthFieldNed_uT[3] = {20.0, 0.0, 45.0};

struct Quat {
    double w, x, y, z;
    Quat operator*(const Quat& q) const {
        return Quat{w * q.w - x * q.x - y * q.y - z * q.z, w * q.x + x * q.w + y * q.z - z * q.y,
                    w * q.y - x * q.z + y * q.w + z * q.x, w * q.z + x * q.y - y * q.x + z * q.w};
    }
    Quat conj() const { return Quat{w, -x, -y, -z}; }
};

// A turn of angle_rad about body axis 0 (x), 1 (y) or 2 (z).
inline Quat axis_angle(int axis, double angle_rad) {
    const double c = std::cos(angle_rad / 2), s = std::sin(angle_rad / 2);
    return Quat{c, axis == 0 ? s : 0.0, axis == 1 ? s : 0.0, axis == 2 ? s : 0.0};
}

// The aerospace Z-Y-X sequence (APM25.md "Frames and axes"): R = Rz(yaw) Ry(pitch) Rx(roll).
inline Quat from_euler(double roll_rad, double pitch_rad, double yaw_rad) {
    return axis_angle(2, yaw_rad) * axis_angle(1, pitch_rad) * axis_angle(0, roll_rad);
}

// v_body = R^T v_earth with R the body -> earth rotation of q.
inline void earth_to_body(const Quat& q, const double v[3], double out[3]) {
    const Quat p{0.0, v[0], v[1], v[2]};
    const Quat r = q.conj() * p * q;
    out[0] = r.x;
    out[1] = r.y;
    out[2] = r.z;
}

}  // namespace sim
