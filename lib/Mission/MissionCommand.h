// SPDX-License-Identifier: GPL-3.0-or-later
// A mission command as AP_Mission keeps it: the MAVLink command id, one 16-bit parameter,
// a place (1e-7 degrees, cm) and two flags, packed into kCommandBytes = 14 bytes of
// EEPROM (AP_Mission's 15 less its separate flags byte: the flags share the id's byte).
//
//   byte 0     bits 0-3 the command's code (kCodes), bit 4 relative height, bit 5 counter-
//              clockwise; an erased byte (0xFF, code 15) is no command
//   bytes 1-2  p1, little-endian
//   bytes 3-5  alt_cm, int24 little-endian (+-83 km)
//   bytes 6-9  lat_e7, int32 little-endian
//   bytes 10-13 lon_e7
//
// What each command keeps where (AP_Mission's choices where it has them):
//   NAV_WAYPOINT 16        the place (param 1, a hold time, is not flown by ArduPlane)
//   NAV_LOITER_UNLIM 17    the place; p1 the radius in m (0: WP_LOITER_RAD); ccw: param 3 < 0
//   NAV_LOITER_TURNS 18    the place; p1 low byte the turns, high byte the radius in m
//   NAV_LOITER_TIME 19     the place; p1 the seconds (the radius is WP_LOITER_RAD)
//   NAV_RETURN_TO_LAUNCH 20  nothing
//   NAV_TAKEOFF 22         the height; p1 the least pitch, degrees
//   DO_JUMP 177            p1 the target's seq; lat_e7 the repeat count (-1 for ever)
//   DO_CHANGE_SPEED 178    p1 the speed type (0 airspeed, 1 ground speed); lat_e7 the
//                          speed in cm/s (< 0: unchanged); lon_e7 the throttle % (< 0: unchanged)
// A place of latitude and longitude 0 is "here, when the command starts" (ArduPlane's).
#pragma once

#include <stdint.h>

namespace mission {

enum CommandId : uint16_t {
    kNavWaypoint = 16,
    kNavLoiterUnlim = 17,
    kNavLoiterTurns = 18,
    kNavLoiterTime = 19,
    kNavReturnToLaunch = 20,
    kNavTakeoff = 22,
    kDoJump = 177,
    kDoChangeSpeed = 178,
};

constexpr uint8_t kCommandBytes = 14;
constexpr int32_t kAltMaxCm = 8388607;  // int24

struct Command {
    uint16_t id = 0;
    uint16_t p1 = 0;
    int32_t lat_e7 = 0;
    int32_t lon_e7 = 0;
    int32_t alt_cm = 0;
    bool relative_alt = true;  // alt_cm above home (else above mean sea level)
    bool loiter_ccw = false;

    bool has_place() const { return lat_e7 != 0 || lon_e7 != 0; }
};

// One of the eight commands this firmware flies (NAV_LAND and the rest: no).
bool is_supported(uint16_t id);
// A navigation command (the executor flies it until it completes); DO_ commands act at once.
bool is_nav(uint16_t id);

void pack(const Command& c, uint8_t out[kCommandBytes]);
// False for bytes that hold no supported command (erased, another firmware's).
bool unpack(const uint8_t in[kCommandBytes], Command& c);

// Loiter turns and radius in p1 (NAV_LOITER_TURNS).
inline uint8_t loiter_turns(const Command& c) { return (uint8_t)(c.p1 & 0xFFu); }
inline uint8_t loiter_turns_radius_m(const Command& c) { return (uint8_t)(c.p1 >> 8); }

}  // namespace mission
