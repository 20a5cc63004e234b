// SPDX-License-Identifier: GPL-3.0-or-later
// The console: bytes typed or pasted into the serial port become commands (lib/Console
// parses; README "Console"), and their replies go out a part (a line) at a time.
//
// Nothing typed is lost: bytes are taken from Serial's 64-byte receive ring and parsed at
// once, on every pass of the loop and again on every sample (at 115200 baud the ring
// fills in 5.6 ms), and the parsed commands wait in a queue. A reply part goes out only
// when the output queue has room for it and an output line after it, and only when it
// ends before the next sample is due (the task table's budgets): a paste is answered as
// fast as the UART carries the replies, and the angle lines keep flowing.
//
// In MAVLink the same bytes are a ground station's frames (GcsLink.h): a ground
// station's HEARTBEAT in a text mode switches the port to MAVLink.
#pragma once

#include <stdint.h>

namespace console_link {

// Loop task: received bytes -> commands (or ground-station frames).
void take_input();
// Sample task: the same, but a line's end waits for the loop (its parse on top of the
// sample's work would make the loop's longest iteration).
void take_input_in_step();
// The bytes of a line so far are no command (the port switched to MAVLink).
void forget_partial_line();

// Loop tasks: the next part of a reply, as text or as STATUSTEXT frames (their packing
// costs more: each row has its own budget).
bool reply_due_text();
bool reply_due_mavlink();
// ... and the work of `save` and `defaults`, longer than a line, a part with its own budget.
bool command_due();
void reply();

// "# settings: rate ... mode ...": at start-up and in `status`.
void print_settings_line();

}  // namespace console_link
