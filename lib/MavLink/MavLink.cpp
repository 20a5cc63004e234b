// SPDX-License-Identifier: GPL-3.0-or-later
#include "MavLink.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

// The generated headers (build/mavlink): one channel, no signing (the SHA-256 code and
// the per-channel tables stay out of the AVR image). The generated C is not the
// project's: its warnings (-Wconversion, -Wdouble-promotion, -Wcast-align) are not ours
// to fix, so they are silenced for these includes only.
#define MAVLINK_COMM_NUM_BUFFERS 1
#define MAVLINK_NO_SIGN_PACKET
#define MAVLINK_NO_SIGNATURE_CHECK
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpragmas"  // avr-gcc 5.4 does not know every name below
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wfloat-conversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wcast-align"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Waddress-of-packed-member"
#ifdef __AVR__
// MAVLink's CRC-16/MCRF4XX step (checksum.h) is avr-libc's _crc_ccitt_update: the same
// reflected polynomial 0x8408, whose C equivalent in util/crc16.h is MAVLink's line for
// line, in hand-written assembly. It runs for every byte received and sent: ~15 cycles
// against ~60 for the compiled one and its call.
#include <util/crc16.h>
#define HAVE_CRC_ACCUMULATE
static inline __attribute__((always_inline)) void crc_accumulate(uint8_t data, uint16_t* crc) { *crc = _crc_ccitt_update(*crc, data); }
#endif
// mavlink_types.h first: the Arduino IDE finds a library by a header at its top level,
// so with build/mavlink installed as a library (README) this include makes the IDE add
// it to the include path; common/mavlink.h, one folder down, then resolves.
#include "mavlink_types.h"
#include "common/mavlink.h"
#pragma GCC diagnostic pop

#include "MissionProtocol.h"

