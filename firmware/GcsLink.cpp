// SPDX-License-Identifier: GPL-3.0-or-later
#include "GcsLink.h"

#include "Baro.h"
#include "Board.h"
#include "Console.h"
#include "ConsoleLink.h"
#include "LoopLoad.h"
#include "ParamLink.h"
#include "Port.h"
#include "SerialText.h"
#include "Vehicle.h"

namespace gcs_link {

using vehicle::compass;
using vehicle::flight_io;
using vehicle::imu;
using vehicle::pipe;

static mav::Parser input;
static mav::ParamReplies param_replies;
static bool save_pending = false;           // a PARAM_SET changed a value: save when there is time
static bool defaults_said_pending = false;  // PREFLIGHT_STORAGE defaults ran: its line, in a pass of its own
constexpr uint16_t kStreamPeriodMs = 200;   // RC_CHANNELS, SERVO_OUTPUT_RAW, SCALED_PRESSURE at 5 Hz
static uint32_t last_stream_ms = 0;

mav::Parser& parser() { return input; }

void take_heartbeat() {
    if (!input.ready()) return;
    if (input.frame().msgid == mav::kMsgHeartbeat) {
        input.release();
        if (!port::mavlink_mode()) {
            port::set_gcs_link(true);
            console_link::forget_partial_line();  // the frame's bytes so far are no command
        }
        return;
    }
    if (!port::mavlink_mode()) input.release();
}

// An output line after a reply: a raw line, the longest, or an ATTITUDE frame.
uint16_t output_line_bytes() { return port::mavlink_mode() ? mav::kAttitudeFrame : fmt::kRawLineMax; }

static bool room_for(uint16_t frame_bytes) {
    return port::mavlink_mode() && serial_text::room() >= frame_bytes + output_line_bytes();
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
        // sample period; a PARAM_SET is saved at once anyway.
        if (p[0] == 1.0f) {
            vehicle::store.start_save(pipe.settings());
        } else if (p[0] == 2.0f) {
            pipe.restore_defaults();
            defaults_said_pending = true;
        } else {
            return mav::Result::Unsupported;
        }
        return mav::Result::Accepted;
    }
    return mav::Result::Unsupported;
}

// A request: room for its ACK (and the "# " lines a save or calibration says).
bool request_due() { return input.ready() && room_for(2u * mav::kMaxFrame); }

void take_request() {
    const mav::Received& rx = input.frame();
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
        if (changed) save_pending = true;
    } else if (mav::decode_command_long(rx, cmd)) {
        const mav::Result r = run_command(cmd);
        uint8_t frame[mav::kMaxFrame];
        port::send_frame(frame, port::mavlink.command_ack(frame, cmd.command, r, rx.sysid, rx.compid));
    }
    input.release();
}

bool defaults_line_due() { return defaults_said_pending && room_for(2u * mav::kMaxFrame); }
void say_defaults() {
    defaults_said_pending = false;
    console::print_defaults(vehicle::out);
}

bool save_due() { return save_pending && room_for(2u * mav::kMaxFrame); }
void save() {
    save_pending = false;
    vehicle::store.start_save(pipe.settings());
}

bool param_value_due() {
    uint16_t index;
    return param_replies.peek(index) && room_for(mav::kParamValueFrame);
}
void send_param_value() {
    uint16_t index;
    param_replies.peek(index);
    uint8_t frame[mav::kMaxFrame];
    const uint8_t n = mav::pack_param_value(port::mavlink, frame, pipe.settings(), index, param_replies.count());
    if (n > 0) port::send_frame(frame, n);
    param_replies.pop();
}

bool streams_due() {
    return (FlightIo::kEnabled || baro::present()) && millis() - last_stream_ms >= kStreamPeriodMs &&
           room_for(2u * mav::kRcChannelsFrame + mav::kScaledPressureFrame);
}
void send_streams() {
    const uint32_t now_ms = millis();
    last_stream_ms = now_ms;
    uint8_t frame[mav::kMaxFrame];
    if (FlightIo::kEnabled) {
        port::send_frame(frame, flight_io.rc_channels(port::mavlink, frame, now_ms));
        port::send_frame(frame, flight_io.servo_output_raw(port::mavlink, frame, micros()));
    }
    if (baro::present())
        port::send_frame(frame, port::mavlink.scaled_pressure(frame, now_ms, baro::pressure_pa(), baro::temperature_c()));
}

void send_heartbeat_and_status() {
    if (!port::mavlink_mode()) return;
    const pipeline::Phase ph = pipe.phase();
    const mav::State state = !imu.ok() || !compass.ok() ? mav::State::Critical
                             : ph == pipeline::Phase::WaitImu ? mav::State::Boot
                             : ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating()
                                 ? mav::State::Calibrating
                                 : mav::State::Active;
    uint8_t frame[mav::kMaxFrame];
    uint8_t n = port::mavlink.heartbeat(frame, flight_io.failsafe() ? mav::State::Critical : state,
                                        flight_io.plane_mode());
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    const uint32_t missed = imu.missed_samples();
    mav::Health sensors = mav::health(true, imu.ok(), true, compass.ok());
    mav::add_sensor(sensors, mav::kAbsolutePressure, baro::present(), baro::healthy());
    n = port::mavlink.sys_status(frame, sensors,
                                 (uint16_t)(loop_load::percent() * 10u),
                                 (uint16_t)(missed < 0xFFFFu ? missed : 0xFFFFu));
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
}

}  // namespace gcs_link
