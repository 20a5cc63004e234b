// SPDX-License-Identifier: GPL-3.0-or-later
// Small helpers the calibration procedures share.
#pragma once

namespace calib {

// Not fabsf: avr-libc's is fabs on double (a promotion warning, though both are 32-bit).
inline float absf(float v) { return v < 0.0f ? -v : v; }
inline bool within(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN

}  // namespace calib
