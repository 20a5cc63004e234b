// SPDX-License-Identifier: GPL-3.0-or-later
// Vector maths on the local map's north-east plane (NorthEast, Location.h), as ArduPilot's
// Vector2f does for L1: x north, y east; `cross(a, b)` is Vector2f's `a % b`
// (a.north b.east - a.east b.north: positive when b lies clockwise of a, seen from above).
// Bearings are clockwise from north; a unit vector (cos b, sin b) stands for bearing b,
// so the guidance needs no trigonometry per step.
#pragma once

#include <math.h>

#include "LinAlg.h"
#include "Location.h"

namespace nav {

inline NorthEast ne(float north_m, float east_m) { return NorthEast{north_m, east_m}; }
inline NorthEast operator+(const NorthEast& a, const NorthEast& b) { return ne(a.north_m + b.north_m, a.east_m + b.east_m); }
inline NorthEast operator-(const NorthEast& a, const NorthEast& b) { return ne(a.north_m - b.north_m, a.east_m - b.east_m); }
inline NorthEast operator*(const NorthEast& a, float k) { return ne(a.north_m * k, a.east_m * k); }
inline float dot(const NorthEast& a, const NorthEast& b) { return a.north_m * b.north_m + a.east_m * b.east_m; }
inline float cross(const NorthEast& a, const NorthEast& b) { return a.north_m * b.east_m - a.east_m * b.north_m; }
inline float length_squared(const NorthEast& a) { return dot(a, a); }
inline float length(const NorthEast& a) { return sqrtf(dot(a, a)); }
// a turned clockwise by the angle whose cosine and sine are c, s.
inline NorthEast rotated(const NorthEast& a, float c, float s) {
    return ne(a.north_m * c - a.east_m * s, a.north_m * s + a.east_m * c);
}
// Bearing of a direction, radians clockwise from north, -pi..pi (one atan2: for telemetry).
inline float bearing_rad(const NorthEast& a) { return linalg::fast_atan2(a.east_m, a.north_m); }

}  // namespace nav
