// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/Location: offsets between places, precise to 1e-7 deg far from (0, 0), across
// the antimeridian, and the same map as the simulator's truth (sim/models/Geodesy).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "Geodesy.h"
#include "Location.h"

namespace {

nav::Location at(double lat_deg, double lon_deg, double alt_m = 0.0) {
    nav::Location l;
    l.lat_e7 = (int32_t)std::lround(lat_deg * 1e7);
    l.lon_e7 = (int32_t)std::lround(lon_deg * 1e7);
    l.alt_cm = (int32_t)std::lround(alt_m * 100.0);
    return l;
}

// The thesis' field.
const nav::Location kField = at(7.135045, -73.119421, 1028.0);

TEST(Location, OneUnitIsACentimetreAtTheField) {
    const nav::LocalMap map(kField);
    nav::Location b = kField;
    b.lat_e7 += 1;
    b.lon_e7 += 1;
    const nav::NorthEast d = map.offset_m(kField, b);
    // 1e-7 deg: 1.106 cm north (meridian radius at 7 deg), 1.104 cm east (x cos 7.1 deg).
    EXPECT_NEAR(d.north_m, 0.011060, 0.00002);
    EXPECT_NEAR(d.east_m, 0.011045, 0.00002);
}

TEST(Location, OneUnitSurvivesAtLargeCoordinates) {
    // 89.9999999 N, 179.9999999 E: as floats these would be rounded to 64 units (7 m).
    const nav::Location a = at(60.0, 179.9999999);
    nav::Location b = a;
    b.lat_e7 += 1;
    const nav::LocalMap map(a);
    EXPECT_NEAR(map.offset_m(a, b).north_m, 0.01116, 0.0001);
    EXPECT_FLOAT_EQ(map.offset_m(a, b).east_m, 0.0f);
    const nav::Location far_south = at(-89.0, -179.0);
    nav::Location c = far_south;
    c.lat_e7 -= 3;
    EXPECT_NEAR(nav::LocalMap(far_south).offset_m(far_south, c).north_m, -0.0335, 0.0002);
}

TEST(Location, AcrossTheAntimeridianTheShortWay) {
    const nav::Location west = at(10.0, -179.9999);  // 0.0002 deg apart across 180
    const nav::Location east = at(10.0, 179.9999);
    const nav::LocalMap map(west);
    const nav::NorthEast d = map.offset_m(west, east);
    EXPECT_NEAR(d.east_m, -0.0002 * 111319.5 * std::cos(10.0 * M_PI / 180.0), 0.05);
    EXPECT_NEAR(map.offset_m(east, west).east_m, -d.east_m, 1e-4);
    EXPECT_EQ(nav::longitude_difference_e7(1799999999, -1799999999), -2);
    EXPECT_EQ(nav::longitude_difference_e7(-1799999999, 1799999999), 2);
    EXPECT_EQ(nav::longitude_difference_e7(1800000000, -1800000000), 0);
    EXPECT_EQ(nav::longitude_difference_e7(900000000, -900000000), 1800000000);
    EXPECT_EQ(nav::longitude_difference_e7(-5, 7), -12);
    // Moving east over +180 comes back at -180.
    const nav::Location moved = map.moved(east, 0.0f, 30.0f);
    EXPECT_LT(moved.lon_e7, -1799990000);
    EXPECT_NEAR(map.offset_m(east, moved).east_m, 30.0f, 0.02f);
}

TEST(Location, MovedIsTheInverseOfOffset) {
    const nav::LocalMap map(kField);
    const float moves[][2] = {{0.0f, 0.0f}, {1.0f, -1.0f}, {-350.0f, 420.0f}, {2500.0f, 1800.0f}, {0.04f, 0.04f}};
    for (const auto& m : moves) {
        const nav::Location b = map.moved(kField, m[0], m[1]);
        const nav::NorthEast d = map.offset_m(kField, b);
        EXPECT_NEAR(d.north_m, m[0], 0.006f) << m[0];  // half a unit: 5.5 mm
        EXPECT_NEAR(d.east_m, m[1], 0.006f) << m[1];
        EXPECT_EQ(b.alt_cm, kField.alt_cm);
    }
    // Near a pole the latitude stops at 90 deg.
    const nav::Location pole = at(89.9999, 0.0);
    EXPECT_EQ(nav::LocalMap(pole).moved(pole, 1000.0f, 0.0f).lat_e7, 900000000);
}

TEST(Location, SameMapAsTheSimulatorsTruth) {
    // The simulator turns its NED truth into latitude and longitude with the same WGS-84
    // radii (sim::LocalFrame, in double); the board's float map agrees to a centimetre
    // over a kilometre (a sphere, ArduPilot's LOCATION_SCALING_FACTOR, would be 6 m off
    // in latitude there).
    const sim::LocalFrame frame(sim::GeodeticPoint{7.135045, -73.119421, 1028.0});
    const nav::LocalMap map(kField);
    const double ned[][3] = {{1000.0, 0.0, 0.0}, {0.0, -1000.0, 0.0}, {-700.0, 650.0, -120.0}, {3.0, 4.0, 0.0}};
    for (const auto& p : ned) {
        const sim::GeodeticPoint g = frame.to_geodetic(p);
        const nav::NorthEast d = map.offset_m(kField, at(g.lat_deg, g.lon_deg));
        EXPECT_NEAR(d.north_m, p[0], 0.012) << p[0] << "," << p[1];
        EXPECT_NEAR(d.east_m, p[1], 0.012) << p[0] << "," << p[1];
    }
}

TEST(Location, RoundingHoldsItsRange) {
    EXPECT_EQ(nav::round_to_int32(2.5f), 3);
    EXPECT_EQ(nav::round_to_int32(-2.5f), -3);
    EXPECT_EQ(nav::round_to_int32(-0.4f), 0);
    EXPECT_EQ(nav::round_to_int32(1e12f), 2000000000);
    EXPECT_EQ(nav::round_to_int32(-1e12f), -2000000000);
    EXPECT_EQ(nav::round_to_int32(NAN), 0);
}

}  // namespace

