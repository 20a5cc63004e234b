// SPDX-License-Identifier: GPL-3.0-or-later
// MAVLink 2 for ground stations (Mission Planner, QGroundControl, MAVProxy): the messages
// the board sends, packed into the caller's byte buffer, and the ground station's frames,
// parsed (CRC-checked, MAVLink 2 and 1) from the bytes it shares the UART with.
//
//   HEARTBEAT        1 Hz      21 bytes   FIXED_WING, ARDUPILOTMEGA, ArduPlane's mode number
//   ATTITUDE         per line  40 bytes   roll, pitch, yaw (rad, yaw with declination), body rates
//   SYS_STATUS       1 Hz      ~43 bytes  gyro/accel/compass present+enabled+healthy bits, load
//   STATUSTEXT       per "# "  15..66     every "# " console line, severity from its first word
//   RC_CHANNELS      5 Hz      54 bytes   the receiver's eight widths, us
//   SERVO_OUTPUT_RAW 5 Hz      33 bytes   the eight outputs' widths, us
//   SCALED_PRESSURE  5 Hz      ~28 bytes  the barometer's pressure (hPa) and temperature
//   PARAM_VALUE      replies   37 bytes   (ParamLink.h)
//   COMMAND_ACK      replies   ~15 bytes
//   GPS_RAW_INT      1 Hz      <= 64      the fix as the receiver gave it (GpsFix.h)
//   GLOBAL_POSITION_INT 4 Hz   <= 40      the position now, the height above home, velocity
//   VFR_HUD          4 Hz      <= 32      airspeed, ground speed, heading, throttle, height, climb
//   HOME_POSITION    on request and when home changes, <= 40
//   MAG_CAL_PROGRESS 2 Hz      39 bytes   while a ground station's compass calibration runs
//   MAG_CAL_REPORT   once      <= 66      its end: offsets, soft iron, fitness
//   BATTERY_STATUS   1 Hz      <= 53      the power module's voltage, current, charge used (BATT_MONITOR 3, 4)
//   MISSION_*        replies   <= 50      the mission protocol (lib/Mission/MissionProtocol.h): COUNT,
//                                         REQUEST(_INT), ITEM(_INT), ACK, CURRENT; ITEM_REACHED
//   MESSAGE_INTERVAL on MAV_CMD_GET_MESSAGE_INTERVAL, 18 bytes
// (The rates are the SR0_ parameters' defaults: StreamRates.h says which sets which.)
//
// The packing is pymavlink's generated C code (build/mavlink, made by `make mavlink` from
// the common.xml that PyPI's pymavlink ships; nothing generated is committed), so field
// order, CRC_EXTRA and MAVLink 2 zero-trimming are the protocol's own. No signing.
// Sizes are frame bytes: 10 header + payload (trailing zeros trimmed) + 2 CRC.
//
// Why these HEARTBEAT values: QGroundControl creates a vehicle for a heartbeat from
// component MAV_COMP_ID_AUTOPILOT1 (1) unless its type is GCS, ONBOARD_CONTROLLER, GIMBAL
// or ADSB (MultiVehicleManager). The board flies a plane with ArduPlane's modes and
// parameter names, so it says what ArduPlane says: MAV_TYPE_FIXED_WING,
// MAV_AUTOPILOT_ARDUPILOTMEGA and custom_mode = ArduPlane's mode number, which Mission
// Planner, QGroundControl and MAVProxy name (MANUAL, STABILIZE, FBWA). base_mode: custom
// mode enabled, manual input enabled, stabilize enabled outside MANUAL, and
// MAV_MODE_FLAG_SAFETY_ARMED while the throttle is armed (ArduPlane's: always with
// ARMING_REQUIRE 0).
//
// Plain C++: no Arduino include, the same code on the AVR and the host tests.
#pragma once

#include <stdint.h>

#include "BatteryMonitor.h"
#include "GpsFix.h"
#include "LinAlg.h"
#include "Text.h"

namespace mission {
struct Item;  // MissionProtocol.h: MISSION_ITEM(_INT)'s fields
}

