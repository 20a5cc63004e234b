// SPDX-License-Identifier: GPL-3.0-or-later
#include "Port.h"

#include "GcsLink.h"
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

// A message line's frames go in whole with the rest of its line, or not at all.
static void write_frame(void*, const uint8_t* frame, uint8_t len) {
    serial_text::line_part(reinterpret_cast<const char*>(frame), len);
}
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

// The lines dropped because the output was full (serial_text::line_part), told by
// say_held_back(); how many of them were warnings (StatusText's grades: "# warn:",
// "# error:", "# PreArm:"), so that the line telling them is a warning too.
static uint8_t held = 0, held_warnings = 0;
// The line's first characters so far against those prefixes: the characters matched (low
// nibble) and the prefix still matching (kPrefixes' index << 4); kNotWarning, kWarning:
// decided.
static const char kPrefixes[] PROGMEM = "# warn:\0# error:\0# PreArm:";
static uint8_t prefix_start(uint8_t which) { return which == 0u ? 0u : which == 1u ? 8u : 17u; }
constexpr uint8_t kNotWarning = 0xF0, kWarning = 0xF1;
static uint8_t grade = 0;

static void grade_line(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len && grade < kNotWarning; ++i) {
        const uint8_t at = grade & 0x0Fu;
        uint8_t which = (uint8_t)(grade >> 4);
        if (at == 2u) {  // the third character picks the prefix
            which = data[i] == 'w' ? 0u : data[i] == 'e' ? 1u : data[i] == 'P' ? 2u : 3u;
            if (which == 3u) {
                grade = kNotWarning;
                return;
            }
        }
        const char want = (char)text::flash_byte(kPrefixes + prefix_start(which) + at);
        if (data[i] != want) grade = kNotWarning;
        else if (text::flash_byte(kPrefixes + prefix_start(which) + at + 1u) == 0u) grade = kWarning;
        else grade = (uint8_t)(which << 4 | (at + 1u));
    }
}

void write_message(void*, const char* data, uint8_t len) {
    while (len > 0) {
        uint8_t n = 0;  // up to and with the line's end
        while (n < len && data[n++] != '\n') {}
        grade_line(data, n);
        if (mavlink_mode()) status_text.write(data, n);
        else serial_text::line_part(data, n);
        if (data[n - 1u] == '\n') {
            if (!serial_text::end_line()) {
                if (held != 0xFFu) ++held;
                if (grade == kWarning && held_warnings != 0xFFu) ++held_warnings;
            }
            grade = 0;
        }
        data += n;
        len = (uint8_t)(len - n);
    }
}

bool held_back_due() { return held != 0u && serial_text::room() >= mav::kMaxFrame + gcs_link::output_line_bytes(); }

void say_held_back() {
    const uint8_t n = held, warnings = held_warnings;
    held = held_warnings = 0;
    text::Writer w(vehicle::out);
    if (warnings != 0u) w.str(TXT(TXT_WARN)).u32(n).str(TXT(" line(s) held back, ")).u32(warnings).str(TXT(" warning(s)"));
    else w.str(TXT("# ")).u32(n).str(TXT(" line(s) held back: output full"));
    w.end();
    if (held != 0u) {  // not said either (never: its room was there): still to tell
        held = n;
        held_warnings = warnings;
    }
}

void send_frame(const uint8_t* frame, uint8_t len) { serial_text::write(reinterpret_cast<const char*>(frame), len); }

}  // namespace port
