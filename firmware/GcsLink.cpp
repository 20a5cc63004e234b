// SPDX-License-Identifier: GPL-3.0-or-later
#include "GcsLink.h"

#include "Baro.h"
#include "Board.h"
#include "Console.h"
#include "ConsoleLink.h"
#include "GpsPort.h"
#include "LoopLoad.h"
#include "ParamLink.h"
#include "Port.h"
#include "Position.h"
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
static bool configure_pending = false;      // ... and put it in force first, in a pass of its own
static bool defaults_said_pending = false;  // PREFLIGHT_STORAGE defaults ran: its line, in a pass of its own
constexpr uint16_t kStreamPeriodMs = 200;   // RC_CHANNELS, SERVO_OUTPUT_RAW, SCALED_PRESSURE at 5 Hz
static uint32_t last_stream_ms = 0;
static bool home_requested = false;         // GET_HOME_POSITION or REQUEST_MESSAGE 242: HOME_POSITION to send

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

// MAV_CMD_DO_SET_HOME: param1 1 (or a place of all zeros, as ArduPilot) here, else
// param5 latitude, param6 longitude (degrees), param7 height above mean sea level (m).
static mav::Result set_home(const float* p) {
    bool ok;
    if (p[0] == 1.0f || (p[4] == 0.0f && p[5] == 0.0f && p[6] == 0.0f)) {
        ok = position::set_home_here();
    } else if (!(p[4] == p[4] && p[5] == p[5] && p[6] == p[6])) {
        ok = false;  // NaN (MAVLink's "unset") in a place: no place
    } else {
        nav::Location home;
        // A float has 24 bits: 7.135045 deg arrives to 5e-7 deg (5 cm); COMMAND_INT would be exact.
        home.lat_e7 = nav::round_to_int32(p[4] * 1e7f);
        home.lon_e7 = nav::round_to_int32(p[5] * 1e7f);
        home.alt_cm = nav::round_to_int32(p[6] * 100.0f);
        ok = position::set_home(home);
    }
    return ok ? mav::Result::Accepted : mav::Result::Failed;
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
    if (c.command == mav::kCmdDoSetHome) return set_home(p);
    // Arming and modes (FlightIo; ArduPlane's answers: a refusal FAILED, its reasons said).
    if (c.command == mav::kCmdComponentArmDisarm) {
        if (p[0] != 0.0f && p[0] != 1.0f) return mav::Result::Unsupported;
        // Forced by MAVLink's 21196, or to arm by ArduPilot's 2989 (MAVProxy's `arm throttle force`).
        return flight_io.arm_disarm(p[0] == 1.0f, p[1] == mav::kForceMagic || (p[0] == 1.0f && p[1] == mav::kForceArmMagic));
    }
    if (c.command == mav::kCmdDoSetMode && FlightIo::kEnabled) {
        if (((uint8_t)p[0] & mav::kModeFlagCustomModeEnabled) == 0u || !(p[1] >= 0.0f && p[1] < 256.0f))
            return mav::Result::Unsupported;
        return flight_io.set_mode((uint32_t)p[1]) ? mav::Result::Accepted : mav::Result::Failed;
    }
    if (c.command == mav::kCmdGetHomePosition ||
        (c.command == mav::kCmdRequestMessage && p[0] == (float)mav::kMsgHomePosition)) {
        if (!position::navigator().home_set()) return mav::Result::Failed;  // as ArduPilot: no home yet
        home_requested = true;
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
    mav::SetMode set_mode;
    uint16_t override_us[8];
    if (mav::decode_rc_channels_override(rx, override_us)) {
        flight_io.rc_override(override_us);  // no answer, as ArduPilot
    } else if (mav::decode_set_mode(rx, set_mode)) {
        // Only a custom mode (ArduPlane's number); answered as ArduPilot does, with a
        // COMMAND_ACK whose command is SET_MODE's message id.
        mav::Result r = mav::Result::Unsupported;
        if ((set_mode.base_mode & mav::kModeFlagCustomModeEnabled) != 0u && FlightIo::kEnabled)
            r = flight_io.set_mode(set_mode.custom_mode) ? mav::Result::Accepted : mav::Result::Failed;
        uint8_t frame[mav::kMaxFrame];
        port::send_frame(frame, port::mavlink.command_ack(frame, mav::kSetModeAck, r, rx.sysid, rx.compid));
    } else if (mav::decode_param_request_list(rx)) {
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
        if (changed) save_pending = configure_pending = true;
    } else if (mav::decode_command_long(rx, cmd) || mav::decode_command_int(rx, cmd)) {
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
    // The changed value in force first, as the console's `set` puts it (the controllers'
    // terms, the end points' factors, RC_OVERRIDE_TIME; a PARAM_SET of RLL2SRV_P flew the
    // old gains before), then the save: each a pass of its own, as the record's encoding
    // and the gains' terms together outlast the task's budget.
    if (configure_pending) {
        configure_pending = false;
        flight_io.configure();
        return;
    }
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
    mav::Health health = mav::health(true, imu.ok(), true, compass.ok());
    const gps::Fix& fix = gps_port::fix();
    mav::add_sensor(health, mav::kGps, fix.fix != gps::FixType::kNoGps,
                    fix.fix == gps::FixType::k3D && !fix.glitching);
    mav::add_sensor(health, mav::kAbsolutePressure, baro::present(), baro::healthy());
    uint8_t n = port::mavlink.heartbeat(frame, flight_io.failsafe() ? mav::State::Critical : state,
                                        flight_io.plane_mode(), flight_io.armed());
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    const uint32_t missed = imu.missed_samples();
    n = port::mavlink.sys_status(frame, health,
                                 (uint16_t)(loop_load::percent() * 10u),
                                 (uint16_t)(missed < 0xFFFFu ? missed : 0xFFFFu));
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
}

// The position messages: each round (kPositionPeriodMs) GLOBAL_POSITION_INT and VFR_HUD,
// every other round GPS_RAW_INT first; HOME_POSITION before them when due. One frame a run.
constexpr uint16_t kPositionPeriodMs = 250;
enum PositionFrame : uint8_t { kGpsRaw, kGlobalPosition, kVfrHud, kRoundDone };
static uint8_t next_position_frame = kRoundDone;
static uint8_t position_rounds = 0;
static uint32_t position_round_ms = 0;
static uint8_t home_changes_sent = 0;

static bool home_due() {
    return position::navigator().home_set() && (home_requested || home_changes_sent != position::home_changes());
}

bool position_due() {
    if (!port::mavlink_mode() || !room_for(mav::kMaxFrame)) return false;
    if (home_due() || next_position_frame != kRoundDone) return true;
    return millis() - position_round_ms >= kPositionPeriodMs;
}

void send_position() {
    uint8_t frame[mav::kMaxFrame];
    uint8_t n = 0;
    if (home_due()) {
        home_requested = false;
        home_changes_sent = position::home_changes();
        const nav::Location& h = position::navigator().home();
        n = port::mavlink.home_position(frame, h.lat_e7, h.lon_e7, h.alt_cm * 10);
    } else {
        if (next_position_frame == kRoundDone) {
            position_round_ms = millis();
            next_position_frame = (position_rounds++ & 1u) == 0u ? kGpsRaw : kGlobalPosition;
        }
        // No GLOBAL_POSITION_INT before the first fix: a map would put the plane at 0, 0.
        if (next_position_frame == kGlobalPosition && !position::navigator().have_position()) ++next_position_frame;
        mav::PositionReport r;
        switch (next_position_frame++) {
            case kGpsRaw: n = port::mavlink.gps_raw_int(frame, gps_port::fix()); break;
            case kGlobalPosition:
                position::report(r);
                n = port::mavlink.global_position_int(frame, r);
                break;
            default:
                position::report(r);
                n = port::mavlink.vfr_hud(frame, r);
                break;
        }
    }
    if (n > 0) port::send_frame(frame, n);
}

}  // namespace gcs_link
