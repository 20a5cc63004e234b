// SPDX-License-Identifier: GPL-3.0-or-later
#include "Location.h"

#include "Constants.h"
#include "Wgs84.h"

namespace nav {

int32_t longitude_difference_e7(int32_t a_e7, int32_t b_e7) {
    // Unsigned arithmetic wraps modulo 2^32 where int32's would overflow; a difference
    // beyond 180 deg goes the other way round (360 deg = 3.6e9 units).
    constexpr uint32_t kFullTurn = 3600000000u;
    constexpr uint32_t kHalfTurn = 1800000000u;
    if ((a_e7 < 0) == (b_e7 < 0)) return a_e7 - b_e7;  // same sign: no overflow
    if (a_e7 >= 0) {  // a east, b west: a - b in 0..3.6e9
        const uint32_t d = (uint32_t)a_e7 + (uint32_t)(-(b_e7 + 1)) + 1u;
        return d <= kHalfTurn ? (int32_t)d : -(int32_t)(kFullTurn - d);
    }
    const uint32_t d = (uint32_t)b_e7 + (uint32_t)(-(a_e7 + 1)) + 1u;  // b - a
    return d <= kHalfTurn ? -(int32_t)d : (int32_t)(kFullTurn - d);
}

void LocalMap::set_origin(const Location& origin) {
    constexpr float kRadPerE7 = linalg::kRadPerDeg * 1e-7f;
    float north_m_per_rad, east_m_per_rad;
    wgs84::metres_per_radian((float)origin.lat_e7 * kRadPerE7, (float)origin.alt_cm * 0.01f, north_m_per_rad,
                             east_m_per_rad);
    north_m_per_e7_ = north_m_per_rad * kRadPerE7;
    east_m_per_e7_ = east_m_per_rad * kRadPerE7;
    e7_per_north_m_ = 1.0f / north_m_per_e7_;
    // At a pole a degree of longitude has no length: no east offset can be mapped there.
    e7_per_east_m_ = east_m_per_e7_ > 1e-9f ? 1.0f / east_m_per_e7_ : 0.0f;
}

NorthEast LocalMap::offset_m(const Location& from, const Location& to) const {
    // int32 differences first (see the header): a latitude difference cannot overflow
    // (|lat| <= 9e8), a longitude one goes the short way round.
    const int32_t dlat = to.lat_e7 - from.lat_e7;
    const int32_t dlon = longitude_difference_e7(to.lon_e7, from.lon_e7);
    return NorthEast{(float)dlat * north_m_per_e7_, (float)dlon * east_m_per_e7_};
}

int32_t round_to_int32(float x) {
    if (x != x) return 0;  // NaN: no move
    if (x <= -2.0e9f) return -2000000000;
    if (x >= 2.0e9f) return 2000000000;
    return (int32_t)(x < 0.0f ? x - 0.5f : x + 0.5f);
}

Location LocalMap::moved(const Location& loc, float north_m, float east_m) const {
    Location out = loc;
    // In 64 bits: a move near the antimeridian or a pole may leave int32's range before
    // it is wrapped (longitude) or held (latitude) back into it.
    constexpr int64_t kHalfTurn = 1800000000;
    constexpr int64_t kPole = 900000000;
    int64_t lat = (int64_t)loc.lat_e7 + round_to_int32(north_m * e7_per_north_m_);
    int64_t lon = (int64_t)loc.lon_e7 + round_to_int32(east_m * e7_per_east_m_);
    if (lat > kPole) lat = kPole;
    else if (lat < -kPole) lat = -kPole;
    if (lon > kHalfTurn) lon -= 2 * kHalfTurn;
    else if (lon < -kHalfTurn) lon += 2 * kHalfTurn;
    out.lat_e7 = (int32_t)lat;
    out.lon_e7 = (int32_t)lon;
    return out;
}

}  // namespace nav