namespace mav {

static_assert(MAVLINK_NUM_NON_PAYLOAD_BYTES == kFrameOverhead, "MAVLink 2 frame overhead");
static_assert(kMaxFrame == kFrameOverhead + MAVLINK_MSG_ID_STATUSTEXT_LEN, "longest frame: STATUSTEXT");
static_assert(kHeartbeatFrame == kFrameOverhead + MAVLINK_MSG_ID_HEARTBEAT_LEN, "HEARTBEAT size");
static_assert(kAttitudeFrame == kFrameOverhead + MAVLINK_MSG_ID_ATTITUDE_LEN, "ATTITUDE size");
static_assert(kMaxFrame >= kFrameOverhead + MAVLINK_MSG_ID_SYS_STATUS_LEN, "SYS_STATUS fits");
static_assert(kTextChunk == MAVLINK_MSG_STATUSTEXT_FIELD_TEXT_LEN, "STATUSTEXT text length");
static_assert((uint8_t)State::Calibrating == MAV_STATE_CALIBRATING && (uint8_t)State::Active == MAV_STATE_ACTIVE &&
                  (uint8_t)State::Critical == MAV_STATE_CRITICAL && (uint8_t)State::Boot == MAV_STATE_BOOT,
              "State values are MAV_STATE's");
static_assert((uint8_t)Severity::Critical == MAV_SEVERITY_CRITICAL && (uint8_t)Severity::Error == MAV_SEVERITY_ERROR && (uint8_t)Severity::Warning == MAV_SEVERITY_WARNING &&
                  (uint8_t)Severity::Notice == MAV_SEVERITY_NOTICE && (uint8_t)Severity::Info == MAV_SEVERITY_INFO,
              "Severity values are MAV_SEVERITY's");
static_assert(kGyro3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_GYRO && kAccel3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_ACCEL &&
                  kMag3d == (uint32_t)MAV_SYS_STATUS_SENSOR_3D_MAG &&
                  kAbsolutePressure == (uint32_t)MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE,
              "SensorBits are MAV_SYS_STATUS_SENSOR's");
static_assert(kComponentId == (uint8_t)MAV_COMP_ID_AUTOPILOT1, "QGroundControl makes vehicles of AUTOPILOT1 only");
static_assert(kParamTypeInt8 == MAV_PARAM_TYPE_INT8 && kParamTypeInt16 == MAV_PARAM_TYPE_INT16 &&
                  kParamTypeReal32 == MAV_PARAM_TYPE_REAL32,
              "MAV_PARAM_TYPE values");
static_assert(kParamIdLen == MAVLINK_MSG_PARAM_VALUE_FIELD_PARAM_ID_LEN, "param_id length");
static_assert(kParamValueFrame == kFrameOverhead + MAVLINK_MSG_ID_PARAM_VALUE_LEN, "PARAM_VALUE size");
static_assert(kRcChannelsFrame == kFrameOverhead + MAVLINK_MSG_ID_RC_CHANNELS_LEN, "RC_CHANNELS size");
static_assert(kScaledPressureFrame == kFrameOverhead + MAVLINK_MSG_ID_SCALED_PRESSURE_LEN, "SCALED_PRESSURE size");
static_assert(kMaxFrame >= kRcChannelsFrame && kMaxFrame >= kFrameOverhead + MAVLINK_MSG_ID_SERVO_OUTPUT_RAW_LEN &&
                  kMaxFrame >= kFrameOverhead + MAVLINK_MSG_ID_COMMAND_ACK_LEN,
              "the replies and streams fit kMaxFrame");
static_assert(kRxPayloadMax >= MAVLINK_MSG_ID_COMMAND_LONG_LEN && kRxPayloadMax >= MAVLINK_MSG_ID_PARAM_SET_LEN &&
                  kRxPayloadMax >= MAVLINK_MSG_ID_PARAM_REQUEST_READ_LEN && kRxPayloadMax >= MAVLINK_MSG_ID_HEARTBEAT_LEN,
              "the received payloads fit");
static_assert(kMsgHeartbeat == MAVLINK_MSG_ID_HEARTBEAT && kMsgParamRequestRead == MAVLINK_MSG_ID_PARAM_REQUEST_READ &&
                  kMsgParamRequestList == MAVLINK_MSG_ID_PARAM_REQUEST_LIST && kMsgParamSet == MAVLINK_MSG_ID_PARAM_SET &&
                  kMsgCommandLong == MAVLINK_MSG_ID_COMMAND_LONG,
              "MsgId values are the message ids");
static_assert(kCmdPreflightCalibration == MAV_CMD_PREFLIGHT_CALIBRATION && kCmdPreflightStorage == MAV_CMD_PREFLIGHT_STORAGE &&
                  kCmdComponentArmDisarm == MAV_CMD_COMPONENT_ARM_DISARM && kCmdDoSetMode == MAV_CMD_DO_SET_MODE,
              "MAV_CMD values");
static_assert(kMsgSetMode == MAVLINK_MSG_ID_SET_MODE && kMsgCommandInt == MAVLINK_MSG_ID_COMMAND_INT &&
                  kMsgRcChannelsOverride == MAVLINK_MSG_ID_RC_CHANNELS_OVERRIDE &&
                  kModeFlagCustomModeEnabled == MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
              "the mode and override messages' values");
// The fields kept: COMMAND_INT's up to its target_component (offset 31), the override's
// eight channels and targets (18 bytes), SET_MODE whole (6).
static_assert(MAVLINK_MSG_ID_SET_MODE_LEN <= kRxPayloadMax && 18 <= kRxPayloadMax && 32 <= kRxPayloadMax,
              "the fields read fit the received payload");
static_assert(kGps == (uint32_t)MAV_SYS_STATUS_SENSOR_GPS, "MAV_SYS_STATUS_SENSOR_GPS");
static_assert(kBattery == (uint32_t)MAV_SYS_STATUS_SENSOR_BATTERY, "MAV_SYS_STATUS_SENSOR_BATTERY");
// BATTERY_STATUS: its payload up to charge_state (41 bytes) fits; the extensions after it
// are sent 0 and trimmed (MAVLink 2 drops trailing zero bytes).
static_assert(kBatteryStatusFrame == kFrameOverhead + 41 && kMaxFrame >= kFrameOverhead + MAVLINK_MSG_ID_BATTERY_STATUS_LEN,
              "BATTERY_STATUS fits kMaxFrame");
static_assert(kDifferentialPressure == (uint32_t)MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE &&
                  kAngularRateControl == (uint32_t)MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL &&
                  kAttitudeStabilization == (uint32_t)MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION &&
                  kYawPosition == (uint32_t)MAV_SYS_STATUS_SENSOR_YAW_POSITION &&
                  kMotorOutputs == (uint32_t)MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS &&
                  kRcReceiver == (uint32_t)MAV_SYS_STATUS_SENSOR_RC_RECEIVER &&
                  kGeofence == (uint32_t)MAV_SYS_STATUS_GEOFENCE && kAhrs == (uint32_t)MAV_SYS_STATUS_AHRS,
              "the plane's SYS_STATUS bits are MAV_SYS_STATUS_SENSOR's");
static_assert(kCmdDoSetHome == MAV_CMD_DO_SET_HOME && kCmdGetHomePosition == MAV_CMD_GET_HOME_POSITION &&
                  kCmdRequestMessage == MAV_CMD_REQUEST_MESSAGE && kMsgHomePosition == MAVLINK_MSG_ID_HOME_POSITION,
              "the position commands' values");
static_assert(kMsgMissionRequestList == MAVLINK_MSG_ID_MISSION_REQUEST_LIST &&
                  kMsgMissionCount == MAVLINK_MSG_ID_MISSION_COUNT &&
                  kMsgMissionClearAll == MAVLINK_MSG_ID_MISSION_CLEAR_ALL && kMsgTimesync == MAVLINK_MSG_ID_TIMESYNC &&
                  kMsgAutopilotVersion == MAVLINK_MSG_ID_AUTOPILOT_VERSION &&
                  kCmdRequestAutopilotCapabilities == MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES &&
                  kCmdPreflightRebootShutdown == MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN,
              "the conversation's message and command ids");
static_assert(kCapabilities == (MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT | MAV_PROTOCOL_CAPABILITY_MISSION_INT |
                                MAV_PROTOCOL_CAPABILITY_MAVLINK2) &&
                  kVersionTypeOfficial == FIRMWARE_VERSION_TYPE_OFFICIAL &&
                  (uint8_t)MissionResult::Unsupported == MAV_MISSION_UNSUPPORTED &&
                  (uint8_t)MissionResult::Accepted == MAV_MISSION_ACCEPTED,
              "capabilities, version type and mission results are MAVLink's");
static_assert(kRxPayloadMax >= MAVLINK_MSG_ID_MISSION_COUNT_LEN && kRxPayloadMax >= MAVLINK_MSG_ID_TIMESYNC_LEN &&
                  kRxPayloadMax >= MAVLINK_MSG_ID_MISSION_REQUEST_LIST_LEN,
              "the conversation's received payloads fit");
// The mission protocol: MISSION_ITEM(_INT) whole with mission_type, the longest received.
static_assert(kMsgMissionItem == MAVLINK_MSG_ID_MISSION_ITEM && kMsgMissionRequest == MAVLINK_MSG_ID_MISSION_REQUEST &&
                  kMsgMissionSetCurrent == MAVLINK_MSG_ID_MISSION_SET_CURRENT &&
                  kMsgMissionAck == MAVLINK_MSG_ID_MISSION_ACK && kMsgMissionRequestInt == MAVLINK_MSG_ID_MISSION_REQUEST_INT &&
                  kMsgMissionItemInt == MAVLINK_MSG_ID_MISSION_ITEM_INT,
              "the mission protocol's message ids");
static_assert(kRxPayloadMax == MAVLINK_MSG_ID_MISSION_ITEM_INT_LEN && kRxPayloadMax == MAVLINK_MSG_ID_MISSION_ITEM_LEN &&
                  kFrameOverhead + MAVLINK_MSG_ID_MISSION_ITEM_LEN <= kMaxFrame,
              "MISSION_ITEM(_INT) received whole and sent within kMaxFrame");
static_assert((uint8_t)mission::Result::kUnsupported == MAV_MISSION_UNSUPPORTED &&
                  (uint8_t)mission::Result::kNoSpace == MAV_MISSION_NO_SPACE &&
                  (uint8_t)mission::Result::kInvalidSequence == MAV_MISSION_INVALID_SEQUENCE &&
                  (uint8_t)mission::Result::kOperationCancelled == MAV_MISSION_OPERATION_CANCELLED &&
                  (uint8_t)mission::Result::kUnsupportedFrame == MAV_MISSION_UNSUPPORTED_FRAME &&
                  (uint8_t)mission::Result::kInvalidParam5 == MAV_MISSION_INVALID_PARAM5_X &&
                  (uint8_t)mission::Result::kInvalidParam6 == MAV_MISSION_INVALID_PARAM6_Y &&
                  (uint8_t)mission::kFrameGlobalRelativeAltInt == (uint8_t)MAV_FRAME_GLOBAL_RELATIVE_ALT_INT &&
                  (uint8_t)mission::kFrameMission == (uint8_t)MAV_FRAME_MISSION,
              "mission::Result is MAV_MISSION_RESULT, the frames MAV_FRAME");
static_assert(kFrameOverhead + MAVLINK_MSG_ID_TIMESYNC_LEN <= kMaxFrame &&
                  kFrameOverhead + MAVLINK_MSG_ID_SYSTEM_TIME_LEN <= kMaxFrame,
              "TIMESYNC and SYSTEM_TIME fit kMaxFrame");
// Whole frames fit kMaxFrame: GPS_RAW_INT with its extensions (64), GLOBAL_POSITION_INT
// (40), VFR_HUD (32); HOME_POSITION without its time_usec extension, which is sent 0
// and so trimmed (MAVLink 2 drops trailing zero bytes).
static_assert(kFrameOverhead + MAVLINK_MSG_ID_GPS_RAW_INT_LEN <= kMaxFrame &&
                  kFrameOverhead + MAVLINK_MSG_ID_GLOBAL_POSITION_INT_LEN <= kMaxFrame &&
                  kFrameOverhead + MAVLINK_MSG_ID_VFR_HUD_LEN <= kMaxFrame &&
                  kFrameOverhead + MAVLINK_MSG_ID_HOME_POSITION_MIN_LEN <= kMaxFrame,
              "the position messages fit kMaxFrame");
static_assert((uint8_t)gps::FixType::kNoGps == GPS_FIX_TYPE_NO_GPS && (uint8_t)gps::FixType::kNoFix ==
                  GPS_FIX_TYPE_NO_FIX && (uint8_t)gps::FixType::k2D == GPS_FIX_TYPE_2D_FIX &&
                  (uint8_t)gps::FixType::k3D == GPS_FIX_TYPE_3D_FIX,
              "FixType values are GPS_FIX_TYPE's");
static_assert((uint8_t)MagCalStatus::NotStarted == MAG_CAL_NOT_STARTED &&
                  (uint8_t)MagCalStatus::RunningStepOne == MAG_CAL_RUNNING_STEP_ONE &&
                  (uint8_t)MagCalStatus::RunningStepTwo == MAG_CAL_RUNNING_STEP_TWO &&
                  (uint8_t)MagCalStatus::Success == MAG_CAL_SUCCESS && (uint8_t)MagCalStatus::Failed == MAG_CAL_FAILED,
              "MagCalStatus values are MAG_CAL_STATUS's");
static_assert(kFrameOverhead + MAVLINK_MSG_ID_MAG_CAL_REPORT_LEN <= kMaxFrame, "MAG_CAL_REPORT fits kMaxFrame");
static_assert((uint8_t)Result::Accepted == MAV_RESULT_ACCEPTED && (uint8_t)Result::TemporarilyRejected ==
                  MAV_RESULT_TEMPORARILY_REJECTED && (uint8_t)Result::Denied == MAV_RESULT_DENIED &&
                  (uint8_t)Result::Unsupported == MAV_RESULT_UNSUPPORTED && (uint8_t)Result::Failed == MAV_RESULT_FAILED,
              "Result values are MAV_RESULT's");

namespace {

// The generated pack functions write a mavlink_message_t (291 bytes, on the stack only
// for the call) and count the sequence in a mavlink_status_t; the Packer keeps just
// the sequence byte between calls.
struct Frame {
    mavlink_message_t msg;
    mavlink_status_t status;
    explicit Frame(uint8_t seq) {
        memset(&status, 0, sizeof status);
        status.current_tx_seq = seq;
    }
    uint8_t finish(uint8_t out[kMaxFrame], uint8_t& seq) {
        seq = status.current_tx_seq;
        return (uint8_t)mavlink_msg_to_send_buffer(out, &msg);
    }
};

// Degrees to radians; a heading 0..360 becomes -pi..pi (ATTITUDE's yaw range).
float yaw_rad(float heading_deg) {
    const float h = heading_deg > 180.0f ? heading_deg - 360.0f : heading_deg;
    return h * linalg::kRadPerDeg;
}

}  // namespace

Health health(bool mpu_present, bool mpu_ok, bool mag_present, bool mag_ok) {
    Health h{0u, 0u, 0u};
    add_sensor(h, kGyro3d | kAccel3d, mpu_present, mpu_ok);
    add_sensor(h, kMag3d, mag_present, mag_ok);
    return h;
}

void add_sensor(Health& h, uint32_t bits, bool present, bool ok) {
    if (!present) return;
    h.present |= bits;
    h.enabled |= bits;
    if (ok) h.healthy |= bits;
}

void add_plane_status(Health& h, const PlaneStatus& p) {
    add_sensor(h, kAhrs, true, p.ahrs_ok);
    h.healthy |= kGeofence;
    if (!p.flight) return;
    const uint32_t control = kAngularRateControl | kAttitudeStabilization;
    h.present |= control | kYawPosition;
    h.healthy |= control | kYawPosition;
    if (p.stabilizing) h.enabled |= control;
    add_sensor(h, kMotorOutputs, true, true);
    add_sensor(h, kRcReceiver, true, p.receiver_ok);
}

uint8_t Packer::heartbeat(uint8_t out[kMaxFrame], State state, PlaneMode mode, bool armed) {
    Frame f(seq_);
    uint8_t base = MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | MAV_MODE_FLAG_MANUAL_INPUT_ENABLED;
    if (armed) base |= MAV_MODE_FLAG_SAFETY_ARMED;
    if (mode != PlaneMode::Manual) base |= MAV_MODE_FLAG_STABILIZE_ENABLED;
    mavlink_msg_heartbeat_pack_status(kSystemId, kComponentId, &f.status, &f.msg, MAV_TYPE_FIXED_WING,
                                      MAV_AUTOPILOT_ARDUPILOTMEGA, base, (uint32_t)mode, (uint8_t)state);
    return f.finish(out, seq_);
}

uint8_t Packer::attitude(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float roll_deg, float pitch_deg,
                         float heading_deg, const linalg::Vector3f& rate_rad_s) {
    Frame f(seq_);
    mavlink_msg_attitude_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_boot_ms,
                                     roll_deg * linalg::kRadPerDeg, pitch_deg * linalg::kRadPerDeg,
                                     yaw_rad(heading_deg), rate_rad_s.x, rate_rad_s.y, rate_rad_s.z);
    return f.finish(out, seq_);
}

