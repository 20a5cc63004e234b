// SPDX-License-Identifier: GPL-3.0-or-later
// Arduino.h, then the core's function-like macros removed: Arduino.h
// #defines constrain/min/max/abs/round/sq/radians/degrees, which would rewrite the
// project's own functions (linalg::constrain) in every header included after it.
#pragma once

#include <Arduino.h>

#undef constrain
#undef min
#undef max
#undef abs
#undef round
#undef sq
#undef radians
#undef degrees
