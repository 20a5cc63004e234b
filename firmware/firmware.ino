// SPDX-License-Identifier: GPL-3.0-or-later
// apm25-attitude: roll, pitch and heading from the ArduPilot Mega 2.5's own sensors,
// printed on the serial port (115200 baud) 50 times a second:
//
//   roll:-1.23 pitch:4.56 yaw:271.80
//
// This is the sketch: set-up, the 200 Hz loop, the output (the pipeline's events and
// `status` lines in the words of lib/Pipeline/PipelineText). The board's pieces are the
// other files of this folder (Board: pins and buses; Imu: the MPU6000; Compass: the
// HMC5883L; SerialText: output that never blocks; SettingsStore: EEPROM); everything
// that turns samples into angles is the AttitudePipeline (lib/Pipeline), which the
// host replay tool runs too. Your own code goes in user.ino.
//
// The loop is paced by the MPU6000's data-ready (200 Hz): each sample is read,
// calibrated, checked and fed to the DCM estimator (lib/DCM); a compass sample is
// read when its DRDY pin says so. Every line that is not angle data begins with "# ".
// Other output modes (`mode csv|quat|raw|mavlink|quiet`): README.md; in `mode mavlink`
// the board speaks MAVLink 2 to a ground station and its "# " lines go as STATUSTEXT.
//
// It also flies (README "Flying"): FlightIo takes the receiver's PPM and the attitude
// through lib/Flight's modes, controllers and mixer to the eight servo outputs, 50 times
// a second. Features.h leaves them out: the attitude-only build (README "Builds").
#include <SPI.h>
#include <Wire.h>

#include "Airspeed.h"
#include "ArduinoCore.h"
#include "Board.h"
#include "Compass.h"
#include "Console.h"
#include "FlightIo.h"
#include "Format.h"
#include "Imu.h"
#include "MavLink.h"
#include "ParamLink.h"
#include "Pipeline.h"
#include "PipelineText.h"
#include "SerialText.h"
#include "SettingsStore.h"
#include "UserCode.h"

using text::Flash;
using text::Writer;

// Every "# " message goes through `out`: to the serial port as text, or, in `mode
// mavlink`, as STATUSTEXT frames (write_message, below). The pipeline's events are
// worded there too (lib/Pipeline/PipelineText).
static void write_message(void*, const char* data, uint8_t len);
const text::Sink message_sink = {nullptr, write_message};
const text::Sink* const out = &message_sink;
const pipeline::EventSink pipeline_events = pipeline_text::events_to(&message_sink);
pipeline::AttitudePipeline pipe(&pipeline_events, pipeline::AttitudePipeline::SettingsLoadedLater{});
Imu imu(board::kSpi, out);
Compass compass(board::kI2c, out, pipe);
SettingsStore store(out);
console::LineReader reader;
FlightIo flight_io(out);
mav::Parser mavlink_input;  // a ground station's frames (ground station link, below)

// Loop load: the share of each second spent on samples (measured, shown by `status`).
uint32_t work_us = 0, window_start_us = 0;
uint8_t load_pct = 0;
pipeline::RateLimiter warn_angle;

// ---------------------------------------------------------------------------
// Output

static void say(Flash text) { Writer(out).str(text).end(); }

