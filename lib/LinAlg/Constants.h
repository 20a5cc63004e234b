// SPDX-License-Identifier: GPL-3.0-or-later
// Mathematical and physical constants, defined once for lib/, firmware/ and sim/.
//
// Each is written once, as a double in linalg::dbl (the host tools' arithmetic, sim/),
// and linalg's float is that double rounded once to float: the libraries and the
// firmware compute in float. Never derive a float constant here by double arithmetic:
// avr-gcc's double is 32-bit, so it would be rounded at each step on the AVR and only at
// the end on the host, and the two could differ in the last bit.
#pragma once

namespace linalg {

namespace dbl {
constexpr double kPi = 3.14159265358979323846;
constexpr double kDegPerRad = 57.295779513082320877;   // 180 / pi
constexpr double kRadPerDeg = 0.017453292519943295769;  // pi / 180
constexpr double kGravity_m_s2 = 9.80665;               // standard gravity (CGPM 1901)
constexpr double kMicroteslaPerGauss = 100.0;           // 1 G = 1e-4 T
constexpr double kAirDensity_kg_m3 = 1.225;             // ISA sea level
}  // namespace dbl

constexpr float kPi = (float)dbl::kPi;
constexpr float kDegPerRad = (float)dbl::kDegPerRad;
constexpr float kRadPerDeg = (float)dbl::kRadPerDeg;
constexpr float kGravity_m_s2 = (float)dbl::kGravity_m_s2;
constexpr float kMicroteslaPerGauss = (float)dbl::kMicroteslaPerGauss;
constexpr float kAirDensity_kg_m3 = (float)dbl::kAirDensity_kg_m3;

}  // namespace linalg