namespace mav {

constexpr uint8_t kSystemId = 1;
constexpr uint8_t kComponentId = 1;     // MAV_COMP_ID_AUTOPILOT1
constexpr uint8_t kFrameOverhead = 12;  // MAVLink 2 header (10) + CRC (2), unsigned
constexpr uint8_t kTextChunk = 50;      // STATUSTEXT text field, characters
// The longest frame sent: STATUSTEXT with 50 characters (payload 54 = severity, text,
// id, chunk_seq).
constexpr uint8_t kMaxFrame = kFrameOverhead + 54;

constexpr uint8_t kHeartbeatFrame = kFrameOverhead + 9;  // never trimmed: mavlink_version = 3 last
constexpr uint8_t kAttitudeFrame = kFrameOverhead + 28;  // trimmed only if yawspeed is exactly 0

constexpr uint8_t kParamIdLen = 16;  // PARAM_* param_id, characters
constexpr uint8_t kParamValueFrame = kFrameOverhead + 25;
constexpr uint8_t kRcChannelsFrame = kFrameOverhead + 42;
constexpr uint8_t kScaledPressureFrame = kFrameOverhead + 16;  // at most (zeros trimmed)

// PARAM_VALUE param_type (MAV_PARAM_TYPE): the ones ArduPilot uses.
constexpr uint8_t kParamTypeInt8 = 2;
constexpr uint8_t kParamTypeInt16 = 4;
constexpr uint8_t kParamTypeReal32 = 9;

// COMMAND_ACK result (MAV_RESULT).
enum class Result : uint8_t { Accepted = 0, TemporarilyRejected = 1, Denied = 2, Unsupported = 3, Failed = 4 };

// HEARTBEAT system_status (MAV_STATE).
enum class State : uint8_t {
    Boot = 1,         // before the first attitude
    Calibrating = 2,  // gyro bias or compass calibration running
    Active = 4,       // estimating
    Critical = 5,     // a sensor is missing or has failed
};

// ArduPlane's mode numbers (HEARTBEAT custom_mode). The failsafe (wings level, gliding,
// throttle at THR_FS_OUT) is ArduPlane's FS_SHORT_ACTN 2, "FBWA at zero throttle": the
// board reports FBWA then, as ArduPlane does, with system_status CRITICAL.
enum class PlaneMode : uint8_t { Manual = 0, Stabilize = 2, FlyByWireA = 5 };

// STATUSTEXT severity (MAV_SEVERITY).
enum class Severity : uint8_t { Critical = 2, Error = 3, Warning = 4, Notice = 5, Info = 6 };

// SYS_STATUS sensor bits (MAV_SYS_STATUS_SENSOR_3D_GYRO, _3D_ACCEL, _3D_MAG,
// _ABSOLUTE_PRESSURE, _GPS: present once a receiver has been heard, healthy with a 3D
// fix the driver does not call a glitch).
constexpr uint32_t kGyro3d = 1u;
constexpr uint32_t kAccel3d = 2u;
constexpr uint32_t kMag3d = 4u;
constexpr uint32_t kAbsolutePressure = 8u;
constexpr uint32_t kDifferentialPressure = 16u;
constexpr uint32_t kGps = 32u;
constexpr uint32_t kBattery = 0x2000000u;  // MAV_SYS_STATUS_SENSOR_BATTERY
// ... and the controllers and the rest ArduPlane reports (MAV_SYS_STATUS_SENSOR_*).
constexpr uint32_t kAngularRateControl = 0x400u;
constexpr uint32_t kAttitudeStabilization = 0x800u;
constexpr uint32_t kYawPosition = 0x1000u;
constexpr uint32_t kMotorOutputs = 0x8000u;
constexpr uint32_t kRcReceiver = 0x10000u;
constexpr uint32_t kGeofence = 0x100000u;
constexpr uint32_t kAhrs = 0x200000u;

struct Health {
    uint32_t present;  // sensor bits found at start-up
    uint32_t enabled;  // ... in use now (a sensor: when present; a controller: in the modes that use it)
    uint32_t healthy;  // sensor bits answering with plausible data now
};
// The MPU6000 is both the 3D gyro and the 3D accelerometer.
Health health(bool mpu_present, bool mpu_ok, bool mag_present, bool mag_ok);
// Another sensor's bits: present (and enabled) when present, healthy when also ok.
void add_sensor(Health& h, uint32_t bits, bool present, bool ok);

// MAG_CAL_STATUS (common.xml): where a compass calibration stands.
enum class MagCalStatus : uint8_t {
    NotStarted = 0,
    RunningStepOne = 2,  // collecting samples
    RunningStepTwo = 3,  // fitting
    Success = 4,
    Failed = 5,
};
constexpr uint8_t kMagCalProgressFrame = kFrameOverhead + 27;  // ardupilotmega.xml's 191: 3 floats, 15 bytes

// MAG_CAL_REPORT's figures in ArduPilot's units (AP_Compass's COMPASS_OFS_*, _DIA_*, _ODI_*).
struct MagCalReport {
    MagCalStatus status;         // Success or Failed
    bool autosaved;              // the result is in use and being saved
    float fitness_mgauss;        // the fit's RMS residual (ArduPilot's COMPASS_CAL_FIT unit)
    linalg::Vector3f ofs_mgauss;  // added to the field
    linalg::Vector3f diag, offdiag;  // the soft-iron matrix: diagonal; xy, xz, yz
};
// The battery as SYS_STATUS and BATTERY_STATUS carry it; MAVLink's "unknown" where the
// monitor does not measure it (voltage UINT16_MAX, current, consumed and remaining -1).
struct BatteryReport {
    uint16_t voltage_mv;
    int16_t current_ca;     // 10 mA units
    int32_t consumed_mah;
    int8_t remaining_pct;
    bool failsafe;          // BATTERY_STATUS's charge_state LOW (else OK)
};
// The monitor's readings (BATT_MONITOR 0: all unknown), rounded and held within the fields.
BatteryReport battery_report(const battery::Monitor& m, const battery::Settings& s);
constexpr uint8_t kBatteryStatusFrame = kFrameOverhead + 41;  // at most: the extensions after charge_state are 0
// What ArduPlane's SYS_STATUS says beyond the sensors (GCS_Plane's
// update_sensor_status_flags), for a board that flies (the attitude-only build: only the
// AHRS and the fence bit).
struct PlaneStatus {
    bool flight;          // the flight build: receiver, outputs and controllers present
    bool stabilizing;     // a mode whose controllers fly the attitude (STABILIZE, the failsafe's FBWA)
    bool receiver_ok;     // good receiver frames (not in the receiver failsafe)
    bool ahrs_ok;         // the estimator running
};
// Adds the controllers' bits: angular rate control and attitude stabilisation present,
// enabled in a stabilizing mode, healthy; yaw position present (enabled only by
// navigation modes, which the board has not); motor outputs present, enabled (no safety
// switch on the APM 2.5) and healthy; the RC receiver healthy when its frames are good;
// the AHRS healthy when running. The geofence's health bit is set, as ArduPlane does
// whenever no fence is breached (no fence: never): MAVProxy says "fence breach" when a
// SYS_STATUS lacks it.
void add_plane_status(Health& h, const PlaneStatus& p);

// GLOBAL_POSITION_INT's and VFR_HUD's fields (the firmware's Position module fills them).
struct PositionReport {
    uint32_t time_boot_ms;
    int32_t lat_e7, lon_e7;      // now (moved on from the fix)
    int32_t alt_msl_mm;          // above mean sea level
    int32_t relative_alt_mm;     // above home (0 without one)
    float vel_ned_m_s[3];        // ground velocity
    float heading_deg;           // the attitude's, 0..360 (declination applied); < 0: unknown
    float airspeed_m_s;          // the pitot's, else the ground speed (VFR_HUD)
    float climb_m_s;             // up positive
    uint8_t throttle_pct;
};

// NAV_CONTROLLER_OUTPUT's fields (ArduPlane's: degrees, metres; the firmware's NavModes fills
// them while a navigation mode flies). aspd_error is not sent (0), as ArduPlane without a pitot.
struct NavOutput {
    float nav_roll_deg, nav_pitch_deg;        // the demands
    int16_t nav_bearing_deg;                  // to the L1 point, 0..359
    int16_t target_bearing_deg;               // to the waypoint or the loiter's centre, 0..359
    uint16_t wp_dist_m;
    float alt_error_m;                        // the height demand less the height (positive: low)
    float xtrack_error_m;                     // left of the track positive (ArduPilot's)
};

// MISSION_ACK's type (MAV_MISSION_RESULT; mission::Result has them all).
enum class MissionResult : uint8_t { Accepted = 0, Unsupported = 3 };

// AUTOPILOT_VERSION's contents. flight_sw_version is ArduPilot's packing: major << 24 |
// minor << 16 | patch << 8 | FIRMWARE_VERSION_TYPE (MAVProxy's decode_flight_sw_version).
struct Version {
    uint8_t major, minor, patch;
    uint8_t git[8];  // the first 8 characters of the commit's hash (ArduPilot's GIT_VERSION), or zeros
};
constexpr uint8_t kVersionTypeOfficial = 255;  // FIRMWARE_VERSION_TYPE_OFFICIAL
// What the board supports (MAV_PROTOCOL_CAPABILITY): PARAM_FLOAT (values as floats) and
// MAVLINK2 (it speaks only MAVLink 2), MISSION_INT (MISSION_ITEM_INT taken and sent). Not COMMAND_INT
// (add it when the board takes COMMAND_INT), FTP, SET_*_TARGET.
constexpr uint32_t kCapabilities = 0x2u | 0x4u | 0x2000u;
// The USB ids the APM 2.5's ATmega32U2 enumerates with (the Arduino Mega 2560's).
constexpr uint16_t kUsbVendorId = 0x2341u;
constexpr uint16_t kUsbProductId = 0x0010u;

// Packs messages; one sequence counter across all of them (a GCS counts gaps as loss).
// Each call writes one frame into `out` and returns its length (0 only on bad input).
class Packer {
public:
    uint8_t heartbeat(uint8_t out[kMaxFrame], State state, PlaneMode mode, bool armed);
    // The pipeline's angles in degrees (heading 0..360, declination applied) are sent
    // in radians, heading wrapped to -pi..pi as ATTITUDE's yaw; rates in rad/s, body axes.
    uint8_t attitude(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float roll_deg, float pitch_deg,
                     float heading_deg, const linalg::Vector3f& rate_rad_s);
    // load_permille: loop CPU load, 0..1000; errors: autopilot-specific count 1 (the
    // firmware's loop overruns, saturated). battery: its fields (nullptr: "not measured").
    uint8_t sys_status(uint8_t out[kMaxFrame], const Health& h, uint16_t load_permille, uint16_t errors,
                       const BatteryReport* battery = nullptr);
    // BATTERY_STATUS (id 0, function and type unknown as ArduPilot sends them): the pack's
    // voltage in voltages[0] (no cell voltages: the others UINT16_MAX), no temperature.
    uint8_t battery_status(uint8_t out[kMaxFrame], const BatteryReport& b);
    // text: up to kTextChunk characters (shorter ones NUL-terminated). id 0 = a message
    // in one chunk; otherwise chunks of one message share id and count chunk_seq from 0.
    uint8_t statustext(uint8_t out[kMaxFrame], Severity severity, const char* text, uint8_t len,
                       uint16_t id, uint8_t chunk_seq);
    // PARAM_VALUE: name up to kParamIdLen characters (NUL-terminated when shorter),
    // type a MAV_PARAM_TYPE, the value as a float (ArduPilot's convention for every type).
    uint8_t param_value(uint8_t out[kMaxFrame], const char* name, float value, uint8_t type, uint16_t count,
                        uint16_t index);
    // COMMAND_ACK to the ground station that sent the command.
    uint8_t command_ack(uint8_t out[kMaxFrame], uint16_t command, Result result, uint8_t target_system,
                        uint8_t target_component);
    // COMMAND_LONG from the board to the ground stations (ArduPilot's accel calibration asks
    // for a position with MAV_CMD_ACCELCAL_VEHICLE_POS, param1 the position).
    uint8_t command_long(uint8_t out[kMaxFrame], uint16_t command, float param1);
    // RC_CHANNELS: `count` channels (0: no receiver signal), the eight widths in us
    // (channels 9-18 unused: UINT16_MAX), RSSI unknown.
    uint8_t rc_channels(uint8_t out[kMaxFrame], uint32_t time_boot_ms, const uint16_t width_us[8], uint8_t count);
    // SERVO_OUTPUT_RAW: the eight outputs' widths in us, port 0.
    uint8_t servo_output_raw(uint8_t out[kMaxFrame], uint32_t time_boot_us, const uint16_t width_us[8]);
    // GPS_RAW_INT: the fix as the receiver gave it (time_usec its arrival on the board's
    // clock; eph its hDOP x 100, epv unknown; vel and cog unknown without a fix).
    uint8_t gps_raw_int(uint8_t out[kMaxFrame], const gps::Fix& fix);
    uint8_t global_position_int(uint8_t out[kMaxFrame], const PositionReport& p);
    uint8_t vfr_hud(uint8_t out[kMaxFrame], const PositionReport& p);
    uint8_t nav_controller_output(uint8_t out[kMaxFrame], const NavOutput& n);
    // HOME_POSITION: home (alt above mean sea level, mm); its local position x, y, z 0
    // (there is no local frame but home's), q level, no approach vector: as ArduPilot.
    uint8_t home_position(uint8_t out[kMaxFrame], int32_t lat_e7, int32_t lon_e7, int32_t alt_msl_mm);
    // SCALED_PRESSURE: the barometer's absolute pressure (Pa, sent in hPa) and its
    // temperature (degC, sent in 0.01 degC); no differential pressure (0).
    uint8_t scaled_pressure(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float pressure_pa, float temperature_c);
    // MAG_CAL_PROGRESS (ArduPilot's dialect: ardupilotmega.xml, CRC_EXTRA 92), compass 0
    // alone (cal_mask 1): completion_mask's bits the direction cells seen (the first
    // 26 of its 80: this calibrator's cells, not ArduPilot's geodesic sections); direction
    // the field now, a unit vector in the body frame.
    uint8_t mag_cal_progress(uint8_t out[kMaxFrame], MagCalStatus status, uint8_t attempt, uint8_t completion_pct,
                             uint32_t completion_bits, const linalg::Vector3f& direction);
    // MAG_CAL_REPORT, compass 0: orientation unchanged (ROTATION_NONE, confidence 0), no
    // scale factor (0).
    uint8_t mag_cal_report(uint8_t out[kMaxFrame], const MagCalReport& r);
    // The mission protocol's frames to the ground station that asked (MissionProtocol's
    // replies; fence and rally lists are empty, their uploads refused).
    uint8_t mission_count(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component, uint16_t count,
                          uint8_t mission_type);
    uint8_t mission_ack(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component, MissionResult result,
                        uint8_t mission_type);
    // MISSION_REQUEST_INT (int_form) or MISSION_REQUEST for item seq.
    uint8_t mission_request(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component, uint16_t seq,
                            bool int_form, uint8_t mission_type);
    // MISSION_ITEM_INT (item.int_form: x, y in 1e-7 degrees) or MISSION_ITEM (float degrees).
    uint8_t mission_item(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component,
                         const mission::Item& item);
    // MISSION_CURRENT: seq, total the commands stored (home not counted, as ArduPilot).
    uint8_t mission_current(uint8_t out[kMaxFrame], uint16_t seq, uint16_t total);
    uint8_t mission_item_reached(uint8_t out[kMaxFrame], uint16_t seq);
    // TIMESYNC: tc1 the board's clock in ns, ts1 the request's echoed (ArduPilot's answer).
    uint8_t timesync(uint8_t out[kMaxFrame], int64_t tc1_ns, int64_t ts1);
    // SYSTEM_TIME: UNIX time in us (0: unknown, no GPS time yet) and the board's clock.
    uint8_t system_time(uint8_t out[kMaxFrame], uint64_t time_unix_us, uint32_t time_boot_ms);
    // MESSAGE_INTERVAL: MAV_CMD_GET_MESSAGE_INTERVAL's answer (interval_us -1: not sent).
    uint8_t message_interval(uint8_t out[kMaxFrame], uint16_t message_id, int32_t interval_us);
    // AUTOPILOT_VERSION: kCapabilities, the version packed as ArduPilot does, the git hash.
    uint8_t autopilot_version(uint8_t out[kMaxFrame], const Version& v);
    uint8_t next_sequence() const { return seq_; }

private:
    uint8_t seq_ = 0;
};

// Where frames go (the firmware: its UART; tests: a buffer).
struct FrameSink {
    void* ctx;
    void (*write)(void* ctx, const uint8_t* frame, uint8_t len);
};

// The console's text output in `mode mavlink`: a text::Sink whose "# " lines become
// STATUSTEXT frames, "# " stripped; severity Error for "# error: ...", Warning for
// "# warn: ...", Critical for "# PreArm: ..." (ArduPilot's, which ground stations show
// as an alert), Info for every other "# " line. Lines that do not start with "# "
// (angle or csv lines) are dropped: ATTITUDE carries the angles. A line longer than
// kTextChunk goes out as chunks with one non-zero id, an empty last chunk when it ends
// on a chunk boundary (a receiver takes a chunk with a NUL as the last). Streaming: no
// line buffer beyond one chunk.
class StatusText {
public:
    constexpr StatusText(Packer& packer, FrameSink out) : packer_(packer), out_(out) {}  // no start-up code
    void write(const char* data, uint8_t len);
    // For text::Sink{&status_text, &StatusText::write_text}.
    static void write_text(void* ctx, const char* data, uint8_t len) {
        static_cast<StatusText*>(ctx)->write(data, len);
    }
    text::Sink sink() { return text::Sink{this, &StatusText::write_text}; }

private:
    enum class Line : uint8_t { Start, Hash, Body, Skip };
    void put(char c);
    void end_line();
    void flush_chunk();

