// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsFix.h"

namespace gps {

uint64_t unix_time_us(const Fix& f, uint32_t now_ms) {
    if (f.week == 0u || f.fix < FixType::k2D) return 0u;
    constexpr uint64_t kGpsEpochUnix_s = 315964800u;  // 1980-01-06 00:00:00 UTC
    constexpr uint64_t kLeap_ms = 18000u;             // GPS - UTC since 2017-01-01
    constexpr uint64_t kWeek_ms = 604800000u;
    const uint64_t gps_ms = (uint64_t)f.week * kWeek_ms + f.itow_ms + (uint32_t)(now_ms - f.received_ms);
    return (kGpsEpochUnix_s * 1000u + gps_ms - kLeap_ms) * 1000u;
}

}  // namespace gps
