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

Location moved_e7(const Location& loc, int32_t north_e7, int32_t east_e7) {
    // A move near the antimeridian or a pole may leave int32's range before it is wrapped
    // (longitude) or held (latitude) back into it. Not in int64_t (avr-gcc expands each
    // 64-bit addition and comparison inline: ~860 bytes here): the 32-bit sum's overflow
    // says where the true sum is, beyond +-2^31 and so beyond +-90 and +-180 deg.
    constexpr int32_t kHalfTurn = 1800000000;
    constexpr int32_t kPole = 900000000;
    constexpr int32_t kTurnPast32 = 694967296;  // 2^32 - 3.6e9: a turn, less the wrap
    Location out = loc;
    int32_t lat;
    if (__builtin_add_overflow(loc.lat_e7, north_e7, &lat)) lat = north_e7 > 0 ? kPole : -kPole;
    else if (lat > kPole) lat = kPole;
    else if (lat < -kPole) lat = -kPole;
    int32_t lon;
    if (__builtin_add_overflow(loc.lon_e7, east_e7, &lon)) {
        // The true sum is lon +- 2^32; less (more) a turn it is lon +- (2^32 - 3.6e9).
        lon = east_e7 > 0 ? lon + kTurnPast32 : lon - kTurnPast32;
    } else if (lon > kHalfTurn) {
        lon = (lon - kHalfTurn) - kHalfTurn;  // each step within int32
    } else if (lon < -kHalfTurn) {
        lon = (lon + kHalfTurn) + kHalfTurn;
    }
    out.lat_e7 = lat;
    out.lon_e7 = lon;
    return out;
}

Location LocalMap::moved(const Location& loc, float north_m, float east_m) const {
    return moved_e7(loc, round_to_int32(north_m * e7_per_north_m_), round_to_int32(east_m * e7_per_east_m_));
}

}  // namespace nav
