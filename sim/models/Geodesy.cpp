// SPDX-License-Identifier: GPL-3.0-or-later
#include "Geodesy.h"

#include <cmath>

#include "Wgs84.h"

namespace sim {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
// ISA troposphere (ICAO Doc 7488): p0 101325 Pa, T0 288.15 K, lapse 0.0065 K/m,
// exponent g M / (R L) = 5.25588.
constexpr double kIsaP0_pa = 101325.0;
constexpr double kIsaK_per_m = 2.25577e-5;  // L / T0
constexpr double kIsaExponent = 5.25588;

}  // namespace

LocalFrame::LocalFrame(const GeodeticPoint& home) : home_(home) {
    // The board's own map (lib/Nav/Wgs84.h), in double.
    nav::wgs84::metres_per_radian(home.lat_deg * kDegToRad, home.alt_m + kGeoidSeparation_m, m_per_rad_lat_,
                                  m_per_rad_lon_);
}

GeodeticPoint LocalFrame::to_geodetic(const double ned_m[3]) const {
    GeodeticPoint p;
    p.lat_deg = home_.lat_deg + ned_m[0] / m_per_rad_lat_ / kDegToRad;
    p.lon_deg = home_.lon_deg + ned_m[1] / m_per_rad_lon_ / kDegToRad;
    p.alt_m = home_.alt_m - ned_m[2];
    return p;
}

void LocalFrame::to_ned(const GeodeticPoint& p, double ned_m[3]) const {
    ned_m[0] = (p.lat_deg - home_.lat_deg) * kDegToRad * m_per_rad_lat_;
    ned_m[1] = (p.lon_deg - home_.lon_deg) * kDegToRad * m_per_rad_lon_;
    ned_m[2] = home_.alt_m - p.alt_m;
}

void geodetic_to_ecef(double lat_deg, double lon_deg, double ellipsoid_height_m, double ecef_m[3]) {
    const double lat = lat_deg * kDegToRad, lon = lon_deg * kDegToRad;
    const double s = std::sin(lat);
    const double n = kWgs84A_m / std::sqrt(1.0 - kWgs84E2 * s * s);
    ecef_m[0] = (n + ellipsoid_height_m) * std::cos(lat) * std::cos(lon);
    ecef_m[1] = (n + ellipsoid_height_m) * std::cos(lat) * std::sin(lon);
    ecef_m[2] = (n * (1.0 - kWgs84E2) + ellipsoid_height_m) * s;
}

void ned_to_ecef_vector(double lat_deg, double lon_deg, const double ned[3], double ecef[3]) {
    const double sl = std::sin(lat_deg * kDegToRad), cl = std::cos(lat_deg * kDegToRad);
    const double so = std::sin(lon_deg * kDegToRad), co = std::cos(lon_deg * kDegToRad);
    ecef[0] = -sl * co * ned[0] - so * ned[1] - cl * co * ned[2];
    ecef[1] = -sl * so * ned[0] + co * ned[1] - cl * so * ned[2];
    ecef[2] = cl * ned[0] - sl * ned[2];
}

double isa_pressure_pa(double alt_m) { return kIsaP0_pa * std::pow(1.0 - kIsaK_per_m * alt_m, kIsaExponent); }

double isa_temperature_c(double alt_m) { return 15.0 - 0.0065 * alt_m; }

double isa_altitude_m(double pressure_pa) {
    return (1.0 - std::pow(pressure_pa / kIsaP0_pa, 1.0 / kIsaExponent)) / kIsaK_per_m;
}

}  // namespace sim
