// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/Navigator: home's rule, the height above home from the barometer (else the
// GPS), the position moved on by the velocity and the lag, the driver's glitches
// dead-reckoned over, the ground station's home.
#include <gtest/gtest.h>

#include "Navigator.h"

namespace {

const nav::Location kField = [] {
    nav::Location l;
    l.lat_e7 = 71350450;
    l.lon_e7 = -731194210;
    l.alt_cm = 102800;
    return l;
}();
const nav::LocalMap kMap(kField);

// A u-blox fix at (north, east, up) metres from the field, flying at vel (m/s NED).
gps::Fix fix_at(float north_m, float east_m, float up_m, uint32_t received_ms, const float vel[3] = nullptr,
                uint8_t sats = 10, uint16_t hdop_cm = 90) {
    const nav::Location l = kMap.moved(kField, north_m, east_m);
    gps::Fix f;
    f.lat_e7 = l.lat_e7;
    f.lon_e7 = l.lon_e7;
    f.alt_msl_mm = (kField.alt_cm + (int32_t)(up_m * 100.0f)) * 10;
    for (int i = 0; i < 3; ++i) f.vel_ned_cm_s[i] = vel ? (int32_t)(vel[i] * 100.0f) : 0;
    f.received_ms = received_ms;
    f.sats = sats;
    f.hdop_cm = hdop_cm;
    f.fix = gps::FixType::k3D;
    f.have_vertical_velocity = true;
    return f;
}

const nav::BaroReading kNoBaro = {false, 0.0f};

TEST(Navigator, HomeIsTheFirstGoodFix) {
    nav::Navigator n;
    gps::Fix f = fix_at(0.0f, 0.0f, 0.0f, 1000u);
    f.fix = gps::FixType::k2D;
    EXPECT_FALSE(n.on_fix(f, kNoBaro, 6));
    EXPECT_FALSE(n.have_position());
    EXPECT_FALSE(n.on_fix(fix_at(1.0f, 0.0f, 0.0f, 1200u, nullptr, 5), kNoBaro, 6));  // 5 satellites
    EXPECT_TRUE(n.have_position());
    EXPECT_FALSE(n.on_fix(fix_at(1.0f, 0.0f, 0.0f, 1400u, nullptr, 9, 251), kNoBaro, 6));  // hDOP 2.51
    EXPECT_FALSE(n.home_set());
    const gps::Fix good = fix_at(1.0f, 0.5f, 0.0f, 1600u, nullptr, 6, 250);
    EXPECT_TRUE(n.on_fix(good, kNoBaro, 6));
    ASSERT_TRUE(n.home_set());
    EXPECT_EQ(n.home_source(), nav::HomeSource::kGps);
    EXPECT_EQ(n.home().lat_e7, good.lat_e7);
    EXPECT_EQ(n.home().lon_e7, good.lon_e7);
    EXPECT_EQ(n.home().alt_cm, kField.alt_cm);
    EXPECT_EQ(n.home_changes(), 1u);
    // Set once: later fixes do not move it.
    EXPECT_FALSE(n.on_fix(fix_at(30.0f, 0.0f, 0.0f, 6800u), kNoBaro, 6));
    EXPECT_EQ(n.home().lat_e7, good.lat_e7);
    EXPECT_EQ(n.home_changes(), 1u);
    // AHRS_GPS_MINSATS 0 sets it on any 3D fix with a good hDOP.
    nav::Navigator any;
    EXPECT_TRUE(any.on_fix(fix_at(0.0f, 0.0f, 0.0f, 0u, nullptr, 4), kNoBaro, 0));
    // Not from a fix the driver calls a glitch.
    nav::Navigator glitched;
    glitched.on_fix(fix_at(0.0f, 0.0f, 0.0f, 0u, nullptr, 4), kNoBaro, 6);
    gps::Fix jump = fix_at(50.0f, 0.0f, 0.0f, 200u);
    jump.glitching = true;
    EXPECT_FALSE(glitched.on_fix(jump, kNoBaro, 6));
    EXPECT_FALSE(glitched.home_set());
}

TEST(Navigator, PositionMovedOnByVelocityAndLag) {
    nav::Navigator n;
    const float vel[3] = {10.0f, -5.0f, -2.0f};  // climbing 2 m/s
    n.on_fix(fix_at(0.0f, 0.0f, 0.0f, 1000u), kNoBaro, 6);
    n.on_fix(fix_at(100.0f, 50.0f, 20.0f, 13000u, vel), kNoBaro, 6);
    // At the fix's arrival: its position + velocity x 0.2 s (the lag).
    EXPECT_NEAR(n.north_m(), 102.0f, 0.02f);
    EXPECT_NEAR(n.east_m(), 49.0f, 0.02f);
    EXPECT_NEAR(n.height_above_home_m(), 20.4f, 0.02f);
    EXPECT_FALSE(n.height_from_baro());
    // 100 ms later: + velocity x 0.1 s.
    n.update(13100u, kNoBaro);
    EXPECT_NEAR(n.north_m(), 103.0f, 0.02f);
    EXPECT_NEAR(n.east_m(), 48.5f, 0.02f);
    EXPECT_NEAR(n.height_above_home_m(), 20.6f, 0.02f);
    // A GPS gone quiet is moved on for kMaxExtrapolation_ms only.
    n.update(70000u, kNoBaro);
    EXPECT_NEAR(n.north_m(), 100.0f + 10.0f * 1.2f, 0.02f);
    EXPECT_NEAR(n.velocity_ned_m_s()[2], -2.0f, 1e-6f);
}

TEST(Navigator, HeightAboveHomeFromTheBarometer) {
    nav::Navigator n;
    // The barometer reads 0.4 m at home (its start-up level was lower); the GPS says 1028 m.
    n.on_fix(fix_at(0.0f, 0.0f, 0.0f, 1000u), {true, 0.4f}, 6);
    ASSERT_TRUE(n.home_set());
    EXPECT_NEAR(n.height_above_home_m(), 0.0f, 0.011f);
    EXPECT_TRUE(n.height_from_baro());
    // Later the GPS's height is 3 m off (its noise): the barometer's is taken.
    n.on_fix(fix_at(0.0f, 0.0f, 53.0f, 2000u), {true, 50.4f}, 6);
    EXPECT_NEAR(n.height_above_home_m(), 50.0f, 0.011f);
    EXPECT_EQ(n.position().alt_cm, kField.alt_cm + 5000);
    n.update(2100u, {true, 51.4f});
    EXPECT_NEAR(n.height_above_home_m(), 51.0f, 0.011f);
    // The barometer fails: the GPS's (53 m, still).
    n.update(2200u, kNoBaro);
    EXPECT_FALSE(n.height_from_baro());
    EXPECT_NEAR(n.height_above_home_m(), 53.0f, 0.011f);
}

TEST(Navigator, ABarometerThatComesLateIsTiedToTheGps) {
    nav::Navigator n;
    n.on_fix(fix_at(0.0f, 0.0f, 0.0f, 1000u), kNoBaro, 6);
    ASSERT_TRUE(n.home_set());
    n.on_fix(fix_at(0.0f, 0.0f, 10.0f, 2000u), {true, 7.0f}, 6);  // datum: GPS 10 m at baro 7 m
    EXPECT_NEAR(n.height_above_home_m(), 10.0f, 0.011f);
    n.update(2100u, {true, 8.0f});
    EXPECT_NEAR(n.height_above_home_m(), 11.0f, 0.011f);
}

TEST(Navigator, AGlitchIsDeadReckonedOverAndRecovered) {
    nav::Navigator n;
    float vel[3] = {20.0f, 0.0f, 0.0f};
    uint32_t t = 1000;
    float north = 0.0f;
    n.on_fix(fix_at(north, 0.0f, 0.0f, t, vel), kNoBaro, 6);
    // 2 s of a 50 m jump north (the driver flags it), flying north at 20 m/s, 1 m/s faster
    // each fix: the fixes' own velocities carry the position on.
    for (int i = 0; i < 10; ++i) {
        t += 200;
        north += 0.2f * (vel[0] + 0.5f);
        vel[0] += 1.0f;
        gps::Fix f = fix_at(north + 50.0f, 0.0f, 0.0f, t, vel);
        f.glitching = true;
        n.on_fix(f, kNoBaro, 6);
        EXPECT_NEAR(n.north_m(), north + 0.2f * vel[0], 0.05f) << i;  // the truth + 0.2 s of lag
    }
    EXPECT_EQ(n.glitched_fixes(), 10u);
    t += 200;
    north += 4.0f;
    n.on_fix(fix_at(north, 0.0f, 0.0f, t, vel), kNoBaro, 6);
    EXPECT_NEAR(n.north_m(), north + 0.2f * vel[0], 0.05f);
    EXPECT_EQ(n.glitched_fixes(), 10u);
}

TEST(Navigator, TheGroundStationsHome) {
    nav::Navigator n;
    EXPECT_FALSE(n.set_home_here(kNoBaro));  // no position yet
    n.on_fix(fix_at(0.0f, 0.0f, 0.0f, 1000u, nullptr, 4), {true, 0.0f}, 6);  // too few satellites for home
    ASSERT_FALSE(n.home_set());
    n.on_fix(fix_at(10.0f, 0.0f, 5.0f, 5000u, nullptr, 4), {true, 5.0f}, 6);
    ASSERT_TRUE(n.set_home_here({true, 5.0f}));
    EXPECT_EQ(n.home_source(), nav::HomeSource::kGroundStation);
    EXPECT_NEAR(n.north_m(), 0.0f, 0.01f);
    EXPECT_NEAR(n.height_above_home_m(), 0.0f, 0.011f);
    // A good fix later does not take home back.
    EXPECT_FALSE(n.on_fix(fix_at(10.0f, 0.0f, 5.0f, 5200u), {true, 5.0f}, 6));
    EXPECT_EQ(n.home_source(), nav::HomeSource::kGroundStation);
    // A place 100 m south, 20 m below.
    nav::Location there = kMap.moved(kField, -90.0f, 0.0f);
    there.alt_cm = kField.alt_cm - 1500;
    ASSERT_TRUE(n.set_home(there, {true, 5.0f}));
    EXPECT_NEAR(n.north_m(), 100.0f, 0.02f);
    EXPECT_NEAR(n.height_above_home_m(), 20.0f, 0.011f);
    EXPECT_EQ(n.home_changes(), 2u);
    nav::Location off_earth = there;
    off_earth.lat_e7 = 900000001;
    EXPECT_FALSE(n.set_home(off_earth, kNoBaro));
    off_earth = there;
    off_earth.alt_cm = 3000000;
    EXPECT_FALSE(n.set_home(off_earth, kNoBaro));
    EXPECT_EQ(n.home_changes(), 2u);
}

}  // namespace
