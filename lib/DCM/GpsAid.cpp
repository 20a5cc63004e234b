// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsAid.h"

#include "Fixed.h"

namespace dcm {

using linalg::Vector3f;
using linalg::Vector3l;

bool GpsAccel::on_velocity(const Vector3f& vel_m_s, float interval_s, float gain, float accel_units_per_m_s2,
                           Vector3l& observation) {
    since_fix_ = 0;
    // The sum nearest the GPS's interval (GpsAid.h): one fix late when the lag is at
    // least half the interval.
    const bool delayed = kGpsLag_s >= 0.5f * interval_s;
    const Vector3l& sum = delayed ? prev_sum_ : sum_;
    const uint8_t windows = delayed ? prev_windows_ : windows_;
    const bool pair = fixes_ >= (delayed ? 2u : 1u) && interval_s > 0.0f && interval_s <= kGpsMaxInterval_s &&
                      windows > 0u && windows < kGpsMaxWindows;
    if (pair) {
        // mean(R f) - gain dv/dt, in accel units (gain: AHRS_GPS_GAIN, 1 = all of it).
        const float per_window = 1.0f / (float)windows;
        const Vector3f a_gps = (vel_m_s - prev_vel_m_s_) * (gain * accel_units_per_m_s2 / interval_s);
        observation = Vector3l(linalg::fixed_from_float((float)sum.x * per_window - a_gps.x, 0),
                               linalg::fixed_from_float((float)sum.y * per_window - a_gps.y, 0),
                               linalg::fixed_from_float((float)sum.z * per_window - a_gps.z, 0));
    }
    aiding_ = pair;
    prev_sum_ = sum_;
    prev_windows_ = windows_;
    sum_ = Vector3l();
    windows_ = 0;
    prev_vel_m_s_ = vel_m_s;
    if (fixes_ < 2u) ++fixes_;
    return pair;
}

}  // namespace dcm
