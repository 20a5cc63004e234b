// SPDX-License-Identifier: GPL-3.0-or-later
// The messages the board sends on a timer, in ArduPilot's stream groups (GCS_MAVLINK's
// SRn_ rates, Hz; ArduPlane's GCS_Mavlink.cpp lists): the group rates are the SR0_
// parameters (VehicleSettings::sr0_hz, saved), a ground station's REQUEST_DATA_STREAM sets
// them (ArduPilot's handle_request_data_stream), MAV_CMD_SET_MESSAGE_INTERVAL sets one
// message's interval in RAM (its set_message_interval), and every interval is capped by
// what the link carries. Plain C++, host-tested.
//
//   group (SR0_)  MAV_DATA_STREAM     messages the board sends          frame bytes (longest)
//   RAW_SENS      1 RAW_SENSORS       SCALED_PRESSURE                   28
//   EXT_STAT      2 EXTENDED_STATUS   SYS_STATUS, GPS_RAW_INT,          66, 64,
//                                     NAV_CONTROLLER_OUTPUT, MISSION_CURRENT  38, 18
//   RC_CHAN       3 RC_CHANNELS       RC_CHANNELS, SERVO_OUTPUT_RAW     54, 33
//   POSITION      6 POSITION          GLOBAL_POSITION_INT               40
//   EXTRA1       10 EXTRA1            ATTITUDE (at most one an output line: the console's `rate`)  40
//   EXTRA2       11 EXTRA2            VFR_HUD                           32
//   EXTRA3       12 EXTRA3            SYSTEM_TIME, BATTERY_STATUS       24, 53
//   PARAMS        -                   (PARAM_VALUE replies go as fast as the link has room)
//
// HEARTBEAT is 1 Hz always (a ground station drops a link after ~3 s without one).
//
// The link's cap: the streams may take 75 % of the port's 11520 bytes a second (the rest
// for parameters, commands and STATUSTEXT); when the intervals asked would take more, every
// interval is stretched by the same factor until they fit (plan()).
#pragma once

#include <stdint.h>

#include "MavLink.h"

namespace mav {

// The port: 115200 baud, 10 bits a byte; three quarters for the streams.
constexpr uint16_t kLinkBytesPerS = 11520;
constexpr uint16_t kLinkBudgetBytesPerS = kLinkBytesPerS / 4u * 3u;  // 8640
constexpr uint8_t kStreamRateMaxHz = 50;  // ArduPilot's SRn_ range: 0..50

// MAV_DATA_STREAM.
constexpr uint8_t kDataStreamAll = 0;

// ArduPilot's groups in the SRn_ parameters' order (VehicleSettings::sr0_hz).
enum StreamGroup : uint8_t {
    kGroupRawSens, kGroupExtStat, kGroupRcChan, kGroupPosition, kGroupExtra1, kGroupExtra2, kGroupExtra3,
    kGroupParams, kStreamGroups
};
// The messages sent on a timer, each in its group (the table in StreamRates.cpp).
enum StreamMsg : uint8_t {
    kStreamScaledPressure, kStreamSysStatus, kStreamGpsRawInt, kStreamRcChannels, kStreamServoOutputRaw,
    kStreamGlobalPositionInt, kStreamAttitude, kStreamVfrHud, kStreamSystemTime, kStreamBatteryStatus,
    kStreamNavControllerOutput, kStreamMissionCurrent, kStreamMsgs
};

// MESSAGE_INTERVAL (244) and the commands that ask for it.
constexpr uint16_t kCmdGetMessageInterval = 510;  // param1 the message id: MESSAGE_INTERVAL, then the ACK
constexpr uint16_t kCmdSetMessageInterval = 511;  // param1 the message id, param2 us (-1 stop, 0 default)
constexpr uint8_t kMessageIntervalFrame = kFrameOverhead + 6;

// The group a MAV_DATA_STREAM id names, or kStreamGroups for none (ALL included).
StreamGroup group_of_data_stream(uint8_t stream_id);
// The table's message for a MAVLink id, or kStreamMsgs.
StreamMsg stream_msg_of(uint32_t msgid);

// REQUEST_DATA_STREAM onto the SR0_ rates (ArduPilot's handle_request_data_stream):
// start_stop 1 sets rate_hz (at most kStreamRateMaxHz), 0 sets 0; another start_stop
// or an unknown stream does nothing. ALL sets every group but PARAMS. True when a value
// changed (the caller saves: ArduPilot's set_and_save_ifchanged, so a ground station
// connecting again does not wear the EEPROM). The groups set are marked in *groups_set
// (bit g), whose messages follow their group again (StreamRates::follow_groups).
bool apply_data_stream_request(uint8_t sr0_hz[kStreamGroups], uint8_t stream_id, uint16_t rate_hz,
                               uint8_t start_stop, uint8_t* groups_set);

class StreamRates {
public:
    // The intervals in force from the SR0_ rates, the messages' own (set_interval) and the
    // console's output rate (ATTITUDE at most one an output line), capped to the link.
    void plan(const uint8_t sr0_hz[kStreamGroups], uint8_t output_rate_hz);
    // A message's interval in force, ms (0: not sent).
    uint16_t interval_ms(StreamMsg m) const { return interval_ms_[m]; }
    // Due: its interval has passed since it was last due.
    bool due(StreamMsg m, uint32_t now_ms) const {
        return interval_ms_[m] != 0u && (int32_t)(now_ms - next_ms_[m]) >= 0;
    }
    // Sent (or skipped) now: due again an interval after it was due, so that the rate
    // over time is the one asked; a period late or more (a full queue, the text console),
    // an interval from now, with no burst to catch up.
    void sent(StreamMsg m, uint32_t now_ms);
    // due() then sent(). ATTITUDE asked at least as often as the output lines come goes
    // with every line: the lines keep the MPU6000's clock, and a timer of the same period on
    // the board's would drop one each time the two drift a step apart.
    bool take(StreamMsg m, uint32_t now_ms) {
        if (m == kStreamAttitude && every_line_) return true;
        if (!due(m, now_ms)) return false;
        sent(m, now_ms);
        return true;
    }
    // MAV_CMD_SET_MESSAGE_INTERVAL (ArduPilot's set_message_interval): interval_us -1 stops
    // the message, 0 gives it its group's rate again, below 1000 is 1 ms, above 60 s is 60 s
    // (all then capped by plan()). Denied for a message not in the table (and HEARTBEAT: 1 Hz
    // always). The caller plans again.
    Result set_interval(uint32_t msgid, float interval_us);
    // MAV_CMD_GET_MESSAGE_INTERVAL's MESSAGE_INTERVAL: the interval in force in us, -1 when
    // the message is not sent (stopped, or not one the board sends: ArduPilot's answer).
    int32_t interval_us(uint32_t msgid) const;
    // The messages of the groups in mask (bit g) back to their group's rate.
    void follow_groups(uint8_t mask);
    // What the streams take at the intervals in force, bytes a second.
    uint16_t bytes_per_s() const;

private:
    // All zeros at start (no constructor: nothing to run, nothing in flash): every message
    // follows its group, none planned yet.
    static constexpr uint16_t kFollowGroup = 0;
    static constexpr uint16_t kStopped = 0xFFFFu;
    uint16_t own_ms_[kStreamMsgs] = {};       // SET_MESSAGE_INTERVAL's, kStopped, or kFollowGroup
    uint16_t interval_ms_[kStreamMsgs] = {};  // in force (plan())
    uint32_t next_ms_[kStreamMsgs] = {};      // when due next
    bool every_line_ = false;            // ATTITUDE on every output line (take())
};

}  // namespace mav
