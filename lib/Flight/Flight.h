// SPDX-License-Identifier: GPL-3.0-or-later
// Flying: receiver frames and the attitude in, eight servo widths out.
//
//   sticks (receiver widths -> normalised commands, RCn_* end points, RCMAP_*)
//   -> the mode: MANUAL (the sticks are the surfaces), STABILIZE (the sticks demand a
//      bank and a pitch; AxisController turns the attitude error into surface), FAILSAFE
//      (wings level, a gentle nose-down glide, throttle at its failsafe value)
//   -> the mixer (plain aileron/elevator/throttle/rudder on OUT1-4 in ArduPlane's order,
//      elevons or V-tail) -> widths (SERVOn_* end points, reverse, limits).
//
// Conventions (docs/flight.md): roll positive = right wing down, pitch positive = nose
// up (lib/DCM's Euler angles). A normalised surface command is in centi-degrees, 4500 =
// full throw, positive = roll right (aileron), nose up (elevator), nose right (rudder);
// throttle is in tenths of a percent, 0..1000. With no reverse set, a receiver channel
// above its trim is a positive command and a positive command puts an output above its
// trim. Pure C++: the caller supplies the time and the attitude.
#pragma once

#include <stdint.h>

#include "FlightSettings.h"
#include "Modes.h"