static void print_settings_line() {
    const settings::Settings& s = pipe.settings();
    char buf[14];
    Writer(out).str(TXT("# settings: rate ")).u32(s.rate_hz).str(TXT(" Hz, decl "))
        .str(buf, text::format_centi(buf, s.declination_centideg)).str(TXT(" deg, mode "))
        .str(console::mode_name(s.mode)).str(TXT(", compass cal "))
        .str((s.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none")).end();
}

static Flash ok_or_failed(bool ok) { return ok ? TXT("ok") : TXT("FAILED"); }

// The airspeed sensor on A0 (lib/Pipeline/Airspeed.h), for the estimator's centripetal
// correction. Never blocking: each step reads the conversion the previous step started
// (13 ADC clocks at 125 kHz, long done 5 ms later) and starts the next. While the gyro
// calibrates (the board still) the readings are the sensor's zero; a zero far from
// 2.5 V is no sensor. Then the mean of each kAirspeedReadings readings is the airspeed.
enum class AirspeedState : uint8_t { kZero, kSensor, kNone };
constexpr uint8_t kAirspeedReadings = 8;
static AirspeedState airspeed_state = AirspeedState::kZero;
static bool airspeed_started = false;
static uint16_t airspeed_zero = 0;
static uint16_t airspeed_n = 0;
static uint32_t airspeed_sum = 0;

static void airspeed_begin() {
    ADMUX = _BV(REFS0);  // AVcc reference, channel 0 (MUX5 in ADCSRB clear)
    ADCSRB &= (uint8_t)~_BV(MUX5);
    ADCSRA |= _BV(ADEN) | _BV(ADSC);
}

static void airspeed_step() {
    if (airspeed_state == AirspeedState::kNone) {
        // No sensor: the configured cruise speed (TRIM_ARSPD_CM, grown in a banked turn as
        // the lift needs), only while the receiver's throttle is above idle (FlightIo).
        const flight::FlightSettings& fs = pipe.settings().flight;
        if (fs.trim_arspd_cm == 0u || pipe.steps() % kAirspeedReadings != 0u) return;
        pipe.set_cruise_airspeed_m_s(flight_io.powered() ? (float)fs.trim_arspd_cm * 0.01f : 0.0f);
        return;
    }
    if (ADCSRA & _BV(ADSC)) return;
    const uint16_t counts = ADC;
    ADCSRA |= _BV(ADSC);
    if (!airspeed_started) {  // the first conversion is the ADC's longer first one: not used
        airspeed_started = true;
        return;
    }
    airspeed_sum += counts;
    ++airspeed_n;
    if (airspeed_state == AirspeedState::kZero) {
        if (pipe.phase() != pipeline::Phase::Running || airspeed_n < kAirspeedReadings) return;
        airspeed_zero = (uint16_t)(airspeed_sum / airspeed_n);
        airspeed_state = airspeed::present(airspeed_zero) ? AirspeedState::kSensor : AirspeedState::kNone;
        if (airspeed_state == AirspeedState::kNone) say(TXT("# airspeed: no sensor on A0"));
    } else if (airspeed_n >= kAirspeedReadings) {
        pipe.set_airspeed_m_s(airspeed::airspeed_m_s(airspeed_sum, (uint8_t)airspeed_n, airspeed_zero));
    } else {
        return;
    }
    airspeed_sum = 0;
    airspeed_n = 0;
}

// `status`, a line (a part: console::kPartReply) at a time: false past the last part.
// Parts 2 and 3 are the gyro bias and compass lines, the long ones to format (numbers
// from floats: lib/Pipeline/PipelineText).
constexpr uint8_t kStatusBiasPart = 2, kStatusCompassPart = 3;
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
            w.str(TXT("# load ")).u32(load_pct).str(TXT("%, overruns ")).u32(imu.missed_samples())
                .str(TXT(", spikes ")).u32(pipe.spikes()).str(TXT(", uptime "))
                .str(buf, text::format_centi(buf, (int32_t)(millis() / 10u))).str(TXT(" s, airspeed "));
            if (airspeed_state == AirspeedState::kSensor)
                w.str(buf, text::format_centi(buf, (int32_t)(pipe.airspeed_m_s() * 100.0f))).str(TXT(" m/s"));
            else
                w.str(airspeed_state == AirspeedState::kNone ? TXT("none") : TXT("zeroing"));
            w.end();
            return true;
        }
        case kStatusBiasPart: pipeline_text::write_bias_status(out, pipe); return true;
        case kStatusCompassPart: pipeline_text::write_compass_status(out, pipe); return true;
        case 4: print_settings_line(); return true;
        case 5: return flight_io.print_status_line();
        default: return false;
    }
}

// MAVLink (lib/MavLink): frames go out whole or not at all, through the same queue as
// the text, so a frame is never cut by a message.
mav::Packer mavlink;
static void write_frame(void*, const uint8_t* frame, uint8_t len) {
    serial_text::write(reinterpret_cast<const char*>(frame), len);  // STATUSTEXT: a reply, never dropped
}
mav::StatusText status_text(mavlink, mav::FrameSink{nullptr, write_frame});

