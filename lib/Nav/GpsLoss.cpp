// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsLoss.h"

#include "Constants.h"
#include "NeVector.h"

namespace nav {

namespace {
bool finite(const NorthEast& v) { return linalg::is_finite(v.north_m) && linalg::is_finite(v.east_m); }
}  // namespace

GpsLoss::Event GpsLoss::step(bool fix_ok, NorthEast& pos_m, NorthEast& vel_m_s, uint16_t heading_cd,
                             const NorthEast* wind_m_s, float dt_s, uint16_t now_ms) {
    if (phase_ == Phase::kFix && fix_ok) return kNone;
    const float heading_rad = (float)heading_cd * (linalg::kRadPerDeg * 0.01f);
    const NorthEast nose = ne(cosf(heading_rad), sinf(heading_rad));
    const NorthEast wind = wind_m_s != nullptr ? *wind_m_s : ne(0.0f, 0.0f);
    Event event = kNone;
    if (phase_ == Phase::kFix) {
        // Lost: from the navigator's last position (moved on by the last fix's velocity
        // for at most Navigator::kMaxExtrapolation_ms), with its velocity less the wind.
        // With an estimate the air moves along the nose (the fix's velocity is 0.2-0.5 s
        // older than the heading: in a turn its angle to the nose is no crab).
        const NorthEast air = vel_m_s - wind;
        air_m_s_ = ne(dot(air, nose), wind_m_s != nullptr ? 0.0f : cross(nose, air));
        pos_m_ = pos_m;
        since_ms_ = now_ms;
        good_steps_ = 0;
        phase_ = Phase::kDeadReckoning;
        dt_s = 0.0f;  // from here
        event = kLost;
    } else {
        good_steps_ = fix_ok ? (uint8_t)(good_steps_ + 1u) : (uint8_t)0;
        if (good_steps_ >= kBackSteps) {
            phase_ = Phase::kFix;  // the navigator's again, from this step
            return kBack;
        }
    }
    if (phase_ == Phase::kDeadReckoning) {
        const NorthEast right = ne(-nose.east_m, nose.north_m);
        const NorthEast v = nose * air_m_s_.north_m + right * air_m_s_.east_m + wind;
        const NorthEast p = pos_m_ + v * dt_s;
        // Past its time, or a NaN from any input (the last finite position kept): nothing
        // more to fly.
        if ((uint16_t)(now_ms - since_ms_) >= kDeadReckoning_ms || !finite(p)) {
            phase_ = Phase::kWingsLevel;
        } else {
            pos_m_ = p;
            vel_m_s = v;
        }
    }
    pos_m = pos_m_;
    return event;
}

}  // namespace nav