namespace flight {

constexpr int16_t kFullThrow_cd = 4500;
constexpr int16_t kFullThrottle = 1000;
constexpr uint16_t kSignalTimeoutMs = 500;  // no good frame for this long: the receiver is lost
constexpr float kControlDt_s = 0.02f;       // the control step's period: the servo frame

// --- Normalising and end points (ArduPilot's RC_Channel / SRV_Channel maps) -----------
//
// Each map is a multiply and a shift by a factor worked out from the end points when
// they change (FlightControl::configure): no division in the 50 Hz step. With the
// default end points (500 us each side of 1500) the factors are exact: a width comes
// back out as itself.

// A map's factors above and below trim (a throttle map: `up` only).
struct Scale {
    uint16_t up;
    uint16_t down;
};
// Receiver width -> centred command: centi-degrees per us, Q8 (0 for a side under 18 us).
Scale angle_input_scale(const EndPoints& ep);
// Receiver width -> throttle: tenths of a percent per us, Q8.
Scale throttle_input_scale(const EndPoints& ep);
// Centred command -> output width: us per centi-degree, Q16.
Scale angle_output_scale(const EndPoints& ep);
// Throttle -> output width: us per tenth of a percent, Q15.
Scale throttle_output_scale(const EndPoints& ep);

// A receiver width as a centred command, -4500..4500 (trim = 0).
int16_t width_to_angle(uint16_t width_us, const EndPoints& ep, Scale sc, bool reversed);
// A receiver width as a throttle, 0..1000 from min to max.
int16_t width_to_throttle(uint16_t width_us, const EndPoints& ep, Scale sc, bool reversed);
// A centred command (-4500..4500) as an output width within min..max.
uint16_t angle_to_width(int16_t angle_cd, const EndPoints& ep, Scale sc, bool reversed);
// A throttle (0..1000) as an output width within min..max.
uint16_t throttle_to_width(int16_t throttle, const EndPoints& ep, Scale sc, bool reversed);

// The same with the factors worked out on the spot (tests, set-up).
inline int16_t width_to_angle(uint16_t w, const EndPoints& ep, bool rev) { return width_to_angle(w, ep, angle_input_scale(ep), rev); }
inline int16_t width_to_throttle(uint16_t w, const EndPoints& ep, bool rev) {
    return width_to_throttle(w, ep, throttle_input_scale(ep), rev);
}
inline uint16_t angle_to_width(int16_t a, const EndPoints& ep, bool rev) { return angle_to_width(a, ep, angle_output_scale(ep), rev); }
inline uint16_t throttle_to_width(int16_t t, const EndPoints& ep, bool rev) {
    return throttle_to_width(t, ep, throttle_output_scale(ep), rev);
}

// The factors the step uses: the mapped roll, pitch, throttle and yaw channels' (by
// role), and OUT1-OUT4's (OUT3 the throttle).
struct Scales {
    Scale in[4];
    Scale out[4];
};
Scales scales_of(const FlightSettings& s);

// ArduPlane's mode switch bands (1..6) for a width: <=1230, <=1360, <=1490, <=1620, <=1749, above.
uint8_t switch_position(uint16_t width_us);

// --- The attitude controller, one axis (AP_RollController / AP_PitchController) ------
//
// The attitude error over the time constant is the demanded rate; the surface is
//   P' x demanded rate + D x (demanded rate - measured rate) + integrator,
// P' = max((P - I tau) tau - D, 0) as ArduPilot converts its P to a feed-forward on the
// demanded rate, so that P reads as "degrees of surface per degree of error"; the
// integrator sums I tau x rate error x dt, is limited to imax and does not grow while
// the output is saturated. In integers (centi-degrees, centi-degrees per second) with the
// gains turned into fixed-point factors when they change (axis_terms): the AVR has no
// float unit, and every float operation of a controller would be a library call.

// The gains as the step uses them.
struct AxisTerms {
    int16_t inv_tau_q12;  // 1 / TCONST, Q12
    int16_t kp_ff_q12;    // P', Q12
    int16_t kd_q14;       // D, Q14
    int16_t ki_dt_q16;    // I x TCONST x dt, Q16
    int16_t imax_cd;
};
AxisTerms axis_terms(const AxisGains& g, float dt_s);

class AxisController {
public:
    // error_cd: demanded less measured attitude, centi-degrees; rate_offset_cds: added to
    // the demanded rate (the pitch axis's turn coordination); rate_cds: measured, both
    // centi-degrees per second. Returns the surface, centi-degrees, -4500..4500.
    int16_t step(const AxisTerms& t, int32_t error_cd, int32_t rate_offset_cds, int32_t rate_cds);
    void reset() { integrator_q16_ = 0; saturation_ = 0; }
    float integrator_deg() const { return (float)integrator_q16_ * (1.0f / 65536.0f / 100.0f); }

private:
    int32_t integrator_q16_ = 0;  // centi-degrees of surface, Q16
    int8_t saturation_ = 0;       // the last output's saturation: -1, 0, +1
};

// The pitch rate (centi-degrees per second) that holds the nose in a level turn at this
// bank: g / V x tan(bank) x sin(bank) x cos(pitch) (AP_PitchController's coordination),
// bank limited to +-80 deg, none inverted. gain_cds = g / V x PTCH2SRV_RLL in
// centi-degrees per second (turn_gain_cds).
int32_t turn_rate_offset_cds(int32_t roll_cd, int32_t pitch_cd, int16_t gain_cds);
int16_t turn_gain_cds(float airspeed_m_s, float roll_ff);

// --- The mixer ----------------------------------------------------------------------

// What the mode asks of the airframe.
struct Surfaces {
    int16_t aileron_cd;
    int16_t elevator_cd;
    int16_t throttle;  // 0..1000
    int16_t rudder_cd;
};

// The eight output widths: OUT1-4 from the surfaces (plain, elevons or V-tail), OUT5-8
// the widths of receiver channels 5-8 (`aux_us`, as ArduPlane's aux channels with no
// function: the width itself, reversed about trim when SERVOn_REVERSED, within the
// output's limits; nullptr holds them at trim).
void mix(const FlightSettings& s, const Scales& sc, const Surfaces& in, const uint16_t* aux_us,
         uint16_t out_us[kChannels]);

// --- The modes ----------------------------------------------------------------------

// What the controller is doing; FAILSAFE and NoSignal are not choices but states.
enum class State : uint8_t {
    NoSignal,   // no receiver frame since power-up: outputs at trim, throttle at its failsafe value
    Manual,
    Stabilize,
    Failsafe,
    Navigate,   // a navigation mode (Law::Navigate, NavigateOn): set_nav_demands' bank, pitch, throttle
};

// The attitude the controller sees (the estimator's), and whether it is to be trusted.
struct Attitude {
    int32_t roll_cd;
    int32_t pitch_cd;
    int32_t roll_rate_cds;   // body x, centi-degrees per second
    int32_t pitch_rate_cds;  // body y
    bool valid;              // false: the estimator is not running or the IMU failed
    uint16_t airspeed_cm_s;  // measured (the pitot), for the turn coordination; 0: none measured
};

// The airspeed the turn coordination takes (cm/s), as AP_PitchController: the measured one,
// not below ARSPD_FBW_MIN; without one the cruise speed (TRIM_ARSPD_CM), or when that is 0
// the mean of ARSPD_FBW_MIN and ARSPD_FBW_MAX.
uint16_t coordination_airspeed_cm_s(const FlightSettings& s, uint16_t measured_cm_s);

// Something for the firmware to say on the console (bits of FlightControl::take_events).
enum Event : uint8_t {
    kEvFailsafeLost = 0x01,     // the receiver's frames stopped
    kEvFailsafeEncoder = 0x02,  // the encoder's own failsafe (throttle below THR_FS_VALUE)
    kEvFailsafeEnd = 0x04,      // good frames again: back to the mode before
    kEvSensorFallback = 0x08,   // STABILIZE without an attitude: the sticks pass through (MANUAL) until it returns
    kEvAttitudeBack = 0x20,     // ... it returned: STABILIZE again
    kEvModeChanged = 0x10,      // the mode switch chose another mode
    kEvModeRefused = 0x40,      // the mode switch chose a mode that cannot run now (refused_mode())
};

enum class FailsafeCause : uint8_t { None, Lost, Encoder };

class FlightControl {
public:
    explicit FlightControl(const FlightSettings& s) : s_(s) { configure(); }
    // The firmware's static object (no work before init(): AttitudePipeline's
    // SettingsLoadedLater): setup() calls configure() once the settings are loaded.
    struct ConfiguredLater {};
    // constexpr: the static object needs no start-up code (its terms zeroed until then).
    constexpr FlightControl(const FlightSettings& s, ConfiguredLater)
        : s_(s), scales_{}, roll_terms_{}, pitch_terms_{} {}

