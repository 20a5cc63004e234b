// SPDX-License-Identifier: GPL-3.0-or-later
// Where the simulated board is on the earth, for the GPS and barometer models.
//
// The physics backend and the trajectory files give positions in metres north, east and
// down (NED) of an origin, `--home LAT,LON,ALT_M` (ALT_M above mean sea level). The origin's
// tangent plane is taken as flat (the backend's own frame is flat: its "down" never bends),
// and mapped to latitude and longitude with the WGS-84 ellipsoid's radii of curvature at the
// origin:
//   lat = lat0 + n / (R_M + h0),  lon = lon0 + e / ((R_N + h0) cos lat0),  alt = alt0 - d
//   R_M = a (1 - e^2) / (1 - e^2 sin^2 lat0)^1.5,  R_N = a / sqrt(1 - e^2 sin^2 lat0)
// (the radii are lib/Nav/Wgs84.h's: the firmware's navigation uses the same map). Within
// a few kilometres of the origin this is the local-level frame to millimetres in latitude
// and longitude (the map's own error grows as distance^2 / R: 0.08 m at 1 km, a property
// of the flat frame, which the backend shares); ECEF (NAV-SOL) from the WGS-84 ellipsoid
// exactly.
//
// Heights: ALT_M and the backend's -d are above mean sea level (hMSL). The ellipsoid
// height is hMSL + kGeoidSeparation_m, a constant of this model (not EGM96's value at the
// field): non-zero so that a driver that takes NAV-POSLLH `height` for `hMSL` is visibly off.
//
// The barometer's air: the International Standard Atmosphere's troposphere (ICAO Doc 7488;
// below 11 km), with the height above mean sea level as the geopotential height:
//   p = 101325 Pa (1 - 2.25577e-5 h)^5.25588,  T = 15 degC - 0.0065 h
#pragma once

#include "Wgs84.h"

namespace sim {

constexpr double kWgs84A_m = nav::wgs84::kA_m;   // semi-major axis
constexpr double kWgs84E2 = nav::wgs84::kE2;     // first eccentricity squared
constexpr double kGeoidSeparation_m = 10.0;             // ellipsoid height - hMSL (this model's)

struct GeodeticPoint {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    double alt_m = 0.0;  // above mean sea level
};

// The thesis' field (../shared: the default of --home).
constexpr double kHomeLat_deg = 7.135045;
constexpr double kHomeLon_deg = -73.119421;
constexpr double kHomeAlt_m = 1028.0;

class LocalFrame {
public:
    explicit LocalFrame(const GeodeticPoint& home);
    const GeodeticPoint& home() const { return home_; }
    // NED metres from the origin to latitude, longitude, height above mean sea level.
    GeodeticPoint to_geodetic(const double ned_m[3]) const;
    // The inverse (the same flat map).
    void to_ned(const GeodeticPoint& p, double ned_m[3]) const;

private:
    GeodeticPoint home_;
    double m_per_rad_lat_, m_per_rad_lon_;
};

// WGS-84 geodetic (ellipsoid height) to earth-centred earth-fixed, metres.
void geodetic_to_ecef(double lat_deg, double lon_deg, double ellipsoid_height_m, double ecef_m[3]);
// A NED vector at (lat, lon) in ECEF axes.
void ned_to_ecef_vector(double lat_deg, double lon_deg, const double ned[3], double ecef[3]);

// The International Standard Atmosphere below 11 km (height above mean sea level, m).
double isa_pressure_pa(double alt_m);
double isa_temperature_c(double alt_m);
double isa_altitude_m(double pressure_pa);  // the inverse of isa_pressure_pa

}  // namespace sim
