// SPDX-License-Identifier: GPL-3.0-or-later
// One GPS solution as the parsers (u-blox UBX, NMEA) deliver it and the rest of the
// firmware (position and home, the estimator's GPS-aided correction, the ground station's
// GPS_RAW_INT and GLOBAL_POSITION_INT) reads it. Integers in the receivers' own units
// (u-blox 6 Receiver Description, UBX-NAV-POSLLH, -VELNED, -SOL), so nothing is rounded
// twice; plain C++, no Arduino.
#pragma once

#include <stdint.h>

namespace gps {

// MAVLink's GPS_FIX_TYPE numbering (GPS_RAW_INT.fix_type).
enum class FixType : uint8_t {
    kNoGps = 0,  // nothing heard from a receiver
    kNoFix = 1,  // a receiver, no position
    k2D = 2,
    k3D = 3,     // 3D and the receiver's fix-valid flag (NAV-STATUS gpsFixOk)
};

struct Fix {
    uint32_t itow_ms = 0;            // GPS time of week of the solution (NAV-* iTOW; NMEA: time of day)
    uint16_t week = 0;               // GPS week (NAV-SOL week); 0: unknown (NMEA)
    uint32_t received_ms = 0;        // the board's millis() when the solution was complete
    int32_t lat_e7 = 0;              // degrees * 1e7, north positive
    int32_t lon_e7 = 0;              // degrees * 1e7, east positive
    int32_t alt_msl_mm = 0;          // height above mean sea level (POSLLH hMSL)
    int32_t vel_ned_cm_s[3] = {0, 0, 0};  // north, east, down (VELNED velN/E/D)
    uint32_t ground_speed_cm_s = 0;  // horizontal speed (VELNED gSpeed)
    int32_t course_e5 = 0;           // course over ground, degrees * 1e5, 0..360e5 (VELNED heading)
    uint32_t h_acc_mm = 0;           // horizontal accuracy estimate (POSLLH hAcc); 0: unknown
    uint32_t speed_acc_cm_s = 0;     // speed accuracy estimate (VELNED sAcc); 0: unknown
    uint16_t hdop_cm = 9999;         // horizontal dilution of precision * 100 (SOL pDOP or GGA HDOP)
    uint8_t sats = 0;                // satellites used in the solution
    FixType fix = FixType::kNoGps;
    bool have_vertical_velocity = false;  // NMEA carries no vel_ned_cm_s[2]
    bool glitching = false;  // the position jumped further than the last good one, its velocity and
                             // 10 m/s/s explain (AP_GPS_Glitch): do not use lat/lon/alt
};

// The solution's UNIX time in microseconds, moved on to now_ms on the board's clock
// (received_ms is the fix's arrival), from the GPS week and time of week: the GPS epoch
// (1980-01-06, UNIX 315964800 s) less the leap seconds (18 s since 2017, as ArduPilot's
// GPS_LEAPSECONDS_MILLIS). 0 without a 2D or 3D fix or a week (NMEA).
uint64_t unix_time_us(const Fix& f, uint32_t now_ms);

}  // namespace gps
