// SPDX-License-Identifier: GPL-3.0-or-later
// The ground station link (lib/MavLink: Parser, ParamLink): a ground station's requests
// answered, its parameters and commands, HEARTBEAT once a second, the streams at the
// rates asked (StreamRates.h). Replies go through the same queue as everything else,
// each only when it fits whole with an output line after it and ends before the next
// sample is due (the task table's budgets), so no sample is missed and no frame
// dropped: a PARAM_REQUEST_LIST's ~100 PARAM_VALUEs go out a few per sample as the UART
// drains them (~37 bytes each, ~3 ms at 115200 baud).
#pragma once

#include <stdint.h>

#include "MavLink.h"
#include "Pipeline.h"
#include "StreamRates.h"

namespace gcs_link {

// The frames received (ConsoleLink feeds it the port's bytes).
mav::Parser& parser();
// Called for every frame end: a ground station's HEARTBEAT switches a text mode to
// MAVLink; in a text mode the other requests are not answered (the ground station asks
// again once the board speaks MAVLink).
void take_heartbeat();
// Output queue bytes an output line takes at most in the port's language.
uint16_t output_line_bytes();
// In MAVLink, room in the queue for a frame of frame_bytes and an output line after it.
bool room_for(uint16_t frame_bytes);

// Loop tasks, each with its budget: a received frame taken (PARAM_SET applied, a
// command set aside), the command run and ACKed, PREFLIGHT_STORAGE's defaults (restored,
// then their line), a save after a PARAM_SET (or a REQUEST_DATA_STREAM that changed an
// SR0_ rate), one PARAM_VALUE.
bool request_due();
void take_request();
bool command_due();
void run_pending_command();
bool defaults_due();
void run_defaults();
bool save_due();
void save();
// A save in a pass of its own, as after a PARAM_SET (the compass calibration accepted).
void save_soon();
// The answers sent when the output has room, one a run: TIMESYNC, AUTOPILOT_VERSION,
// the mission protocols' (MissionLink.h).
bool reply_due();
void send_reply();
// MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN param1 1, ACKed: a watchdog reset once the ACK is out.
bool reboot_due();
void reboot();
// A parameter changed by another path (the console's `set`, a calibration accepted):
// the ground station is told with a PARAM_VALUE (no-op outside MAVLink: it asks anew).
void announce_param(uint16_t index);
// The rows a calibration wrote, each told with a PARAM_VALUE as ArduPilot's AP_Param does
// when the vehicle sets a parameter: the level (AHRS_TRIM_*), the six positions
// (INS_ACC*), `cal mag` applied (COMPASS_OFS/DIA/ODI_*), the barometer's ground.
enum class Calibrated : uint8_t { kLevel, kAccel, kCompass, kBaroGround };
void announce_calibration(Calibrated what);
// The pipeline's events: a calibration's good verdict announces its rows.
void announce_calibration(const pipeline::AttitudePipeline& pipe, const pipeline::Event& e);
bool param_value_due();
void send_param_value();
// The messages on a timer (mav::StreamRates: the SR0_ rates, SET_MESSAGE_INTERVAL, the
// link's cap): one of SYS_STATUS, RC_CHANNELS, SERVO_OUTPUT_RAW, SCALED_PRESSURE,
// SYSTEM_TIME a run, or the intervals planned again after a change.
bool streams_due();
void send_streams();
// A stream message of another task due (BATTERY_STATUS); take_stream: due, and counted as
// sent at now_ms (ATTITUDE with the output line).
bool stream_due(mav::StreamMsg m);
bool take_stream(mav::StreamMsg m, uint32_t now_ms);
// The position messages (Position.h), one frame a run: GPS_RAW_INT, GLOBAL_POSITION_INT
// and VFR_HUD at their streams' rates (1, 4, 4 Hz by default); HOME_POSITION when home changes and when asked for
// (MAV_CMD_GET_HOME_POSITION, MAV_CMD_REQUEST_MESSAGE 242). The compass calibration's
// MAG_CAL_PROGRESS and REPORT (MagCalLink) go first when due.
bool position_due();
void send_position();
// Once a second in MAVLink: HEARTBEAT, whatever the rates asked (a ground station drops a
// link after ~3 s without a heartbeat).
void send_heartbeat_and_status();

}  // namespace gcs_link
