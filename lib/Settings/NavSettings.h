// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation's settings as the second EEPROM record keeps them (VehicleSettings::nav):
// ArduPlane's names, each in the smallest type its range and step allow (29 bytes), and
// lib/Mission's nav_params() (NavParams.h) turns them into the float parameters lib/Nav's
// L1Control and Tecs and lib/Mission's MissionExecutor hold references to.
#pragma once

#include <stdint.h>


namespace settings {

struct NavSettings {
    uint8_t navl1_period_s;        // NAVL1_PERIOD: s, 1..60
    uint8_t navl1_damping_c;       // NAVL1_DAMPING: hundredths, 0.6..1.0
    uint8_t tecs_clmb_max_d;       // TECS_CLMB_MAX: tenths of m/s, 0.1..20
    uint8_t tecs_sink_min_d;       // TECS_SINK_MIN: tenths of m/s, 0.1..10
    uint8_t tecs_time_const_d;     // TECS_TIME_CONST: tenths of s, 3..10
    uint8_t tecs_thr_damp_d;       // TECS_THR_DAMP: tenths, 0.1..1
    uint8_t tecs_integ_gain_c;     // TECS_INTEG_GAIN: hundredths, 0..0.5
    uint8_t tecs_vert_acc_d;       // TECS_VERT_ACC: tenths of m/s^2, 1..10
    uint8_t tecs_hgt_omega_t;      // TECS_HGT_OMEGA: twentieths of rad/s, 1..5
    uint8_t tecs_spd_omega_c;      // TECS_SPD_OMEGA: hundredths of rad/s, 0.5..2
    uint8_t tecs_rll2thr;          // TECS_RLL2THR: 5..30
    uint8_t tecs_spdweight_d;      // TECS_SPDWEIGHT: tenths, 0..2
    uint8_t tecs_ptch_damp_d;      // TECS_PTCH_DAMP: tenths, 0..1
    uint8_t tecs_sink_max_d;       // TECS_SINK_MAX: tenths of m/s, 0..20
    int16_t wp_radius_m;           // WP_RADIUS: m, 1..32767
    int16_t wp_loiter_rad_m;       // WP_LOITER_RAD: m, negative counter-clockwise
    int16_t alt_hold_rtl_cm;       // ALT_HOLD_RTL: cm above home, -1 the height RTL starts at
    uint16_t glide_slope_min_m;    // GLIDE_SLOPE_MIN: m, 0..1000
    uint8_t thr_min_pct;           // THR_MIN: %
    uint8_t thr_max_pct;           // THR_MAX: %
    uint8_t trim_throttle_pct;     // TRIM_THROTTLE: %
    uint8_t fbwb_climb_rate_m_s;   // FBWB_CLIMB_RATE: m/s at full stick, 1..10
    uint8_t fs_long_actn;          // FS_LONG_ACTN: 0 continue (AUTO) else RTL, 1 RTL, 2 glide
    uint16_t fs_long_timeout_s;    // FS_LONG_TIMEOUT: s, 1..300
};

// FS_LONG_ACTN's values (ArduPlane 3.x).
constexpr uint8_t kFsLongContinue = 0;
constexpr uint8_t kFsLongRtl = 1;
constexpr uint8_t kFsLongGlide = 2;


}  // namespace settings