    Packer& packer_;
    FrameSink out_;
    char chunk_[kTextChunk] = {};
    uint8_t len_ = 0;         // characters in chunk_
    uint8_t chunk_seq_ = 0;   // chunks of this line already sent
    uint16_t id_ = 0;         // this line's id when it needs more than one chunk
    uint16_t last_id_ = 0;    // the last id given out
    Severity severity_ = Severity::Info;
    Line state_ = Line::Start;
};

// The messages the board answers (msgid).
enum MsgId : uint8_t {
    kMsgHeartbeat = 0,
    kMsgSetMode = 11,
    kMsgRcChannelsOverride = 70,
    kMsgCommandInt = 75,
    kMsgParamRequestRead = 20,
    kMsgParamRequestList = 21,
    kMsgParamSet = 23,
    kMsgCommandLong = 76,
    kMsgCommandAck = 77,
    kMsgMissionItem = 39,
    kMsgMissionRequest = 40,
    kMsgMissionSetCurrent = 41,
    kMsgMissionRequestList = 43,
    kMsgMissionCount = 44,
    kMsgMissionClearAll = 45,
    kMsgMissionAck = 47,
    kMsgMissionRequestInt = 51,
    kMsgMissionItemInt = 73,
    kMsgTimesync = 111,
    kMsgRequestDataStream = 66,
};
// MISSION_ITEM(_INT)'s with mission_type, the longest kept whole; of RC_CHANNELS_OVERRIDE
// (38 too) the channels 9-18 are not needed.
constexpr uint8_t kRxPayloadMax = 38;

// A frame from the ground station, CRC-checked: its payload zero-filled to the message's
// full length (MAVLink 2 trims trailing zeros).
struct Received {
    uint8_t msgid;  // MsgId
    uint8_t sysid, compid;
    uint8_t payload[kRxPayloadMax];
};

// Splits received bytes into MAVLink frames (from a GCS: its HEARTBEAT, PARAM_REQUEST_LIST
// ...) and console text, and checks each frame of a message the board answers (CRC with
// the message's CRC_EXTRA, payload not longer than the message's). A frame starts with
// 0xFD (v2) or 0xFE (v1), bytes that never occur in console text (printable ASCII); its
// length byte gives the frame size, so a frame never reaches the console's line reader
// (where it would be "non-text bytes"). Signed frames are taken without checking the
// signature (the board does not sign).
class Parser {
public:
    // True when `byte` belongs to a MAVLink frame (in `mode mavlink`, not console input).
    bool consume(uint8_t byte);
    // A good frame of a message the board answers has ended: frame() holds it until
    // release(). Until then consume() must not be called (the caller stops reading).
    bool ready() const { return ready_; }
    const Received& frame() const { return rx_; }
    void release() { ready_ = false; }
    uint16_t frames() const { return frames_; }     // complete frames seen
    uint16_t bad_crc() const { return bad_crc_; }   // ... of a message the board answers, CRC wrong

private:
    void start(uint8_t stx);
    void finish();

