// SPDX-License-Identifier: GPL-3.0-or-later
// Position and home (lib/Nav/Navigator): the GPS port's fix (GpsPort.h) and the
// barometer's height (Baro.h) composed, for the ground station, the console and, later,
// the navigation. The loop task `nav` runs on each new fix and every kPeriodMs between
// them (ArduPlane's navigation rate, 10 Hz), moving the position on by the GPS velocity.
// Home is set once, from the first good fix or by a ground station, and said:
//   "# home: set at 7.1350450 -73.1194210, 1028.00 m (10 satellites, hdop 0.90)"
// `status` has a line for it: "# home: ... 12.30 m N, -4.10 m E, 5.20 m up (baro), wind ...".
// The wind (lib/Nav/Wind) is learnt on each fix while the pitot is fitted.
#pragma once

#include <stdint.h>

#include "Location.h"
#include "MavLink.h"
#include "Navigator.h"
#include "Text.h"
#include "Wind.h"

namespace position {

constexpr uint16_t kPeriodMs = 100;

// The loop task: a new fix, or kPeriodMs since the last run.
bool due();
void run();

// Position.cpp's, named here so that navigator() is a constant expression: NavModes'
// mission executor keeps its map and home with no start-up code.
extern nav::Navigator nav_;
constexpr const nav::Navigator& navigator() { return nav_; }
const nav::WindEstimator& wind();

// MAV_CMD_DO_SET_HOME (the ground station's home, said on the console): false when
// there is no position yet (here) or the place is off the earth.
bool set_home_here();
bool set_home(const nav::Location& home);
// Counts home's changes: the ground station is sent HOME_POSITION when it moves.
uint8_t home_changes();

// GLOBAL_POSITION_INT's and VFR_HUD's fields now.
void report(mav::PositionReport& r);

// `status`'s line: "# home: not set" or where the plane is from it.
void print_status_line(const text::Sink* out);

}  // namespace position
