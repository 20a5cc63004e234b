// SPDX-License-Identifier: GPL-3.0-or-later
// A GPS position that the last good fix's velocity cannot explain is a glitch (multipath,
// a satellite lost, a receiver's jump): rejected, as ArduPilot's AP_GPS_Glitch did
// (Copter 3.1-3.2, GPSGLITCH_RADIUS 200 cm, GPSGLITCH_ACCEL 1000 cm/s^2).
//
// The rule: from the last good fix, at its velocity, the plane would be at P = good +
// v_good * t after t seconds. A new fix within
//     kRadius_m + 1/2 kAccelMax_m_s2 t^2
// of P is good; one further is rejected. Why these numbers:
//  - kRadius_m 2 m: the u-blox's own position noise between fixes (a horizontal RMS of
//    ~1 m that wanders slowly, hAcc ~2 m) must never be called a glitch;
//  - kAccelMax_m_s2 10 m/s^2: what the plane can do to its velocity unseen. The steepest
//    bank the flight modes allow (LIM_ROLL_CD 45 deg) turns at 1 g in a level turn, so
//    at 5 Hz (t = 0.2 s) a true fix strays 0.2 m from P, well inside the radius;
//  - the time-out: the allowance grows with t^2, so a position that stays where it
//    jumped is believed after sqrt(2 D / a): a 50 m jump after 3.2 s, a 500 m one after
//    10 s (a receiver that has moved its solution for that long is more likely right
//    than 3 s of dead reckoning), and after kTimeout_ms any fix is taken whatever the
//    distance (a receiver reset, the plane carried while the GPS was off).
// A fix lost (not 3D) changes nothing: the next 3D fix is checked against the last good
// one, with the allowance its age gives.
//
// Frame: north and east metres on the local map (Location.h); times in the board's ms.
#pragma once

#include <stdint.h>

#include "Location.h"

namespace nav {

class GlitchFilter {
public:
    static constexpr float kRadius_m = 2.0f;
    static constexpr float kAccelMax_m_s2 = 10.0f;
    static constexpr uint16_t kTimeout_ms = 10000;

    // A new 3D fix (position, horizontal velocity, the board's time it came): true if
    // it is good (it becomes the last good fix), false if rejected as a glitch.
    bool check(const Location& pos, const NorthEast& vel_m_s, uint32_t now_ms, const LocalMap& map);
    // Forget the last good fix: the next is taken as it is (a new home, a new map).
    void reset() { have_good_ = glitching_ = false; }

    bool glitching() const { return glitching_; }
    // The last fix's distance from where the last good one predicted, m.
    float distance_m() const { return distance_m_; }
    uint32_t good_ms() const { return good_ms_; }
    uint16_t rejected() const { return rejected_; }  // fixes rejected since power-up (saturates)

private:
    Location good_;
    NorthEast good_vel_m_s_ = {0.0f, 0.0f};
    uint32_t good_ms_ = 0;
    float distance_m_ = 0.0f;
    uint16_t rejected_ = 0;
    bool have_good_ = false;
    bool glitching_ = false;
};

}  // namespace nav