// A ground station's HEARTBEAT in a text mode switches the port to MAVLink until reset:
// not a setting (`save` keeps the mode typed), and a typed `mode` ends it.
static bool gcs_link = false;
static fmt::OutputMode output_mode() { return gcs_link ? fmt::OutputMode::Mavlink : pipe.settings().mode; }
static bool mavlink_mode() { return output_mode() == fmt::OutputMode::Mavlink; }

static void write_message(void*, const char* data, uint8_t len) {
    if (mavlink_mode()) status_text.write(data, len);
    else serial_text::write(data, len);
}

// HEARTBEAT and SYS_STATUS, once a second in `mode mavlink` (MAVLink's 1 Hz convention:
// a ground station drops a link after ~3 s without a heartbeat).
static void send_heartbeat_and_status() {
    const pipeline::Phase ph = pipe.phase();
    const mav::State state = !imu.ok() || !compass.ok() ? mav::State::Critical
                             : ph == pipeline::Phase::WaitImu ? mav::State::Boot
                             : ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating()
                                 ? mav::State::Calibrating
                                 : mav::State::Active;
    uint8_t frame[mav::kMaxFrame];
    uint8_t n = mavlink.heartbeat(frame, flight_io.failsafe() ? mav::State::Critical : state, flight_io.plane_mode());
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    const uint32_t missed = imu.missed_samples();
    n = mavlink.sys_status(frame, mav::health(true, imu.ok(), true, compass.ok()), (uint16_t)(load_pct * 10u),
                           (uint16_t)(missed < 0xFFFFu ? missed : 0xFFFFu));
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
}

// One output line (or frame) in the chosen mode, none in quiet mode. Lines are written
// only when they fit whole: a backlog of replies delays a line, never a sample. True
// when it worked out the angles in hundredths (c): the control step takes them.
static bool emit_output(uint32_t now_ms, pipeline::AnglesCentideg& c) {
    const fmt::OutputMode mode = output_mode();
    if (mode == fmt::OutputMode::Quiet) return false;
    // Plot and csv lines print hundredths, which the integer path gives without a float;
    // MAVLink's ATTITUDE carries floats.
    pipeline::Angles a{};
    if (mode == fmt::OutputMode::Mavlink) {
        board::mark_begin(board::kSecEuler);
        a = pipe.angles();
        board::mark_end(board::kSecEuler);
    } else if (mode == fmt::OutputMode::Plot || mode == fmt::OutputMode::Csv) {
        board::mark_begin(board::kSecEuler);
        c = pipe.angles_centideg();
        board::mark_end(board::kSecEuler);
    }
    char line[fmt::kRawLineMax];
    uint8_t n;
    board::mark_begin(board::kSecFormat);
    if (mode == fmt::OutputMode::Quat) {
        n = fmt::format_quat_line(line, pipe.quaternion());
    } else if (mode == fmt::OutputMode::Raw) {
        const float inv_g = 1.0f / dcm::kGravity_m_s2;
        n = fmt::format_raw_line(line, pipe.gyro_rad_s() * linalg::kDegPerRad, pipe.accel_m_s2() * inv_g,
                                 pipe.field_uT());
    } else if (mode == fmt::OutputMode::Mavlink) {
        n = mavlink.attitude(reinterpret_cast<uint8_t*>(line), now_ms, a.roll_deg, a.pitch_deg, a.heading_deg,
                             pipe.body_rate_rad_s());
    } else if (mode == fmt::OutputMode::Csv) {
        n = fmt::format_csv_line_centideg(line, now_ms, c.roll_centideg, c.pitch_centideg, c.heading_centideg);
    } else {
        n = fmt::format_plot_line_centideg(line, c.roll_centideg, c.pitch_centideg, c.heading_centideg);
    }
    board::mark_end(board::kSecFormat);
    if (n > 0) serial_text::write_line_if_room(line, n);
    else if (warn_angle.allow(now_ms, 2000)) say(TXT(TXT_WARN "output not finite: line skipped"));
    return mode == fmt::OutputMode::Plot || mode == fmt::OutputMode::Csv;
}

