// SPDX-License-Identifier: GPL-3.0-or-later
#include "ConsoleLink.h"

#include "AirspeedInput.h"
#include "ArduinoCore.h"
#include "Baro.h"
#include "BatteryInput.h"
#include "Console.h"
#include "GcsLink.h"
#include "GpsPort.h"
#include "LoopLoad.h"
#include "MagCalLink.h"
#include "MissionLink.h"
#include "Params.h"
#include "Port.h"
#include "PipelineText.h"
#include "Position.h"
#include "SerialText.h"
#include "Tasks.h"
#include "Vehicle.h"

namespace console_link {

using text::Flash;
using text::Writer;
using vehicle::compass;
using vehicle::flight_io;
using vehicle::imu;
using vehicle::out;
using vehicle::pipe;

static console::LineReader reader;
static console::CommandQueue commands;
static uint8_t reply_part = 0;  // the next part of the reply to commands.peek()
constexpr uint8_t kEscapeReturns = 3;
static uint8_t returns = 0;     // CR or LF in a row outside frames, in MAVLink

void forget_partial_line() { reader = console::LineReader(); }

// Received bytes -> parsed commands, while the command queue has room (when it has none,
// the bytes wait in Serial's ring). In a step (in_step) a line's end waits in the ring
// for the loop: its parse (a `set`) on top of a long step would be the loop's longest
// iteration; the step only keeps the ring from filling, and takes at most kStepBytesMax
// (~380 cycles a byte with a frame's end: a step's worst was 16 245, over its 1 ms). The
// loop's `input` task takes the rest on every pass; the 128-byte ring holds the ~70 bytes
// that arrive at 115200 baud over the longest pass and a step.
constexpr uint8_t kStepBytesMax = 32;
static void take(bool in_step) {
    mav::Parser& frames = gcs_link::parser();
    uint8_t step_bytes = 0;
    bool mavlink = port::mavlink_mode();  // changes only with a frame's end or the escape
    while (!commands.full() && !frames.ready()) {
        if (in_step && (++step_bytes > kStepBytesMax)) return;
        if (in_step && !mavlink) {
            const int next = Serial.peek();
            if (next == '\r' || next == '\n') return;
        }
        const int b = Serial.read();
        if (b < 0) return;
        // In MAVLink a ground station's frames are set aside (not garbage to answer). In
        // a text mode every byte is the console's too (0xFD/0xFE in garbage would hide the
        // next ~260 bytes), and the parser only looks for a ground station's HEARTBEAT.
        const bool was_mavlink = mavlink;
        if (frames.consume((uint8_t)b)) {
            returns = 0;
            if (frames.ready()) {
                gcs_link::take_heartbeat();
                mavlink = port::mavlink_mode();
            }
            if (was_mavlink || mavlink) continue;
        }
        if (was_mavlink) {
            // In MAVLink only frames act: no text line is a command (a ground station's
            // garbage must not set a gain or silence the link). The one escape is
            // ArduPilot's: three returns (CR or LF) in a row give the text console.
            returns = (b == '\r' || b == '\n') ? (uint8_t)(returns + 1u) : (uint8_t)0;
            if (returns == kEscapeReturns) {
                returns = 0;
                port::escape_to_text();
                mavlink = port::mavlink_mode();
                forget_partial_line();
                console::Command help{};
                help.id = console::CommandId::Help;  // the console's first words: what it takes
                commands.push(help);
            }
            continue;
        }
        const console::Command c = reader.feed((uint8_t)b);
        if (c.id != console::CommandId::None) commands.push(c);
    }
}

void take_input() { take(false); }
void take_input_in_step() { take(true); }

static Flash ok_or_failed(bool ok) { return ok ? TXT("ok") : TXT("FAILED"); }

void print_settings_line() {
    const settings::Settings& s = pipe.settings();
    char buf[14];
    Writer(out).str(TXT("# settings: rate ")).u32(s.rate_hz).str(TXT(" Hz, decl "))
        .str(buf, text::format_centi(buf, s.declination_centideg)).str(TXT(" deg, mode "))
        .str(console::mode_name(s.mode)).str(TXT(", compass cal "))
        .str((s.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none")).end();
}

// `status`, a line (a part: console::kPartReply) at a time: false past the last part.
static bool print_status(uint8_t part) {
    Writer w(out);
    switch (part) {
        case 0: {
            w.str(TXT("# status: " TXT_MPU " ")).str(ok_or_failed(imu.ok())).str(TXT(", " TXT_HMC " "))
                .str(ok_or_failed(compass.ok()));
            if (!compass.ok()) w.str(TXT(" (yaw gyro-only)"));
            const pipeline::Phase ph = pipe.phase();
            w.str(TXT(", estimator "))
                .str(ph == pipeline::Phase::Running       ? TXT("running")
                     : ph == pipeline::Phase::Calibrating ? TXT("calibrating")
                                                          : TXT("waiting for " TXT_MPU))
                .end();
            return true;
        }
        case 1: {
            char buf[14];
            w.str(TXT("# load ")).u32(loop_load::percent()).str(TXT("%, overruns ")).u32(imu.missed_samples())
                .str(TXT(", spikes ")).u32(pipe.spikes()).str(TXT(", uptime "))
                .str(buf, text::format_centi(buf, (int32_t)(millis() / 10u))).str(TXT(" s, airspeed "));
            const airspeed_input::State a = airspeed_input::state();
            if (a == airspeed_input::State::kSensor)
                w.str(buf, text::format_centi(buf, (int32_t)(pipe.airspeed_m_s() * 100.0f))).str(TXT(" m/s"));
            else
                w.str(a == airspeed_input::State::kNone ? TXT("none") : TXT("zeroing"));
            w.end();
            return true;
        }
        case 2: pipeline_text::write_bias_status(out, pipe); return true;
        case 3: pipeline_text::write_compass_status(out, pipe); return true;
        case 4: print_settings_line(); return true;
        case 5: baro::print_line(out); return true;
        case 6: tasks::print_status_line(out); return true;
        case 7: gps_port::print_status_line(out); return true;
        case 8: position::print_status_line(out); return true;
        case 9: battery_input::print_status_line(out); return true;
        case 10: return flight_io.print_status_line();
        default: return false;
    }
}

// `save`, `defaults` and `set` work longer than a reply line (the record encoded; every
// setting and the controllers' gains set again; a name looked up in the parameter table
// and the controllers configured): their work is a part of its own, the `command` task
// with its own budget (`set` says its line there), and the defaults' line the next part.
static bool heavy(const console::Command& c) {
    return c.id == console::CommandId::Save || c.id == console::CommandId::Defaults ||
           c.id == console::CommandId::Set;
}

// Writes part `part` of the reply to c (and runs c with part 0); false when c's reply
// has no such part (it is complete).
static bool answer(const console::Command& c, uint8_t part) {
    switch (c.id) {
        case console::CommandId::Error: return console::print_error(c, part, out);
        case console::CommandId::Help: return console::print_help(part, out);
        case console::CommandId::Status: return print_status(part);
        case console::CommandId::Show:
            if (c.arg == console::kShowParams) return console::print_param(part, pipe.settings(), out);
            if (c.arg == console::kShowGps) return gps_port::print(part, out);
            if (c.arg == console::kShowMission) return mission_link::print(part, out);
            if (c.arg == console::kShowBaro) {
                if (part > 0) return false;
                baro::print_line(out);
                return true;
            }
            break;
        default: break;
    }
    if (heavy(c)) {  // part 0 the work (the `command` task), part 1 its line
        if (part == 1 && c.id == console::CommandId::Defaults) console::print_defaults(out);
        if (part > 0) return false;
        if (c.id == console::CommandId::Save) {
            vehicle::store.start_save(pipe.settings());
        } else if (c.id == console::CommandId::Set) {
            const float before = params::get(pipe.settings(), c.arg);
            console::apply_setting(c, pipe.settings(), out);
            if (params::get(pipe.settings(), c.arg) != before) mag_cal_link::parameter_changed(c.arg);
            pipe.refresh_board_frame();  // AHRS_ORIENTATION, AHRS_TRIM_*, INS_ACC* at once
            flight_io.configure();
            gcs_link::announce_param(c.arg);
        } else {
            pipe.restore_defaults();
            flight_io.configure();
        }
        return true;
    }
    if (part > 0) return false;
    switch (c.id) {
        case console::CommandId::CalGyro: pipe.start_gyro_calibration(); break;
        case console::CommandId::CalMag: pipe.start_mag_calibration(); break;
        case console::CommandId::CalAccel:
            // The first starts it; each next one says the airframe is in the position asked.
            if (pipe.accel_calibrating() ? !pipe.confirm_accel_position(pipe.accel_position_asked())
                                         : !pipe.start_accel_calibration())
                text::Writer(out).str(TXT(TXT_ERROR "cal accel: not now (busy, or measuring a position)")).end();
            break;
        case console::CommandId::CalLevel:
            if (!pipe.start_level_calibration())
                text::Writer(out).str(TXT(TXT_ERROR "cal level: not now (starting, or a calibration runs); nothing changed")).end();
            break;
        case console::CommandId::Flight:
        case console::CommandId::Show: flight_io.answer(c); break;  // flight manual|stabilize, rc, servo
        case console::CommandId::Mode:
            port::set_gcs_link(false);  // the mode typed, not the ground station's
            console::apply_setting(c, pipe.settings(), out);
            break;
        default:  // rate, decl, get
            console::apply_setting(c, pipe.settings(), out);
            break;
    }
    return true;
}

// Output queue bytes a part takes, at most: a line of up to console::kPartReply
// characters, in MAVLink STATUSTEXT, two frames (<= 94 characters after "# ").
static uint16_t part_bytes() { return port::mavlink_mode() ? 2u * mav::kMaxFrame : console::kPartReply; }
// Both fit the empty queues, else a part would never run.
static_assert(2u * mav::kMaxFrame + mav::kAttitudeFrame <= serial_text::kCapacity - 1u + SERIAL_TX_BUFFER_SIZE - 1u &&
                  console::kPartReply + fmt::kRawLineMax <= serial_text::kCapacity - 1u + SERIAL_TX_BUFFER_SIZE - 1u,
              "serial_text's queue and Serial's ring hold a reply part and an output line");

// A part waits, in the port's language, with room for it and an output line after it.
static bool due(bool mavlink) {
    return !commands.empty() && !(reply_part == 0 && heavy(commands.peek())) && port::mavlink_mode() == mavlink &&
           serial_text::room() >= part_bytes() + gcs_link::output_line_bytes();
}
bool reply_due_text() { return due(false); }
bool reply_due_mavlink() { return due(true); }
bool command_due() {
    return !commands.empty() && reply_part == 0 && heavy(commands.peek()) &&
           serial_text::room() >= part_bytes() + gcs_link::output_line_bytes();
}

void reply() {
    if (answer(commands.peek(), reply_part)) {
        ++reply_part;
    } else {
        commands.pop();
        reply_part = 0;
    }
}

}  // namespace console_link
