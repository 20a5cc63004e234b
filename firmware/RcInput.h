// SPDX-License-Identifier: GPL-3.0-or-later
// The receiver: the PPM sum from the APM 2.5's encoder on ICP5 = PL1 (pin 48), captured
// by Timer5 as ArduPilot's APM2 HAL does (mode 15: TOP = OCR5A = 39999, prescaler 8:
// 0.5 us ticks; input capture on the rising edge, ICES5). The capture interrupt only
// stores ICR5 in a small ring; the loop hands the timestamps to lib/Flight's PpmDecoder
// (pure, host-tested).
#pragma once

#include <stdint.h>

#include "Ppm.h"

namespace rc_input {

void begin();
// Feeds the captures since the last call to `decoder`, up to the first that closes an
// accepted frame: true then (decoder.frame_us() holds it; call again for more). A ring
// overflow (captures lost) resets the decoder.
bool poll(flight::PpmDecoder& decoder);

}  // namespace rc_input
