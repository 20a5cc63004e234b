// SPDX-License-Identifier: GPL-3.0-or-later
// The settings added after the first record's version 5: the vehicle's arming, board
// orientation and level, the accelerometer's and compass's calibration as parameters,
// the battery monitor, the telemetry rates. They are the parameter table's rows that
// live here (Params.cpp, after COMPASS_DEC), in table order, and go in the second EEPROM
// record (params::encode_vehicle): the first record is full (251 of its 255 bytes).
//
// Each feature keeps its fields under its own heading, ArduPilot's names beside them;
// units in the names. Defaults are in the parameter table only.
#pragma once

#include <stdint.h>

namespace settings {

struct VehicleSettings {
    // Arming (ArduPlane's AP_Arming), and a ground station's sticks (RC_Channels' override).
    uint8_t arming_require;     // ARMING_REQUIRE: 0 never disarmed, 1 throttle at its minimum until armed
    uint16_t arming_check;      // ARMING_CHECK: the pre-arm checks, ArduPilot's bitmask (1 all; flight::CheckBit)
    uint8_t arming_rudder;      // ARMING_RUDDER: 0 no rudder arming, 1 arm only, 2 arm and disarm
    float rc_override_time_s;   // RC_OVERRIDE_TIME: an override's life, s (0 overrides off, -1 forever)

    // Board orientation, level, the accelerometer's calibration (AP_AHRS, AP_InertialSensor).

    // Compass (AP_Compass).

    // Battery monitor and its failsafe (AP_BattMonitor, ArduPlane's FS_BATT_*).

    // Telemetry rates (GCS_MAVLink's SRn_*).
};

}  // namespace settings
