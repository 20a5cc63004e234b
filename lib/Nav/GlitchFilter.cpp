// SPDX-License-Identifier: GPL-3.0-or-later
#include "GlitchFilter.h"

#include <math.h>

namespace nav {

bool GlitchFilter::check(const Location& pos, const NorthEast& vel_m_s, uint32_t now_ms, const LocalMap& map) {
    const uint32_t age_ms = now_ms - good_ms_;
    bool good = !have_good_ || age_ms >= kTimeout_ms;
    if (!good) {
        const float t_s = (float)age_ms * 0.001f;
        const NorthEast d = map.offset_m(good_, pos);
        const float dn = d.north_m - good_vel_m_s_.north_m * t_s;
        const float de = d.east_m - good_vel_m_s_.east_m * t_s;
        const float allowed_m = kRadius_m + 0.5f * kAccelMax_m_s2 * t_s * t_s;
        const float d2 = dn * dn + de * de;
        good = d2 <= allowed_m * allowed_m;
        distance_m_ = sqrtf(d2);
    } else {
        distance_m_ = 0.0f;
    }
    glitching_ = !good;
    if (!good) {
        if (rejected_ != UINT16_MAX) ++rejected_;
        return false;
    }
    good_ = pos;
    good_vel_m_s_ = vel_m_s;
    good_ms_ = now_ms;
    have_good_ = true;
    return true;
}

}  // namespace nav
