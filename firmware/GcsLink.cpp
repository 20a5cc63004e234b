// SPDX-License-Identifier: GPL-3.0-or-later
#include "GcsLink.h"

#include <string.h>

#include "AirspeedInput.h"
#include "Baro.h"
#include "BatteryInput.h"
#include "Board.h"
#include "Console.h"
#include "ConsoleLink.h"
#include "GpsPort.h"
#include "NavModes.h"
#include "LoopLoad.h"
#include "MagCalLink.h"
#include "ParamLink.h"
#include "Port.h"
#include "Position.h"
#include "SerialText.h"
#include "Vehicle.h"
#include "Version.h"

namespace gcs_link {

using vehicle::compass;
using vehicle::flight_io;
using vehicle::imu;
using vehicle::pipe;

static mav::Parser input;
static mav::ParamReplies param_replies;
static bool save_pending = false;           // a PARAM_SET changed a value: save when there is time
static bool configure_pending = false;      // ... and put it in force first, in a pass of its own
// PREFLIGHT_STORAGE defaults: restored (and every parameter announced) in a pass, its line in the next.
enum class Defaults : uint8_t { None, Restore, Say };
static Defaults defaults_pending = Defaults::None;
// A COMMAND_LONG taken off the parser at once (a burst behind it keeps flowing), run and
// ACKed when the output has room for the ACK and the lines it may say.
static mav::CommandLong command;
static uint8_t command_sysid = 0, command_compid = 0;
static bool command_pending = false;
static uint32_t last_frame_ms = 0;  // the last request taken (a save waits for a quiet link)

// The answers a frame or the clock asks for, sent one a run by send_reply() when the
// output has room: a byte of flags and what they need (7 + 8 bytes).
enum ReplyFlag : uint8_t {
    kReplyVersion = 1u << 0,      // AUTOPILOT_VERSION (REQUEST_AUTOPILOT_CAPABILITIES, REQUEST_MESSAGE 148)
    kReplyTimesync = 1u << 1,     // TIMESYNC: timesync_ts1 echoed
    kReplySystemTime = 1u << 2,   // SYSTEM_TIME, once a second
    kReplyMissionCount = 1u << 3, // MISSION_COUNT 0 of mission_type
    kReplyMissionAck = 1u << 4,   // MISSION_ACK mission_result of mission_type
};
static uint8_t replies = 0;
static int64_t timesync_ts1 = 0;
static uint8_t mission_type = 0;
static mav::MissionResult mission_result = mav::MissionResult::Accepted;
static uint8_t mission_sysid = 0, mission_compid = 0;
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

bool room_for(uint16_t frame_bytes) {
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

// ArduPilot refuses MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN while armed: the arming's check
// goes here (until then the board is never refused a reboot).
static bool safe_to_reboot() { return true; }
static bool reboot_pending = false;  // ACKed: the reboot once the ACK and any save are out

// MAV_CMD_PREFLIGHT_CALIBRATION: param1 1 the gyro (`cal gyro`), param2 1 the compass
// (`cal mag`, saved when good: MagCalLink's START with autosave), param5 2 the level
// (`cal level`), param5 1 the accelerometer's six positions; the others (baro, airspeed
// ...) the board does not have.
// MAV_CMD_PREFLIGHT_STORAGE: param1 1 write (`save`), 2 defaults (`defaults`, not
// saved); 0 (read) UNSUPPORTED. The result comes as "# " lines.
static mav::Result run_command(const mav::CommandLong& c) {
    const float* p = c.param;
    if (c.command == mav::kCmdPreflightCalibration && p[4] == 1.0f) {
        // param5 1: the accelerometer in six positions (Mission Planner's Calibrate Accel,
        // MAVProxy's accelcal); each position asked by STATUSTEXT and ACCELCAL_VEHICLE_POS.
        for (uint8_t i = 0; i < 7; ++i)
            if (i != 4 && p[i] != 0.0f) return mav::Result::Unsupported;
        return pipe.start_accel_calibration() ? mav::Result::Accepted : mav::Result::TemporarilyRejected;
    }
    if (c.command == mav::kCmdAccelcalVehiclePos) {
        // Mission Planner: the vehicle is in the position asked (param1).
        const float pos = p[0];
        return pos >= 1.0f && pos <= 6.0f && pipe.confirm_accel_position((uint8_t)pos) ? mav::Result::Accepted
                                                                                       : mav::Result::Failed;
    }
    if (c.command == mav::kCmdPreflightCalibration && p[4] == 2.0f) {
        // param5 2: the level (Mission Planner's "Calibrate Level", MAVProxy's ahrstrim):
        // accepted as it starts, the verdict a "# cal level" line (STATUSTEXT).
        for (uint8_t i = 0; i < 7; ++i)
            if (i != 4 && p[i] != 0.0f) return mav::Result::Unsupported;
        return pipe.start_level_calibration() ? mav::Result::Accepted : mav::Result::TemporarilyRejected;
    }
    if (c.command == mav::kCmdPreflightCalibration) {
        const bool gyro = p[0] == 1.0f, mag = p[1] == 1.0f;
        for (uint8_t i = 2; i < 7; ++i)
            if (p[i] != 0.0f) return mav::Result::Unsupported;
        if (!gyro && !mag) return mav::Result::Unsupported;
        if (pipe.gyro_calibrating() || pipe.mag_calibrating() || pipe.phase() != pipeline::Phase::Running)
            return mav::Result::TemporarilyRejected;
        if (mag) {  // first: it refuses while the gyro calibrates
            const mav::Result r = mag_cal_link::start(true);
            if (r != mav::Result::Accepted) return r;
        }
        if (gyro) pipe.start_gyro_calibration();
        return mav::Result::Accepted;
    }
    if (c.command == mav::kCmdPreflightStorage) {
        // No read (param1 0): both slots read, checked and decoded take longer than a
        // sample period; a PARAM_SET is saved at once anyway.
        if (p[0] == 1.0f) {
            vehicle::store.start_save(pipe.settings());
        } else if (p[0] == 2.0f) {
            defaults_pending = Defaults::Restore;
        } else {
            return mav::Result::Unsupported;
        }
        return mav::Result::Accepted;
    }
    if (c.command == mav::kCmdDoSetHome) return set_home(p);
    if (mag_cal_link::handles(c.command)) return mag_cal_link::command(c);
    if (c.command == mav::kCmdPreflightRebootShutdown) {
        // param1 1: the autopilot (ArduPilot's 2 shutdown, 3 the bootloader: not here);
        // param2 (the companion computer) 0 or absent.
        if (p[0] != 1.0f) return mav::Result::Unsupported;
        if (!safe_to_reboot()) return mav::Result::TemporarilyRejected;
        reboot_pending = true;
        return mav::Result::Accepted;
    }
    if (c.command == mav::kCmdRequestAutopilotCapabilities ||
        (c.command == mav::kCmdRequestMessage && p[0] == (float)mav::kMsgAutopilotVersion)) {
        replies |= kReplyVersion;  // after the ACK, as ArduPilot
        return mav::Result::Accepted;
    }
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

// The mission, fence and rally protocols until the board stores them (ArduPilot's
// answers for empty ones): a list asked for is empty (MISSION_COUNT 0), an upload is
// refused (MISSION_ACK UNSUPPORTED), a clear or an empty upload accepted; a ground
// station never waits in silence. TIMESYNC is answered as ArduPilot does.
static void take_conversation(const mav::Received& rx) {
    uint16_t count = 0;
    uint8_t type = 0;
    if (mav::decode_mission_request_list(rx, type)) {
        replies |= kReplyMissionCount;
    } else if (mav::decode_mission_count(rx, count, type)) {
        mission_result = count == 0u ? mav::MissionResult::Accepted : mav::MissionResult::Unsupported;
        replies |= kReplyMissionAck;
    } else if (mav::decode_mission_clear_all(rx, type)) {
        mission_result = mav::MissionResult::Accepted;
        replies |= kReplyMissionAck;
    } else if (mav::decode_timesync_request(rx, timesync_ts1)) {
        replies |= kReplyTimesync;
        return;
    } else {
        return;
    }
    mission_type = type;
    mission_sysid = rx.sysid;
    mission_compid = rx.compid;
}

bool reply_due() { return replies != 0u && room_for(mav::kMaxFrame); }
void send_reply() {
    uint8_t frame[mav::kMaxFrame];
    uint8_t n = 0;
    if (replies & kReplyTimesync) {  // first: its use is the round trip's time
        replies &= (uint8_t)~kReplyTimesync;
        n = port::mavlink.timesync(frame, (int64_t)micros() * 1000, timesync_ts1);
    } else if (replies & kReplyVersion) {
        replies &= (uint8_t)~kReplyVersion;
        mav::Version v{APM25_VERSION_MAJOR, APM25_VERSION_MINOR, APM25_VERSION_PATCH, {}};
        static const char kGit[] PROGMEM = APM25_GIT_HASH;  // in flash: RAM is for the loop
        for (uint8_t i = 0; i < sizeof v.git && i + 1u < sizeof kGit; ++i) v.git[i] = pgm_read_byte(&kGit[i]);
        n = port::mavlink.autopilot_version(frame, v);
    } else if (replies & kReplyMissionCount) {
        replies &= (uint8_t)~kReplyMissionCount;
        n = port::mavlink.mission_count(frame, mission_sysid, mission_compid, 0u, mission_type);
    } else if (replies & kReplyMissionAck) {
        replies &= (uint8_t)~kReplyMissionAck;
        n = port::mavlink.mission_ack(frame, mission_sysid, mission_compid, mission_result, mission_type);
    } else {
        replies = 0;  // kReplySystemTime
        const uint32_t now_ms = millis();
        n = port::mavlink.system_time(frame, gps::unix_time_us(gps_port::fix(), now_ms), now_ms);
    }
    if (n > 0) port::send_frame(frame, n);
}

// A frame: taken as soon as it is complete, whatever the output's backlog, so that the
// parser never stops reading the 64-byte receive ring (5.6 ms of bytes at 115200 baud):
// what a frame asks for is noted (a PARAM_VALUE's bit, a command's slot) and sent by
// the tasks below when the link has room. A PARAM_SET costs ~0.3 ms (a parameter looked
// up and set), so a burst is taken as fast as it arrives.
// A second command while one waits stays in the parser: a ground station sends the
// next after the ACK.
bool request_due() { return input.ready() && !(command_pending && input.frame().msgid == mav::kMsgCommandLong); }

void take_request() {
    const mav::Received& rx = input.frame();
    last_frame_ms = millis();
    mav::ParamRequest read;
    mav::ParamSet set;
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
        if (changed) {
            save_pending = configure_pending = true;
            // Only a COMPASS_ row can be the calibration's: the table is not walked again
            // for the others (a burst's frames wait in the 64-byte receive ring meanwhile).
            if (strncmp(set.name, "COMPASS_", 8) == 0) mag_cal_link::parameter_changed((uint16_t)index);
        }
    } else if (rx.msgid == mav::kMsgCommandAck) {
        // MAVProxy's accelcal: COMMAND_ACK with command = the position it confirms.
        uint16_t position;
        uint8_t result;
        if (mav::decode_command_ack(rx, position, result) && position >= 1u && position <= 6u)
            pipe.confirm_accel_position((uint8_t)position);
    } else if (mav::decode_command_long(rx, command) || mav::decode_command_int(rx, command)) {
        command_sysid = rx.sysid;
        command_compid = rx.compid;
        command_pending = true;
    } else {
        take_conversation(rx);
    }
    input.release();
}

bool command_due() { return command_pending && room_for(2u * mav::kMaxFrame); }
void run_pending_command() {
    command_pending = false;
    const mav::Result r = run_command(command);
    uint8_t frame[mav::kMaxFrame];
    port::send_frame(frame, port::mavlink.command_ack(frame, command.command, r, command_sysid, command_compid));
}

// The reboot: when the ACK has left (the queue empty, the UART drained) and no save is
// pending or under way, the watchdog at its shortest (15 ms) and a wait for it, as
// ArduPilot's APM2 HAL does: the board resets and starts as at power-up (Board.cpp stops
// the watchdog before anything else runs).
bool reboot_due() {
    return reboot_pending && !save_pending && !vehicle::store.busy() && serial_text::queued() == 0u;
}
void reboot() {
    Serial.flush();
    board::reset_by_watchdog();
}

void announce_param(uint16_t index) {
    if (port::mavlink_mode()) param_replies.request_one(index);
}

bool defaults_due() { return defaults_pending != Defaults::None && room_for(2u * mav::kMaxFrame); }
void run_defaults() {
    if (defaults_pending == Defaults::Restore) {
        pipe.restore_defaults();
        param_replies.request_every_one();  // the ground station's list is stale
        defaults_pending = Defaults::Say;
        return;
    }
    defaults_pending = Defaults::None;
    flight_io.configure();  // the controllers' terms from the defaults (a pass of its own)
    console::print_defaults(vehicle::out);
}

// The save's start (the record encoded: ~5.6 ms, as long as the receive ring takes to
// fill) waits for a link quiet for kSaveQuietMs: a burst of PARAM_SETs (one every ~3 ms)
// is over, its frames all read, and one save keeps them all.
constexpr uint16_t kSaveQuietMs = 50;
bool save_due() {
    return save_pending && millis() - last_frame_ms >= kSaveQuietMs && room_for(2u * mav::kMaxFrame);
}
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
void save_soon() { save_pending = true; }

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

// The six-position calibration's position asked (and at its end SUCCESS or FAILED) as
// ArduPilot sends it: COMMAND_LONG ACCELCAL_VEHICLE_POS to the ground station, once.
static uint8_t accel_asks_sent = 0;
static bool accel_cal_running = false;
static void announce_accel_position(uint8_t frame[mav::kMaxFrame]) {
    const uint8_t asked = pipe.accel_position_asked();
    float param1 = 0.0f;
    if (asked != 0u && pipe.accel_asks() != accel_asks_sent) {
        param1 = (float)asked;  // a position asked, or asked again after a refusal
    } else if (accel_cal_running && !pipe.accel_calibrating()) {
        param1 = pipe.accel_fit_quality() == calib::AccelFit::Quality::Ok ? mav::kAccelcalSuccess : mav::kAccelcalFailed;
    }
    accel_cal_running = pipe.accel_calibrating();
    if (param1 == 0.0f) return;
    accel_asks_sent = pipe.accel_asks();
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame),
                                    port::mavlink.command_long(frame, mav::kCmdAccelcalVehiclePos, param1));
}

