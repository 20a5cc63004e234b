// SPDX-License-Identifier: GPL-3.0-or-later
// Height above the ground reference from the barometric formula, and the climb rate.
//
// Height (ArduPilot's AP_Baro::get_altitude_difference): the standard atmosphere's
// troposphere, temperature falling at L = 0.0065 K/m from the ground's T0 (K), solved for
// the height between the ground's pressure p0 and p:
//   h = T0 / L * (1 - (p / p0)^(R L / g)),   R L / g = 0.190259 (dry air, g = 9.80665)
// as T0 / L * (1 - exp(0.190259 ln(p / p0))). The isothermal form ln(p0 / p) T0 R / g that
// ArduPilot used on APM2 is this to first order; it is off by h^2 L / (2 T0) (0.1 m at
// 100 m, 2.9 m at 500 m), this one only by the real air's departure from the standard lapse.
// Filter: an alpha-beta tracker on the height at the caller's rate (10 Hz, each sample the
// mean of ~8 pressures), one state for the height, one for its rate:
//   predicted h' = h + v dt;  r = h_measured - h';  h = h' + alpha r;  v += beta r / dt.
// alpha 0.3 keeps the height within a sample or two of a climb's true value (no lag on a
// steady climb: the rate state carries it); beta = alpha^2 / (2 - alpha) (Benedict and
// Bordner 1962, the tracker of least noise for a given lag) smooths the rate: with the
// pressure's 0.3 m of noise on a 10 Hz height the rate's noise is ~0.2 m/s.
// Plain float; a logf and an expf per update.
#pragma once

#include <stdint.h>

namespace ms5611 {

constexpr float kLapseRate_K_per_m = 0.0065f;      // ISA troposphere (ICAO Doc 7488)
constexpr float kLapseExponent = 0.190259f;        // R L / g
constexpr float kCelsiusToKelvin = 273.15f;
constexpr float kHeightAlpha = 0.3f;
constexpr float kHeightBeta = kHeightAlpha * kHeightAlpha / (2.0f - kHeightAlpha);

class BaroHeight {
public:
    // The ground's pressure (Pa, > 0) and temperature (degC); the height restarts at 0.
    void set_ground(float pressure_pa, float temperature_c);
    bool have_ground() const { return have_ground_; }
    // A new mean pressure (Pa, > 0) dt_s after the last (0 < dt_s < 2: else restarts the rate).
    void update(float pressure_pa, float dt_s);

    // Above the ground reference, m; 0 until set_ground.
    float height_m() const { return height_m_; }
    float climb_m_s() const { return climb_m_s_; }
    // The formula alone, no filter: m above the ground for pressure_pa.
    float raw_height_m(float pressure_pa) const;

private:
    float ln_ground_ = 0.0f;  // ln(p0 / 1 Pa)
    float scale_m_ = 0.0f;    // T0 / L
    float height_m_ = 0.0f, climb_m_s_ = 0.0f;
    bool have_ground_ = false, have_height_ = false;
};

}  // namespace ms5611