    // The end points' factors and the gains' terms again: call after any change of the
    // settings.
    void configure();

    // An accepted receiver frame, at now_ms.
    void on_frame(const uint16_t width_us[kChannels], uint32_t now_ms);
    // A ground station's RC_CHANNELS_OVERRIDE (MAVLink's meanings, per channel: UINT16_MAX
    // leaves the channel as it is, 0 gives it back to the receiver, a width 800..2200 us
    // overrides it; other widths are ignored). An override holds until
    // set_override_timeout's time has passed since its last message. Once the receiver
    // has been heard, a fresh override of the throttle channel above THR_FS_VALUE is
    // valid input as a good frame is (ArduPilot's): it keeps the board out of FAILSAFE
    // while the receiver is lost, and channels it does not override keep the receiver's
    // last widths. When the overrides stop, each channel is the receiver's again after
    // the timeout, and FAILSAFE follows 0.5 s after the last good input.
    void on_override(const uint16_t width_us[kChannels], uint32_t now_ms);
    // RC_OVERRIDE_TIME in 8 ms units: 0 overrides are ignored, kOverrideForever never time out.
    static constexpr uint16_t kOverrideForever = 0xFFFFu;
    void set_override_timeout(uint16_t timeout_8ms) { override_timeout_8ms_ = timeout_8ms; }
    // The width flown for channel ch (0..7) at now_ms: a fresh override, else the receiver's.
    uint16_t input_us(uint8_t ch, uint32_t now_ms) const;
    // A stick by role (RCMAP_*) as the step reads it: -4500..4500 cd, the throttle 0..1000.
    int16_t stick(uint8_t role, uint32_t now_ms) const;
    // The console's or a ground station's choice; the mode switch's next move overrides
    // it. A number the board does not have (Modes.h) flies MANUAL: the caller refuses it.
    void choose(Mode m);
    // The navigation modes' demands (the firmware's 10 Hz navigation step): the bank and
    // the pitch (centi-degrees, within LIM_ROLL_CD and LIM_PITCH_*; TRIM_PITCH_CD is added
    // as to every pitch, ArduPlane's stabilize_pitch) and the throttle (0..1000).
    void set_nav_demands(int16_t roll_cd, int16_t pitch_cd, int16_t throttle) {
        nav_roll_cd_ = roll_cd;
        nav_pitch_cd_ = pitch_cd;
        nav_throttle_ = throttle;
    }
    // The modes (bit i: Modes.h's row i) that cannot run now (no GPS fix, no home, no
    // mission): the mode switch does not choose them, it keeps the mode flying and says so
    // (kEvModeRefused, refused_mode()). The caller refuses its own choices before choose().
    void set_unavailable(uint16_t rows) { unavailable_ = rows; }
    Mode refused_mode() const { return refused_; }
    // false: the throttle output holds its minimum in every state (disarmed: Arming.h).
    void set_throttle_live(bool live) { throttle_live_ = live; }
    // One control step, every kControlDt_s: the eight output widths, within their limits.
    void step(uint32_t now_ms, const Attitude& att, uint16_t out_us[kChannels]);

