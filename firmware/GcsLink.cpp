// SPDX-License-Identifier: GPL-3.0-or-later
#include "GcsLink.h"

#include <stddef.h>
#include <string.h>

#include "Params.h"

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
#include "MissionLink.h"
#include "ParamLink.h"
#include "Port.h"
#include "Position.h"
#include "SerialText.h"
#include "StreamRates.h"
#include "Tasks.h"
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
};
static uint8_t replies = 0;
static int64_t timesync_ts1 = 0;
// The messages on a timer (mav::StreamRates): their intervals planned from the SR0_ rates,
// a ground station's SET_MESSAGE_INTERVAL and the console's `rate`, again whenever one of
// them differs from what the plan was made with (a PARAM_SET, the console's `set`, the
// defaults: no path needs to say so).
static mav::StreamRates streams;
static uint8_t planned_sr0_hz[mav::kStreamGroups];
static uint8_t planned_rate_hz = 0;  // 0: not planned yet
static bool replan = false;          // a REQUEST_DATA_STREAM or SET_MESSAGE_INTERVAL taken
static_assert(sizeof(settings::VehicleSettings::sr0_hz) == mav::kStreamGroups, "an SR0_ row per stream group");
static bool home_requested = false;         // GET_HOME_POSITION or REQUEST_MESSAGE 242: HOME_POSITION to send

mav::Parser& parser() { return input; }

static bool plan_stale() {
    const settings::Settings& s = pipe.settings();
    return replan || s.rate_hz != planned_rate_hz || memcmp(s.vehicle.sr0_hz, planned_sr0_hz, sizeof planned_sr0_hz) != 0;
}
static void plan() {
    const settings::Settings& s = pipe.settings();
    replan = false;
    planned_rate_hz = s.rate_hz;
    memcpy(planned_sr0_hz, s.vehicle.sr0_hz, sizeof planned_sr0_hz);
    streams.plan(planned_sr0_hz, planned_rate_hz);
}
bool stream_due(mav::StreamMsg m) { return streams.due(m, millis()); }
bool take_stream(mav::StreamMsg m, uint32_t now_ms) { return streams.take(m, now_ms); }

// A COMMAND_LONG's message id (a float): the id, or kNoMessage when it is none.
constexpr uint32_t kNoMessage = 0xFFFFFFFFu;
static uint32_t message_id(float f) { return f >= 0.0f && f < 65536.0f ? (uint32_t)f : kNoMessage; }

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
    if (c.command == mav::kCmdDoSetMissionCurrent)  // as MISSION_SET_CURRENT (ArduPilot's reset: not here)
        return p[1] == 0.0f && p[0] >= 0.0f && p[0] < 65536.0f && mission_link::set_current((uint16_t)p[0])
                   ? mav::Result::Accepted : mav::Result::Failed;
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
    if (c.command == mav::kCmdSetMessageInterval) {
        // In RAM, as ArduPilot; a message the board does not send on a timer is DENIED.
        replan = true;
        return streams.set_interval(message_id(p[0]), p[1]);
    }
    if (c.command == mav::kCmdGetHomePosition ||
        (c.command == mav::kCmdRequestMessage && p[0] == (float)mav::kMsgHomePosition)) {
        if (!position::navigator().home_set()) return mav::Result::Failed;  // as ArduPilot: no home yet
        home_requested = true;
        return mav::Result::Accepted;
    }
    return mav::Result::Unsupported;
}

// TIMESYNC is answered as ArduPilot does.
static void take_conversation(const mav::Received& rx) {
    if (mav::decode_timesync_request(rx, timesync_ts1)) replies |= kReplyTimesync;
}