uint8_t Packer::sys_status(uint8_t out[kMaxFrame], const Health& h, uint16_t load_permille, uint16_t errors,
                           const BatteryReport* battery) {
    Frame f(seq_);
    const uint16_t load = load_permille > 1000u ? 1000u : load_permille;
    // Without a battery report: voltage UINT16_MAX, current -1, remaining -1 = "not measured".
    const uint16_t mv = battery ? battery->voltage_mv : UINT16_MAX;
    const int16_t ca = battery ? battery->current_ca : (int16_t)-1;
    const int8_t pct = battery ? battery->remaining_pct : (int8_t)-1;
    mavlink_msg_sys_status_pack_status(kSystemId, kComponentId, &f.status, &f.msg, h.present, h.enabled,
                                       h.healthy, load, mv, ca, pct, 0u, 0u, errors, 0u, 0u, 0u, 0u,
                                       0u, 0u);
    return f.finish(out, seq_);
}

namespace {
// A reading rounded to the nearest unit and held within lo..hi (NaN: `unknown`).
int32_t rounded(float v, int32_t lo, int32_t hi, int32_t unknown) {
    if (v != v) return unknown;
    if (v <= (float)lo) return lo;
    if (v >= (float)hi) return hi;
    return (int32_t)(v >= 0.0f ? v + 0.5f : v - 0.5f);
}
}  // namespace

BatteryReport battery_report(const battery::Monitor& m, const battery::Settings& s) {
    BatteryReport r{UINT16_MAX, -1, -1, -1, false};
    if (!battery::Monitor::enabled(s)) return r;
    // UINT16_MAX is "unknown": a reading held at one less.
    r.voltage_mv = (uint16_t)rounded(m.voltage_v() * 1000.0f, 0, UINT16_MAX - 1, 0);
    if (battery::Monitor::has_current(s)) {
        r.current_ca = (int16_t)rounded(m.current_a() * 100.0f, -32767, 32767, -1);
        r.consumed_mah = rounded(m.consumed_mah(), -1000000, 1000000, -1);
        r.remaining_pct = m.remaining_pct(s);
    }
    r.failsafe = m.failsafe() != battery::Failsafe::kNone;
    return r;
}

uint8_t Packer::battery_status(uint8_t out[kMaxFrame], const BatteryReport& b) {
    Frame f(seq_);
    uint16_t cells[MAVLINK_MSG_BATTERY_STATUS_FIELD_VOLTAGES_LEN];
    for (uint16_t& c : cells) c = UINT16_MAX;
    cells[0] = b.voltage_mv;
    const uint16_t ext[MAVLINK_MSG_BATTERY_STATUS_FIELD_VOLTAGES_EXT_LEN] = {0u, 0u, 0u, 0u};
    const uint8_t charge = b.failsafe ? MAV_BATTERY_CHARGE_STATE_LOW : MAV_BATTERY_CHARGE_STATE_OK;
    mavlink_msg_battery_status_pack_status(kSystemId, kComponentId, &f.status, &f.msg, 0u,
                                           MAV_BATTERY_FUNCTION_UNKNOWN, MAV_BATTERY_TYPE_UNKNOWN, INT16_MAX, cells,
                                           b.current_ca, b.consumed_mah, -1, b.remaining_pct, 0, charge, ext, 0u,
                                           0u);
    return f.finish(out, seq_);
}