// ---------------------------------------------------------------------------
// Console: each complete line is one command (lib/Console parses; help in README.md).
//
// Nothing typed or pasted is lost: bytes are taken from Serial's 64-byte receive ring
// and parsed at once, every loop iteration and again inside the step after the
// estimator (at 115200 baud the ring fills in 5.6 ms, longer than the longest step), and
// the parsed commands wait in a queue. A reply goes out a part (a line) at a time, each
// only when the output queue has room for it and an output line after it: a paste is
// answered line by line as fast as the UART carries the replies, a reply never blocks
// the loop, and the angle lines keep flowing (between the lines of a long reply too).
console::CommandQueue commands;
uint8_t reply_part = 0;  // the next part of the reply to commands.peek()

// Writes part `part` of the reply to c (and runs c with part 0); false when c's reply
// has no such part (it is complete).
static bool answer(const console::Command& c, uint8_t part) {
    switch (c.id) {
        case console::CommandId::Error: return console::print_error(c, part, out);
        case console::CommandId::Help: return console::print_help(part, out);
        case console::CommandId::Status: return print_status(part);
        case console::CommandId::Show:
            if (c.arg == console::kShowParams) return console::print_param(part, pipe.settings(), out);
            break;
        default: break;
    }
    if (part > 0) return false;
    switch (c.id) {
        case console::CommandId::Save: store.start_save(pipe.settings()); break;
        case console::CommandId::CalGyro: pipe.start_gyro_calibration(); break;
        case console::CommandId::CalMag: pipe.start_mag_calibration(); break;
        case console::CommandId::Defaults:
            pipe.restore_defaults();
            flight_io.configure();
            console::print_defaults(out);
            break;
        case console::CommandId::Flight:
        case console::CommandId::Show: flight_io.answer(c); break;  // flight manual|stabilize, rc, servo
        case console::CommandId::Mode:
            gcs_link = false;  // the mode typed, not the ground station's
            console::apply_setting(c, pipe.settings(), out);
            break;
        default:  // rate, decl, set, get
            console::apply_setting(c, pipe.settings(), out);
            if (c.id == console::CommandId::Set) flight_io.configure();
            break;
    }
    return true;
}

// Received bytes -> parsed commands, while the command queue has room (when it has none,
// the bytes wait in Serial's ring). In a step (in_step) a line's end waits in the ring
// for the loop: its parse (a `set`: ~25k cycles) on top of a long step would be the
// loop's longest iteration; the step only keeps the ring from filling.
static void take_gcs_heartbeat();
static void take_console_input(bool in_step = false) {
    while (!commands.full() && !mavlink_input.ready()) {
        if (in_step && !mavlink_mode()) {
            const int next = Serial.peek();
            if (next == '\r' || next == '\n') return;
        }
        const int b = Serial.read();
        if (b < 0) return;
        // In `mode mavlink`, a ground station's frames are set aside (not garbage to
        // answer). In a text mode every byte is the console's too (0xFD/0xFE in garbage
        // would hide the next ~260 bytes), and the parser only looks for a ground
        // station's HEARTBEAT, which switches to MAVLink.
        const bool was_mavlink = mavlink_mode();
        if (mavlink_input.consume((uint8_t)b)) {
            take_gcs_heartbeat();
            if (was_mavlink || mavlink_mode()) continue;
        }
        const console::Command c = reader.feed((uint8_t)b);
        if (c.id != console::CommandId::None) commands.push(c);
    }
}

// Output queue bytes a part takes, at most: a line of up to console::kPartReply
// characters, in `mode mavlink` STATUSTEXT, two frames (<= 94 characters after "# ").
static uint16_t part_bytes() { return mavlink_mode() ? 2u * mav::kMaxFrame : console::kPartReply; }
// ... and room for an output line after it: a raw line, the longest, or an ATTITUDE frame.
static uint16_t output_line_bytes() { return mavlink_mode() ? mav::kAttitudeFrame : fmt::kRawLineMax; }
// Both fit the empty queues, else a part would never run.
static_assert(2u * mav::kMaxFrame + mav::kAttitudeFrame <= serial_text::kCapacity - 1u + SERIAL_TX_BUFFER_SIZE - 1u &&
                  console::kPartReply + fmt::kRawLineMax <= serial_text::kCapacity - 1u + SERIAL_TX_BUFFER_SIZE - 1u,
              "serial_text's queue and Serial's ring hold a reply part and an output line");

