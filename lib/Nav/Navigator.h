// SPDX-License-Identifier: GPL-3.0-or-later
// Where the plane is and where home is, from the GPS fix (lib/GPS/GpsFix.h) and the
// barometer's height, as ArduPlane composes AP_GPS, AP_Baro and AP_AHRS_DCM's position:
//
// - home: the first 3D fix with at least AHRS_GPS_MINSATS satellites and hDOP <= 2.5
//   (ArduPilot's GPS_HDOP_GOOD ... the fix a plane may navigate from), or the ground
//   station's (MAV_CMD_DO_SET_HOME: here, or a latitude, longitude and height). Its
//   height above mean sea level is the GPS's.
// - the height above home: the barometer's while it is healthy, tied to mean sea level
//   by a datum (the GPS height where the barometer's height was zero, taken once: at home
//   from the home fix itself, so that the height above home is the barometer's change
//   since home, without the GPS's vertical noise); else the GPS's.
// - the position now: the last good fix moved on by its velocity for the fix's age plus
//   the u-blox's lag, kGpsLag_s 0.2 s (ArduPilot's: the solution leaves the receiver that
//   long after its time), for at most kMaxExtrapolation_ms past the fix (a GPS that went
//   quiet is not extrapolated for ever). A fix the driver's glitch rule rejects
//   (gps::Fix::glitching: AP_GPS_Glitch's test, lib/GPS/GpsReceiver.h, which also says
//   it) moves the position on by its velocity only: the last good position dead-reckoned
//   with the GPS's fresh velocities.
//
// Frames: positions as Location (1e-7 deg, cm above mean sea level); north, east, down
// metres from home on the local map at home (Location.h); velocities NED m/s. Times are
// the board's milliseconds (gps::Fix::received_ms and the caller's clock).
#pragma once

#include <stdint.h>

#include "GpsFix.h"
#include "Location.h"

namespace nav {

// The barometer as the navigation takes it: its height above its start-up ground level.
struct BaroReading {
    bool healthy;
    float height_m;
};

enum class HomeSource : uint8_t { kNone, kGps, kGroundStation };

class Navigator {
public:
    static constexpr float kGpsLag_s = 0.2f;
    static constexpr uint16_t kMaxHdopCm = 250;  // hDOP 2.5
    static constexpr uint16_t kMaxExtrapolation_ms = 1000;

    // A new fix (the driver's fix count moved on). min_sats: AHRS_GPS_MINSATS. True when
    // home was set from it (home(), home_source()).
    bool on_fix(const gps::Fix& fix, const BaroReading& baro, uint8_t min_sats);
    // The position moved on to now_ms and the height from the barometer (10 Hz between fixes).
    void update(uint32_t now_ms, const BaroReading& baro);

    // The ground station's home: here (false: no position yet), or a place (false: a
    // latitude or longitude off the earth, a height outside -1000..20000 m).
    bool set_home_here(const BaroReading& baro);
    bool set_home(const Location& home, const BaroReading& baro);

    bool home_set() const { return home_source_ != HomeSource::kNone; }
    HomeSource home_source() const { return home_source_; }
    constexpr const Location& home() const { return home_; }
    // Counts every change of home (the ground station is told each, HOME_POSITION).
    uint8_t home_changes() const { return home_changes_; }

    // A 3D fix was taken (the position below means something).
    bool have_position() const { return have_position_; }
    // Now, moved on (update()); alt_cm above mean sea level.
    const Location& position() const { return position_; }
    // Metres north and east, and up, from home (0 until home is set): worked out on each
    // call (a few float operations) rather than kept.
    NorthEast from_home_m() const;
    float north_m() const { return from_home_m().north_m; }
    float east_m() const { return from_home_m().east_m; }
    float height_above_home_m() const;
    // The barometer gives the height (else the GPS).
    bool height_from_baro() const { return height_from_baro_; }
    // The last fix's velocity, m/s north, east, down.
    const float* velocity_ned_m_s() const { return vel_ned_m_s_; }
    NorthEast ground_velocity_m_s() const { return NorthEast{vel_ned_m_s_[0], vel_ned_m_s_[1]}; }

    // Fixes dead-reckoned over (the driver said they glitched), since power-up.
    uint16_t glitched_fixes() const { return glitched_fixes_; }
    constexpr const LocalMap& map() const { return map_; }

private:
    void take_home(const Location& home, const BaroReading& baro, HomeSource source);

    LocalMap map_;             // at home, else at the first fix
    Location home_;
    Location base_;            // the last good fix, dead-reckoned over rejected ones
    Location position_;
    uint32_t base_ms_ = 0;     // the board's time of base_'s fix
    uint32_t now_ms_ = 0;      // of the last update()
    float vel_ned_m_s_[3] = {0.0f, 0.0f, 0.0f};
    int32_t baro_datum_cm_ = 0;  // mean sea level height of the barometer's zero
    HomeSource home_source_ = HomeSource::kNone;
    uint8_t home_changes_ = 0;
    uint16_t glitched_fixes_ = 0;
    bool have_position_ = false;
    bool have_datum_ = false;
    bool height_from_baro_ = false;
};

}  // namespace nav
