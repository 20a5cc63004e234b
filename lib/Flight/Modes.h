// SPDX-License-Identifier: GPL-3.0-or-later
// The flight modes the board has: one table, ArduPlane's numbers (FLTMODEn, HEARTBEAT's
// custom_mode, SET_MODE, MAV_CMD_DO_SET_MODE) and names (MAVProxy's `mode NAME`, the
// console's `flight NAME`), and the control law each flies. A mode is added by a row
// (and its law in FlightControl::step); everything that takes a mode number (the mode
// switch's parameters, the ground station's requests, the console) checks it here, so a
// number the board does not have is refused, never flown as something else.
#pragma once

#include <stdint.h>

#include "FlightSettings.h"

namespace flight {

// What a mode does with the sticks.
enum class Law : uint8_t {
    PassThrough,  // MANUAL: the sticks are the surfaces
    Attitude,     // the sticks demand a bank and a pitch (LIM_ROLL_CD, LIM_PITCH_*): STABILIZE, FBWA
    // The navigation demands the bank, the pitch and the throttle (FlightControl::set_nav_demands):
    // FBWB and CRUISE (the receiver's failsafe glides, as from FBWA) ...
    Navigate,
    // ... and CIRCLE, AUTO, RTL, LOITER, GUIDED, which fly on through the receiver's short failsafe
    // (ArduPlane 3.x's failsafe_short_on_event with FS_SHORT_ACTN 0).
    NavigateOn,
};

constexpr uint8_t kModeNameMax = 9;  // "STABILIZE"
constexpr uint8_t kModeCount = 10;

// Index of ArduPlane mode number `number` in the table, or -1 (not a mode the board has).
int8_t mode_index(uint8_t number);
inline bool mode_known(uint8_t number) { return mode_index(number) >= 0; }
inline bool navigates(Law l) { return l == Law::Navigate || l == Law::NavigateOn; }
// Row `index` (0 .. kModeCount-1): its number, its law, its name (upper case, NUL-ended).
uint8_t mode_number(uint8_t index);
Law mode_law(uint8_t index);
void mode_name(uint8_t index, char out[kModeNameMax + 1]);
// The row whose name is `name` (any case), or -1.
int8_t mode_by_name(const char* name);

}  // namespace flight