    State state() const { return state_; }
    // The receiver's state at now_ms (FAILSAFE entered or left; step() does it too).
    void update_signal(uint32_t now_ms);
    // Whether the next step uses the attitude (STABILIZE, FAILSAFE; after update_signal):
    // else the caller need not work it out.
    bool wants_attitude() const {
        return state_ == State::Stabilize || state_ == State::Failsafe || state_ == State::Navigate;
    }
    // FAILSAFE in a mode that flies on through it (Law::NavigateOn: AUTO, RTL, LOITER, CIRCLE, GUIDED).
    bool navigating_in_failsafe() const;
    // An attitude mode chosen (STABILIZE, FBWA), but flying as MANUAL for want of an attitude.
    bool without_attitude() const { return no_attitude_; }
    Mode chosen() const { return chosen_; }
    FailsafeCause failsafe_cause() const { return cause_; }
    const uint16_t* rc_us() const { return rc_us_; }
    // Events since the last call (Event bits), cleared.
    uint8_t take_events() {
        const uint8_t e = events_;
        events_ = 0;
        return e;
    }

private:
    void hold_neutral(uint16_t out_us[kChannels]) const;
    Surfaces stabilize(const Attitude& att, int32_t roll_demand_cd, int32_t pitch_demand_cd);

    const FlightSettings& s_;
    Scales scales_;
    AxisTerms roll_terms_;
    AxisTerms pitch_terms_;
    int16_t turn_gain_cds_ = 0;
    int16_t nav_roll_cd_ = 0;
    int16_t nav_pitch_cd_ = 0;
    int16_t nav_throttle_ = 0;
    uint16_t unavailable_ = 0;
    Mode refused_ = Mode::Manual;
    uint16_t turn_airspeed_cm_s_ = 0;  // the airspeed turn_gain_cds_ is for
    AxisController roll_;
    AxisController pitch_;
    uint16_t rc_us_[kChannels] = {};
    uint32_t last_good_ms_ = 0;   // the last frame with the throttle above THR_FS_VALUE
    uint32_t last_frame_ms_ = 0;  // the last frame of any kind
    State state_ = State::NoSignal;
    Mode chosen_ = Mode::Manual;
    FailsafeCause cause_ = FailsafeCause::None;
    uint8_t switch_pos_ = 0;      // 1..6, 0 before the first frame
    uint8_t events_ = 0;
    bool have_frame_ = false;
    bool no_attitude_ = false;    // STABILIZE flying as MANUAL: the attitude is not valid
    bool throttle_live_ = true;
    // RC_CHANNELS_OVERRIDE: the widths (0: none) and when each came, in 8 ms units.
    bool override_fresh(uint8_t ch, uint32_t now_ms) const;
    void read_switch(uint32_t now_ms);
    uint16_t override_us_[kChannels] = {};
    uint16_t override_at_[kChannels] = {};
    uint16_t override_timeout_8ms_ = 375;  // RC_OVERRIDE_TIME's default, 3 s
};

}  // namespace flight
