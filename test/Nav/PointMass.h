// SPDX-License-Identifier: GPL-3.0-or-later
// A point-mass aeroplane for the navigation's host tests (L1, TECS, the route): the bank
// and the pitch follow their demands through first-order lags (the attitude controllers),
// the flight path is the pitch less a constant angle of attack (0 unless set), the turn
// is coordinated (heading rate g tan(bank) / V), and the airspeed follows thrust, drag
// and gravity. The airframe: kThrust_m_s2 at full throttle, level at 15 m/s on 45 %
// (drag 0.012 V^2), induced drag kInduced_m_s2 (1/cos^2 bank - 1); so at 15 m/s it climbs
// 5 m/s at full throttle and sinks 4.1 m/s at idle. Test code: double-free float maths.
#pragma once

#include <math.h>

#include "NeVector.h"
#include "Tecs.h"

namespace testplane {

constexpr float kG = 9.80665f;
constexpr float kThrust_m_s2 = 6.0f;
constexpr float kDragPerV2 = 0.012f;
constexpr float kInduced_m_s2 = 1.0f;

struct PointMass {
    nav::NorthEast pos_m = {0.0f, 0.0f};
    float height_m = 100.0f;
    nav::NorthEast heading = {1.0f, 0.0f};  // unit vector of the course through the air
    float tas_m_s = 15.0f;
    float pitch_rad = 0.0f;
    float bank_rad = 0.0f;
    nav::NorthEast wind_m_s = {0.0f, 0.0f};
    float alpha_rad = 0.0f;  // angle of attack: the flight path is the pitch less this
    float pitch_tau_s = 0.3f;
    float bank_tau_s = 0.5f;
    // The last step's accelerations, as TECS's 50 Hz filters take them.
    float accel_fwd_m_s2 = 0.0f;
    float accel_up_m_s2 = 0.0f;

    float path_rad() const { return pitch_rad - alpha_rad; }
    nav::NorthEast ground_velocity() const { return heading * (tas_m_s * cosf(path_rad())) + wind_m_s; }
    float cos_bank_sq() const { return cosf(bank_rad) * cosf(bank_rad); }

    void step(float pitch_dem_rad, float bank_dem_rad, float throttle, float dt_s) {
        const float climb_before = tas_m_s * sinf(path_rad());
        pitch_rad += (pitch_dem_rad - pitch_rad) * dt_s / pitch_tau_s;
        bank_rad += (bank_dem_rad - bank_rad) * dt_s / bank_tau_s;
        const float c2 = cosf(bank_rad) * cosf(bank_rad);
        accel_fwd_m_s2 = kThrust_m_s2 * throttle - kDragPerV2 * tas_m_s * tas_m_s -
                         kInduced_m_s2 * (1.0f / c2 - 1.0f) - kG * sinf(path_rad());
        tas_m_s += accel_fwd_m_s2 * dt_s;
        if (tas_m_s < 5.0f) tas_m_s = 5.0f;
        pos_m = pos_m + ground_velocity() * dt_s;
        height_m += tas_m_s * sinf(path_rad()) * dt_s;
        accel_up_m_s2 = (tas_m_s * sinf(path_rad()) - climb_before) / dt_s;
        const float turn = kG * tanf(bank_rad) / tas_m_s * dt_s;
        heading = nav::rotated(heading, cosf(turn), sinf(turn));
        heading = heading * (1.0f / nav::length(heading));
    }
};

// TECS's parameters for this airframe: ArduPlane's defaults but for what the airframe
// can do (THR_MAX 100, a climb of 4 m/s of the 5 it has, its idle sink) and its turn drag.
inline nav::TecsParams airframe_tecs_params() {
    nav::TecsParams p = nav::kTecsDefaults;
    p.thr_max_pct = 100;
    p.clmb_max_m_s = 4.0f;
    p.sink_min_m_s = 4.0f;
    p.rll2thr = 15.0f;  // 15 m/s x 1 m/s^2 of induced drag per (1/cos^2 - 1)
    return p;
}

// TECS's input in cruise from the point mass (its airspeed is the pitot's, sea level).
inline nav::TecsInput tecs_input(const PointMass& m, float height_dem_m, float eas_dem_m_s, bool airspeed) {
    nav::TecsInput in;
    in.height_dem_m = height_dem_m;
    in.eas_dem_m_s = eas_dem_m_s;
    in.eas_m_s = m.tas_m_s;
    in.have_airspeed = airspeed;
    in.eas2tas = 1.0f;
    in.cos_bank_sq = m.cos_bank_sq();
    in.pitch_rad = m.pitch_rad;
    in.stage = nav::TecsStage::kNormal;
    in.takeoff_pitch_cd = 0;
    return in;
}

}  // namespace testplane
