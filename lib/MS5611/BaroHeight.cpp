// SPDX-License-Identifier: GPL-3.0-or-later
#include "BaroHeight.h"

#include <math.h>

namespace ms5611 {

namespace {
// avr-libc's logf and expf are macros for log and exp, whose double is float (32 bits):
// explicit casts, free on the AVR, keep -Wdouble-promotion quiet; the host has both.
#ifdef __AVR__
float log_f(float x) { return (float)log((double)x); }
float exp_f(float x) { return (float)exp((double)x); }
#else
float log_f(float x) { return logf(x); }
float exp_f(float x) { return expf(x); }
#endif
}  // namespace

void BaroHeight::set_ground(float pressure_pa, float temperature_c) {
    ln_ground_ = log_f(pressure_pa);
    scale_m_ = (temperature_c + kCelsiusToKelvin) / kLapseRate_K_per_m;
    height_m_ = climb_m_s_ = 0.0f;
    have_ground_ = true;
    have_height_ = false;
}

float BaroHeight::raw_height_m(float pressure_pa) const {
    // ln(p / p0) as ln p - ln p0: no division.
    return (1.0f - exp_f(kLapseExponent * (log_f(pressure_pa) - ln_ground_))) * scale_m_;
}

void BaroHeight::update(float pressure_pa, float dt_s) {
    if (!have_ground_ || !(pressure_pa > 0.0f)) return;
    const float measured = raw_height_m(pressure_pa);
    if (!have_height_ || !(dt_s > 0.0f && dt_s < 2.0f)) {
        height_m_ = measured;
        climb_m_s_ = 0.0f;
        have_height_ = true;
        return;
    }
    const float predicted = height_m_ + climb_m_s_ * dt_s;
    const float residual = measured - predicted;
    height_m_ = predicted + kHeightAlpha * residual;
    climb_m_s_ += kHeightBeta * residual / dt_s;
}

}  // namespace ms5611
