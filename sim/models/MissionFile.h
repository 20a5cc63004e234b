// SPDX-License-Identifier: GPL-3.0-or-later
// A mission file put into the simulated board's EEPROM before a run (apm25sim --mission), so
// that AUTO can be flown without the MAVLink upload: Mission Planner's and QGroundControl's
// plain-text format, "QGC WPL 110", one item a line after the header:
//
//   seq <TAB> current <TAB> frame <TAB> command <TAB> p1 p2 p3 p4 <TAB> lat <TAB> lon <TAB> alt <TAB> autocontinue
//
// (latitude and longitude in degrees, alt in metres; tabs or spaces). Seq 0 is home, as
// ArduPilot's, and is not stored. Each item becomes a command by lib/Mission's own
// from_item (what the MAVLink upload uses) and goes in by MissionStore's upload (the
// area not in use, then the commit): the bytes the firmware would have written.
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

namespace sim {

// Reads `path` and writes its mission into `eeprom` (4096 bytes, the chip's image). False,
// with the reason in `error`, for a file that cannot be read, a line that does not parse,
// a command or frame the firmware refuses (as MAV_MISSION_UNSUPPORTED would), more items
// than the store holds, seqs out of order.
bool write_mission_file(const std::string& path, std::vector<uint8_t>& eeprom, std::string& error);
// The same from the file's text (tests).
bool write_mission_text(const std::string& text, std::vector<uint8_t>& eeprom, std::string& error);

}  // namespace sim
