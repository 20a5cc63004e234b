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
    // Arming (ArduPlane's AP_Arming).
    uint8_t arming_require;     // ARMING_REQUIRE: 0 never disarmed, 1 throttle at its minimum until armed

    // Board orientation, level, the accelerometer's calibration (AP_AHRS, AP_InertialSensor).

    // Compass (AP_Compass).

    // Battery monitor and its failsafe (AP_BattMonitor, ArduPlane's FS_BATT_*).

    // Telemetry rates (GCS_MAVLink's SRn_*).

    // Serial port (AP_SerialManager's SERIALn_*).
    uint8_t serial0_protocol;   // SERIAL0_PROTOCOL: kSerialConsole, or 1/2 MAVLink from power-up
};

// SERIAL0_PROTOCOL's values: ArduPilot's SerialProtocol_Console (0), _MAVLink (1), _MAVLink2 (2).
constexpr uint8_t kSerialConsole = 0;

}  // namespace settings
