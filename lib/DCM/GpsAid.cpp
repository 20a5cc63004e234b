// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsAid.h"

#include "Fixed.h"

namespace dcm {

using linalg::Vector3f;
using linalg::Vector3l;

bool GpsAccel::on_velocity(const Vector3f& vel_m_s, float interval_s, float gain, float accel_units_per_m_s2,
                           Vector3l& observation) {
    since_fix_ = 0;
    // The GPS's interval ended kGpsFixLatency_s ago: `back` sums back from this arrival,
    // between sum j and j + 1 (GpsAid.h); beyond two (fixes faster than 8 Hz) the oldest.
    float back = interval_s > 0.0f ? kGpsFixLatency_s / interval_s : 0.0f;
    if (back > 2.0f) back = 2.0f;
    const uint8_t j = back >= 1.0f ? 1u : 0u;
    const float f = back - (float)j;
    const uint8_t last = f > 0.0f ? (uint8_t)(j + 1u) : j;  // the oldest sum it needs
    bool pair = fixes_ > last && interval_s > 0.0f && interval_s <= kGpsMaxInterval_s;
    for (uint8_t i = j; i <= last; ++i) pair = pair && windows_[i] > 0u && windows_[i] < kGpsMaxWindows;
    if (pair) {
        // The interval's mean specific force, interpolated between the two sums' means.
        const float w_near = (1.0f - f) / (float)windows_[j];
        const float w_far = f > 0.0f ? f / (float)windows_[last] : 0.0f;
        const Vector3l& near = sums_[j];
        const Vector3l& far = sums_[last];
        // mean(R f) - gain dv/dt, in accel units (gain: AHRS_GPS_GAIN, 1 = all of it).
        const Vector3f a_gps = (vel_m_s - prev_vel_m_s_) * (gain * accel_units_per_m_s2 / interval_s);
        observation = Vector3l(
            linalg::fixed_from_float((float)near.x * w_near + (float)far.x * w_far - a_gps.x, 0),
            linalg::fixed_from_float((float)near.y * w_near + (float)far.y * w_far - a_gps.y, 0),
            linalg::fixed_from_float((float)near.z * w_near + (float)far.z * w_far - a_gps.z, 0));
    }
    aiding_ = pair;
    for (uint8_t i = 2; i > 0; --i) {
        sums_[i] = sums_[i - 1];
        windows_[i] = windows_[i - 1];
    }
    sums_[0] = Vector3l();
    windows_[0] = 0;
    prev_vel_m_s_ = vel_m_s;
    if (fixes_ < 3u) ++fixes_;
    return pair;
}

}  // namespace dcm