uint8_t Packer::statustext(uint8_t out[kMaxFrame], Severity severity, const char* text, uint8_t len,
                           uint16_t id, uint8_t chunk_seq) {
    if (len > kTextChunk) return 0;
    char field[kTextChunk];  // the generated code copies all 50: pad with NUL
    memset(field, 0, sizeof field);
    memcpy(field, text, len);
    Frame f(seq_);
    mavlink_msg_statustext_pack_status(kSystemId, kComponentId, &f.status, &f.msg, (uint8_t)severity, field, id,
                                       chunk_seq);
    return f.finish(out, seq_);
}

uint8_t Packer::param_value(uint8_t out[kMaxFrame], const char* name, float value, uint8_t type, uint16_t count,
                            uint16_t index) {
    char id[kParamIdLen];  // the generated code copies all 16: NUL after a shorter name
    uint8_t i = 0;
    for (; i < kParamIdLen && name[i] != '\0'; ++i) id[i] = name[i];
    for (; i < kParamIdLen; ++i) id[i] = '\0';
    Frame f(seq_);
    mavlink_msg_param_value_pack_status(kSystemId, kComponentId, &f.status, &f.msg, id, value, type, count, index);
    return f.finish(out, seq_);
}

uint8_t Packer::command_ack(uint8_t out[kMaxFrame], uint16_t command, Result result, uint8_t target_system,
                            uint8_t target_component) {
    Frame f(seq_);
    mavlink_msg_command_ack_pack_status(kSystemId, kComponentId, &f.status, &f.msg, command, (uint8_t)result, 0u, 0,
                                        target_system, target_component);
    return f.finish(out, seq_);
}

// ardupilotmega.xml's MAG_CAL_PROGRESS, not in the common.xml the headers are made from:
// packed here in its wire order (the floats first, then the bytes, as mavgen orders
// fields by size) and finished by the generated helpers with its CRC_EXTRA.
constexpr uint32_t kMsgMagCalProgress = 191;
constexpr uint8_t kMagCalProgressLen = kMagCalProgressFrame - kFrameOverhead;
constexpr uint8_t kMagCalProgressCrcExtra = 92;

uint8_t Packer::mag_cal_progress(uint8_t out[kMaxFrame], MagCalStatus status, uint8_t attempt,
                                 uint8_t completion_pct, uint32_t completion_bits, const linalg::Vector3f& direction) {
    Frame f(seq_);
    char* p = _MAV_PAYLOAD_NON_CONST(&f.msg);
    memset(p, 0, kMagCalProgressLen);
    _mav_put_float(p, 0, direction.x);
    _mav_put_float(p, 4, direction.y);
    _mav_put_float(p, 8, direction.z);
    _mav_put_uint8_t(p, 12, 0);  // compass_id
    _mav_put_uint8_t(p, 13, 1);  // cal_mask
    _mav_put_uint8_t(p, 14, (uint8_t)status);
    _mav_put_uint8_t(p, 15, attempt);
    _mav_put_uint8_t(p, 16, completion_pct);
    for (uint8_t i = 0; i < 4; ++i) _mav_put_uint8_t(p, 17 + i, (uint8_t)(completion_bits >> (8u * i)));
    f.msg.msgid = kMsgMagCalProgress;
    mavlink_finalize_message_buffer(&f.msg, kSystemId, kComponentId, &f.status, kMagCalProgressLen,
                                    kMagCalProgressLen, kMagCalProgressCrcExtra);
    return f.finish(out, seq_);
}

uint8_t Packer::mag_cal_report(uint8_t out[kMaxFrame], const MagCalReport& r) {
    Frame f(seq_);
    mavlink_msg_mag_cal_report_pack_status(kSystemId, kComponentId, &f.status, &f.msg, 0u, 1u, (uint8_t)r.status,
                                           r.autosaved ? 1u : 0u, r.fitness_mgauss, r.ofs_mgauss.x, r.ofs_mgauss.y,
                                           r.ofs_mgauss.z, r.diag.x, r.diag.y, r.diag.z, r.offdiag.x, r.offdiag.y,
                                           r.offdiag.z, 0.0f, 0u, 0u, 0.0f);
    return f.finish(out, seq_);
}

uint8_t Packer::rc_channels(uint8_t out[kMaxFrame], uint32_t time_boot_ms, const uint16_t w[8], uint8_t count) {
    Frame f(seq_);
    const uint16_t none = UINT16_MAX;
    mavlink_msg_rc_channels_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_boot_ms, count, w[0], w[1],
                                        w[2], w[3], w[4], w[5], w[6], w[7], none, none, none, none, none, none, none,
                                        none, none, none, UINT8_MAX);
    return f.finish(out, seq_);
}

uint8_t Packer::servo_output_raw(uint8_t out[kMaxFrame], uint32_t time_boot_us, const uint16_t w[8]) {
    Frame f(seq_);
    mavlink_msg_servo_output_raw_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_boot_us, 0u, w[0],
                                             w[1], w[2], w[3], w[4], w[5], w[6], w[7], 0u, 0u, 0u, 0u, 0u, 0u, 0u,
                                             0u);
    return f.finish(out, seq_);
}

namespace {
// A float m/s as MAVLink's int16 cm/s, held within its range.
int16_t cm_s(float m_s) {
    const float cm = m_s * 100.0f;
    if (!(cm > -32767.0f)) return cm != cm ? 0 : -32767;
    if (cm > 32767.0f) return 32767;
    return (int16_t)cm;
}
// A heading in degrees as centi-degrees 0..35999, UINT16_MAX when unknown (< 0 or NaN).
uint16_t heading_cd(float deg) {
    if (!(deg >= 0.0f) || !(deg < 360.0f)) return UINT16_MAX;
    const uint16_t cd = (uint16_t)(deg * 100.0f + 0.5f);
    return cd >= 36000u ? 0u : cd;
}
}  // namespace

uint8_t Packer::gps_raw_int(uint8_t out[kMaxFrame], const gps::Fix& fix) {
    Frame f(seq_);
    const bool moving = fix.fix >= gps::FixType::k2D;
    const uint32_t speed = fix.ground_speed_cm_s < UINT16_MAX ? fix.ground_speed_cm_s : UINT16_MAX - 1u;
    const uint16_t vel = moving ? (uint16_t)speed : UINT16_MAX;
    const uint16_t cog = moving ? (uint16_t)((uint32_t)fix.course_e5 / 1000u % 36000u) : UINT16_MAX;
    const uint8_t sats = fix.fix == gps::FixType::kNoGps ? UINT8_MAX : fix.sats;
    mavlink_msg_gps_raw_int_pack_status(kSystemId, kComponentId, &f.status, &f.msg, (uint64_t)fix.received_ms * 1000u,
                                        (uint8_t)fix.fix, fix.lat_e7, fix.lon_e7, fix.alt_msl_mm, fix.hdop_cm,
                                        UINT16_MAX, vel, cog, sats, 0, fix.h_acc_mm, 0u,
                                        fix.speed_acc_cm_s * 10u, 0u, 0u);
    return f.finish(out, seq_);
}

