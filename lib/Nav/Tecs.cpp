// SPDX-License-Identifier: GPL-3.0-or-later
#include "Tecs.h"

#include <string.h>

#include "Constants.h"
#include "LinAlg.h"

namespace nav {

namespace {

using linalg::constrain;
constexpr float kG = linalg::kGravity_m_s2;
constexpr float kStep_s = 0.1f;          // AP_TECS's 10 Hz step, in its rate limits
constexpr float kInvStep = 10.0f;
constexpr float kPitchMargin_rad = 0.0783f;  // the pitch integrator may saturate by 4.5 deg
constexpr float kMinTas_m_s = 3.0f;
constexpr float kRadPerCd = linalg::kRadPerDeg * 0.01f;
constexpr uint32_t kOneBits = 0x3F800000u;  // 1.0f
constexpr uint32_t kNoBits = 0xFFFFFFFFu;   // a NaN: no EAS2TAS yet

float min_of(float a, float b) { return a < b ? a : b; }
float max_of(float a, float b) { return a > b ? a : b; }

}  // namespace

void Tecs::set_params() {
    const TecsParams& p = params_;
    k_.ste_dot_max = p.clmb_max_m_s * kG;
    k_.ste_dot_min = -p.sink_min_m_s * kG;
    k_.thr_max = (float)p.thr_max_pct * 0.01f;
    k_.thr_min = (float)p.thr_min_pct * 0.01f;
    k_.thr_trim = (float)p.trim_throttle_pct * 0.01f;
    const float ste_range = k_.ste_dot_max - k_.ste_dot_min;
    k_.thr_per_ste_dot = ste_range > 0.0f ? (k_.thr_max - k_.thr_min) / ste_range : 0.0f;
    k_.k_ste_to_thr = p.time_const_s > 0.0f ? k_.thr_per_ste_dot / p.time_const_s : 0.0f;
    k_.inv_tc_g = 1.0f / (max_of(p.time_const_s, 0.1f) * kG);
    k_.pitch_max_rad = (float)p.pitch_max_cd * kRadPerCd;
    k_.pitch_min_rad = (float)p.pitch_min_cd * kRadPerCd;
    k_.inv_pitch_max = k_.pitch_max_rad > 0.0f ? 1.0f / k_.pitch_max_rad : 0.0f;
    k_.inv_pitch_min = k_.pitch_min_rad < 0.0f ? 1.0f / k_.pitch_min_rad : 0.0f;
    const float w = p.hgt_omega_rad_s;
    k_.hgt_k1 = w * w * w;
    k_.hgt_k2 = 3.0f * w * w;
    k_.hgt_k3 = 3.0f * w;
    k_.spd_kx = p.spd_omega_rad_s * p.spd_omega_rad_s;
    k_.spd_kv = p.spd_omega_rad_s * 1.4142135f;
    k_.arspd_min = (float)p.arspd_min_m_s;
    k_.arspd_max = max_of((float)p.arspd_max_m_s, k_.arspd_min);
    k_.tas_step_up = 0.5f * k_.ste_dot_max * kStep_s;
    k_.tas_step_down = 0.5f * k_.ste_dot_min * kStep_s;
    k_.hgt_step_up = p.clmb_max_m_s * kStep_s;
    k_.hgt_step_down = p.sink_max_m_s * kStep_s;
    // TECS_SPDWEIGHT within 0..2, then neither weight above 1 (ArduPlane 3.8's AP_TECS;
    // 3.0-3.7 let the height's reach 2 without a pitot, which doubles the pitch loop's
    // gain and feed-forward: twice the flight path a climb rate needs).
    const float ske_w = constrain(p.spdweight, 0.0f, 2.0f);
    k_.spe_w = min_of(2.0f - ske_w, 1.0f);
    k_.ske_w = min_of(ske_w, 1.0f);
    k_.integ_thr_k = p.integ_gain * k_.k_ste_to_thr;
    k_.tc_g = p.time_const_s * kG;
    k_.pitch_max_margin = k_.pitch_max_rad + kPitchMargin_rad;
    k_.pitch_min_margin = k_.pitch_min_rad - kPitchMargin_rad;
    k_.thr_underspeed = k_.thr_max * 0.95f;
    k_.pitch_damped = p.ptch_damp != 0.0f;
    k_.unit_weights = k_.spe_w == 1.0f && k_.ske_w == 1.0f;
    range_.eas2tas_bits = kNoBits;  // the speed range again at the next step
}

void Tecs::refresh_speed_range(float eas2tas) {
    uint32_t bits;
    memcpy(&bits, &eas2tas, sizeof bits);
    if (bits == range_.eas2tas_bits) return;
    range_.eas2tas_bits = bits;
    range_.tas_max = k_.arspd_max * eas2tas;
    range_.tas_min = k_.arspd_min * eas2tas;
    range_.ske_min = 0.5f * range_.tas_min * range_.tas_min;
    range_.ske_max = 0.5f * range_.tas_max * range_.tas_max;
    range_.underspeed_tas = range_.tas_min * 0.9f;
}

float Tecs::tas_of(float eas_m_s, float eas2tas) const {
    return range_.eas2tas_bits == kOneBits ? eas_m_s : eas_m_s * eas2tas;
}

void Tecs::update_50hz(float height_m, float accel_up_m_s2, float accel_fwd_m_s2, float dt_s) {
    if (!filters_started_ || dt_s > 1.0f) {
        height_m_ = height_m;
        climb_m_s_ = 0.0f;
        accel_bias_m_s2_ = 0.0f;
        vel_dot_m_s2_ = accel_fwd_m_s2;
        filters_started_ = true;
        return;
    }
    // Third-order complementary filter, all three poles at omega (Widnall & Sinha),
    // integrated by backward Euler as AP_TECS::update_50hz.
    const float err = height_m - height_m_;
    accel_bias_m_s2_ += err * k_.hgt_k1 * dt_s;
    climb_m_s_ += (accel_bias_m_s2_ + accel_up_m_s2 + err * k_.hgt_k2) * dt_s;
    height_m_ += (climb_m_s_ + err * k_.hgt_k3) * dt_s;
    // AP_TECS takes a 5-point moving average (a 2-sample delay); a first-order low-pass of
    // the same delay keeps one float instead of five.
    vel_dot_m_s2_ += (accel_fwd_m_s2 - vel_dot_m_s2_) * (1.0f / 3.0f);
}

void Tecs::initialise(const TecsInput& in, float tas_m_s) {
    tas_m_s_ = tas_m_s;
    tas_integ_ = 0.0f;
    integ_thr_ = 0.0f;
    integ_pitch_ = 0.0f;
    throttle_dem_ = k_.thr_trim;
    pitch_dem_ = in.pitch_rad;
    hgt_dem_adj_ = height_m_;
    hgt_dem_prev_ = height_m_;
    hgt_dem_in_old_ = height_m_;
    tas_dem_last_ = tas_of(in.eas_dem_m_s, in.eas2tas);
    tas_dem_adj_ = tas_dem_last_;
    ste_dot_err_last_ = 0.0f;
    underspeed_ = false;
    bad_descent_ = false;
    need_reset_ = false;
}

void Tecs::update_speed(const TecsInput& in, float eas_m_s, float dt_s) {
    // Second-order complementary filter: the airspeed with the along-track acceleration.
    const float err = tas_of(eas_m_s, in.eas2tas) - tas_m_s_;
    float integ_in = err * k_.spd_kx;
    if (tas_m_s_ < 3.1f) integ_in = max_of(integ_in, 0.0f);  // no wind-up at standstill
    tas_integ_ += integ_in * dt_s;
    tas_m_s_ += (tas_integ_ + vel_dot_m_s2_ + err * k_.spd_kv) * dt_s;
    tas_m_s_ = max_of(tas_m_s_, kMinTas_m_s);
}

Tecs::Demands Tecs::update_demands(const TecsInput& in, float inv_tas) {
    Demands d;
    // Speed: within ARSPD_FBW_MIN..MAX (the least when underspeed or descending badly),
    // changing no faster than half the energy rate the aircraft has.
    const float tas_min = range_.tas_min, tas_max = range_.tas_max;
    float tas_dem = bad_descent_ || underspeed_ ? tas_min : tas_of(in.eas_dem_m_s, in.eas2tas);
    tas_dem = constrain(tas_dem, tas_min, tas_max);
    const float up_step = k_.tas_step_up * inv_tas;
    const float down_step = k_.tas_step_down * inv_tas;
    const float change = tas_dem - tas_dem_adj_;
    if (change > up_step) {
        tas_dem_adj_ += up_step;
        d.tas_rate = up_step * kInvStep;
    } else if (change < down_step) {
        tas_dem_adj_ += down_step;
        d.tas_rate = down_step * kInvStep;
    } else {
        tas_dem_adj_ = tas_dem;
        d.tas_rate = (tas_dem - tas_dem_last_) * kInvStep;
    }
    tas_dem_adj_ = constrain(tas_dem_adj_, tas_min, tas_max);
    tas_dem_last_ = tas_dem;

    // Height: a 2-point average, the climb within TECS_CLMB_MAX and the sink within
    // TECS_SINK_MAX, then a first-order lag (AP_TECS::_update_height_demand).
    float hgt_dem = 0.5f * (in.height_dem_m + hgt_dem_in_old_);
    hgt_dem_in_old_ = hgt_dem;
    hgt_dem = constrain(hgt_dem, hgt_dem_prev_ - k_.hgt_step_down, hgt_dem_prev_ + k_.hgt_step_up);
    hgt_dem_prev_ = hgt_dem;
    // 0.05 of the way (0.05 new + 0.95 old), and the rate that is over 0.1 s.
    const float change_m = hgt_dem - hgt_dem_adj_;
    hgt_dem_adj_ += 0.05f * change_m;
    d.hgt_rate = (0.05f * kInvStep) * change_m;
    return d;
}

void Tecs::update_pitch_throttle(const TecsInput& in, float dt_s) {
    const float eas = in.have_airspeed ? in.eas_m_s
                                       : 0.5f * (float)(params_.arspd_min_m_s + params_.arspd_max_m_s);
    refresh_speed_range(in.eas2tas);
    if (need_reset_ || dt_s > 1.0f) {
        initialise(in, tas_of(eas, in.eas2tas));
        dt_s = kStep_s;
    }
    update_speed(in, eas, dt_s);
    const float inv_tas = 1.0f / tas_m_s_;  // the step's one divide (and 1/cos^2 in a bank)

    const bool takeoff = in.stage == TecsStage::kTakeoff;
    float pitch_min = k_.pitch_min_rad;
    float thr_min = k_.thr_min;
    if (takeoff) {
        // Climb-out: at least the takeoff pitch, full throttle, the height demand from here.
        pitch_min = min_of((float)in.takeoff_pitch_cd * kRadPerCd, k_.pitch_max_rad);
        thr_min = k_.thr_max - 0.01f;
        hgt_dem_adj_ = height_m_;
        hgt_dem_prev_ = height_m_;
        tas_dem_last_ = tas_of(in.eas_dem_m_s, in.eas2tas);
        tas_dem_adj_ = tas_dem_last_;
        underspeed_ = false;
        bad_descent_ = false;
    }
    const Demands d = update_demands(in, inv_tas);

    // Underspeed: slow at full throttle; held while below the height demand.
    underspeed_ = in.have_airspeed && !takeoff &&
                  ((tas_m_s_ < range_.underspeed_tas && throttle_dem_ >= k_.thr_underspeed) ||
                   (height_m_ < hgt_dem_adj_ && underspeed_));

    // Specific energies (m^2/s^2) and their rates as errors: potential g h, kinetic V^2 / 2.
    const float spe_err = (hgt_dem_adj_ - height_m_) * kG;
    const float spe_dot_dem = d.hgt_rate * kG;
    const float spe_dot = climb_m_s_ * kG;
    if (!in.have_airspeed) {
        update_throttle_without_airspeed(in, thr_min, takeoff ? pitch_min : k_.pitch_min_rad);
        // Pitch holds the height alone: the speed's weight 0, the height's 1.
        update_pitch(in, pitch_min, spe_err, spe_dot_dem, spe_dot_dem - spe_dot, inv_tas, dt_s);
        return;
    }
    const float ske_dem = 0.5f * tas_dem_adj_ * tas_dem_adj_;
    const float ske_err = ske_dem - 0.5f * tas_m_s_ * tas_m_s_;
    const float ske_dot_dem = tas_m_s_ * d.tas_rate;
    const float ske_dot = tas_m_s_ * vel_dot_m_s2_;
    const float ste_dot = spe_dot + ske_dot;

    // Total energy error, its potential part limited to what the speed range can hold.
    const float ste_error = constrain(spe_err, range_.ske_min - ske_dem, range_.ske_max - ske_dem) + ske_err;
    update_throttle(in, thr_min, ste_error, ste_dot, spe_dot_dem + ske_dot_dem, dt_s);
    // Bad descent: a speed demand it cannot reach, sinking at full throttle.
    bad_descent_ = !underspeed_ && ((ste_error > 200.0f && ste_dot < 0.0f && throttle_dem_ >= k_.thr_max * 0.9f) ||
                                    (bad_descent_ && ste_error > 0.0f));

    // Pitch: the energy balance, speed weighted by TECS_SPDWEIGHT (all speed when
    // underspeed or taking off).
    const bool speed_first = underspeed_ || takeoff;
    if (!speed_first && k_.unit_weights) {  // x 1: the same sums without the products
        update_pitch(in, pitch_min, spe_err - ske_err, spe_dot_dem - ske_dot_dem,
                     (spe_dot_dem - spe_dot) - (ske_dot_dem - ske_dot), inv_tas, dt_s);
        return;
    }
    const float spe_w = speed_first ? 0.0f : k_.spe_w;
    const float ske_w = speed_first ? 1.0f : k_.ske_w;
    const float seb_err = spe_err * spe_w - ske_err * ske_w;
    const float seb_dot_dem = spe_dot_dem * spe_w - ske_dot_dem * ske_w;
    const float seb_dot_err = (spe_dot_dem - spe_dot) * spe_w - (ske_dot_dem - ske_dot) * ske_w;
    update_pitch(in, pitch_min, seb_err, seb_dot_dem, seb_dot_err, inv_tas, dt_s);
}

void Tecs::update_throttle(const TecsInput& in, float thr_min, float ste_error, float ste_dot, float ste_dot_dem_raw,
                           float dt_s) {
    float ste_dot_dem = constrain(ste_dot_dem_raw, k_.ste_dot_min, k_.ste_dot_max);
    // The rate error through a 0.5 s low-pass (the accelerometer's noise).
    const float ste_dot_err = ste_dot_err_last_ + 0.2f * (ste_dot_dem - ste_dot - ste_dot_err_last_);
    ste_dot_err_last_ = ste_dot_err;
    if (underspeed_) {
        throttle_dem_ = k_.thr_max;
        return;
    }
    // Feed-forward: TRIM_THROTTLE plus the energy rate asked for, plus the bank's.
    ste_dot_dem += bank_ste_dot(in);
    const float ff = k_.thr_trim + ste_dot_dem * k_.thr_per_ste_dot;
    float thr = (ste_error + ste_dot_err * params_.thr_damp) * k_.k_ste_to_thr + ff;
    thr = constrain(thr, thr_min, k_.thr_max);
    // The integrator may push 10 % beyond the limits (noise), no further.
    const float integ_max = k_.thr_max - thr + 0.1f;
    const float integ_min = thr_min - thr - 0.1f;
    integ_thr_ += ste_error * dt_s * k_.integ_thr_k;
    integ_thr_ = in.stage == TecsStage::kTakeoff ? integ_max : constrain(integ_thr_, integ_min, integ_max);
    throttle_dem_ = constrain(thr + integ_thr_, thr_min, k_.thr_max);
}

void Tecs::update_throttle_without_airspeed(const TecsInput& in, float thr_min, float pitch_min) {
    // TRIM_THROTTLE moved towards THR_MAX or THR_MIN as the (last) pitch demand goes
    // towards LIM_PITCH_MAX or LIM_PITCH_MIN, plus the bank's extra.
    float thr;
    if (in.stage == TecsStage::kTakeoff) {
        thr = k_.thr_max;
    } else if (pitch_dem_ > 0.0f && k_.pitch_max_rad > 0.0f) {
        thr = k_.thr_trim + (k_.thr_max - k_.thr_trim) * pitch_dem_ * k_.inv_pitch_max;
    } else if (pitch_dem_ < 0.0f && pitch_min < 0.0f) {
        thr = k_.thr_trim + (thr_min - k_.thr_trim) * pitch_dem_ * k_.inv_pitch_min;
    } else {
        thr = k_.thr_trim;
    }
    thr += bank_ste_dot(in) * k_.thr_per_ste_dot;
    throttle_dem_ = constrain(thr, thr_min, k_.thr_max);
}

float Tecs::bank_ste_dot(const TecsInput& in) const {
    return params_.rll2thr * (1.0f / constrain(in.cos_bank_sq, 0.1f, 1.0f) - 1.0f);
}

void Tecs::update_pitch(const TecsInput& in, float pitch_min, float seb_err, float seb_dot_dem, float seb_dot_err,
                        float inv_tas, float dt_s) {
    const float pitch_max = k_.pitch_max_rad;
    // Integrator, its input held back while the last demand sat beyond a limit.
    float integ_in = seb_err * params_.integ_gain;
    if (pitch_dem_ > pitch_max) {
        integ_in = min_of(integ_in, pitch_max - pitch_dem_);
    } else if (pitch_dem_ < pitch_min) {
        integ_in = max_of(integ_in, pitch_min - pitch_dem_);
    }
    integ_pitch_ += integ_in * dt_s;
    // Energy balance per radian of pitch: V TECS_TIME_CONST g.
    const float gain_inv = tas_m_s_ * k_.tc_g;
    float temp = seb_err + seb_dot_dem * params_.time_const_s;
    if (k_.pitch_damped) temp += seb_dot_err * params_.ptch_damp;
    if (in.stage == TecsStage::kTakeoff) temp += pitch_min * gain_inv;
    const float pitch_min_margin = in.stage == TecsStage::kTakeoff ? pitch_min - kPitchMargin_rad : k_.pitch_min_margin;
    integ_pitch_ = constrain(integ_pitch_, gain_inv * pitch_min_margin - temp, gain_inv * k_.pitch_max_margin - temp);
    float pitch = constrain((temp + integ_pitch_) * inv_tas * k_.inv_tc_g, pitch_min, pitch_max);
    // No faster than TECS_VERT_ACC allows.
    const float step = dt_s * params_.vert_acc_m_s2 * inv_tas;
    pitch_dem_ = constrain(pitch, pitch_dem_ - step, pitch_dem_ + step);
}

int16_t Tecs::pitch_dem_cd() const { return (int16_t)(pitch_dem_ * linalg::kDegPerRad * 100.0f); }
uint8_t Tecs::throttle_pct() const { return (uint8_t)(throttle_dem_ * 100.0f + 0.5f); }

}  // namespace nav
