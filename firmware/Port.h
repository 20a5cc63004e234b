// SPDX-License-Identifier: GPL-3.0-or-later
// The serial port's language: text (the output mode of the settings: plot, csv, quat,
// raw, quiet) or MAVLink, and the writing of "# " messages in it. A ground station's
// HEARTBEAT switches a text mode to MAVLink until reset (not a setting: `save` keeps the
// mode typed), and a typed `mode` ends it.
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

// text::Sink's write for every "# " message: text, or STATUSTEXT frames in MAVLink.
void write_message(void*, const char* data, uint8_t len);
// A frame (a reply: never dropped; waits for room).
void send_frame(const uint8_t* frame, uint8_t len);

}  // namespace port
