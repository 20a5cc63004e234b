// SPDX-License-Identifier: GPL-3.0-or-later
#include "NavParams.h"

namespace mission {

namespace {
// Divided, not multiplied by 0.1f: the nearest float to the decimal, as PARAM_VALUE shows it.
float tenths(uint8_t v) { return (float)v / 10.0f; }
float hundredths(uint8_t v) { return (float)v / 100.0f; }
}  // namespace

void nav_params(const settings::NavSettings& n, const flight::FlightSettings& f, nav::L1Params& l1,
                nav::TecsParams& tecs, ExecutorParams& ex) {
    l1.period_s = (float)n.navl1_period_s;
    l1.damping = hundredths(n.navl1_damping_c);
    tecs.time_const_s = tenths(n.tecs_time_const_d);
    tecs.clmb_max_m_s = tenths(n.tecs_clmb_max_d);
    tecs.sink_min_m_s = tenths(n.tecs_sink_min_d);
    tecs.sink_max_m_s = tenths(n.tecs_sink_max_d);
    tecs.thr_damp = tenths(n.tecs_thr_damp_d);
    tecs.integ_gain = hundredths(n.tecs_integ_gain_c);
    tecs.ptch_damp = tenths(n.tecs_ptch_damp_d);
    tecs.spdweight = tenths(n.tecs_spdweight_d);
    tecs.rll2thr = (float)n.tecs_rll2thr;
    tecs.hgt_omega_rad_s = (float)n.tecs_hgt_omega_t / 20.0f;
    tecs.spd_omega_rad_s = hundredths(n.tecs_spd_omega_c);
    tecs.vert_acc_m_s2 = tenths(n.tecs_vert_acc_d);
    tecs.pitch_max_cd = f.lim_pitch_max_cd;
    tecs.pitch_min_cd = f.lim_pitch_min_cd;
    // THR_MIN above THR_MAX (each in range alone) would invert TECS's throttle range.
    tecs.thr_max_pct = n.thr_max_pct;
    tecs.thr_min_pct = n.thr_min_pct <= n.thr_max_pct ? n.thr_min_pct : n.thr_max_pct;
    tecs.trim_throttle_pct = n.trim_throttle_pct;
    tecs.arspd_min_m_s = f.arspd_min_m_s;
    tecs.arspd_max_m_s = f.arspd_max_m_s;
    ex.wp_radius_m = (float)n.wp_radius_m;
    ex.loiter_radius_m = n.wp_loiter_rad_m;
    ex.rtl_alt_cm = n.alt_hold_rtl_cm;
    ex.glide_slope_min_m = (float)n.glide_slope_min_m;
}

}  // namespace mission