    Received rx_ = {};
    uint16_t crc_ = 0;
    uint16_t remaining_ = 0;  // bytes of the current frame still to come
    uint16_t pos_ = 0;        // bytes of the current frame seen
    uint8_t len_ = 0;         // payload length (as sent)
    uint8_t crc_extra_ = 0;   // 0: a message the board does not answer (or too long): not kept
    uint8_t crc_lo_ = 0;
    bool v2_ = false;
    bool ready_ = false;
    bool crc_ok_ = false;
    uint16_t frames_ = 0;
    uint16_t bad_crc_ = 0;
};

// True when a request names this board (target system 0 = all, or kSystemId; target
// component 0 = all, or kComponentId).
bool for_us(uint8_t target_system, uint8_t target_component);

// The requests' fields (false: not for this board, or not that message).
struct ParamRequest {
    int16_t index;                // -1: by name
    char name[kParamIdLen + 1];   // NUL-terminated
};
bool decode_param_request_read(const Received& rx, ParamRequest& out);
bool decode_param_request_list(const Received& rx);
struct ParamSet {
    char name[kParamIdLen + 1];
    float value;
};
bool decode_param_set(const Received& rx, ParamSet& out);
struct CommandLong {
    uint16_t command;  // MAV_CMD
    float param[7];
};
bool decode_command_long(const Received& rx, CommandLong& out);
// A ground station's COMMAND_ACK (MAVProxy's accelcal answers a position with one whose
// command is the position's number); not addressed, so not checked.
bool decode_command_ack(const Received& rx, uint16_t& command, uint8_t& result);

// The mission protocols' requests: mission_type 0 mission, 1 fence, 2 rally (MAV_MISSION_TYPE).
bool decode_mission_request_list(const Received& rx, uint8_t& mission_type);
bool decode_mission_count(const Received& rx, uint16_t& count, uint8_t& mission_type);
bool decode_mission_clear_all(const Received& rx, uint8_t& mission_type);
// MISSION_ITEM_INT or MISSION_ITEM (its float degrees to 1e-7: mission::e7_from_degrees).
bool decode_mission_item(const Received& rx, mission::Item& out);
// MISSION_REQUEST_INT (int_form) or MISSION_REQUEST.
bool decode_mission_request(const Received& rx, uint16_t& seq, bool& int_form, uint8_t& mission_type);
// A ground station's MISSION_ACK (its type not needed: any ends a download or cancels an upload).
bool decode_mission_ack(const Received& rx, uint8_t& mission_type);
bool decode_mission_set_current(const Received& rx, uint16_t& seq);
// TIMESYNC: a request (tc1 0) to answer; false for a reply to someone else's request.
bool decode_timesync_request(const Received& rx, int64_t& ts1);
// COMMAND_INT as a CommandLong: param1-4, then x, y as param5, param6 (int32 as float,
// enough for the commands taken so), z as param7.
bool decode_command_int(const Received& rx, CommandLong& out);
// SET_MODE: custom_mode taken only with MAV_MODE_FLAG_CUSTOM_MODE_ENABLED in base_mode.
struct SetMode {
    uint8_t base_mode;
    uint32_t custom_mode;
};
bool decode_set_mode(const Received& rx, SetMode& out);
constexpr uint8_t kModeFlagCustomModeEnabled = 1;  // MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
// RC_CHANNELS_OVERRIDE: channels 1-8 as sent (UINT16_MAX ignore, 0 release; 9-18 not kept).
bool decode_rc_channels_override(const Received& rx, uint16_t width_us[8]);
// REQUEST_DATA_STREAM (deprecated by MAVLink, still what Mission Planner and MAVProxy send):
// a stream group (MAV_DATA_STREAM), its rate in Hz, start_stop 0 to stop it.
struct DataStreamRequest {
    uint8_t stream_id;
    uint16_t rate_hz;
    uint8_t start_stop;
};
bool decode_request_data_stream(const Received& rx, DataStreamRequest& out);

// The commands the board carries out (MAV_CMD).
constexpr uint16_t kCmdPreflightCalibration = 241;
constexpr uint16_t kCmdPreflightStorage = 245;
constexpr uint16_t kCmdDoSetHome = 179;          // param1 1: here; else param5 lat, param6 lon (deg), param7 alt (m MSL)
constexpr uint16_t kCmdGetHomePosition = 410;    // answered with HOME_POSITION (and the ACK)
constexpr uint16_t kCmdRequestMessage = 512;     // param1 the message id: 242 HOME_POSITION here
constexpr uint8_t kMsgHomePosition = 242;
// ArduPilot's compass calibrator (ardupilotmega.xml): param1 the compasses (0 all), START's
// param2 retry, param3 autosave, param4 delay (s), param5 reboot.
constexpr uint16_t kCmdDoStartMagCal = 42424;
constexpr uint16_t kCmdDoAcceptMagCal = 42425;
constexpr uint16_t kCmdDoCancelMagCal = 42426;
// ArduPilot's accelerometer calibration: the board asks for a position, the ground station
// answers with the same when the vehicle is there (param1: ACCELCAL_VEHICLE_POS 1..6,
// SUCCESS 16777215, FAILED 16777216).
constexpr uint16_t kCmdAccelcalVehiclePos = 42429;
constexpr float kAccelcalSuccess = 16777215.0f;
constexpr float kAccelcalFailed = 16777216.0f;
constexpr uint16_t kCmdRequestAutopilotCapabilities = 520;  // answered with AUTOPILOT_VERSION
constexpr uint16_t kCmdPreflightRebootShutdown = 246;       // param1 1: reboot (a watchdog reset)
constexpr uint8_t kMsgAutopilotVersion = 148;               // ... and REQUEST_MESSAGE 148
constexpr uint16_t kCmdComponentArmDisarm = 400;  // param1 1 arm, 0 disarm; param2 kForceMagic: without the checks
constexpr uint16_t kCmdDoSetMissionCurrent = 224;  // param1 the seq (MAVProxy's `wp set`), param2 1 reset: FAILED
constexpr uint16_t kCmdDoSetMode = 176;           // param1 base_mode (CUSTOM_MODE_ENABLED), param2 the custom mode
constexpr uint16_t kSetModeAck = 11;               // ArduPilot answers SET_MODE with a COMMAND_ACK of "command" 11
constexpr float kForceMagic = 21196.0f;     // MAVLink's: arm or disarm without the checks
constexpr float kForceArmMagic = 2989.0f;   // ArduPilot's own for arming

}  // namespace mav
