// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5's airspeed input: an MPXV7002DP differential pressure sensor on analog input
// A0 (APM25.md "Flying"; Freescale MPXV7002 data sheet: Vout = VS x (0.2 x P + 0.5) V, P in
// kPa, VS = 5.0 V, the range -2..2 kPa; ArduPilot's APM2 analog airspeed reads it), its
// pitot's pressure the dynamic pressure 1/2 rho v^2 at sea level (ISA rho = 1.225 kg/m^3).
#pragma once

#include <algorithm>

#include "Constants.h"

namespace sim {

struct Mpxv7002dpModel {
    static constexpr double kSupply_mV = 5000.0;

    // The output in millivolts for an airspeed (m/s, along the pitot), held within the
    // 0.5..4.5 V the range gives.
    static double output_mV(double airspeed_m_s) {
        const double pressure_kPa = 0.5 * linalg::dbl::kAirDensity_kg_m3 * airspeed_m_s * airspeed_m_s * 1e-3;
        const double mV = kSupply_mV * (0.2 * pressure_kPa + 0.5);
        return std::min(std::max(mV, 0.1 * kSupply_mV), 0.9 * kSupply_mV);
    }
};

}  // namespace sim
