// SPDX-License-Identifier: GPL-3.0-or-later
// The output format a user picks with `mode` (the lines themselves: lib/Console's
// Format.h, and lib/MavLink). Its stored byte is Settings::mode, so it is declared here,
// below the record and the formatter both.
#pragma once

#include <stdint.h>

namespace fmt {

// The stored byte of Settings::mode: values are never renumbered (EEPROM records hold them).
enum class OutputMode : uint8_t { Plot = 0, Csv = 1, Quiet = 2, Quat = 3, Raw = 4, Mavlink = 5 };
constexpr OutputMode kLastOutputMode = OutputMode::Mavlink;

}  // namespace fmt
