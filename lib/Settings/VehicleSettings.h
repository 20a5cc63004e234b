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

namespace settings {

struct VehicleSettings {
    // Arming (ArduPlane's AP_Arming).
    uint8_t arming_require;     // ARMING_REQUIRE: 0 never disarmed, 1 throttle at its minimum until armed

    // Board orientation, level, the accelerometer's calibration (AP_AHRS, AP_InertialSensor).

    // Compass (AP_Compass).
    float compass_dec_rad;      // COMPASS_DEC: declination, east positive, as sent (record 1 keeps it rounded)

    // Battery monitor and its failsafe (AP_BattMonitor, ArduPlane's FS_BATT_*).

    // Telemetry rates (GCS_MAVLink's SRn_*).
};

}  // namespace settings
