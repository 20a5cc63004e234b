// SPDX-License-Identifier: GPL-3.0-or-later
// A place on the earth as the GPS and MAVLink give it (ArduPilot's Location: latitude and
// longitude in 1e-7 degrees, height in cm above mean sea level), and the offsets between
// two places in metres north and east on the flat local map of the WGS-84 ellipsoid at
// an origin (Wgs84.h), as ArduPilot's location_diff and location_offset.
//
// Precision: a float has 24 bits, and a latitude of 7 degrees is 7e7 units of 1e-7 deg
// (~1 cm): as a float it would be rounded to 8 units, far from the equator to 64. So the
// two places are subtracted as int32 first (exact), and only the difference (within
// 2^24 units, 180 km, exactly) becomes a float.
#pragma once

#include <stdint.h>

namespace nav {

struct Location {
    int32_t lat_e7 = 0;  // degrees * 1e7, north positive
    int32_t lon_e7 = 0;  // degrees * 1e7, east positive
    int32_t alt_cm = 0;  // above mean sea level
};

// a - b in 1e-7 degrees of longitude, the short way round (across +-180 deg too).
int32_t longitude_difference_e7(int32_t a_e7, int32_t b_e7);

struct NorthEast {
    float north_m;
    float east_m;
};

// The local map at an origin: metres per 1e-7 degree north and east (its latitude's
// WGS-84 radii of curvature and its height, Wgs84.h). Set once per origin: a sine, a
// cosine and a square root.
class LocalMap {
public:
    LocalMap() = default;
    explicit LocalMap(const Location& origin) { set_origin(origin); }
    void set_origin(const Location& origin);
    bool valid() const { return north_m_per_e7_ > 0.0f; }
    float north_m_per_e7() const { return north_m_per_e7_; }
    float east_m_per_e7() const { return east_m_per_e7_; }

    // Metres north and east from `from` to `to` (location_diff(from, to)).
    NorthEast offset_m(const Location& from, const Location& to) const;
    // `loc` moved by north_m, east_m (location_offset), rounded to the nearest 1e-7 deg;
    // the height is not changed.
    Location moved(const Location& loc, float north_m, float east_m) const;

private:
    float north_m_per_e7_ = 0.0f;
    float east_m_per_e7_ = 0.0f;
    float e7_per_north_m_ = 0.0f;  // the inverses: a multiply, not a divide, per move
    float e7_per_east_m_ = 0.0f;
};

// Rounds to the nearest integer (half away from zero), held within +-2e9; NaN gives 0.
int32_t round_to_int32(float x);

// `loc` moved by north_e7, east_e7 (|each| <= 2e9, round_to_int32's): the latitude held
// within +-90 deg, the longitude wrapped once by a turn beyond +-180 deg (LocalMap::moved).
Location moved_e7(const Location& loc, int32_t north_e7, int32_t east_e7);

}  // namespace nav
