// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation's parameter rows (settings::NavSettings, Params.cpp): ArduPlane's names and
// defaults, the Scaled8 rows' bytes and steps, and nav_params() giving lib/Nav's and
// lib/Mission's float parameters the defaults docs/navigation.md lists (their own kDefaults).
#include <gtest/gtest.h>

#include "NavParams.h"
#include "Params.h"
#include "Settings.h"

namespace {

uint16_t index_of(const char* name) {
    const int16_t i = params::find(name);
    EXPECT_GE(i, 0) << name;
    return (uint16_t)i;
}

settings::Settings defaults() {
    settings::Settings s{};
    params::apply_defaults(s);
    return s;
}

TEST(NavParams, DefaultsAreLibNavsAndLibMissions) {
    settings::Settings s = defaults();
    s.flight.lim_pitch_max_cd = nav::kTecsDefaults.pitch_max_cd;  // STABILIZE's row, 2500 by default here
    nav::L1Params l1{};
    nav::TecsParams t{};
    mission::ExecutorParams ex{};
    mission::nav_params(s.vehicle.nav, s.flight, l1, t, ex);
    EXPECT_EQ(l1.period_s, nav::kL1Defaults.period_s);
    EXPECT_EQ(l1.damping, nav::kL1Defaults.damping);
    const nav::TecsParams& d = nav::kTecsDefaults;
    EXPECT_EQ(t.time_const_s, d.time_const_s);
    EXPECT_EQ(t.clmb_max_m_s, d.clmb_max_m_s);
    EXPECT_EQ(t.sink_min_m_s, d.sink_min_m_s);
    EXPECT_EQ(t.sink_max_m_s, d.sink_max_m_s);
    EXPECT_EQ(t.thr_damp, d.thr_damp);
    EXPECT_EQ(t.integ_gain, d.integ_gain);
    EXPECT_EQ(t.ptch_damp, d.ptch_damp);
    EXPECT_EQ(t.spdweight, d.spdweight);
    EXPECT_EQ(t.rll2thr, d.rll2thr);
    EXPECT_EQ(t.hgt_omega_rad_s, d.hgt_omega_rad_s);
    EXPECT_EQ(t.spd_omega_rad_s, d.spd_omega_rad_s);
    EXPECT_EQ(t.vert_acc_m_s2, d.vert_acc_m_s2);
    EXPECT_EQ(t.pitch_max_cd, d.pitch_max_cd);
    EXPECT_EQ(t.pitch_min_cd, d.pitch_min_cd);
    EXPECT_EQ(t.thr_min_pct, d.thr_min_pct);
    EXPECT_EQ(t.thr_max_pct, d.thr_max_pct);
    EXPECT_EQ(t.trim_throttle_pct, d.trim_throttle_pct);
    EXPECT_EQ(t.arspd_min_m_s, d.arspd_min_m_s);
    EXPECT_EQ(t.arspd_max_m_s, d.arspd_max_m_s);
    const mission::ExecutorParams& e = mission::kExecutorDefaults;
    EXPECT_EQ(ex.wp_radius_m, e.wp_radius_m);
    EXPECT_EQ(ex.loiter_radius_m, e.loiter_radius_m);
    EXPECT_EQ(ex.rtl_alt_cm, e.rtl_alt_cm);
    EXPECT_EQ(ex.glide_slope_min_m, e.glide_slope_min_m);
    EXPECT_EQ(s.vehicle.nav.fbwb_climb_rate_m_s, 2u);
    EXPECT_EQ(s.vehicle.nav.fs_long_actn, settings::kFsLongContinue);
    EXPECT_EQ(s.vehicle.nav.fs_long_timeout_s, 20u);
}

TEST(NavParams, ScaledRowsKeepTheirStepInAByte) {
    settings::Settings s = defaults();
    const uint16_t damping = index_of("NAVL1_DAMPING");
    params::Info in;
    ASSERT_TRUE(params::info(damping, in));
    EXPECT_EQ(in.type, params::Type::Scaled8);
    EXPECT_FALSE(params::is_integer(in.type));
    EXPECT_EQ(params::get(s, damping), 0.75f);
    EXPECT_EQ(s.vehicle.nav.navl1_damping_c, 75u);
    ASSERT_TRUE(params::set(s, damping, 0.85f));
    EXPECT_EQ(s.vehicle.nav.navl1_damping_c, 85u);
    EXPECT_EQ(params::get(s, damping), 0.85f);  // the nearest float to the decimal, as sent
    EXPECT_FALSE(params::set(s, damping, 1.05f));
    EXPECT_FALSE(params::set(s, damping, 0.5f));
    EXPECT_EQ(s.vehicle.nav.navl1_damping_c, 85u);  // a refusal changes nothing
    // The top of each range fits its byte: 20 m/s in tenths, 5 rad/s in twentieths.
    ASSERT_TRUE(params::set(s, index_of("TECS_CLMB_MAX"), 20.0f));
    EXPECT_EQ(s.vehicle.nav.tecs_clmb_max_d, 200u);
    ASSERT_TRUE(params::set(s, index_of("TECS_HGT_OMEGA"), 5.0f));
    EXPECT_EQ(s.vehicle.nav.tecs_hgt_omega_t, 100u);
    ASSERT_TRUE(params::set(s, index_of("TECS_HGT_OMEGA"), 2.05f));
    EXPECT_EQ(params::get(s, index_of("TECS_HGT_OMEGA")), 2.05f);
    ASSERT_TRUE(params::set(s, index_of("TECS_INTEG_GAIN"), 0.0f));
    EXPECT_EQ(s.vehicle.nav.tecs_integ_gain_c, 0u);
    EXPECT_TRUE(params::all_valid(s));
}

TEST(NavParams, IntegerRowsInTheirUnits) {
    settings::Settings s = defaults();
    ASSERT_TRUE(params::set(s, index_of("WP_LOITER_RAD"), -80.0f));
    EXPECT_EQ(s.vehicle.nav.wp_loiter_rad_m, -80);
    ASSERT_TRUE(params::set(s, index_of("ALT_HOLD_RTL"), -1.0f));
    EXPECT_EQ(s.vehicle.nav.alt_hold_rtl_cm, -1);
    EXPECT_FALSE(params::set(s, index_of("ALT_HOLD_RTL"), -2.0f));
    EXPECT_FALSE(params::set(s, index_of("WP_RADIUS"), 0.0f));
    EXPECT_FALSE(params::set(s, index_of("THR_MAX"), 101.0f));
    EXPECT_FALSE(params::set(s, index_of("FS_LONG_ACTN"), 3.0f));
    EXPECT_FALSE(params::set(s, index_of("FS_LONG_TIMEOUT"), 0.0f));
    EXPECT_TRUE(params::set(s, index_of("FS_LONG_TIMEOUT"), 300.0f));
}

TEST(NavParams, ThrottleMinimumAboveMaximumIsHeldToIt) {
    settings::Settings s = defaults();
    ASSERT_TRUE(params::set(s, index_of("THR_MIN"), 80.0f));
    nav::L1Params l1{};
    nav::TecsParams t{};
    mission::ExecutorParams ex{};
    mission::nav_params(s.vehicle.nav, s.flight, l1, t, ex);
    EXPECT_EQ(t.thr_min_pct, 75u);
    EXPECT_EQ(t.thr_max_pct, 75u);
}

TEST(NavParams, TheirRowsTake29BytesOfTheSecondRecord) {
    // The rows from NAVL1_PERIOD to FS_LONG_TIMEOUT, each its type's bytes.
    unsigned bytes = 0;
    for (uint16_t i = index_of("NAVL1_PERIOD"); i <= index_of("FS_LONG_TIMEOUT"); ++i) {
        params::Info in;
        ASSERT_TRUE(params::info(i, in));
        bytes += in.type == params::Type::Int16 || in.type == params::Type::UInt16 ? 2u : 1u;
        EXPECT_NE(in.type, params::Type::Float) << in.name;
    }
    EXPECT_EQ(bytes, 29u);
    const uint16_t with = params::vehicle_bytes();
    EXPECT_LE(with, 244u);
    // Each row's value in the record: the record's bytes move with it.
    settings::Settings s = defaults();
    ASSERT_TRUE(params::set(s, index_of("FS_LONG_TIMEOUT"), 123.0f));
    uint8_t rec[244];
    params::vehicle_part(s, 0, (uint8_t)with, rec);
    settings::Settings t = defaults();
    params::decode_vehicle(rec, (uint8_t)with, t);
    EXPECT_EQ(t.vehicle.nav.fs_long_timeout_s, 123u);
}

}  // namespace
