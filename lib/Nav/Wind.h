// SPDX-License-Identifier: GPL-3.0-or-later
// The wind from the GPS ground velocity and the pitot's airspeed, as the airspeed branch
// of ArduPilot's AP_AHRS_DCM::estimate_wind: the air moves over the ground at
//     wind = v_ground - TAS * (cos pitch cos heading, cos pitch sin heading)
// (the air velocity along the fuselage, no sideslip), low-passed. ArduPilot's filter is
// wind = 0.92 wind + 0.08 new every 2 s (a time constant of 24 s); here the same first
// order filter runs on every fix with kTimeConstant_s 10 s: the pitot's scale error and
// a turn's sideslip make an error along the heading, which a circle (~15 s at 30 deg of
// bank and 15 m/s) turns all the way round, so a time constant of about a circle
// averages it out while following a wind that changes over a minute. Below
// kMinAirspeed_m_s (the pitot's resolution near zero: an ADC count is ~3 m/s there) or on
// the ground it is not updated. Only a number for the ground station and the console now.
//
// Frame: north-east, m/s; TAS = EAS * sqrt(rho0 / rho) (eas_to_tas: the pitot's
// conversion takes sea-level air density).
#pragma once

#include "Location.h"

namespace nav {

class WindEstimator {
public:
    static constexpr float kTimeConstant_s = 10.0f;
    static constexpr float kMinAirspeed_m_s = 5.0f;

    // A new ground velocity (m/s north, east), the true airspeed (m/s), the attitude's
    // heading (true north) and pitch (radians), and the time since the last call.
    void update(const NorthEast& ground_m_s, float tas_m_s, float heading_rad, float pitch_rad, float dt_s);
    bool valid() const { return valid_; }
    // The air's velocity over the ground (where the wind blows to), m/s north, east.
    const NorthEast& wind_m_s() const { return wind_; }
    float speed_m_s() const;
    // Where the wind comes from, degrees 0..360 (meteorology's and ArduPilot's WIND.direction).
    float from_deg() const;

private:
    NorthEast wind_ = {0.0f, 0.0f};
    bool valid_ = false;
};

// The true airspeed per equivalent airspeed for air at pressure_pa and temperature_c
// (dry air, the ideal gas law): 1.05 at the thesis' field (1028 m, ~90 kPa, 8 degC).
float eas_to_tas(float pressure_pa, float temperature_c);

}  // namespace nav