void send_heartbeat_and_status() {
    if (!port::mavlink_mode()) return;
    replies |= kReplySystemTime;
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
    const airspeed_input::State airspeed = airspeed_input::state();
    mav::add_sensor(health, mav::kDifferentialPressure, airspeed != airspeed_input::State::kNone,
                    airspeed == airspeed_input::State::kSensor);
    const mav::PlaneMode mode = flight_io.plane_mode();
    mav::add_plane_status(health, mav::PlaneStatus{FlightIo::kEnabled, mode != mav::PlaneMode::Manual,
                                                   !flight_io.failsafe(), ph == pipeline::Phase::Running});
    mav::add_sensor(health, mav::kBattery, battery_input::enabled(), battery_input::healthy());
    const mav::BatteryReport battery = battery_input::report();
    uint8_t n = port::mavlink.heartbeat(frame, flight_io.failsafe() ? mav::State::Critical : state, mode,
                                        flight_io.armed());
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    const uint32_t missed = imu.missed_samples();
    n = port::mavlink.sys_status(frame, health,
                                 (uint16_t)(loop_load::percent() * 10u),
                                 (uint16_t)(missed < 0xFFFFu ? missed : 0xFFFFu), &battery);
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    announce_accel_position(frame);
}

// The position messages: each round (kPositionPeriodMs) GLOBAL_POSITION_INT and VFR_HUD,
// then NAV_CONTROLLER_OUTPUT while a navigation mode flies, every other round GPS_RAW_INT
// first; HOME_POSITION before them when due. One frame a run.
constexpr uint16_t kPositionPeriodMs = 250;
enum PositionFrame : uint8_t { kGpsRaw, kGlobalPosition, kVfrHud, kNavOutput, kRoundDone };
static uint8_t next_position_frame = kRoundDone;
static uint8_t position_rounds = 0;
static uint32_t position_round_ms = 0;
static uint8_t home_changes_sent = 0;

static bool home_due() {
    return position::navigator().home_set() && (home_requested || home_changes_sent != position::home_changes());
}

// The compass calibration's frames (MagCalLink) take this task's runs while due: a row of
// their own in the task table would cost every loop pass a call in the text modes too, and
// move the firmware's timeline (the compass's DRDY read falls on another step).
bool position_due() {
    if (!port::mavlink_mode() || !room_for(mav::kMaxFrame)) return false;
    if (mag_cal_link::due() || home_due() || next_position_frame != kRoundDone) return true;
    return millis() - position_round_ms >= kPositionPeriodMs;
}

void send_position() {
    if (mag_cal_link::due()) return mag_cal_link::send();
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
            case kVfrHud:
                position::report(r);
                n = port::mavlink.vfr_hud(frame, r);
                break;
            default: {
                mav::NavOutput nav;
                if (nav_modes::report(nav)) n = port::mavlink.nav_controller_output(frame, nav);
                break;
            }
        }
    }
    if (n > 0) port::send_frame(frame, n);
}

}  // namespace gcs_link