// A sample is missed when the next read comes more than 1.5 periods (7.5 ms) after the
// previous one: a part starts only when it ends by 7.3 ms, by what a part costs at most
// with a margin (README "Performance", console replies): `status`'s gyro bias and
// compass lines (numbers from floats) cost the most, and `mode mavlink` adds the
// STATUSTEXT packing. A part that cannot start now waits for a step that leaves it time.
static uint32_t latest_start_us(bool float_lines) {
    if (mavlink_mode()) return float_lines ? 3500u : 5200u;
    return float_lines ? 5300u : 6000u;
}
static void run_console_command() {
    if (commands.empty()) return;
    const console::Command c = commands.peek();
    if (serial_text::room() < part_bytes() + output_line_bytes()) return;
    const bool float_lines = c.id == console::CommandId::Status &&
                             (reply_part == kStatusBiasPart || reply_part == kStatusCompassPart);
    if (imu.us_since_sample(micros()) > latest_start_us(float_lines)) return;
    if (answer(c, reply_part)) {
        ++reply_part;
    } else {
        commands.pop();
        reply_part = 0;
    }
}

// ---------------------------------------------------------------------------
// The ground station link (lib/MavLink: Parser, ParamLink): its requests answered, the
// radio and servo pages' streams. Replies go through the same queue as everything else,
// each only when it fits whole with an output line after it and leaves time before the
// next sample (latest_start_us), so no sample is missed and no frame dropped: a
// PARAM_REQUEST_LIST's ~100 PARAM_VALUEs go out a few per loop step as the UART drains
// them (~37 bytes each, ~3 ms at 115200 baud).

mav::ParamReplies param_replies;
static bool save_due = false;  // a PARAM_SET changed a value: save (start_save) when there is time
static bool defaults_said_due = false;  // PREFLIGHT_STORAGE defaults ran: its line, in a pass of its own
constexpr uint16_t kStreamPeriodMs = 200;  // RC_CHANNELS and SERVO_OUTPUT_RAW at 5 Hz
static uint32_t last_stream_ms = 0;

// Called for every frame end: a ground station's HEARTBEAT switches a text mode to
// MAVLink; in a text mode the other requests are not answered (the ground station asks
// again once the board speaks MAVLink).
static void take_gcs_heartbeat() {
    if (!mavlink_input.ready()) return;
    if (mavlink_input.frame().msgid == mav::kMsgHeartbeat) {
        mavlink_input.release();
        if (!mavlink_mode()) {
            gcs_link = true;
            reader = console::LineReader();  // the frame's bytes so far are no command
        }
        return;
    }
    if (!mavlink_mode()) mavlink_input.release();
}

// A piece of the link's work starts only when it fits the queue and ends before the next
// sample is late (7.5 ms after the last): what each costs at most (apm25sim --profile,
// sections 14 and 15: README "Performance") with a margin.
constexpr uint32_t kGcsRequestLatestUs = 2000;  // a request: up to PREFLIGHT_STORAGE defaults' reset
constexpr uint32_t kGcsReplyLatestUs = 4000;    // a PARAM_VALUE, or the RC + servo pair
constexpr uint32_t kGcsSaveLatestUs = 1500;     // SettingsStore::start_save (the record encoded)
static bool gcs_can_send(uint8_t frame_bytes, uint32_t latest_us) {
    return serial_text::room() >= frame_bytes + output_line_bytes() && imu.us_since_sample(micros()) <= latest_us;
}

static void send_frame(const uint8_t* frame, uint8_t n) {
    serial_text::write(reinterpret_cast<const char*>(frame), n);
}

