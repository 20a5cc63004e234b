// SPDX-License-Identifier: GPL-3.0-or-later
#include "Flight.h"

namespace flight {

namespace {

// a / b rounded to the nearest, half away from zero (b > 0).
int32_t div_round(int32_t a, int32_t b) { return a >= 0 ? (a + b / 2) / b : -((-a + b / 2) / b); }

int32_t clamp32(int32_t v, int32_t lo, int32_t hi) { return v < lo ? lo : (v > hi ? hi : v); }

bool bit(uint8_t mask, uint8_t index) { return ((mask >> index) & 1u) != 0u; }

// sin and cos of |x| <= pi/2 by their Taylor series to x^7 and x^8 (within 2e-4):
// the turn coordination needs no more, and avr-libc's sinf and cosf cost several times
// as much.
void sin_cos(float x, float& s, float& c) {
    const float x2 = x * x;
    s = x * (1.0f - x2 * (1.0f / 6.0f - x2 * (1.0f / 120.0f - x2 * (1.0f / 5040.0f))));
    c = 1.0f - x2 * (0.5f - x2 * (1.0f / 24.0f - x2 * (1.0f / 720.0f - x2 * (1.0f / 40320.0f))));
}

constexpr float kRadPerCentideg = 3.14159265f / 18000.0f;
constexpr float kDegPerRad = 57.2957795f;
constexpr float kGravity_m_s2 = 9.80665f;
constexpr int32_t kMaxCoordinatedBank_cd = 8000;  // AP_PitchController's limit

}  // namespace

// --- Normalising and end points -----------------------------------------------------

int16_t width_to_angle(uint16_t width_us, const EndPoints& ep, bool reversed) {
    const int32_t d = (int32_t)width_us - ep.trim_us;
    const int32_t span = d >= 0 ? (int32_t)ep.max_us - ep.trim_us : (int32_t)ep.trim_us - ep.min_us;
    int32_t a = span > 0 ? clamp32(div_round(d * kFullThrow_cd, span), -kFullThrow_cd, kFullThrow_cd) : 0;
    return (int16_t)(reversed ? -a : a);
}

int16_t width_to_throttle(uint16_t width_us, const EndPoints& ep, bool reversed) {
    const int32_t span = (int32_t)ep.max_us - ep.min_us;
    if (span <= 0) return 0;
    const int32_t t = clamp32(div_round(((int32_t)width_us - ep.min_us) * kFullThrottle, span), 0, kFullThrottle);
    return (int16_t)(reversed ? kFullThrottle - t : t);
}

uint16_t angle_to_width(int16_t angle_cd, const EndPoints& ep, bool reversed) {
    const int32_t a = clamp32(reversed ? -(int32_t)angle_cd : angle_cd, -kFullThrow_cd, kFullThrow_cd);
    const int32_t span = a >= 0 ? (int32_t)ep.max_us - ep.trim_us : (int32_t)ep.trim_us - ep.min_us;
    return (uint16_t)clamp32(ep.trim_us + div_round(a * span, kFullThrow_cd), ep.min_us, ep.max_us);
}

uint16_t throttle_to_width(int16_t throttle, const EndPoints& ep, bool reversed) {
    int32_t t = clamp32(throttle, 0, kFullThrottle);
    if (reversed) t = kFullThrottle - t;
    const int32_t span = (int32_t)ep.max_us - ep.min_us;
    return (uint16_t)clamp32(ep.min_us + div_round(t * span, kFullThrottle), ep.min_us, ep.max_us);
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

int16_t AxisController::step(const AxisGains& g, int32_t error_cd, float rate_offset_deg_s, float rate_deg_s,
                             float dt_s) {
    const float desired_deg_s = (float)error_cd * 0.01f / g.tconst_s + rate_offset_deg_s;
    const float rate_error_deg_s = desired_deg_s - rate_deg_s;
    const float ki_rate = g.i * g.tconst_s;
    if (ki_rate > 0.0f) {
        float delta = rate_error_deg_s * ki_rate * dt_s;
        // A saturated surface: the integrator may only unwind (ArduPilot's anti-windup).
        if ((saturation_ > 0 && delta > 0.0f) || (saturation_ < 0 && delta < 0.0f)) delta = 0.0f;
        const float limit_deg = (float)g.imax_cd * 0.01f;
        integrator_deg_ += delta;
        if (integrator_deg_ > limit_deg) integrator_deg_ = limit_deg;
        if (integrator_deg_ < -limit_deg) integrator_deg_ = -limit_deg;
    } else {
        integrator_deg_ = 0.0f;
    }
    float kp_ff = (g.p - g.i * g.tconst_s) * g.tconst_s - g.d;
    if (kp_ff < 0.0f) kp_ff = 0.0f;
    const float out_cd = (g.d * rate_error_deg_s + kp_ff * desired_deg_s + integrator_deg_) * 100.0f;
    saturation_ = out_cd >= (float)kFullThrow_cd ? 1 : (out_cd <= -(float)kFullThrow_cd ? -1 : 0);
    if (saturation_ > 0) return kFullThrow_cd;
    if (saturation_ < 0) return -kFullThrow_cd;
    return (int16_t)out_cd;
}

float turn_rate_offset_deg_s(int32_t roll_cd, int32_t pitch_cd, float airspeed_m_s, float gain) {
    if (roll_cd > 9000 || roll_cd < -9000 || airspeed_m_s <= 0.0f) return 0.0f;  // inverted: no coordination
    const int32_t bank_cd = clamp32(roll_cd, -kMaxCoordinatedBank_cd, kMaxCoordinatedBank_cd);
    float sb, cb, sp, cp;
    sin_cos((float)bank_cd * kRadPerCentideg, sb, cb);
    sin_cos((float)clamp32(pitch_cd, -9000, 9000) * kRadPerCentideg, sp, cp);
    // tan(bank) sin(bank) = sin^2 / cos; cos(bank) >= cos(80 deg) here.
    return cp * kDegPerRad * kGravity_m_s2 / airspeed_m_s * (sb * sb / cb) * gain;
}

// --- The mixer --------------------------------------------------------------------------

namespace {

int16_t clamp_throw(int32_t v) { return (int16_t)clamp32(v, -kFullThrow_cd, kFullThrow_cd); }

// Two surfaces that share two commands (elevons: elevator and aileron; V-tail: elevator
// and rudder), each half of both as ArduPlane's default MIXING_GAIN 0.5: the left
// surface's command is (a - b) / 2, the right one's (a + b) / 2.
void mix_pair(int16_t a, int16_t b, int16_t& left, int16_t& right) {
    left = clamp_throw(((int32_t)a - b) / 2);
    right = clamp_throw(((int32_t)a + b) / 2);
}

}  // namespace

void mix(const FlightSettings& s, const Surfaces& in, const int16_t* aux_cd, uint16_t out_us[kChannels]) {
    int16_t cmd[kChannels] = {in.aileron_cd, in.elevator_cd, 0, in.rudder_cd, 0, 0, 0, 0};
    if (s.elevon_output != 0u) mix_pair(in.elevator_cd, in.aileron_cd, cmd[0], cmd[1]);
    if (s.vtail_output != 0u) mix_pair(in.elevator_cd, in.rudder_cd, cmd[1], cmd[3]);
    if (aux_cd != nullptr)
        for (uint8_t i = 4; i < kChannels; ++i) cmd[i] = aux_cd[i - 4];
    for (uint8_t i = 0; i < kChannels; ++i) {
        const bool rev = bit(s.servo_reversed, i);
        out_us[i] = i == 2 ? throttle_to_width(in.throttle, s.servo[i], rev) : angle_to_width(cmd[i], s.servo[i], rev);
    }
}

// --- The modes --------------------------------------------------------------------------

namespace {

State state_of(Mode m) { return m == Mode::Stabilize ? State::Stabilize : State::Manual; }

}  // namespace

void FlightControl::hold_neutral(uint16_t out_us[kChannels]) const {
    const Surfaces neutral{0, 0, (int16_t)(s_.thr_fs_pct * 10u), 0};
    mix(s_, neutral, nullptr, out_us);
}

void FlightControl::choose(Mode m) {
    if (m != Mode::Stabilize) m = Mode::Manual;
    chosen_ = m;
    if (state_ == State::Manual || state_ == State::Stabilize) {
        if (state_ != state_of(m)) {
            roll_.reset();
            pitch_.reset();
        }
        state_ = state_of(m);
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
    const uint8_t ch = s_.fltmode_ch;
    if (ch >= 1u && ch <= kChannels) {
        const uint8_t pos = switch_position(width_us[ch - 1u]);
        if (pos != switch_pos_) {
            switch_pos_ = pos;
            const Mode before = chosen_;
            choose((Mode)s_.fltmode[pos - 1u]);
            if (chosen_ != before) events_ |= kEvModeChanged;
        }
    }
}

void FlightControl::update_signal(uint32_t now_ms) {
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

Surfaces FlightControl::stabilize(const Attitude& att, int32_t roll_demand_cd, int32_t pitch_demand_cd, float dt_s) {
    int32_t roll_error_cd = roll_demand_cd - att.roll_cd;
    if (roll_error_cd > 18000) roll_error_cd -= 36000;  // the short way round
    if (roll_error_cd < -18000) roll_error_cd += 36000;
    const float airspeed_m_s = 0.5f * (float)(s_.arspd_min_m_s + s_.arspd_max_m_s);
    const float offset = turn_rate_offset_deg_s(att.roll_cd, att.pitch_cd, airspeed_m_s, s_.pitch_roll_ff);
    Surfaces out{};
    out.aileron_cd = roll_.step(s_.roll, roll_error_cd, 0.0f, att.roll_rate_deg_s, dt_s);
    out.elevator_cd = pitch_.step(s_.pitch, pitch_demand_cd - att.pitch_cd, offset, att.pitch_rate_deg_s, dt_s);
    return out;
}

void FlightControl::step(uint32_t now_ms, const Attitude& att, float dt_s, uint16_t out_us[kChannels]) {
    update_signal(now_ms);
    if (state_ == State::NoSignal) {
        hold_neutral(out_us);
        return;
    }
    // STABILIZE without an attitude (the estimator starting, the IMU failed) flies as
    // MANUAL, and STABILIZE resumes when the attitude does (the estimator restarts from
    // gravity): said both ways.
    const bool fallback = state_ == State::Stabilize && !att.valid;
    if (fallback != no_attitude_) {
        events_ |= fallback ? kEvSensorFallback : kEvAttitudeBack;
        no_attitude_ = fallback;
        roll_.reset();
        pitch_.reset();
    }
    const int16_t fs_throttle = (int16_t)(s_.thr_fs_pct * 10u);
    if (state_ == State::Failsafe) {
        Surfaces sf{0, 0, fs_throttle, 0};
        if (att.valid) sf = stabilize(att, 0, s_.fs_pitch_cd, dt_s);
        sf.throttle = fs_throttle;
        sf.rudder_cd = 0;
        mix(s_, sf, nullptr, out_us);
        return;
    }
    int16_t in[kChannels];
    for (uint8_t i = 0; i < kChannels; ++i) in[i] = width_to_angle(rc_us_[i], s_.rc[i], bit(s_.rc_reversed, i));
    const uint8_t* map = s_.rcmap;
    const uint8_t thr = (uint8_t)(map[kThrottle] - 1u);
    Surfaces sf{in[map[kRoll] - 1u], in[map[kPitch] - 1u],
                width_to_throttle(rc_us_[thr], s_.rc[thr], bit(s_.rc_reversed, thr)), in[map[kYaw] - 1u]};
    if (state_ == State::Stabilize && !fallback) {
        const int32_t roll_demand = div_round((int32_t)sf.aileron_cd * s_.lim_roll_cd, kFullThrow_cd);
        const int32_t pitch_demand = sf.elevator_cd >= 0
                                         ? div_round((int32_t)sf.elevator_cd * s_.lim_pitch_max_cd, kFullThrow_cd)
                                         : div_round(-(int32_t)sf.elevator_cd * s_.lim_pitch_min_cd, kFullThrow_cd);
        const Surfaces c = stabilize(att, roll_demand, pitch_demand, dt_s);
        sf.aileron_cd = c.aileron_cd;
        sf.elevator_cd = c.elevator_cd;
    }
    mix(s_, sf, in + 4, out_us);
}

}  // namespace flight