uint8_t Packer::global_position_int(uint8_t out[kMaxFrame], const PositionReport& p) {
    Frame f(seq_);
    mavlink_msg_global_position_int_pack_status(kSystemId, kComponentId, &f.status, &f.msg, p.time_boot_ms, p.lat_e7,
                                                p.lon_e7, p.alt_msl_mm, p.relative_alt_mm, cm_s(p.vel_ned_m_s[0]),
                                                cm_s(p.vel_ned_m_s[1]), cm_s(p.vel_ned_m_s[2]),
                                                heading_cd(p.heading_deg));
    return f.finish(out, seq_);
}

uint8_t Packer::vfr_hud(uint8_t out[kMaxFrame], const PositionReport& p) {
    Frame f(seq_);
    const float* v = p.vel_ned_m_s;
    const float ground_m_s = sqrtf(v[0] * v[0] + v[1] * v[1]);
    const uint16_t hdg = heading_cd(p.heading_deg);
    const int16_t heading_deg = hdg == UINT16_MAX ? 0 : (int16_t)((hdg + 50u) / 100u % 360u);
    mavlink_msg_vfr_hud_pack_status(kSystemId, kComponentId, &f.status, &f.msg, p.airspeed_m_s, ground_m_s,
                                    heading_deg, p.throttle_pct, (float)p.alt_msl_mm * 0.001f, p.climb_m_s);
    return f.finish(out, seq_);
}

uint8_t Packer::nav_controller_output(uint8_t out[kMaxFrame], const NavOutput& n) {
    Frame f(seq_);
    mavlink_msg_nav_controller_output_pack_status(kSystemId, kComponentId, &f.status, &f.msg, n.nav_roll_deg,
                                                  n.nav_pitch_deg, n.nav_bearing_deg, n.target_bearing_deg,
                                                  n.wp_dist_m, n.alt_error_m, 0.0f, n.xtrack_error_m);
    return f.finish(out, seq_);
}

uint8_t Packer::home_position(uint8_t out[kMaxFrame], int32_t lat_e7, int32_t lon_e7, int32_t alt_msl_mm) {
    Frame f(seq_);
    const float q[4] = {1.0f, 0.0f, 0.0f, 0.0f};
    mavlink_msg_home_position_pack_status(kSystemId, kComponentId, &f.status, &f.msg, lat_e7, lon_e7, alt_msl_mm,
                                          0.0f, 0.0f, 0.0f, q, 0.0f, 0.0f, 0.0f, 0u);
    if (kFrameOverhead + f.msg.len > kMaxFrame) return 0;  // never: the trimmed payload ends at q[0]
    return f.finish(out, seq_);
}

// ---------------------------------------------------------------------------------------

void StatusText::write(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) put(data[i]);
}

void StatusText::put(char c) {
    if (c == '\r') return;
    if (c == '\n') {
        end_line();
        return;
    }
    switch (state_) {
        case Line::Start: state_ = c == '#' ? Line::Hash : Line::Skip; return;
        case Line::Hash: state_ = c == ' ' ? Line::Body : Line::Skip; return;
        case Line::Skip: return;
        case Line::Body: break;
    }
    if (len_ == kTextChunk) {
        // A 51st character: this line takes more than one chunk.
        if (chunk_seq_ == 0) {
            if (++last_id_ == 0u) last_id_ = 1u;  // 0 means "a single chunk"
            id_ = last_id_;
        }
        flush_chunk();
    }
    chunk_[len_++] = c;
}

void StatusText::end_line() {
    if (state_ == Line::Body) {
        // A multi-chunk line that ends on a chunk boundary gets an empty last chunk.
        const bool terminator = chunk_seq_ > 0 && len_ == kTextChunk;
        flush_chunk();
        if (terminator) flush_chunk();
    }
    state_ = Line::Start;
    len_ = 0;
    chunk_seq_ = 0;
    id_ = 0;
}

namespace {
// True if the len bytes at s begin with the TXT string prefix (flash on the AVR: not
// SRAM).
bool starts_with(const char* s, uint8_t len, text::Flash prefix) {
    for (uint8_t i = 0;; ++i) {
        const char ch = (char)text::flash_byte(prefix.p + i);
        if (ch == '\0') return true;
        if (i >= len || s[i] != ch) return false;
    }
}
}  // namespace

void StatusText::flush_chunk() {
    if (chunk_seq_ == 0) {
        // The first word gives the severity ("# error: ..." and "# warn: ..." lines).
        severity_ = Severity::Info;
        if (starts_with(chunk_, len_, TXT("error:"))) severity_ = Severity::Error;
        else if (starts_with(chunk_, len_, TXT("warn:"))) severity_ = Severity::Warning;
        else if (starts_with(chunk_, len_, TXT("PreArm:"))) severity_ = Severity::Critical;
    }
    uint8_t frame[kMaxFrame];
    const uint8_t n = packer_.statustext(frame, severity_, chunk_, len_, id_, chunk_seq_);
    if (out_.write != nullptr && n > 0) out_.write(out_.ctx, frame, n);
    ++chunk_seq_;
    len_ = 0;
}

// ---------------------------------------------------------------------------------------

namespace {

// The CRC_EXTRA of a message the board answers, and its payload length; 0 for the others.
uint8_t crc_extra_of(uint32_t msgid, uint8_t& max_len) {
    switch (msgid) {
        case MAVLINK_MSG_ID_HEARTBEAT: max_len = MAVLINK_MSG_ID_HEARTBEAT_LEN; return MAVLINK_MSG_ID_HEARTBEAT_CRC;
        case MAVLINK_MSG_ID_PARAM_REQUEST_READ:
            max_len = MAVLINK_MSG_ID_PARAM_REQUEST_READ_LEN;
            return MAVLINK_MSG_ID_PARAM_REQUEST_READ_CRC;
        case MAVLINK_MSG_ID_PARAM_REQUEST_LIST:
            max_len = MAVLINK_MSG_ID_PARAM_REQUEST_LIST_LEN;
            return MAVLINK_MSG_ID_PARAM_REQUEST_LIST_CRC;
        case MAVLINK_MSG_ID_PARAM_SET: max_len = MAVLINK_MSG_ID_PARAM_SET_LEN; return MAVLINK_MSG_ID_PARAM_SET_CRC;
        case MAVLINK_MSG_ID_COMMAND_LONG:
            max_len = MAVLINK_MSG_ID_COMMAND_LONG_LEN;
            return MAVLINK_MSG_ID_COMMAND_LONG_CRC;
        case MAVLINK_MSG_ID_COMMAND_ACK:  // MAVProxy's accelcal confirms a position with one
            max_len = MAVLINK_MSG_ID_COMMAND_ACK_LEN;
            return MAVLINK_MSG_ID_COMMAND_ACK_CRC;
        case MAVLINK_MSG_ID_MISSION_REQUEST_LIST:
            max_len = MAVLINK_MSG_ID_MISSION_REQUEST_LIST_LEN;
            return MAVLINK_MSG_ID_MISSION_REQUEST_LIST_CRC;
        case MAVLINK_MSG_ID_MISSION_COUNT:
            max_len = MAVLINK_MSG_ID_MISSION_COUNT_LEN;
            return MAVLINK_MSG_ID_MISSION_COUNT_CRC;
        case MAVLINK_MSG_ID_MISSION_CLEAR_ALL:
            max_len = MAVLINK_MSG_ID_MISSION_CLEAR_ALL_LEN;
            return MAVLINK_MSG_ID_MISSION_CLEAR_ALL_CRC;
        case MAVLINK_MSG_ID_MISSION_ITEM: max_len = MAVLINK_MSG_ID_MISSION_ITEM_LEN; return MAVLINK_MSG_ID_MISSION_ITEM_CRC;
        case MAVLINK_MSG_ID_MISSION_ITEM_INT:
            max_len = MAVLINK_MSG_ID_MISSION_ITEM_INT_LEN;
            return MAVLINK_MSG_ID_MISSION_ITEM_INT_CRC;
        case MAVLINK_MSG_ID_MISSION_REQUEST:
            max_len = MAVLINK_MSG_ID_MISSION_REQUEST_LEN;
            return MAVLINK_MSG_ID_MISSION_REQUEST_CRC;
        case MAVLINK_MSG_ID_MISSION_REQUEST_INT:
            max_len = MAVLINK_MSG_ID_MISSION_REQUEST_INT_LEN;
            return MAVLINK_MSG_ID_MISSION_REQUEST_INT_CRC;
        case MAVLINK_MSG_ID_MISSION_ACK: max_len = MAVLINK_MSG_ID_MISSION_ACK_LEN; return MAVLINK_MSG_ID_MISSION_ACK_CRC;
        case MAVLINK_MSG_ID_MISSION_SET_CURRENT:
            max_len = MAVLINK_MSG_ID_MISSION_SET_CURRENT_LEN;
            return MAVLINK_MSG_ID_MISSION_SET_CURRENT_CRC;
        case MAVLINK_MSG_ID_TIMESYNC: max_len = MAVLINK_MSG_ID_TIMESYNC_LEN; return MAVLINK_MSG_ID_TIMESYNC_CRC;
        case MAVLINK_MSG_ID_COMMAND_INT:
            max_len = MAVLINK_MSG_ID_COMMAND_INT_LEN;
            return MAVLINK_MSG_ID_COMMAND_INT_CRC;
        case MAVLINK_MSG_ID_SET_MODE: max_len = MAVLINK_MSG_ID_SET_MODE_LEN; return MAVLINK_MSG_ID_SET_MODE_CRC;
        case MAVLINK_MSG_ID_RC_CHANNELS_OVERRIDE:
            max_len = MAVLINK_MSG_ID_RC_CHANNELS_OVERRIDE_LEN;
            return MAVLINK_MSG_ID_RC_CHANNELS_OVERRIDE_CRC;
        case MAVLINK_MSG_ID_REQUEST_DATA_STREAM:
            max_len = MAVLINK_MSG_ID_REQUEST_DATA_STREAM_LEN;
            return MAVLINK_MSG_ID_REQUEST_DATA_STREAM_CRC;
        default: return 0;
    }
}

}  // namespace

