// SPDX-License-Identifier: GPL-3.0-or-later
#include "OutputLine.h"

#include "Board.h"
#include "GcsLink.h"
#include "Port.h"
#include "SerialText.h"
#include "Vehicle.h"

namespace output_line {

using vehicle::pipe;
using vehicle::tick;

static pipeline::RateLimiter warn_angle;

bool due() {
    tick.output = pipe.output_due();
    return tick.output;
}

// The float modes' lines, each in a function of its own (never inline): inlined, their
// float temporaries joined emit's frame beyond the 63 bytes ldd/std reach, and every
// access to it took a subi/sbci pair each side, in every mode (plot's too).
__attribute__((noinline)) static uint8_t quat_line(char* line) {
    return fmt::format_quat_line(line, pipe.quaternion());
}
__attribute__((noinline)) static uint8_t raw_line(char* line) {
    const float inv_g = 1.0f / dcm::kGravity_m_s2;
    return fmt::format_raw_line(line, pipe.gyro_rad_s() * linalg::kDegPerRad, pipe.accel_m_s2() * inv_g,
                                pipe.field_uT());
}
// MAVLink's ATTITUDE carries floats: the Euler extraction's float form, then the frame.
__attribute__((noinline)) static uint8_t attitude_frame(char* line, uint32_t now_ms) {
    board::mark_begin(board::kSecEuler);
    const pipeline::Angles a = pipe.angles();
    board::mark_end(board::kSecEuler);
    board::mark_begin(board::kSecFormat);
    const uint8_t n = port::mavlink.attitude(reinterpret_cast<uint8_t*>(line), now_ms, a.roll_deg, a.pitch_deg,
                                             a.heading_deg, pipe.body_rate_rad_s());
    board::mark_end(board::kSecFormat);
    return n;
}

// True when it worked out the angles in hundredths (c). Never inline: its line buffer and
// ATTITUDE's frame (~330 B) would join the loop's frame (main, with the estimator step
// inlined), beyond the 63 bytes ldd/std reach, and slow every access to it.
__attribute__((noinline)) static bool emit(uint32_t now_ms, pipeline::AnglesCentideg& c) {
    const fmt::OutputMode mode = port::output_mode();
    if (mode == fmt::OutputMode::Quiet) return false;
    // ATTITUDE at SR0_EXTRA1's rate (or its own interval), on the output lines it falls on
    // (every line when asked as often or more); a line moves a sample step later when a field
    // sample takes its step, so one a step early counts.
    constexpr uint16_t kStepMs = 1000u / pipeline::kRateHz;
    if (mode == fmt::OutputMode::Mavlink && !gcs_link::take_stream(mav::kStreamAttitude, now_ms + kStepMs))
        return false;
    // Plot and csv lines print hundredths, which the integer path gives without a float.
    const bool centideg = mode == fmt::OutputMode::Plot || mode == fmt::OutputMode::Csv;
    if (centideg) {
        board::mark_begin(board::kSecEuler);
        c = pipe.angles_centideg();
        board::mark_end(board::kSecEuler);
    }
    char line[fmt::kRawLineMax];
    uint8_t n;
    if (mode == fmt::OutputMode::Mavlink) {
        n = attitude_frame(line, now_ms);
    } else {
        board::mark_begin(board::kSecFormat);
        if (mode == fmt::OutputMode::Quat) {
            n = quat_line(line);
        } else if (mode == fmt::OutputMode::Raw) {
            n = raw_line(line);
        } else if (mode == fmt::OutputMode::Csv) {
            n = fmt::format_csv_line_centideg(line, now_ms, c.roll_centideg, c.pitch_centideg, c.heading_centideg);
        } else {
            n = fmt::format_plot_line_centideg(line, c.roll_centideg, c.pitch_centideg, c.heading_centideg);
        }
        board::mark_end(board::kSecFormat);
    }
    if (n > 0) serial_text::write_line_if_room(line, n);
    else if (warn_angle.allow(now_ms, 2000)) vehicle::say(TXT(TXT_WARN "output not finite: line skipped"));
    return centideg;
}

void run() { tick.have_angles = emit(tick.now_ms, tick.angles); }

void say_skipped() {
    if (const uint16_t n = warn_angle.deferred(millis(), 2000))
        text::Writer(vehicle::out).str(TXT(TXT_WARN "output not finite: ")).u32(n).str(TXT(" more lines skipped")).end();
}

}  // namespace output_line
