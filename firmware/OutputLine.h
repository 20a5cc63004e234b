// SPDX-License-Identifier: GPL-3.0-or-later
// The output line: the angles in the chosen mode (`roll:... pitch:... yaw:...`, csv,
// quat, raw) or an ATTITUDE frame in MAVLink, none in quiet mode, at the settings' rate.
// A line is written only when it fits whole: a backlog of replies delays a line, never
// a sample.
#pragma once

#include <stdint.h>

namespace output_line {

// Sample task: whether a line is due on this sample (kept in vehicle::tick.output).
bool due();
// Sample task: the line; the angles it worked out in hundredths are kept in
// vehicle::tick for the control step.
void run();
// Once a second: how many lines were skipped for angles that were not finite.
void say_skipped();

}  // namespace output_line