void Parser::start(uint8_t stx) {
    v2_ = stx == MAVLINK_STX;
    pos_ = 1;
    crc_init(&crc_);
    crc_extra_ = 0;
    memset(&rx_, 0, sizeof rx_);
}

// Frame layout after STX (v2): len, incompat, compat, seq, sysid, compid, msgid (3
// bytes), payload, CRC (2), [signature 13]; (v1): len, seq, sysid, compid, msgid,
// payload, CRC (2). The CRC covers len .. the payload's end, then CRC_EXTRA.
bool Parser::consume(uint8_t byte) {
    if (pos_ == 0) {
        if (byte != MAVLINK_STX && byte != MAVLINK_STX_MAVLINK1) return false;
        start(byte);
        return true;
    }
    const uint8_t header = v2_ ? 10u : 6u;  // STX .. msgid
    if (pos_ == 1) {
        len_ = byte;
        remaining_ = (uint16_t)(header - 1u + byte + 2u);  // this byte to the CRC's last
    } else if (pos_ < header) {
        const uint8_t sysid_at = v2_ ? 5u : 3u;
        const uint8_t at = (uint8_t)(pos_ - sysid_at);  // 0 sysid, 1 compid, 2.. msgid
        if (v2_ && pos_ == 2 && (byte & MAVLINK_IFLAG_SIGNED) != 0u)
            remaining_ = (uint16_t)(remaining_ + MAVLINK_SIGNATURE_BLOCK_LEN);
        if (pos_ >= sysid_at) {
            if (at == 0) rx_.sysid = byte;
            else if (at == 1) rx_.compid = byte;
            else if (at == 2) {
                rx_.msgid = byte;
                uint8_t max_len = 0;
                crc_extra_ = crc_extra_of(byte, max_len);
                if (len_ > max_len) crc_extra_ = 0;
            } else if (byte != 0u) {
                crc_extra_ = 0;  // msgid above 255: not one of ours
            }
        }
    } else if (pos_ < header + len_) {
        const uint16_t i = (uint16_t)(pos_ - header);
        if (i < kRxPayloadMax) rx_.payload[i] = byte;
    } else if (pos_ == header + len_) {
        crc_lo_ = byte;
    } else if (pos_ == header + len_ + 1u) {
        crc_ok_ = crc_lo_ == (uint8_t)(crc_ & 0xFFu) && byte == (uint8_t)(crc_ >> 8);
    }
    if (pos_ < header + len_) crc_accumulate(byte, &crc_);
    if (pos_ + 1u == header + len_ && crc_extra_ != 0u) crc_accumulate(crc_extra_, &crc_);
    ++pos_;
    if (--remaining_ == 0u) finish();
    return true;
}

void Parser::finish() {
    pos_ = 0;
    ++frames_;
    if (crc_extra_ == 0u) return;  // not a message the board answers
    if (crc_ok_) ready_ = true;
    else ++bad_crc_;
}

bool for_us(uint8_t target_system, uint8_t target_component) {
    return (target_system == 0u || target_system == kSystemId) &&
           (target_component == 0u || target_component == kComponentId);
}

namespace {
void copy_id(char out[kParamIdLen + 1], const char* id) {
    memcpy(out, id, kParamIdLen);
    out[kParamIdLen] = '\0';
}
}  // namespace

// The generated structs are the payload's wire layout (little-endian, as the AVR and
// the hosts this builds on are; their fields naturally aligned): a copy of the
// zero-filled payload decodes it, as the generated mavlink_msg_*_decode does. The copy
// takes at most the payload's bytes: on x86-64 GCC ignores MAVPACKED on the typedef and
// pads COMMAND_LONG's 33 bytes to 36, and a copy of the whole struct would read past
// Received's end.
template <class Message>
void copy_payload(Message& m, const Received& rx) {
    memset(&m, 0, sizeof m);
    memcpy(&m, rx.payload, sizeof m < kRxPayloadMax ? sizeof m : kRxPayloadMax);
}

bool decode_param_request_read(const Received& rx, ParamRequest& out) {
    if (rx.msgid != kMsgParamRequestRead) return false;
    mavlink_param_request_read_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    out.index = m.param_index;
    copy_id(out.name, m.param_id);
    return true;
}

bool decode_param_request_list(const Received& rx) {
    if (rx.msgid != kMsgParamRequestList) return false;
    mavlink_param_request_list_t m;
    copy_payload(m, rx);
    return for_us(m.target_system, m.target_component);
}

bool decode_param_set(const Received& rx, ParamSet& out) {
    if (rx.msgid != kMsgParamSet) return false;
    mavlink_param_set_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    copy_id(out.name, m.param_id);
    out.value = m.param_value;
    return true;
}

bool decode_command_ack(const Received& rx, uint16_t& command, uint8_t& result) {
    if (rx.msgid != kMsgCommandAck) return false;
    mavlink_command_ack_t m;
    copy_payload(m, rx);
    command = m.command;
    result = m.result;
    return true;
}

