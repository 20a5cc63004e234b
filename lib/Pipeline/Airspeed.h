// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5's airspeed sensor: an MPXV7002DP on analog input A0, read by the 10-bit ADC
// against the 5 V supply. Data sheet: Vout = VS (0.2 P + 0.5), P in kPa: 1 V per kPa at
// VS = 5 V, 2.5 V at rest. The zero is measured at start-up while the board is still
// (as ArduPilot's AP_Airspeed calibrates its offset), since the part's offset is
// +-6.25 % of VS, and kept as ARSPD_OFFSET for a start that is not still (start_zero).
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

// The zero as ARSPD_OFFSET keeps it, ArduPilot's unit: APM 1's 12-bit ADC counts of the 5 V
// supply, which ArduPilot kept on the APM 2 (819 per ratiometric volt): here the mean
// 10-bit reading times 4 (819.2 per volt, 2048 at the nominal 2.5 V), which also keeps a
// quarter of a count of the mean of many readings. 0: none measured yet.
constexpr uint16_t kOffsetPerCount = 4;
inline bool offset_present(uint16_t offset) { return present((uint16_t)(offset / kOffsetPerCount)); }
// The mean of n readings (their sum) in ARSPD_OFFSET's unit, rounded.
inline uint16_t offset_of(uint32_t sum_counts, uint16_t n) {
    if (n == 0u) return 0;
    return (uint16_t)((sum_counts * kOffsetPerCount + n / 2u) / n);
}

// Airspeed (m/s) from a sum of n ADC readings and the zero (ARSPD_OFFSET's unit, measured at
// rest): v = sqrt(2 dP / rho); a pressure below the zero (noise, a reversed tube) reads 0,
// and so does any pressure against a zero no still sensor reads (ARSPD_OFFSET set to one,
// or to 0 by `defaults`): no airspeed rather than a wrong one.
inline float airspeed_m_s(uint32_t sum_counts, uint8_t n, uint16_t zero_offset) {
    if (n == 0 || !offset_present(zero_offset)) return 0.0f;
    const float dp_Pa = ((float)sum_counts / n - (float)zero_offset * (1.0f / kOffsetPerCount)) * kPa_per_count;
    return dp_Pa > 0.0f ? sqrtf(2.0f * dp_Pa / kAirDensity_kg_m3) : 0.0f;
}

// What a start makes of the pitot's zero. `measured` is the mean of the readings taken
// while the gyro calibrated (ARSPD_OFFSET's unit), `still` whether that calibration found
// the board still, `saved` the ARSPD_OFFSET an earlier start kept (0: none).
//   - Still: the measured zero is the zero. Within kOffsetNoise of the saved one it is the
//     same zero and the saved one stays (no EEPROM write at every start); else it is saved.
//   - Not still (a restart in flight, a brown-out on the servo rail): the reading may be
//     the flight's dynamic pressure, within the sensor's offset tolerance at cruise (0.2 kPa
//     at 18 m/s: 41 counts), which as a zero would read every airspeed as none. The saved
//     zero is used when there is one a still sensor can read and the reading is not below
//     it (a pitot reads no suction) nor beyond the sensor's 4.5 V full scale (a floating
//     input, a rail); else the cruise speed, as without the sensor.
//   - A measured zero outside 2.0-3.0 V is no sensor, whatever was saved.
// kOffsetNoise: 2 counts (9.8 Pa). A reading's step is a count (4.9 Pa), about its noise
// too (the 5 V supply the sensor and the ADC share ripples by a few mV), and the part's zero
// moves with its temperature; a zero 2 counts off reads 18 m/s as 17.5 or 18.4 (and
// 12 m/s as 11.3 or 12.6), well within what the centripetal and the dV/dt terms need.
constexpr uint16_t kOffsetNoise = 2u * kOffsetPerCount;
constexpr uint16_t kFullScaleOffset = (uint16_t)(4500.0f / kAdcFullScale_mV * kAdcCounts) * kOffsetPerCount;
enum class StartZero : uint8_t {
    kKeep,    // still, the saved zero within the noise: the saved one, no write
    kSave,    // still, a new zero: ARSPD_OFFSET set to the measured one and saved
    kSaved,   // not still: the saved zero
    kCruise,  // not still, no saved zero (or one refused): the cruise speed TRIM_ARSPD_CM
    kNone,    // no sensor on A0
};
inline StartZero start_zero(uint16_t measured, bool still, uint16_t saved) {
    if (still) {
        if (!offset_present(measured)) return StartZero::kNone;
        const uint16_t diff = measured > saved ? (uint16_t)(measured - saved) : (uint16_t)(saved - measured);
        return offset_present(saved) && diff <= kOffsetNoise ? StartZero::kKeep : StartZero::kSave;
    }
    if (offset_present(saved) && measured + kOffsetNoise >= saved && measured <= kFullScaleOffset)
        return StartZero::kSaved;
    return offset_present(measured) ? StartZero::kCruise : StartZero::kNone;
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
