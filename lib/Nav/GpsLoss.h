// SPDX-License-Identifier: GPL-3.0-or-later
// GPS loss in a mode that navigates by the GPS (AUTO, RTL, LOITER, CRUISE's locked track;
// docs/navigation.md "GPS loss"): what the guidance flies when the fix goes.
//
//   kFix            the navigator's position and velocity, as they are
//   kDeadReckoning  for kDeadReckoning_ms from the loss: the position carried on from the
//                   navigator's last one by the air's velocity along the heading now plus
//                   the wind estimate (ArduPlane's DCM dead reckoning). The air's speed is
//                   the ground velocity at the loss less the wind, along the nose (what
//                   TECS holds after: the pitot's demand, or the trim throttle's). Without
//                   a wind estimate (no pitot) the wind is in that velocity: its part across
//                   the nose (the crab) is kept too and turns with the heading, right on a
//                   straight line, wrong by the wind's turn in a turn
//   kWingsLevel     after that: no position to fly (the caller holds the wings level and
//                   the height, which is the barometer's)
//
// The fix back (kBackSteps good steps in a row: a fix that comes and goes is not said
// twice a second) returns to kFix. Each change that matters is an Event for the caller to
// say: kLost once at the loss, kBack once at the return. No clock: the caller gives the
// step's time and length.
//
// Frame: metres north and east of home (the local map, Location.h), m/s; the heading in
// centidegrees from true north (the attitude's, 0..35999).
#pragma once

#include <stdint.h>

#include "Location.h"

namespace nav {

class GpsLoss {
public:
    // 10 s: the heading's error (a few degrees) and the wind's (a metre a second) carry
    // the position 10-20 m off in that time, within WP_RADIUS (30 m); beyond, the error
    // grows past what a leg's capture can tell from the truth.
    static constexpr uint16_t kDeadReckoning_ms = 10000;
    static constexpr uint8_t kBackSteps = 10;  // 1 s at the navigation's 10 Hz

    enum class Phase : uint8_t { kFix, kDeadReckoning, kWingsLevel };
    enum Event : uint8_t { kNone = 0, kLost = 1, kBack = 2 };

    // One navigation step. fix_ok: a 3D fix recent enough that the navigator's position
    // and velocity are the aircraft's. pos_m and vel_m_s come in as the navigator's and go
    // out as what to fly: the dead reckoning's in kDeadReckoning, the last of it in
    // kWingsLevel (not to be flown). wind_m_s: the wind estimate (where the air goes),
    // nullptr without one. dt_s: since the step before.
    // (Not inlined: the firmware's navigation step would grow by more than its size.)
    __attribute__((noinline)) Event step(bool fix_ok, NorthEast& pos_m, NorthEast& vel_m_s, uint16_t heading_cd,
                                         const NorthEast* wind_m_s, float dt_s, uint16_t now_ms);
    Phase phase() const { return phase_; }
    bool wings_level() const { return phase_ == Phase::kWingsLevel; }
    // Out of the GPS modes: forgotten, nothing said.
    void reset() { phase_ = Phase::kFix; }

private:
    NorthEast pos_m_ = {0.0f, 0.0f};
    NorthEast air_m_s_ = {0.0f, 0.0f};  // along and across (right positive) the nose
    uint16_t since_ms_ = 0;             // the loss's time (the step's now_ms)
    Phase phase_ = Phase::kFix;
    uint8_t good_steps_ = 0;
};

}  // namespace nav
