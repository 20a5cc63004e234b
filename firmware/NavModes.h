// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation modes (docs/navigation.md "The modes"): lib/Nav's L1 and TECS and
// lib/Mission's executor composed on the board, as ArduPlane 3.x flies them:
//
//   CIRCLE 1   a gentle turn (a third of LIM_ROLL_CD) with the height held: no GPS needed
//   FBWB 6     the roll stick banks as FBWA; TECS holds the height, which the pitch stick
//              moves at FBWB_CLIMB_RATE, and the speed
//   CRUISE 7   FBWB, and the ground track locked while the roll stick is centred
//   AUTO 10    the stored mission (MissionStore, read through mission_store())
//   RTL 11     home at ALT_HOLD_RTL, then its circle of WP_LOITER_RAD
//   LOITER 12  a circle of WP_LOITER_RAD where the mode was entered, at that height
//   GUIDED 15  a circle of WP_LOITER_RAD about a ground station's "fly to here" (fly_to()) at
//              its height; entered by its number alone, LOITER's circle where it is
//
// Two loop tasks: the navigation step at 10 Hz (the target into L1 and TECS; their bank,
// pitch and throttle to FlightIo's controllers) and TECS's filters at 50 Hz. A mode that
// cannot run (a GPS mode without a 3D fix or home, AUTO without a mission) is refused
// with its reason, from the switch, the ground station and the console; a GPS mode that
// loses its fix dead-reckons for 10 s, then holds the wings level until it returns, the
// mode kept (lib/Nav/GpsLoss). The attitude-only build has none of it.
#pragma once

#include <stdint.h>

#include "Features.h"
#include "FlightSettings.h"
#include "MavLink.h"
#include "MissionCommand.h"
#include "Text.h"

#if APM25_FLIGHT
#include "MissionStore.h"
#endif

namespace nav_modes {

constexpr uint16_t kPeriodMs = 100;      // ArduPlane's navigation rate, 10 Hz
constexpr uint16_t kFilterPeriodMs = 20;  // TECS's update_50hz

// The loop tasks.
bool due();
void run();
bool filters_due();
void filters_run();

// The parameters again after a change of the settings.
void configure();

// Why mode m cannot run now ("no 3D GPS fix", "no home", "no mission"); an empty text
// (text::Flash's nullptr) when it can.
bool refused(flight::Mode m, text::Flash& reason);
// The rows of lib/Flight/Modes.h that cannot run now (FlightControl::set_unavailable).
uint16_t unavailable_rows();

// NAV_CONTROLLER_OUTPUT's fields, while a navigation mode flies (false: none).
bool report(mav::NavOutput& r);

// A ground station's "fly to here" (MISSION_ITEM(_INT) with current 2): GUIDED entered (or
// its circle moved) about the command's place at its height; false when GUIDED is refused
// (its reason said).
bool fly_to(const mission::Command& to);

#if APM25_FLIGHT
// The stored mission AUTO flies: the one place that reads it (MissionLink's accessor
// replaces it when the upload lands).
const mission::MissionStore& mission_store();
#endif

}  // namespace nav_modes
