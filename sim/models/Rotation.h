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

// The board mounted in the airframe at ArduPilot's Rotation r (AHRS_ORIENTATION, 0..37:
// MAVLink's MAV_SENSOR_ORIENTATION names them by roll, pitch, yaw): the firmware turns
// the board's vectors by M = Rz(yaw) Ry(pitch) Rx(roll) into the airframe's, so the
// sensors on the board read M^T times the airframe's (apm25sim --orientation).
constexpr int kBoardRotations = 38;
inline bool board_rotation_rpy(int r, double rpy_deg[3]) {
    static const short kRpy[kBoardRotations][3] = {
        {0, 0, 0},    {0, 0, 45},    {0, 0, 90},   {0, 0, 135},  {0, 0, 180},   {0, 0, 225},  {0, 0, 270},
        {0, 0, 315},  {180, 0, 0},   {180, 0, 45}, {180, 0, 90}, {180, 0, 135}, {0, 180, 0},  {180, 0, 225},
        {180, 0, 270}, {180, 0, 315}, {90, 0, 0},  {90, 0, 45},  {90, 0, 90},   {90, 0, 135}, {270, 0, 0},
        {270, 0, 45}, {270, 0, 90},  {270, 0, 135}, {0, 90, 0},  {0, 270, 0},   {0, 180, 90}, {0, 180, 270},
        {90, 90, 0},  {180, 90, 0},  {270, 90, 0}, {90, 180, 0}, {270, 180, 0}, {90, 270, 0}, {180, 270, 0},
        {270, 270, 0}, {90, 180, 90}, {90, 0, 270}};
    if (r < 0 || r >= kBoardRotations) return false;
    for (int i = 0; i < 3; ++i) rpy_deg[i] = kRpy[r][i];
    return true;
}
// v <- M^T v for the board at rpy_deg (roll, pitch, yaw) in the airframe.
inline void airframe_to_board(const double rpy_deg[3], double v[3]) {
    const double d = 3.14159265358979323846 / 180.0;
    const Quat q = from_euler(rpy_deg[0] * d, rpy_deg[1] * d, rpy_deg[2] * d);
    double out[3];
    earth_to_body(q, v, out);  // q's R^T v
    for (int i = 0; i < 3; ++i) v[i] = out[i];
}

}  // namespace sim
