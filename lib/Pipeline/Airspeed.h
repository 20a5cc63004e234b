// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5's airspeed sensor: an MPXV7002DP on analog input A0, read by the 10-bit ADC
// against the 5 V supply. Data sheet: Vout = VS (0.2 P + 0.5), P in kPa: 1 V per kPa at
// VS = 5 V, 2.5 V at rest. The zero is measured at start-up while the board is still
// (as ArduPilot's AP_Airspeed calibrates its offset), since the part's offset is
// +-6.25 % of VS.
#pragma once

#include <math.h>
#include <stdint.h>

#include "Constants.h"

namespace airspeed {

constexpr float kAdcFullScale_mV = 5000.0f;  // the ADC's reference: the board's 5 V
constexpr uint16_t kAdcCounts = 1024;
constexpr float kSensitivity_Pa_per_mV = 1.0f;  // 1 V per kPa at 5 V supply
using linalg::kAirDensity_kg_m3;                // ISA sea level: indicated airspeed
constexpr float kPa_per_count = kAdcFullScale_mV / kAdcCounts * kSensitivity_Pa_per_mV;

// A fitted sensor reads 2.5 V at rest, +-6.25 % of its supply (0.3125 V) for its offset;
// an open input floats or reads a rail: outside 2.0..3.0 V there is no sensor.
constexpr uint16_t kPresentMinCounts = (uint16_t)(2000.0f / kAdcFullScale_mV * kAdcCounts);
constexpr uint16_t kPresentMaxCounts = (uint16_t)(3000.0f / kAdcFullScale_mV * kAdcCounts);

inline bool present(uint16_t zero_counts) { return zero_counts >= kPresentMinCounts && zero_counts <= kPresentMaxCounts; }

// Airspeed (m/s) from a sum of n ADC readings and the zero (counts, measured at rest):
// v = sqrt(2 dP / rho); a pressure below the zero (noise, a reversed tube) reads 0.
inline float airspeed_m_s(uint32_t sum_counts, uint8_t n, uint16_t zero_counts) {
    if (n == 0) return 0.0f;
    const float dp_Pa = ((float)sum_counts / n - (float)zero_counts) * kPa_per_count;
    return dp_Pa > 0.0f ? sqrtf(2.0f * dp_Pa / kAirDensity_kg_m3) : 0.0f;
}

// A configured cruise speed (TRIM_ARSPD_CM: no sensor) in a banked turn. The trim holds
// the wing near its trimmed angle of attack, so its lift coefficient stays: the lift
// n W = 1/2 rho V^2 S C_L of a load factor n takes V = V_trim sqrt(n), and n = 1/cos(bank)
// in a level coordinated turn. cos(bank) is the estimate's (earth down's body z
// component, cos(roll) cos(pitch)), held at 0.5 or more (n <= 2: a bank within 60 deg).
// Without it the speed read is short by sqrt(n) in the turn, the centripetal term short
// by as much, and STABILIZE's bank (held on the estimate) creeps past the one asked for.
constexpr float kMinCosBank = 0.5f;
inline float cruise_in_turn_m_s(float trim_m_s, float down_z) {
    const float cos_bank = down_z > 1.0f ? 1.0f : (down_z > kMinCosBank ? down_z : kMinCosBank);
    return trim_m_s / sqrtf(cos_bank);
}

}  // namespace airspeed