// MAV_CMD_PREFLIGHT_CALIBRATION: param1 1 the gyro (`cal gyro`), param2 1 the compass
// (`cal mag`); the others (baro, accel, airspeed ...) the board does not have.
// MAV_CMD_PREFLIGHT_STORAGE: param1 1 write (`save`), 2 defaults (`defaults`, not
// saved); 0 (read) UNSUPPORTED. The result comes as "# " lines.
static mav::Result run_command(const mav::CommandLong& c) {
    const float* p = c.param;
    if (c.command == mav::kCmdPreflightCalibration) {
        const bool gyro = p[0] == 1.0f, mag = p[1] == 1.0f;
        for (uint8_t i = 2; i < 7; ++i)
            if (p[i] != 0.0f) return mav::Result::Unsupported;
        if (!gyro && !mag) return mav::Result::Unsupported;
        if (pipe.gyro_calibrating() || pipe.mag_calibrating() || pipe.phase() != pipeline::Phase::Running)
            return mav::Result::TemporarilyRejected;
        if (gyro) pipe.start_gyro_calibration();
        if (mag) pipe.start_mag_calibration();
        return mav::Result::Accepted;
    }
    if (c.command == mav::kCmdPreflightStorage) {
        // No read (param1 0): both slots read, checked and decoded take longer than a
        // sample period (README "Ground stations"); a PARAM_SET is saved at once anyway.
        if (p[0] == 1.0f) {
            store.start_save(pipe.settings());
        } else if (p[0] == 2.0f) {
            pipe.restore_defaults();
            defaults_said_due = true;
        } else {
            return mav::Result::Unsupported;
        }
        return mav::Result::Accepted;
    }
    return mav::Result::Unsupported;
}

static void take_gcs_request(const mav::Received& rx) {
    mav::ParamRequest read;
    mav::ParamSet set;
    mav::CommandLong cmd;
    if (mav::decode_param_request_list(rx)) {
        param_replies.request_all();
    } else if (mav::decode_param_request_read(rx, read)) {
        const int16_t index = mav::requested_index(read);
        if (index >= 0) param_replies.request_one((uint16_t)index);
    } else if (mav::decode_param_set(rx, set)) {
        bool changed = false;
        const int16_t index = mav::apply_param_set(pipe.settings(), set, changed);
        if (index >= 0) param_replies.request_one((uint16_t)index);
        // As ArduPilot: a parameter set is saved at once (the two-slot store keeps the
        // settings before it whole until the new ones are), in a pass of its own.
        if (changed) save_due = true;
    } else if (mav::decode_command_long(rx, cmd)) {
        const mav::Result r = run_command(cmd);
        uint8_t frame[mav::kMaxFrame];
        send_frame(frame, mavlink.command_ack(frame, cmd.command, r, rx.sysid, rx.compid));
    }
}

static void answer_ground_station(uint32_t now_ms) {
    if (!mavlink_mode()) return;
    uint8_t frame[mav::kMaxFrame];
    // A request: room for its ACK (and the "# " lines a save or calibration says).
    if (mavlink_input.ready() && gcs_can_send(2u * mav::kMaxFrame, kGcsRequestLatestUs)) {
        board::mark_begin(board::kSecGcsRequest);
        take_gcs_request(mavlink_input.frame());
        mavlink_input.release();
        board::mark_end(board::kSecGcsRequest);
        return;
    }
    if (defaults_said_due && gcs_can_send(2u * mav::kMaxFrame, kGcsRequestLatestUs)) {
        defaults_said_due = false;
        console::print_defaults(out);
        return;
    }
    if (save_due && gcs_can_send(2u * mav::kMaxFrame, kGcsSaveLatestUs)) {
        save_due = false;
        store.start_save(pipe.settings());
        return;
    }
    uint16_t index;
    if (param_replies.peek(index) && gcs_can_send(mav::kParamValueFrame, kGcsReplyLatestUs)) {
        board::mark_begin(board::kSecGcsReply);
        const uint8_t n = mav::pack_param_value(mavlink, frame, pipe.settings(), index, param_replies.count());
        board::mark_end(board::kSecGcsReply);
        if (n > 0) send_frame(frame, n);
        param_replies.pop();
        return;
    }
    if (FlightIo::kEnabled && now_ms - last_stream_ms >= kStreamPeriodMs &&
        gcs_can_send(2u * mav::kRcChannelsFrame, kGcsReplyLatestUs)) {
        last_stream_ms = now_ms;
        board::mark_begin(board::kSecGcsReply);
        send_frame(frame, flight_io.rc_channels(mavlink, frame, now_ms));
        send_frame(frame, flight_io.servo_output_raw(mavlink, frame, micros()));
        board::mark_end(board::kSecGcsReply);
    }
}

// ---------------------------------------------------------------------------
// The 200 Hz step, once the MPU6000 has a sample.