uint8_t Packer::command_long(uint8_t out[kMaxFrame], uint16_t command, float param1) {
    Frame f(seq_);
    // To every ground station (target 0, 0): the board does not know which one asked.
    mavlink_msg_command_long_pack_status(kSystemId, kComponentId, &f.status, &f.msg, 0u, 0u, command, 0u, param1,
                                         0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
    return f.finish(out, seq_);
}

namespace {
// COMMAND_LONG's and COMMAND_INT's common fields; p5..p7 their last three (param5-7, or x, y, z).
template <class Message>
void take_command(CommandLong& out, const Message& m, float p5, float p6, float p7) {
    out.command = m.command;
    out.param[0] = m.param1;
    out.param[1] = m.param2;
    out.param[2] = m.param3;
    out.param[3] = m.param4;
    out.param[4] = p5;
    out.param[5] = p6;
    out.param[6] = p7;
}
}  // namespace

bool decode_command_long(const Received& rx, CommandLong& out) {
    if (rx.msgid != kMsgCommandLong) return false;
    mavlink_command_long_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    take_command(out, m, m.param5, m.param6, m.param7);
    return true;
}

bool decode_command_int(const Received& rx, CommandLong& out) {
    if (rx.msgid != kMsgCommandInt) return false;
    mavlink_command_int_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    take_command(out, m, (float)m.x, (float)m.y, m.z);
    return true;
}

bool decode_set_mode(const Received& rx, SetMode& out) {
    if (rx.msgid != kMsgSetMode) return false;
    mavlink_set_mode_t m;
    copy_payload(m, rx);
    if (m.target_system != kSystemId) return false;  // SET_MODE names a system only
    out.base_mode = m.base_mode;
    out.custom_mode = m.custom_mode;
    return true;
}

bool decode_rc_channels_override(const Received& rx, uint16_t width_us[8]) {
    if (rx.msgid != kMsgRcChannelsOverride) return false;
    mavlink_rc_channels_override_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    const uint16_t w[8] = {m.chan1_raw, m.chan2_raw, m.chan3_raw, m.chan4_raw,
                           m.chan5_raw, m.chan6_raw, m.chan7_raw, m.chan8_raw};
    memcpy(width_us, w, sizeof w);
    return true;
}

static_assert(kMsgRequestDataStream == MAVLINK_MSG_ID_REQUEST_DATA_STREAM &&
                  MAVLINK_MSG_ID_REQUEST_DATA_STREAM_LEN <= kRxPayloadMax,
              "REQUEST_DATA_STREAM's id and payload");
bool decode_request_data_stream(const Received& rx, DataStreamRequest& out) {
    if (rx.msgid != kMsgRequestDataStream) return false;
    mavlink_request_data_stream_t m;
    copy_payload(m, rx);
    if (!for_us(m.target_system, m.target_component)) return false;
    out.stream_id = m.req_stream_id;
    out.rate_hz = m.req_message_rate;
    out.start_stop = m.start_stop;
    return true;
}

bool decode_mission_request_list(const Received& rx, uint8_t& mission_type) {
    if (rx.msgid != kMsgMissionRequestList) return false;
    mavlink_mission_request_list_t m;
    copy_payload(m, rx);
    mission_type = m.mission_type;
    return for_us(m.target_system, m.target_component);
}

bool decode_mission_count(const Received& rx, uint16_t& count, uint8_t& mission_type) {
    if (rx.msgid != kMsgMissionCount) return false;
    mavlink_mission_count_t m;
    copy_payload(m, rx);
    count = m.count;
    mission_type = m.mission_type;
    return for_us(m.target_system, m.target_component);
}

bool decode_mission_clear_all(const Received& rx, uint8_t& mission_type) {
    if (rx.msgid != kMsgMissionClearAll) return false;
    mavlink_mission_clear_all_t m;
    copy_payload(m, rx);
    mission_type = m.mission_type;
    return for_us(m.target_system, m.target_component);
}

// MISSION_ITEM and MISSION_ITEM_INT share their layout but x, y's type (float degrees, or
// int32 1e-7 degrees), as do MISSION_REQUEST and MISSION_REQUEST_INT: each pair is decoded
// and packed through its _INT struct (the generated code's aligned-fields path), with the
// message's own id and CRC_EXTRA: one copy of the code for both (~0.5 KB of flash).
static_assert(sizeof(mavlink_mission_item_t) == sizeof(mavlink_mission_item_int_t) &&
                  offsetof(mavlink_mission_item_t, x) == offsetof(mavlink_mission_item_int_t, x) &&
                  offsetof(mavlink_mission_item_t, y) == offsetof(mavlink_mission_item_int_t, y) &&
                  offsetof(mavlink_mission_item_t, seq) == offsetof(mavlink_mission_item_int_t, seq) &&
                  offsetof(mavlink_mission_item_t, mission_type) == offsetof(mavlink_mission_item_int_t, mission_type) &&
                  MAVLINK_MSG_ID_MISSION_ITEM_LEN == MAVLINK_MSG_ID_MISSION_ITEM_INT_LEN &&
                  MAVLINK_MSG_ID_MISSION_ITEM_MIN_LEN == MAVLINK_MSG_ID_MISSION_ITEM_INT_MIN_LEN &&
                  sizeof(mavlink_mission_request_t) == sizeof(mavlink_mission_request_int_t) &&
                  MAVLINK_MSG_ID_MISSION_REQUEST_LEN == MAVLINK_MSG_ID_MISSION_REQUEST_INT_LEN &&
                  MAVLINK_MSG_ID_MISSION_REQUEST_MIN_LEN == MAVLINK_MSG_ID_MISSION_REQUEST_INT_MIN_LEN,
              "MISSION_ITEM and _INT, MISSION_REQUEST and _INT: one layout");

bool decode_mission_item(const Received& rx, mission::Item& out) {
    if (rx.msgid != kMsgMissionItemInt && rx.msgid != kMsgMissionItem) return false;
    mavlink_mission_item_int_t m;
    copy_payload(m, rx);
    out.seq = m.seq;
    out.command = m.command;
    out.frame = m.frame;
    out.current = m.current;
    out.autocontinue = m.autocontinue;
    out.param1 = m.param1;
    out.param2 = m.param2;
    out.param3 = m.param3;
    out.param4 = m.param4;
    out.z = m.z;
    out.mission_type = m.mission_type;
    out.int_form = rx.msgid == kMsgMissionItemInt;
    out.x = m.x;
    out.y = m.y;
    if (!out.int_form) {
        // Float degrees (NaN or out of range: e7_from_degrees holds it within int32, the
        // protocol refuses it).
        float lat, lon;
        memcpy(&lat, &m.x, sizeof lat);
        memcpy(&lon, &m.y, sizeof lon);
        out.x = mission::e7_from_degrees(lat);
        out.y = mission::e7_from_degrees(lon);
    }
    return for_us(m.target_system, m.target_component);
}

bool decode_mission_request(const Received& rx, uint16_t& seq, bool& int_form, uint8_t& mission_type) {
    // MISSION_REQUEST and MISSION_REQUEST_INT: the same fields.
    if (rx.msgid != kMsgMissionRequest && rx.msgid != kMsgMissionRequestInt) return false;
    mavlink_mission_request_int_t m;
    copy_payload(m, rx);
    seq = m.seq;
    int_form = rx.msgid == kMsgMissionRequestInt;
    mission_type = m.mission_type;
    return for_us(m.target_system, m.target_component);
}

bool decode_mission_ack(const Received& rx, uint8_t& mission_type) {
    if (rx.msgid != kMsgMissionAck) return false;
    mavlink_mission_ack_t m;
    copy_payload(m, rx);
    mission_type = m.mission_type;
    return for_us(m.target_system, m.target_component);
}

bool decode_mission_set_current(const Received& rx, uint16_t& seq) {
    if (rx.msgid != kMsgMissionSetCurrent) return false;
    mavlink_mission_set_current_t m;
    copy_payload(m, rx);
    seq = m.seq;
    return for_us(m.target_system, m.target_component);
}

bool decode_timesync_request(const Received& rx, int64_t& ts1) {
    if (rx.msgid != kMsgTimesync) return false;
    mavlink_timesync_t m;
    copy_payload(m, rx);
    ts1 = m.ts1;
    return m.tc1 == 0;
}

uint8_t Packer::mission_count(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component, uint16_t count,
                              uint8_t mission_type) {
    Frame f(seq_);
    mavlink_msg_mission_count_pack_status(kSystemId, kComponentId, &f.status, &f.msg, target_system, target_component,
                                          count, mission_type);
    return f.finish(out, seq_);
}

uint8_t Packer::mission_ack(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component,
                            MissionResult result, uint8_t mission_type) {
    Frame f(seq_);
    mavlink_msg_mission_ack_pack_status(kSystemId, kComponentId, &f.status, &f.msg, target_system, target_component,
                                        (uint8_t)result, mission_type);
    return f.finish(out, seq_);
}

uint8_t Packer::mission_request(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component, uint16_t seq,
                                bool int_form, uint8_t mission_type) {
    Frame f(seq_);
    mavlink_mission_request_int_t m;
    m.seq = seq;
    m.target_system = target_system;
    m.target_component = target_component;
    m.mission_type = mission_type;
    memcpy(_MAV_PAYLOAD_NON_CONST(&f.msg), &m, MAVLINK_MSG_ID_MISSION_REQUEST_INT_LEN);
    f.msg.msgid = int_form ? MAVLINK_MSG_ID_MISSION_REQUEST_INT : MAVLINK_MSG_ID_MISSION_REQUEST;
    mavlink_finalize_message_buffer(&f.msg, kSystemId, kComponentId, &f.status, MAVLINK_MSG_ID_MISSION_REQUEST_INT_MIN_LEN,
                                    MAVLINK_MSG_ID_MISSION_REQUEST_INT_LEN,
                                    int_form ? MAVLINK_MSG_ID_MISSION_REQUEST_INT_CRC : MAVLINK_MSG_ID_MISSION_REQUEST_CRC);
    return f.finish(out, seq_);
}

uint8_t Packer::mission_item(uint8_t out[kMaxFrame], uint8_t target_system, uint8_t target_component,
                             const mission::Item& i) {
    Frame f(seq_);
    mavlink_mission_item_int_t m;
    m.param1 = i.param1;
    m.param2 = i.param2;
    m.param3 = i.param3;
    m.param4 = i.param4;
    m.x = i.x;
    m.y = i.y;
    if (!i.int_form) {
        const float lat = mission::degrees_from_e7(i.x), lon = mission::degrees_from_e7(i.y);
        memcpy(&m.x, &lat, sizeof lat);
        memcpy(&m.y, &lon, sizeof lon);
    }
    m.z = i.z;
    m.seq = i.seq;
    m.command = i.command;
    m.target_system = target_system;
    m.target_component = target_component;
    m.frame = i.frame;
    m.current = i.current;
    m.autocontinue = i.autocontinue;
    m.mission_type = i.mission_type;
    memcpy(_MAV_PAYLOAD_NON_CONST(&f.msg), &m, MAVLINK_MSG_ID_MISSION_ITEM_INT_LEN);
    f.msg.msgid = i.int_form ? MAVLINK_MSG_ID_MISSION_ITEM_INT : MAVLINK_MSG_ID_MISSION_ITEM;
    mavlink_finalize_message_buffer(&f.msg, kSystemId, kComponentId, &f.status, MAVLINK_MSG_ID_MISSION_ITEM_INT_MIN_LEN,
                                    MAVLINK_MSG_ID_MISSION_ITEM_INT_LEN,
                                    i.int_form ? MAVLINK_MSG_ID_MISSION_ITEM_INT_CRC : MAVLINK_MSG_ID_MISSION_ITEM_CRC);
    return f.finish(out, seq_);
}

uint8_t Packer::mission_current(uint8_t out[kMaxFrame], uint16_t seq, uint16_t total) {
    Frame f(seq_);
    // mission_state and mission_mode 0: unknown (the executor's state is not said here).
    mavlink_msg_mission_current_pack_status(kSystemId, kComponentId, &f.status, &f.msg, seq, total, 0u, 0u);
    return f.finish(out, seq_);
}

uint8_t Packer::mission_item_reached(uint8_t out[kMaxFrame], uint16_t seq) {
    Frame f(seq_);
    mavlink_msg_mission_item_reached_pack_status(kSystemId, kComponentId, &f.status, &f.msg, seq);
    return f.finish(out, seq_);
}

uint8_t Packer::timesync(uint8_t out[kMaxFrame], int64_t tc1_ns, int64_t ts1) {
    Frame f(seq_);
    mavlink_msg_timesync_pack_status(kSystemId, kComponentId, &f.status, &f.msg, tc1_ns, ts1);
    return f.finish(out, seq_);
}

uint8_t Packer::system_time(uint8_t out[kMaxFrame], uint64_t time_unix_us, uint32_t time_boot_ms) {
    Frame f(seq_);
    mavlink_msg_system_time_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_unix_us, time_boot_ms);
    return f.finish(out, seq_);
}

