// SPDX-License-Identifier: GPL-3.0-or-later
// The settings added after the first record's version 5: the vehicle's arming, board
// orientation and level, the accelerometer's and compass's calibration as parameters,
// the battery monitor, the telemetry rates, and COMPASS_DEC as sent. They are the parameter
// table's rows that live here (Params.cpp, after GND_ABS_PRESS), in table order, and go in
// the second EEPROM record (params::vehicle_part, VehicleRecord.h: at most 244 bytes, a
// unit test holds them to it): the first record is full (251 of its 255 bytes).
//
// Each feature keeps its fields under its own heading, ArduPilot's names beside them;
// units in the names. Defaults are in the parameter table only.
#pragma once

#include <stdint.h>

#include "BatterySettings.h"
#include "NavSettings.h"

namespace settings {

struct VehicleSettings {
    // Arming (ArduPlane's AP_Arming), and a ground station's sticks (RC_Channels' override).
    uint8_t arming_require;     // ARMING_REQUIRE: 0 never disarmed, 1 throttle at its minimum until armed
    uint16_t arming_check;      // ARMING_CHECK: the pre-arm checks, ArduPilot's bitmask (1 all; flight::CheckBit)
    uint8_t arming_rudder;      // ARMING_RUDDER: 0 no rudder arming, 1 arm only, 2 arm and disarm
    float rc_override_time_s;   // RC_OVERRIDE_TIME: an override's life, s (0 overrides off, -1 forever)

    // Board orientation, level, the accelerometer's calibration (AP_AHRS, AP_InertialSensor).
    uint8_t ahrs_orientation;   // AHRS_ORIENTATION: ArduPilot's Rotation, 0..37 (lib/Calibration/BoardFrame.h)
    float ahrs_trim_x_rad;      // AHRS_TRIM_X: the board's roll on a level airframe
    float ahrs_trim_y_rad;      // AHRS_TRIM_Y: its pitch
    float ins_accoffs_m_s2[3];  // INS_ACCOFFS_X/Y/Z: subtracted from the accelerometer (board axes)
    float ins_accscal[3];       // INS_ACCSCAL_X/Y/Z: then multiplied

    // Compass (AP_Compass). Its calibration's rows (COMPASS_OFS_*, _DIA_*, _ODI_*) point into
    // Settings::cal: saved with it in the first record.
    float compass_dec_rad;      // COMPASS_DEC: declination, east positive, as sent (record 1 keeps it rounded)
    uint8_t compass_use;        // COMPASS_USE: 1 the heading from the compass, 0 the gyro's (or the GPS course)
    uint8_t compass_learn;      // COMPASS_LEARN: 1 the hard iron learned in motion (OffsetLearner), 0 not

    // Battery monitor and its failsafe (AP_BattMonitor, ArduPlane's FS_BATT_*).
    battery::Settings battery;  // BATT_MONITOR .. FS_BATT_MAH (lib/Battery/BatterySettings.h)

    // Telemetry rates (GCS_MAVLink's SRn_*), Hz: SR0_RAW_SENS, _EXT_STAT, _RC_CHAN, _POSITION,
    // _EXTRA1, _EXTRA2, _EXTRA3, _PARAMS in this order (mav::StreamGroup, StreamRates.h).
    uint8_t sr0_hz[8];

    // Serial port (AP_SerialManager's SERIALn_*).
    uint8_t serial0_protocol;   // SERIAL0_PROTOCOL: kSerialConsole, or 1/2 MAVLink from power-up

    // Navigation (AP_L1_Control, AP_TECS, ArduPlane's mission, throttle and failsafe names).
    // Each in the least bytes its ArduPlane range and step allow: the Scaled8 rows
    // (Params.h) keep tenths, twentieths or hundredths in a byte; nav_params() turns them
    // into lib/Nav's and lib/Mission's float parameters.
    NavSettings nav;

    // Airspeed (AP_Airspeed).
    uint16_t arspd_offset;      // ARSPD_OFFSET: the pitot's zero in use, 4096ths of 5 V (lib/Pipeline/Airspeed.h; 0: none)
};

// SERIAL0_PROTOCOL's values: ArduPilot's SerialProtocol_Console (0), _MAVLink (1), _MAVLink2 (2).
constexpr uint8_t kSerialConsole = 0;

}  // namespace settings
