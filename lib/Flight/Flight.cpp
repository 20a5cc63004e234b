// SPDX-License-Identifier: GPL-3.0-or-later
#include "Flight.h"

#include "Constants.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#endif

namespace flight {

namespace {

// v held within [lo, hi].
int32_t clamp32(int32_t v, int32_t lo, int32_t hi) { return v < lo ? lo : (v > hi ? hi : v); }

bool bit(uint8_t mask, uint8_t index) { return ((mask >> index) & 1u) != 0u; }

// A stick's command (-4500..4500) as a demanded angle, full stick = limit_cd: |stick x
// limit| (< 2^26) / 4500 as (x >> 7) x (2^24 / 4500) >> 17, within 1 cd and no division.
int32_t demand_cd(int16_t stick_cd, int16_t limit_cd) {
    const int32_t x = (int32_t)stick_cd * limit_cd;
    const uint32_t m = (uint32_t)(x < 0 ? -x : x);
    const int32_t d = (int32_t)(((m >> 7) * 3728u) >> 17);
    return x < 0 ? -d : d;
}

using linalg::kDegPerRad;
using linalg::kGravity_m_s2;
constexpr int32_t kMaxCoordinatedBank_cd = 8000;  // AP_PitchController's limit

}  // namespace

// --- Normalising and end points -----------------------------------------------------

namespace {

// round(num / span), 0 when it would not fit 16 bits (a side too short to scale).
uint16_t factor(uint32_t num, int32_t span) {
    if (span <= 0) return 0;
    const uint32_t f = (num + (uint32_t)span / 2u) / (uint32_t)span;
    return f > 0xFFFFu ? 0 : (uint16_t)f;
}

// (x * f) >> shift rounded, x >= 0.
int32_t scaled(uint16_t x, uint16_t f, uint8_t shift) {
    return (int32_t)(((uint32_t)x * f + (1ul << (shift - 1u))) >> shift);
}

uint16_t clamp_width(int32_t w, const EndPoints& ep) { return (uint16_t)clamp32(w, ep.min_us, ep.max_us); }

}  // namespace

Scale angle_input_scale(const EndPoints& ep) {
    return Scale{factor((uint32_t)kFullThrow_cd << 8, (int32_t)ep.max_us - ep.trim_us),
                 factor((uint32_t)kFullThrow_cd << 8, (int32_t)ep.trim_us - ep.min_us)};
}
Scale throttle_input_scale(const EndPoints& ep) {
    return Scale{factor((uint32_t)kFullThrottle << 8, (int32_t)ep.max_us - ep.min_us), 0};
}
Scale angle_output_scale(const EndPoints& ep) {
    const uint32_t up = (uint32_t)(ep.max_us > ep.trim_us ? ep.max_us - ep.trim_us : 0u) << 16;
    const uint32_t down = (uint32_t)(ep.trim_us > ep.min_us ? ep.trim_us - ep.min_us : 0u) << 16;
    return Scale{factor(up, kFullThrow_cd), factor(down, kFullThrow_cd)};
}
Scale throttle_output_scale(const EndPoints& ep) {
    const uint32_t span = (uint32_t)(ep.max_us > ep.min_us ? ep.max_us - ep.min_us : 0u) << 15;
    return Scale{factor(span, kFullThrottle), 0};
}

int16_t width_to_angle(uint16_t width_us, const EndPoints& ep, Scale sc, bool reversed) {
    const int32_t d = (int32_t)width_us - ep.trim_us;
    // |d| beyond its side's span would only clamp: limited first, so that d x f fits.
    const int32_t a = d >= 0 ? scaled((uint16_t)clamp32(d, 0, 2200), sc.up, 8)
                             : -scaled((uint16_t)clamp32(-d, 0, 2200), sc.down, 8);
    const int32_t c = clamp32(a, -kFullThrow_cd, kFullThrow_cd);
    return (int16_t)(reversed ? -c : c);
}

int16_t width_to_throttle(uint16_t width_us, const EndPoints& ep, Scale sc, bool reversed) {
    const int32_t d = clamp32((int32_t)width_us - ep.min_us, 0, 2200);
    const int32_t t = clamp32(scaled((uint16_t)d, sc.up, 8), 0, kFullThrottle);
    return (int16_t)(reversed ? kFullThrottle - t : t);
}

uint16_t angle_to_width(int16_t angle_cd, const EndPoints& ep, Scale sc, bool reversed) {
    const int32_t a = clamp32(reversed ? -(int32_t)angle_cd : angle_cd, -kFullThrow_cd, kFullThrow_cd);
    const int32_t d = a >= 0 ? scaled((uint16_t)a, sc.up, 16) : -scaled((uint16_t)-a, sc.down, 16);
    return clamp_width(ep.trim_us + d, ep);
}

uint16_t throttle_to_width(int16_t throttle, const EndPoints& ep, Scale sc, bool reversed) {
    int32_t t = clamp32(throttle, 0, kFullThrottle);
    if (reversed) t = kFullThrottle - t;
    return clamp_width(ep.min_us + scaled((uint16_t)t, sc.up, 15), ep);
}

Scales scales_of(const FlightSettings& s) {
    Scales sc;
    for (uint8_t role = 0; role < 4; ++role) {
        const uint8_t ch = s.rcmap[role];
        const EndPoints& ep = s.rc[(ch >= 1u && ch <= kChannels) ? ch - 1u : role];
        sc.in[role] = role == kThrottle ? throttle_input_scale(ep) : angle_input_scale(ep);
        sc.out[role] = role == 2 ? throttle_output_scale(s.servo[role]) : angle_output_scale(s.servo[role]);
    }
    return sc;
}

uint8_t switch_position(uint16_t width_us) {
    // ArduPlane's readSwitch bands.
    if (width_us <= 1230) return 1;
    if (width_us <= 1360) return 2;
    if (width_us <= 1490) return 3;
    if (width_us <= 1620) return 4;
    if (width_us <= 1749) return 5;
    return 6;
}

// --- The attitude controller ----------------------------------------------------------

namespace {

int16_t q(float x, float one) {
    const float v = x * one + 0.5f;
    return v >= 32767.0f ? 32767 : (v <= 0.0f ? 0 : (int16_t)v);
}

// x * f / 2^shift, rounded to the nearest (half away from zero: a left and a right upset
// get mirror-image surfaces); |x| kept within `limit` first so that the product fits 32
// bits.
int32_t mul_shift(int32_t x, int16_t f, uint8_t shift, int32_t limit) {
    const int32_t p = clamp32(x, -limit, limit) * f;
    const int32_t half = shift > 0u ? (int32_t)1 << (shift - 1u) : 0;
    return p >= 0 ? (p + half) >> shift : -((-p + half) >> shift);
}

}  // namespace

AxisTerms axis_terms(const AxisGains& g, float dt_s) {
    float kp_ff = (g.p - g.i * g.tconst_s) * g.tconst_s - g.d;
    if (kp_ff < 0.0f) kp_ff = 0.0f;
    return AxisTerms{q(1.0f / g.tconst_s, 4096.0f), q(kp_ff, 4096.0f), q(g.d, 16384.0f),
                     q(g.i * g.tconst_s * dt_s, 65536.0f), g.imax_cd};
}

int16_t AxisController::step(const AxisTerms& t, int32_t error_cd, int32_t rate_offset_cds, int32_t rate_cds) {
    // Bounds: errors within a turn, rates within 2000 deg/s: every product below 2^31.
    const int32_t desired_cds = mul_shift(error_cd, t.inv_tau_q12, 12, 36000) + rate_offset_cds;
    const int32_t rate_error_cds = clamp32(desired_cds - rate_cds, -400000, 400000);
    if (t.ki_dt_q16 > 0) {
        int32_t delta_q16 = mul_shift(rate_error_cds, t.ki_dt_q16, 0, 400000);
        // A saturated surface: the integrator may only unwind (ArduPilot's anti-windup).
        if ((saturation_ > 0 && delta_q16 > 0) || (saturation_ < 0 && delta_q16 < 0)) delta_q16 = 0;
        const int32_t limit_q16 = (int32_t)t.imax_cd << 16;
        integrator_q16_ = clamp32(integrator_q16_ + delta_q16, -limit_q16, limit_q16);
    } else {
        integrator_q16_ = 0;
    }
    const int32_t out_cd = mul_shift(desired_cds, t.kp_ff_q12, 12, 120000) +
                           mul_shift(rate_error_cds, t.kd_q14, 14, 400000) + (integrator_q16_ >> 16);
    saturation_ = out_cd >= kFullThrow_cd ? 1 : (out_cd <= -kFullThrow_cd ? -1 : 0);
    return (int16_t)clamp32(out_cd, -kFullThrow_cd, kFullThrow_cd);
}

namespace {

#ifdef __AVR__
#define FLIGHT_TABLE PROGMEM
uint16_t table_word(const uint16_t* p) { return pgm_read_word(p); }
#else
#define FLIGHT_TABLE
uint16_t table_word(const uint16_t* p) { return *p; }
#endif

// tan(x) sin(x) at 0, 5.12, ... 81.92 deg (steps of 512 cd: the index a shift), Q12;
// cos(x) at 0, 5.12, ... 92.16 deg, Q15 (0 past 90).
const uint16_t kTanSinQ12[17] FLIGHT_TABLE = {0, 33, 132, 298, 535, 848, 1243, 1732, 2331, 3064, 3970, 5115, 6609, 8668, 11744, 17002, 28566};
const uint16_t kCosQ15[19] FLIGHT_TABLE = {32768, 32637, 32246, 31598, 30697, 29551, 28170, 26564, 24745, 22730, 20533, 18172, 15666, 13035, 10300, 7483, 4606, 1692, 0};

// A table at 512 cd steps, linearly between them, at |angle_cd| (within the table).
uint16_t lookup(const uint16_t* table, int32_t angle_cd) {
    const uint16_t a = (uint16_t)(angle_cd < 0 ? -angle_cd : angle_cd);
    const uint8_t i = (uint8_t)(a >> 9);
    const uint16_t frac = (uint16_t)(a & 511u);
    const int32_t y0 = table_word(table + i);
    if (frac == 0u) return (uint16_t)y0;
    const int32_t y1 = table_word(table + i + 1);
    return (uint16_t)(y0 + (((y1 - y0) * (int32_t)frac) >> 9));
}

}  // namespace

int16_t turn_gain_cds(float airspeed_m_s, float roll_ff) {
    if (airspeed_m_s <= 0.0f) return 0;
    return q(kGravity_m_s2 / airspeed_m_s * kDegPerRad * 100.0f * roll_ff, 1.0f);
}

uint16_t coordination_airspeed_cm_s(const FlightSettings& s, uint16_t measured_cm_s) {
    const uint16_t min_cm_s = (uint16_t)(s.arspd_min_m_s * 100u);
    if (measured_cm_s != 0u) return measured_cm_s > min_cm_s ? measured_cm_s : min_cm_s;
    if (s.trim_arspd_cm != 0u) return s.trim_arspd_cm;
    return (uint16_t)((s.arspd_min_m_s + s.arspd_max_m_s) * 50u);
}

int32_t turn_rate_offset_cds(int32_t roll_cd, int32_t pitch_cd, int16_t gain_cds) {
    if (roll_cd > 9000 || roll_cd < -9000) return 0;  // inverted: no coordination
    const uint16_t f = lookup(kTanSinQ12, clamp32(roll_cd, -kMaxCoordinatedBank_cd, kMaxCoordinatedBank_cd));
    const uint16_t c = lookup(kCosQ15, clamp32(pitch_cd, -9000, 9000));
    return ((((int32_t)gain_cds * f) >> 12) * (int32_t)(c >> 1)) >> 14;
}

// --- The mixer --------------------------------------------------------------------------

namespace {

int16_t clamp_throw(int32_t v) { return (int16_t)clamp32(v, -kFullThrow_cd, kFullThrow_cd); }

// Two surfaces that share two commands, each half of both as ArduPlane's default
// MIXING_GAIN 0.5 (its channel_function_mixer): `minus` takes (a - b) / 2, `plus`
// (a + b) / 2. A positive command is trailing edge up. Elevons (a the elevator, b the
// aileron): the left is `minus`, so that a right roll lowers the left trailing edge and
// raises the right. V-tail (a the elevator, b the rudder): the right is `minus`, so that
// a yaw to the right raises the left trailing edge and lowers the right: each
// ruddervator's force is normal to it, and the two push the tail to the left.
void mix_pair(int16_t a, int16_t b, int16_t& minus, int16_t& plus) {
    minus = clamp_throw(((int32_t)a - b) / 2);
    plus = clamp_throw(((int32_t)a + b) / 2);
}

}  // namespace

void mix(const FlightSettings& s, const Scales& sc, const Surfaces& in, const uint16_t* aux_us,
         uint16_t out_us[kChannels]) {
    int16_t cmd[4] = {in.aileron_cd, in.elevator_cd, 0, in.rudder_cd};
    if (s.elevon_output != 0u) mix_pair(in.elevator_cd, in.aileron_cd, cmd[0], cmd[1]);
    if (s.vtail_output != 0u) mix_pair(in.elevator_cd, in.rudder_cd, cmd[3], cmd[1]);
    for (uint8_t i = 0; i < 4; ++i) {
        const bool rev = bit(s.servo_reversed, i);
        out_us[i] = i == 2 ? throttle_to_width(in.throttle, s.servo[i], sc.out[i], rev)
                           : angle_to_width(cmd[i], s.servo[i], sc.out[i], rev);
    }
    for (uint8_t i = 4; i < kChannels; ++i) {
        const EndPoints& ep = s.servo[i];
        int32_t w = aux_us != nullptr ? aux_us[i - 4] : ep.trim_us;
        if (bit(s.servo_reversed, i)) w = 2 * (int32_t)ep.trim_us - w;
        out_us[i] = clamp_width(w, ep);
    }
}

// --- The modes --------------------------------------------------------------------------

namespace {

// The law of a mode the board has; any other number flies MANUAL.
State state_of(Mode m) {
    const int8_t i = mode_index((uint8_t)m);
    if (i < 0) return State::Manual;
    const Law law = mode_law((uint8_t)i);
    return law == Law::Attitude ? State::Stabilize : navigates(law) ? State::Navigate : State::Manual;
}

}  // namespace

void FlightControl::hold_neutral(uint16_t out_us[kChannels]) const {
    const Surfaces neutral{0, 0, throttle_live_ ? (int16_t)(s_.thr_fs_pct * 10u) : (int16_t)0, 0};
    mix(s_, scales_, neutral, nullptr, out_us);
}

void FlightControl::choose(Mode m) {
    if (!mode_known((uint8_t)m)) m = Mode::Manual;
    const State before = state_of(chosen_);
    chosen_ = m;
    if (state_ == State::Manual || state_ == State::Stabilize || state_ == State::Navigate) {
        if (before != state_of(m)) {
            roll_.reset();
            pitch_.reset();
        }
        state_ = state_of(m);
    }
}

bool FlightControl::override_fresh(uint8_t ch, uint32_t now_ms) const {
    if (override_us_[ch] == 0u || override_timeout_8ms_ == 0u) return false;
    return override_timeout_8ms_ == kOverrideForever ||
           (uint16_t)((uint16_t)(now_ms >> 3) - override_at_[ch]) < override_timeout_8ms_;
}

uint16_t FlightControl::input_us(uint8_t ch, uint32_t now_ms) const {
    return override_fresh(ch, now_ms) ? override_us_[ch] : rc_us_[ch];
}

int16_t FlightControl::stick(uint8_t role, uint32_t now_ms) const {
    const uint8_t ch = (uint8_t)(s_.rcmap[role] - 1u);
    if (ch >= kChannels) return 0;
    const bool rev = bit(s_.rc_reversed, ch);
    const uint16_t w = input_us(ch, now_ms);
    return role == kThrottle ? width_to_throttle(w, s_.rc[ch], scales_.in[role], rev)
                             : width_to_angle(w, s_.rc[ch], scales_.in[role], rev);
}

void FlightControl::read_switch(uint32_t now_ms) {
    const uint8_t ch = s_.fltmode_ch;
    if (ch < 1u || ch > kChannels) return;
    const uint8_t pos = switch_position(input_us((uint8_t)(ch - 1u), now_ms));
    if (pos != switch_pos_) {
        switch_pos_ = pos;
        const Mode before = chosen_;
        const Mode want = (Mode)s_.fltmode[pos - 1u];
        const int8_t row = mode_index((uint8_t)want);
        if (row >= 0 && ((unavailable_ >> row) & 1u) != 0u) {  // kept until the switch moves again (ArduPlane's)
            refused_ = want;
            events_ |= kEvModeRefused;
            return;
        }
        choose(want);
        if (chosen_ != before) events_ |= kEvModeChanged;
    }
}

void FlightControl::on_frame(const uint16_t width_us[kChannels], uint32_t now_ms) {
    for (uint8_t i = 0; i < kChannels; ++i) rc_us_[i] = width_us[i];
    have_frame_ = true;
    last_frame_ms_ = now_ms;
    const uint8_t thr = s_.rcmap[kThrottle];
    // The encoder's failsafe forces the throttle channel low (raw width, as ArduPlane).
    if (thr >= 1u && thr <= kChannels && width_us[thr - 1u] < s_.thr_fs_value_us) return;
    last_good_ms_ = now_ms;
    read_switch(now_ms);
}

void FlightControl::on_override(const uint16_t width_us[kChannels], uint32_t now_ms) {
    if (override_timeout_8ms_ == 0u) return;  // RC_OVERRIDE_TIME 0: overrides off
    for (uint8_t i = 0; i < kChannels; ++i) {
        const uint16_t w = width_us[i];
        if (w == 0u) {
            override_us_[i] = 0;  // back to the receiver
        } else if (w >= 800u && w <= 2200u) {
            override_us_[i] = w;
            override_at_[i] = (uint16_t)(now_ms >> 3);
        }  // UINT16_MAX (ignore) and implausible widths: unchanged
    }
    const uint8_t thr = (uint8_t)(s_.rcmap[kThrottle] - 1u);
    if (!have_frame_ || thr >= kChannels || !override_fresh(thr, now_ms) || override_us_[thr] < s_.thr_fs_value_us)
        return;
    last_good_ms_ = last_frame_ms_ = now_ms;
    read_switch(now_ms);
}

void FlightControl::update_signal(uint32_t now_ms) {
    // Overrides past their time are dropped, before their 8 ms stamps could wrap.
    for (uint8_t i = 0; i < kChannels; ++i)
        if (override_us_[i] != 0u && !override_fresh(i, now_ms)) override_us_[i] = 0;
    if (!have_frame_) return;
    const bool good = now_ms - last_good_ms_ < kSignalTimeoutMs;
    if (!good && state_ != State::Failsafe) {
        const bool frames = now_ms - last_frame_ms_ < kSignalTimeoutMs;
        cause_ = frames ? FailsafeCause::Encoder : FailsafeCause::Lost;
        events_ |= frames ? kEvFailsafeEncoder : kEvFailsafeLost;
        state_ = State::Failsafe;
        roll_.reset();
        pitch_.reset();
    } else if (good && (state_ == State::Failsafe || state_ == State::NoSignal)) {
        if (state_ == State::Failsafe) events_ |= kEvFailsafeEnd;
        cause_ = FailsafeCause::None;
        state_ = state_of(chosen_);
        roll_.reset();
        pitch_.reset();
    }
}

Surfaces FlightControl::stabilize(const Attitude& att, int32_t roll_demand_cd, int32_t pitch_demand_cd) {
    int32_t roll_error_cd = roll_demand_cd - att.roll_cd;
    if (roll_error_cd > 18000) roll_error_cd -= 36000;  // the short way round
    if (roll_error_cd < -18000) roll_error_cd += 36000;
    // g / V again only when the airspeed changed (a division: each new pitot reading).
    const uint16_t v_cm_s = coordination_airspeed_cm_s(s_, att.airspeed_cm_s);
    if (v_cm_s != turn_airspeed_cm_s_) {
        turn_airspeed_cm_s_ = v_cm_s;
        turn_gain_cds_ = turn_gain_cds((float)v_cm_s * 0.01f, s_.pitch_roll_ff);
    }
    const int32_t offset = turn_rate_offset_cds(att.roll_cd, att.pitch_cd, turn_gain_cds_);
    Surfaces out{};
    out.aileron_cd = roll_.step(roll_terms_, roll_error_cd, 0, att.roll_rate_cds);
    out.elevator_cd = pitch_.step(pitch_terms_, pitch_demand_cd - att.pitch_cd, offset, att.pitch_rate_cds);
    return out;
}

bool FlightControl::navigating_in_failsafe() const {
    const int8_t i = mode_index((uint8_t)chosen_);
    return state_ == State::Failsafe && i >= 0 && mode_law((uint8_t)i) == Law::NavigateOn;
}

void FlightControl::configure() {
    scales_ = scales_of(s_);
    roll_terms_ = axis_terms(s_.roll, kControlDt_s);
    pitch_terms_ = axis_terms(s_.pitch, kControlDt_s);
    turn_airspeed_cm_s_ = coordination_airspeed_cm_s(s_, 0);
    turn_gain_cds_ = turn_gain_cds((float)turn_airspeed_cm_s_ * 0.01f, s_.pitch_roll_ff);
}

void FlightControl::step(uint32_t now_ms, const Attitude& att, uint16_t out_us[kChannels]) {
    update_signal(now_ms);
    if (state_ == State::NoSignal) {
        hold_neutral(out_us);
        return;
    }
    // STABILIZE without an attitude (the estimator starting, the IMU failed) flies as
    // MANUAL, and STABILIZE resumes when the attitude does (the estimator restarts from
    // gravity): said both ways.
    const bool fallback = (state_ == State::Stabilize || state_ == State::Navigate) && !att.valid;
    if (fallback != no_attitude_) {
        events_ |= fallback ? kEvSensorFallback : kEvAttitudeBack;
        no_attitude_ = fallback;
        roll_.reset();
        pitch_.reset();
    }
    const int16_t fs_throttle = throttle_live_ ? (int16_t)(s_.thr_fs_pct * 10u) : (int16_t)0;
    const int16_t nav_throttle = throttle_live_ ? nav_throttle_ : (int16_t)0;
    if ((state_ == State::Navigate && !fallback) || (navigating_in_failsafe() && att.valid)) {
        // The rudder stays the pilot's (none in the failsafe), as ArduPlane's without a yaw damper.
        Surfaces sf = stabilize(att, nav_roll_cd_, (int32_t)s_.trim_pitch_cd + nav_pitch_cd_);
        sf.throttle = nav_throttle;
        sf.rudder_cd = state_ == State::Navigate ? stick(kYaw, now_ms) : (int16_t)0;
        uint16_t aux_us[4];
        for (uint8_t i = 0; i < 4; ++i) aux_us[i] = input_us((uint8_t)(i + 4u), now_ms);
        mix(s_, scales_, sf, state_ == State::Navigate ? aux_us : nullptr, out_us);
        return;
    }
    if (state_ == State::Failsafe) {
        Surfaces sf{0, 0, fs_throttle, 0};
        if (att.valid) sf = stabilize(att, 0, (int32_t)s_.trim_pitch_cd + s_.fs_pitch_cd);
        sf.throttle = fs_throttle;
        sf.rudder_cd = 0;
        mix(s_, scales_, sf, nullptr, out_us);
        return;
    }
    // The sticks, by role (RCMAP_*); disarmed, the throttle at its minimum.
    int16_t in[4];
    for (uint8_t role = 0; role < 4; ++role) in[role] = stick(role, now_ms);
    Surfaces sf{in[kRoll], in[kPitch], throttle_live_ ? in[kThrottle] : (int16_t)0, in[kYaw]};
    if (state_ == State::Stabilize && !fallback) {
        const int32_t roll_demand = demand_cd(sf.aileron_cd, s_.lim_roll_cd);
        // The stick's pitch from the trim (ArduPlane's stabilize_pitch adds TRIM_PITCH_CD).
        const int32_t pitch_demand =
            s_.trim_pitch_cd +
            demand_cd(sf.elevator_cd, sf.elevator_cd >= 0 ? s_.lim_pitch_max_cd : (int16_t)-s_.lim_pitch_min_cd);
        const Surfaces c = stabilize(att, roll_demand, pitch_demand);
        sf.aileron_cd = c.aileron_cd;
        sf.elevator_cd = c.elevator_cd;
    }
    uint16_t aux_us[4];
    for (uint8_t i = 0; i < 4; ++i) aux_us[i] = input_us((uint8_t)(i + 4u), now_ms);
    mix(s_, scales_, sf, aux_us, out_us);
}

}  // namespace flight
