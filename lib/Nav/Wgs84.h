// SPDX-License-Identifier: GPL-3.0-or-later
// The WGS-84 ellipsoid near a point: metres per radian of latitude and of longitude, the
// flat local map that both the firmware (lib/Nav, in float) and the simulator
// (sim/models/Geodesy, in double) use between latitude/longitude and metres north/east
// of an origin. One formula, so the board's offsets and the simulated truth's agree:
//   north: R_M + h,  R_M = a (1 - e^2) / (1 - e^2 sin^2 lat)^1.5   (meridian radius)
//   east:  (R_N + h) cos lat,  R_N = a / sqrt(1 - e^2 sin^2 lat)   (prime vertical radius)
// h the height above the ellipsoid. ArduPilot's location_diff uses a sphere of radius a
// (LOCATION_SCALING_FACTOR): 0.6 % long in latitude at 7 deg, 1.9 m over 300 m.
#pragma once

#include <math.h>

namespace nav {
namespace wgs84 {

constexpr double kA_m = 6378137.0;             // semi-major axis
constexpr double kF = 1.0 / 298.257223563;     // flattening
constexpr double kE2 = kF * (2.0 - kF);        // first eccentricity squared

inline float sin_of(float x) { return sinf(x); }
inline double sin_of(double x) { return sin(x); }
inline float cos_of(float x) { return cosf(x); }
inline double cos_of(double x) { return cos(x); }
inline float sqrt_of(float x) { return sqrtf(x); }
inline double sqrt_of(double x) { return sqrt(x); }

// Metres per radian north and east at geodetic latitude lat_rad, height_m above the
// ellipsoid: T is double in the simulator, float on the board.
template <class T>
void metres_per_radian(T lat_rad, T height_m, T& north_m, T& east_m) {
    const T s = sin_of(lat_rad);
    const T w = (T)1 - (T)kE2 * s * s;
    const T root_w = sqrt_of(w);
    north_m = (T)kA_m * ((T)1 - (T)kE2) / (w * root_w) + height_m;
    east_m = ((T)kA_m / root_w + height_m) * cos_of(lat_rad);
}

}  // namespace wgs84
}  // namespace nav
