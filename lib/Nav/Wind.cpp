// SPDX-License-Identifier: GPL-3.0-or-later
#include "Wind.h"

#include <math.h>

#include "Constants.h"

namespace nav {

void WindEstimator::update(const NorthEast& ground_m_s, float tas_m_s, float heading_rad, float pitch_rad,
                           float dt_s) {
    if (!(tas_m_s >= kMinAirspeed_m_s) || !(dt_s > 0.0f)) return;
    // (avr-libc's cosf and sinf return double, which is float there: named floats first.)
    const float cos_pitch = cosf(pitch_rad), cos_heading = cosf(heading_rad), sin_heading = sinf(heading_rad);
    const float horizontal_m_s = tas_m_s * cos_pitch;
    const NorthEast now = {ground_m_s.north_m - horizontal_m_s * cos_heading,
                           ground_m_s.east_m - horizontal_m_s * sin_heading};
    if (!(now.north_m == now.north_m) || !(now.east_m == now.east_m)) return;  // NaN in: nothing learnt
    if (!valid_) {
        wind_ = now;  // the first estimate as it is: nothing to average with yet
        valid_ = true;
        return;
    }
    // First order low-pass, alpha = dt / (tau + dt) (a step in dt never overshoots).
    const float alpha = dt_s / (kTimeConstant_s + dt_s);
    wind_.north_m += alpha * (now.north_m - wind_.north_m);
    wind_.east_m += alpha * (now.east_m - wind_.east_m);
}

float WindEstimator::speed_m_s() const { return sqrtf(wind_.north_m * wind_.north_m + wind_.east_m * wind_.east_m); }

float WindEstimator::from_deg() const {
    // The wind blows from the opposite of where the air goes.
    const float rad = atan2f(-wind_.east_m, -wind_.north_m);
    float deg = rad * linalg::kDegPerRad;
    if (deg < 0.0f) deg += 360.0f;
    return deg;
}

float eas_to_tas(float pressure_pa, float temperature_c) {
    constexpr float kDryAirGasConstant = 287.05f;  // J/(kg K)
    if (!(pressure_pa > 1000.0f) || !(temperature_c > -100.0f) || !(temperature_c < 100.0f)) return 1.0f;
    const float density_kg_m3 = pressure_pa / (kDryAirGasConstant * (temperature_c + 273.15f));
    const float ratio = sqrtf(linalg::kAirDensity_kg_m3 / density_kg_m3);
    return ratio;
}

}  // namespace nav
