// SPDX-License-Identifier: GPL-3.0-or-later
#include "Port.h"

#include "SerialText.h"
#include "Vehicle.h"

namespace port {

mav::Packer mavlink;
static bool gcs_link = false;

static void write_frame(void*, const uint8_t* frame, uint8_t len) { send_frame(frame, len); }
static mav::StatusText status_text(mavlink, mav::FrameSink{nullptr, write_frame});

fmt::OutputMode output_mode() { return gcs_link ? fmt::OutputMode::Mavlink : vehicle::pipe.settings().mode; }
bool mavlink_mode() { return output_mode() == fmt::OutputMode::Mavlink; }
void set_gcs_link(bool on) { gcs_link = on; }

void write_message(void*, const char* data, uint8_t len) {
    if (mavlink_mode()) status_text.write(data, len);
    else serial_text::write(data, len);
}

void send_frame(const uint8_t* frame, uint8_t len) { serial_text::write(reinterpret_cast<const char*>(frame), len); }

}  // namespace port
