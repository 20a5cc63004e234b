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
// Conventions (README "Flying"): roll positive = right wing down, pitch positive = nose
// up (lib/DCM's Euler angles). A normalised surface command is in centi-degrees, 4500 =
// full throw, positive = roll right (aileron), nose up (elevator), nose right (rudder);
// throttle is in tenths of a percent, 0..1000. With no reverse set, a receiver channel
// above its trim is a positive command and a positive command puts an output above its
// trim. Pure C++: the caller supplies the time and the attitude.
#pragma once

#include <stdint.h>

#include "FlightSettings.h"

namespace flight {

constexpr int16_t kFullThrow_cd = 4500;
constexpr int16_t kFullThrottle = 1000;
constexpr uint16_t kSignalTimeoutMs = 500;  // no good frame for this long: the receiver is lost

// --- Normalising and end points (ArduPilot's RC_Channel / SRV_Channel maps) -----------

// A receiver width as a centred command, -4500..4500, from its end points (trim = 0).
int16_t width_to_angle(uint16_t width_us, const EndPoints& ep, bool reversed);
// A receiver width as a throttle, 0..1000 from min to max.
int16_t width_to_throttle(uint16_t width_us, const EndPoints& ep, bool reversed);
// A centred command (-4500..4500) as an output width within min..max.
uint16_t angle_to_width(int16_t angle_cd, const EndPoints& ep, bool reversed);
// A throttle (0..1000) as an output width within min..max.
uint16_t throttle_to_width(int16_t throttle, const EndPoints& ep, bool reversed);

// ArduPlane's mode switch bands (1..6) for a width: <=1230, <=1360, <=1490, <=1620, <=1749, above.
uint8_t switch_position(uint16_t width_us);

// --- The attitude controller, one axis (AP_RollController / AP_PitchController) ------
//
// The attitude error over the time constant is the demanded rate; the surface is
//   P' x demanded rate + D x (demanded rate - measured rate) + integrator,
// P' = max((P - I tau) tau - D, 0) as ArduPilot converts its P to a feed-forward on the
// demanded rate, so that P reads as "degrees of surface per degree of error"; the
// integrator sums I tau x rate error x dt, is limited to imax and does not grow while
// the output is saturated.
class AxisController {
public:
    // error_cd: demanded less measured attitude, centi-degrees; rate_offset_deg_s: added
    // to the demanded rate (the pitch axis's turn coordination); rate_deg_s: measured.
    // Returns the surface, centi-degrees, -4500..4500.
    int16_t step(const AxisGains& g, int32_t error_cd, float rate_offset_deg_s, float rate_deg_s, float dt_s);
    void reset() { integrator_deg_ = 0.0f; saturation_ = 0; }
    float integrator_deg() const { return integrator_deg_; }

private:
    float integrator_deg_ = 0.0f;
    int8_t saturation_ = 0;  // the last output's saturation: -1, 0, +1
};

// The pitch rate (deg/s) that holds the nose in a level turn at this bank: g / V x
// tan(bank) x sin(bank) x cos(pitch) (AP_PitchController's coordination), bank limited
// to +-80 deg, times PTCH2SRV_RLL.
float turn_rate_offset_deg_s(int32_t roll_cd, int32_t pitch_cd, float airspeed_m_s, float gain);

// --- The mixer ----------------------------------------------------------------------

// What the mode asks of the airframe.
struct Surfaces {
    int16_t aileron_cd;
    int16_t elevator_cd;
    int16_t throttle;  // 0..1000
    int16_t rudder_cd;
};

// The eight output widths: OUT1-4 from the surfaces (plain, elevons or V-tail), OUT5-8
// from receiver channels 5-8 (aux: centred commands passed through; `aux` = nullptr
// holds them at trim).
void mix(const FlightSettings& s, const Surfaces& in, const int16_t* aux_cd, uint16_t out_us[kChannels]);

// --- The modes ----------------------------------------------------------------------

// What the controller is doing; FAILSAFE and NoSignal are not choices but states.
enum class State : uint8_t {
    NoSignal,   // no receiver frame since power-up: outputs at trim, throttle at its failsafe value
    Manual,
    Stabilize,
    Failsafe,
};

// The attitude the controller sees (the estimator's), and whether it is to be trusted.
struct Attitude {
    int32_t roll_cd;
    int32_t pitch_cd;
    float roll_rate_deg_s;   // body x
    float pitch_rate_deg_s;  // body y
    bool valid;              // false: the estimator is not running or the IMU failed
};

// Something for the firmware to say on the console (bits of FlightControl::take_events).
enum Event : uint8_t {
    kEvFailsafeLost = 0x01,     // the receiver's frames stopped
    kEvFailsafeEncoder = 0x02,  // the encoder's own failsafe (throttle below THR_FS_VALUE)
    kEvFailsafeEnd = 0x04,      // good frames again: back to the mode before
    kEvSensorFallback = 0x08,   // STABILIZE without an attitude: the sticks pass through (MANUAL) until it returns
    kEvAttitudeBack = 0x20,     // ... it returned: STABILIZE again
    kEvModeChanged = 0x10,      // the mode switch chose another mode
};

enum class FailsafeCause : uint8_t { None, Lost, Encoder };

class FlightControl {
public:
    explicit FlightControl(const FlightSettings& s) : s_(s) {}

    // An accepted receiver frame, at now_ms.
    void on_frame(const uint16_t width_us[kChannels], uint32_t now_ms);
    // The console's choice; the mode switch's next move overrides it.
    void choose(Mode m);
    // One control step, every dt_s: the eight output widths, within their limits.
    void step(uint32_t now_ms, const Attitude& att, float dt_s, uint16_t out_us[kChannels]);

    State state() const { return state_; }
    // STABILIZE chosen, but flying as MANUAL for want of an attitude.
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
    void update_signal(uint32_t now_ms);
    Surfaces stabilize(const Attitude& att, int32_t roll_demand_cd, int32_t pitch_demand_cd, float dt_s);

    const FlightSettings& s_;
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
};

}  // namespace flight