// moved_e7's 32-bit sums against the int64_t arithmetic it replaced (LocalMap::moved's
// before): every latitude and longitude, every step round_to_int32 can give.
namespace {

nav::Location reference_moved_e7(const nav::Location& loc, int32_t north_e7, int32_t east_e7) {
    constexpr int64_t kHalfTurn = 1800000000;
    constexpr int64_t kPole = 900000000;
    nav::Location out = loc;
    int64_t lat = (int64_t)loc.lat_e7 + north_e7;
    int64_t lon = (int64_t)loc.lon_e7 + east_e7;
    if (lat > kPole) lat = kPole;
    else if (lat < -kPole) lat = -kPole;
    if (lon > kHalfTurn) lon -= 2 * kHalfTurn;
    else if (lon < -kHalfTurn) lon += 2 * kHalfTurn;
    out.lat_e7 = (int32_t)lat;
    out.lon_e7 = (int32_t)lon;
    return out;
}

TEST(Location, MovedE7IsTheInt64Sum) {
    const int32_t edges[] = {INT32_MIN, INT32_MIN + 1, -2000000000, -1800000001, -1800000000, -900000001,
                             -900000000, -1, 0, 1, 900000000, 900000001, 1800000000, 1800000001,
                             2000000000, INT32_MAX - 1, INT32_MAX};
    const int32_t steps[] = {-2000000000, -1800000000, -900000000, -1, 0, 1, 900000000, 1800000000, 2000000000};
    std::mt19937 rng(47u);
    auto check = [](int32_t lat, int32_t lon, int32_t n, int32_t e) {
        const nav::Location loc{lat, lon, 12345};
        const nav::Location got = nav::moved_e7(loc, n, e), want = reference_moved_e7(loc, n, e);
        ASSERT_EQ(got.lat_e7, want.lat_e7) << lat << " + " << n;
        ASSERT_EQ(got.lon_e7, want.lon_e7) << lon << " + " << e;
        ASSERT_EQ(got.alt_cm, 12345);
    };
    for (int32_t p : edges)
        for (int32_t s : steps) {
            check(p, p, s, s);
            check(p, -p - 1, s, -s);
        }
    for (int i = 0; i < 200000; ++i) {
        const int32_t n = (int32_t)((int64_t)(rng() % 4000000001u) - 2000000000);
        const int32_t e = (int32_t)((int64_t)(rng() % 4000000001u) - 2000000000);
        check((int32_t)rng(), (int32_t)rng(), n, e);
        check((int32_t)(rng() % 1800000001u) - 900000000, (int32_t)((int64_t)(rng() % 3600000001u) - 1800000000), n, e);
    }
}

}  // namespace
