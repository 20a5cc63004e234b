// SPDX-License-Identifier: GPL-3.0-or-later
#include "Port.h"

#include "SerialText.h"
#include "Vehicle.h"

namespace port {

mav::Packer mavlink;
// Who chose the language last.
enum class Link : uint8_t {
    Start,    // power-up: SERIAL0_PROTOCOL, else the settings' mode
    Gcs,      // a ground station's HEARTBEAT: MAVLink
    Typed,    // a `mode` typed: the settings' mode
    Escaped,  // three returns: the settings' text mode
};
static Link link = Link::Start;

static void write_frame(void*, const uint8_t* frame, uint8_t len) { send_frame(frame, len); }
static mav::StatusText status_text(mavlink, mav::FrameSink{nullptr, write_frame});

fmt::OutputMode output_mode() {
    const settings::Settings& s = vehicle::pipe.settings();
    switch (link) {
        case Link::Gcs: return fmt::OutputMode::Mavlink;
        case Link::Escaped: return s.mode == fmt::OutputMode::Mavlink ? fmt::OutputMode::Plot : s.mode;
        case Link::Start:
            if (s.vehicle.serial0_protocol != settings::kSerialConsole) return fmt::OutputMode::Mavlink;
            return s.mode;
        default: return s.mode;
    }
}
bool mavlink_mode() { return output_mode() == fmt::OutputMode::Mavlink; }
void set_gcs_link(bool on) { link = on ? Link::Gcs : Link::Typed; }
void escape_to_text() { link = Link::Escaped; }

void write_message(void*, const char* data, uint8_t len) {
    if (mavlink_mode()) status_text.write(data, len);
    else serial_text::write(data, len);
}

void send_frame(const uint8_t* frame, uint8_t len) { serial_text::write(reinterpret_cast<const char*>(frame), len); }

}  // namespace port