uint8_t Packer::message_interval(uint8_t out[kMaxFrame], uint16_t message_id, int32_t interval_us) {
    Frame f(seq_);
    mavlink_msg_message_interval_pack_status(kSystemId, kComponentId, &f.status, &f.msg, message_id, interval_us);
    return f.finish(out, seq_);
}

uint8_t Packer::autopilot_version(uint8_t out[kMaxFrame], const Version& v) {
    Frame f(seq_);
    const uint32_t sw = (uint32_t)v.major << 24 | (uint32_t)v.minor << 16 | (uint32_t)v.patch << 8 |
                        kVersionTypeOfficial;
    const uint8_t none[18] = {};
    mavlink_msg_autopilot_version_pack_status(kSystemId, kComponentId, &f.status, &f.msg, kCapabilities, sw, 0u, 0u,
                                              0u, v.git, none, none, kUsbVendorId, kUsbProductId, 0u, none);
    // The trimmed payload ends within flight_custom_version (byte 44): no uid, no
    // middleware or OS version, zeros after it.
    if (kFrameOverhead + f.msg.len > kMaxFrame) return 0;
    return f.finish(out, seq_);
}

uint8_t Packer::scaled_pressure(uint8_t out[kMaxFrame], uint32_t time_boot_ms, float pressure_pa, float temperature_c) {
    Frame f(seq_);
    // The temperature within int16's 0.01 degC (the chip's -40..85 degC is well inside).
    const float c100 = temperature_c * 100.0f;
    const int16_t temp = c100 > 32767.0f ? (int16_t)32767 : c100 < -32767.0f ? (int16_t)-32767 : (int16_t)c100;
    mavlink_msg_scaled_pressure_pack_status(kSystemId, kComponentId, &f.status, &f.msg, time_boot_ms,
                                            pressure_pa * 0.01f, 0.0f, temp, 0);
    return f.finish(out, seq_);
}

}  // namespace mav
