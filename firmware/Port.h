// SPDX-License-Identifier: GPL-3.0-or-later
// The serial port's language: text (the output mode of the settings: plot, csv, quat,
// raw, quiet) or MAVLink, and the writing of "# " messages in it. At power-up the port
// speaks text unless SERIAL0_PROTOCOL is 1 or 2 (ArduPilot's MAVLink: then MAVLink from
// the first byte) or the saved mode is `mavlink`. A ground station's HEARTBEAT switches
// a text mode to MAVLink until reset (not a setting), a typed `mode` sets the mode typed,
// and three returns in a row in MAVLink (ArduPilot's way into its CLI) give the text
// console back, in the saved text mode (plot when that is `mavlink`).
#pragma once

#include <stdint.h>

#include "Format.h"
#include "MavLink.h"

namespace port {

// MAVLink frames go out whole or not at all, through the same queue as the text, so a
// frame is never cut by a message.
extern mav::Packer mavlink;

fmt::OutputMode output_mode();
bool mavlink_mode();
// A ground station's HEARTBEAT arrived (true), or a `mode` was typed (false).
void set_gcs_link(bool on);
// Three returns in a row in MAVLink: the text console.
void escape_to_text();

// text::Sink's write for every "# " message: text, or STATUSTEXT frames in MAVLink. Each
// line goes out whole or, when the output has no room for it now, not at all: never a
// wait for the UART in the loop (serial_text::line_part). The lines dropped are counted...
void write_message(void*, const char* data, uint8_t len);
// ... and told by the loop task `held_back` once the output has room again:
// "# N line(s) held back: output full", or, when warnings (warn, error, PreArm) were among
// them, "# warn: N line(s) held back, W warning(s)" (a STATUSTEXT warning).
bool held_back_due();
void say_held_back();
// A frame (a reply: never dropped; waits for room).
void send_frame(const uint8_t* frame, uint8_t len);

}  // namespace port