// The mission protocols' replies (MissionLink) with room for a STATUSTEXT after them.
static bool mission_reply_due() { return mission_link::reply_due() && room_for(2u * mav::kMaxFrame); }
bool reply_due() { return (replies != 0u && room_for(mav::kMaxFrame)) || mission_reply_due(); }
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
    } else if (mission_reply_due()) {
        return mission_link::send_reply();
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
// A mission frame waits while the mission's EEPROM writes or its last reply do (MissionLink.h).
bool request_due() {
    if (!input.ready()) return false;
    const uint8_t id = input.frame().msgid;
    return !(command_pending && id == mav::kMsgCommandLong) && !(mission_link::is_mission_frame(id) && mission_link::busy());
}

TASK_OWN_FRAME void take_request() {
    const mav::Received& rx = input.frame();
    last_frame_ms = millis();
    mav::ParamRequest read;
    mav::ParamSet set;
    mav::SetMode set_mode;
    mav::DataStreamRequest stream;
    uint16_t override_us[8];
    if (mav::decode_request_data_stream(rx, stream)) {
        // As ArduPilot: no answer (no PARAM_VALUE either), the SR0_ rates saved only when
        // changed; the group's messages follow it again.
        uint8_t groups;
        if (mav::apply_data_stream_request(pipe.settings().vehicle.sr0_hz, stream.stream_id, stream.rate_hz,
                                           stream.start_stop, &groups))
            save_pending = true;
        streams.follow_groups(groups);
        replan = true;
    } else if (mav::decode_rc_channels_override(rx, override_us)) {
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
            // A compass calibration row is a new calibration (its rows' range is found once:
            // a table walk per frame would keep a burst's frames waiting in the receive ring).
            mag_cal_link::parameter_changed((uint16_t)index);
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
    } else if (mission_link::is_mission_frame(rx.msgid)) {
        mission_link::take(rx);
    } else {
        take_conversation(rx);
    }
    input.release();
}

bool command_due() { return command_pending && room_for(2u * mav::kMaxFrame); }
TASK_OWN_FRAME void run_pending_command() {
    command_pending = false;
    uint8_t frame[mav::kMaxFrame];
    mav::Result r = mav::Result::Denied;
    if (command.command == mav::kCmdGetMessageInterval) {
        // As ArduPilot: MESSAGE_INTERVAL (-1 for a message not sent), then the ACK.
        const uint32_t id = message_id(command.param[0]);
        if (id != kNoMessage) {
            port::send_frame(frame, port::mavlink.message_interval(frame, (uint16_t)id, streams.interval_us(id)));
            r = mav::Result::Accepted;
        }
    } else {
        r = run_command(command);
    }
    port::send_frame(frame, port::mavlink.command_ack(frame, command.command, r, command_sysid, command_compid));
}

// The reboot: when the ACK has left (the queue empty, the UART drained) and no save (nor
// a mission's write or reply) is pending or under way, the watchdog at its shortest
// (15 ms) and a wait for it, as ArduPilot's APM2 HAL does: the board resets and starts as
// at power-up (Board.cpp stops the watchdog before anything else runs).
bool reboot_due() {
    return reboot_pending && !save_pending && !vehicle::store.busy() && !mission_link::busy() &&
           serial_text::queued() == 0u;
}
void reboot() {
    Serial.flush();
    board::reset_by_watchdog();
}

void announce_param(uint16_t index) {
    if (port::mavlink_mode()) param_replies.request_one(index);
}

static params::Rows calibration_rows(Calibrated what) {
    using settings::Settings;
    switch (what) {
        case Calibrated::kLevel:
            return params::rows_within(offsetof(Settings, vehicle.ahrs_trim_x_rad),
                                       offsetof(Settings, vehicle.ins_accoffs_m_s2));
        case Calibrated::kAccel:
            return params::rows_within(offsetof(Settings, vehicle.ins_accoffs_m_s2),
                                       offsetof(Settings, vehicle.ins_accscal) + sizeof(float[3]));
        case Calibrated::kCompass: return params::compass_calibration_rows();
        default:
            return params::rows_within(offsetof(Settings, gnd_abs_press_pa),
                                       offsetof(Settings, gnd_abs_press_pa) + sizeof(float));
    }
}

void announce_calibration(Calibrated what) {
    if (!port::mavlink_mode()) return;
    const params::Rows rows = calibration_rows(what);
    for (uint8_t i = 0; i < rows.count; ++i) param_replies.request_one((uint16_t)(rows.first + i));
}

void announce_calibration(const pipeline::AttitudePipeline& p, const pipeline::Event& e) {
    using pipeline::EventKind;
    if (e.code != 0u) return;  // each verdict's Ok is 0: nothing was written otherwise
    if (e.kind == EventKind::kLevelDone) announce_calibration(Calibrated::kLevel);
    else if (e.kind == EventKind::kAccelCalDone) announce_calibration(Calibrated::kAccel);
    else if (e.kind == EventKind::kMagCalDone && p.mag_cal_state() == pipeline::MagCalState::kApplied)
        announce_calibration(Calibrated::kCompass);
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
TASK_OWN_FRAME void save() {
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
    // Room left for a "# " line (two STATUSTEXT frames) beside it: a list asked for at
    // start-up does not crowd out the start-up's messages (Port holds back what has none).
    return param_replies.peek(index) && room_for(mav::kParamValueFrame + 2u * mav::kMaxFrame);
}
void send_param_value() {
    uint16_t index;
    param_replies.peek(index);
    uint8_t frame[mav::kMaxFrame];
    const uint8_t n = mav::pack_param_value(port::mavlink, frame, pipe.settings(), index, param_replies.count());
    if (n > 0) port::send_frame(frame, n);
    param_replies.pop();
}

// SYS_STATUS: the sensors, the controllers' bits, the load, the missed samples, the battery.
static uint8_t sys_status(uint8_t frame[mav::kMaxFrame]) {
    const pipeline::Phase ph = pipe.phase();
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
    const uint32_t missed = imu.missed_samples();
    return port::mavlink.sys_status(frame, health, (uint16_t)(loop_load::percent() * 10u),
                                    (uint16_t)(missed < 0xFFFFu ? missed : 0xFFFFu), &battery);
}

// The streams task's messages (the position task and the battery's have theirs, ATTITUDE
// goes with the output line), one frame a run; a message due whose source is absent (no
// barometer, the attitude-only build's receiver) is passed over until next time.
bool streams_due() {
    if (!port::mavlink_mode()) return false;
    if (plan_stale()) return true;
    const uint32_t now_ms = millis();
    return (streams.due(mav::kStreamSysStatus, now_ms) || streams.due(mav::kStreamRcChannels, now_ms) ||
            streams.due(mav::kStreamServoOutputRaw, now_ms) || streams.due(mav::kStreamScaledPressure, now_ms) ||
            streams.due(mav::kStreamSystemTime, now_ms) || streams.due(mav::kStreamMissionCurrent, now_ms)) &&
           room_for(mav::kMaxFrame);
}
void send_streams() {
    if (plan_stale()) return plan();  // a pass of its own
    const uint32_t now_ms = millis();
    uint8_t frame[mav::kMaxFrame];
    uint8_t n = 0;
    if (streams.take(mav::kStreamSysStatus, now_ms)) {
        n = sys_status(frame);
    } else if (streams.take(mav::kStreamRcChannels, now_ms)) {
        if (FlightIo::kEnabled) n = flight_io.rc_channels(port::mavlink, frame, now_ms);
    } else if (streams.take(mav::kStreamServoOutputRaw, now_ms)) {
        if (FlightIo::kEnabled) n = flight_io.servo_output_raw(port::mavlink, frame, micros());
    } else if (streams.take(mav::kStreamScaledPressure, now_ms)) {
        if (baro::present())
            n = port::mavlink.scaled_pressure(frame, now_ms, baro::pressure_pa(), baro::temperature_c());
    } else if (streams.take(mav::kStreamSystemTime, now_ms)) {
        n = port::mavlink.system_time(frame, gps::unix_time_us(gps_port::fix(), now_ms), now_ms);
    } else if (streams.take(mav::kStreamMissionCurrent, now_ms)) {
        n = port::mavlink.mission_current(frame, mission_link::current_seq(), mission_link::count());
    }
    if (n > 0) port::send_frame(frame, n);
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
    const pipeline::Phase ph = pipe.phase();
    const mav::State state = !imu.ok() || !compass.ok() ? mav::State::Critical
                             : ph == pipeline::Phase::WaitImu ? mav::State::Boot
                             : ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating()
                                 ? mav::State::Calibrating
                                 : mav::State::Active;
    uint8_t frame[mav::kMaxFrame];
    const uint8_t n = port::mavlink.heartbeat(frame, flight_io.failsafe() ? mav::State::Critical : state,
                                              flight_io.plane_mode(), flight_io.armed());
    serial_text::write_line_if_room(reinterpret_cast<const char*>(frame), n);
    announce_accel_position(frame);
}

// The position messages, each at its stream's interval: GPS_RAW_INT (SR0_EXT_STAT),
// GLOBAL_POSITION_INT (SR0_POSITION), VFR_HUD (SR0_EXTRA2), NAV_CONTROLLER_OUTPUT (SR0_EXT_STAT) while a navigation mode
// flies; HOME_POSITION before them when due. One frame a run.
static uint8_t home_changes_sent = 0;

static bool home_due() {
    return position::navigator().home_set() && (home_requested || home_changes_sent != position::home_changes());
}

// The compass calibration's frames (MagCalLink) take this task's runs while due: a row of
// their own in the task table would cost every loop pass a call in the text modes too, and
// move the firmware's timeline (the compass's DRDY read falls on another step).
bool position_due() {
    if (!port::mavlink_mode() || !room_for(mav::kMaxFrame)) return false;
    if (mag_cal_link::due() || home_due()) return true;
    const uint32_t now_ms = millis();
    return streams.due(mav::kStreamGpsRawInt, now_ms) || streams.due(mav::kStreamGlobalPositionInt, now_ms) ||
           streams.due(mav::kStreamVfrHud, now_ms) || streams.due(mav::kStreamNavControllerOutput, now_ms);
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
        const uint32_t now_ms = millis();
        mav::PositionReport r;
        if (streams.take(mav::kStreamGpsRawInt, now_ms)) {
            n = port::mavlink.gps_raw_int(frame, gps_port::fix());
        } else if (streams.take(mav::kStreamGlobalPositionInt, now_ms)) {
            // None before the first fix: a map would put the plane at 0, 0.
            if (position::navigator().have_position()) {
                position::report(r);
                n = port::mavlink.global_position_int(frame, r);
            }
        } else if (streams.take(mav::kStreamVfrHud, now_ms)) {
            position::report(r);
            n = port::mavlink.vfr_hud(frame, r);
        } else if (streams.take(mav::kStreamNavControllerOutput, now_ms)) {
            mav::NavOutput nav;  // none but while a navigation mode flies
            if (nav_modes::report(nav)) n = port::mavlink.nav_controller_output(frame, nav);
        }
    }
    if (n > 0) port::send_frame(frame, n);
}

}  // namespace gcs_link