static void step(uint32_t now_us) {
    board::mark_begin(board::kSecLoop);
    const uint32_t now_ms = millis();
    mpu6000::Sample sample;
    if (imu.read(sample, now_us, now_ms)) {
        compass.service(now_ms);
        if (imu.pacing_on_timer()) pipe.imu_doubtful();
        board::mark_begin(board::kSecEstimator);
        pipe.on_imu_sample(sample);
        board::mark_end(board::kSecEstimator);
        airspeed_step();
        take_console_input(true);
        if (pipe.phase() == pipeline::Phase::Running) user_attitude_step(pipe);
        pipeline::AnglesCentideg c;
        const bool output = pipe.output_due();
        const bool have_angles = output && emit_output(now_ms, c);
        flight_io.after_estimator_step(now_us, now_ms, sample, output, have_angles ? &c : nullptr);
    }
    board::mark_end(board::kSecLoop);
    work_us += micros() - now_us;
}

static void update_leds() {
    const pipeline::Phase ph = pipe.phase();
    board::set_leds(ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating(),
                    imu.ok() && ph == pipeline::Phase::Running, !imu.ok() || !compass.ok());
}

// The set-up runs on a fixed timeline (pipeline::kMpuStartMs ...): the same instants of
// a trajectory are sampled here and in the host replay tool.
static void wait_until_ms(uint16_t ms) {
    while (millis() < ms) serial_text::pump();
}

// ---------------------------------------------------------------------------

void setup() {
    board::init_pins();  // every chip select high before any SPI traffic
    board::set_leds(true, false, false);
    serial_text::begin();
    say(TXT("# apm25-attitude 0.2.0: APM 2.5, 200 Hz loop\n"
            "# " TXT_MPU " 200 Hz, DLPF 42 Hz, 2000 deg/s, 16 g; " TXT_HMC " 75 Hz, 8-sample average, 1.3 Ga"));
    store.load(pipe.settings());
    flight_io.begin();  // the outputs from here on (the loaded settings' end points), the receiver
    airspeed_begin();
    print_settings_line();
    if (pipe.settings().flags & settings::kFlagUpgraded) {
        pipe.settings().flags = (uint8_t)(pipe.settings().flags & ~settings::kFlagUpgraded);
        say(TXT("# settings: a version 2 record: flight settings at their defaults (save to keep)"));
    }

    board::spi_begin();
    wait_until_ms(pipeline::kMpuStartMs);
    imu.start(millis());
    board::wake_on_data_ready();  // the loop idles between samples

    board::wire_begin();
    if (board::sda_low()) board::i2c_recover();
    wait_until_ms(pipeline::kMagStartMs);
    compass.start(true, millis());
    say(TXT("# type help for commands"));
    if (pipe.settings().mode == fmt::OutputMode::Csv) Writer(out).str(console::csv_header());
    serial_text::flush();  // the banner out before the 200 Hz loop starts: no missed sample
    user_setup();
    wait_until_ms(pipeline::kLoopStartMs);
    window_start_us = micros();
    flight_io.loop_starts(window_start_us);
    update_leds();
}

void loop() {
    serial_text::pump();
    take_console_input();
    run_console_command();
    answer_ground_station(millis());
    store.service();
    const uint32_t now_ms = millis();
    if (imu.retry(now_ms)) pipe.restart_estimator();
    compass.retry(now_ms);
    user_loop();

    const uint32_t now_us = micros();
    flight_io.poll(now_us, now_ms);
    if (now_us - window_start_us >= 1000000u) {  // load over the last second
        load_pct = (uint8_t)(work_us / ((now_us - window_start_us) / 100u));
        work_us = 0;
        window_start_us = now_us;
        update_leds();
        if (mavlink_mode()) send_heartbeat_and_status();
        if (const uint16_t n = warn_angle.deferred(millis(), 2000))
            Writer(out).str(TXT(TXT_WARN "output not finite: ")).u32(n).str(TXT(" more lines skipped")).end();
    }
    if (!imu.sample_ready(now_us)) {
        board::idle_until_interrupt();  // until the next sample, a byte, a tick
        return;
    }
    step(now_us);
    if (pipe.steps() % 50u == 0u) update_leds();
}
