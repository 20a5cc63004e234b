// SPDX-License-Identifier: GPL-3.0-or-later
// The flight settings: gains, limits, channel map, receiver and servo end points,
// failsafe values. Names follow ArduPlane's parameters (lib/Settings/Params.cpp lists them with their
// ranges and defaults: the defaults live there only, params::apply_defaults).
//
// Units: widths in microseconds; angles in centi-degrees (ArduPilot's _CD); gains as
// ArduPilot's AP_RollController / AP_PitchController take them: P in degrees of surface
// per degree of attitude error, D in degrees of surface per deg/s of rate error, I in
// degrees of surface per degree of rate error integrated over a second, the integrator
// limit in centi-degrees of surface (4500 = full throw).
#pragma once

#include <stdint.h>

namespace flight {

constexpr uint8_t kChannels = 8;  // receiver channels (the APM 2.5's PPM encoder) and servo outputs

// One axis controller's gains (RLL2SRV_*, PTCH2SRV_*).
struct AxisGains {
    float tconst_s;   // time constant: attitude error -> demanded rate, s
    float p;          // deg of surface per deg of error
    float i;          // deg of surface per deg of rate error x s
    float d;          // deg of surface per deg/s of rate error
    int16_t imax_cd;  // integrator limit, centi-degrees of surface
};

// A receiver channel's or a servo output's end points (RCn_*, SERVOn_*).
struct EndPoints {
    uint16_t min_us;
    uint16_t max_us;
    uint16_t trim_us;  // the neutral width
};

// ArduPlane's flight mode numbers (FLTMODEn values) of the modes the board has (Modes.h).
enum class Mode : uint8_t {
    Manual = 0,
    Circle = 1,
    Stabilize = 2,
    FlyByWireA = 5,
    FlyByWireB = 6,
    Cruise = 7,
    Auto = 10,
    Rtl = 11,
    Loiter = 12,
    Guided = 15,
};

struct FlightSettings {
    AxisGains roll;             // RLL2SRV_*
    AxisGains pitch;            // PTCH2SRV_*
    float pitch_roll_ff;        // PTCH2SRV_RLL: turn coordination gain (1 = the coordinated turn's pitch rate)
    int16_t lim_roll_cd;        // LIM_ROLL_CD: full roll stick in STABILIZE, centi-degrees of bank
    int16_t lim_pitch_max_cd;   // LIM_PITCH_MAX: full up stick
    int16_t lim_pitch_min_cd;   // LIM_PITCH_MIN: full down stick (negative)
    int16_t fs_pitch_cd;        // FS_GLIDE_PITCH: the failsafe glide's pitch from the trim (negative: nose down)
    int16_t trim_pitch_cd;      // TRIM_PITCH_CD: the pitch held with the stick centred, added to every demand
    uint16_t thr_fs_value_us;   // THR_FS_VALUE: throttle channel below this = the encoder's failsafe
    uint8_t thr_fs_pct;         // THR_FS_OUT: throttle output in failsafe, percent
    uint8_t arspd_min_m_s;      // ARSPD_FBW_MIN: the airspeed assumed (no sensor) is the mean of
    uint8_t arspd_max_m_s;      // ARSPD_FBW_MAX:   these two, for the turn coordination
    uint16_t trim_arspd_cm;     // TRIM_ARSPD_CM: cruise airspeed, cm/s, for the estimator's centripetal
                                //   correction on a board without an airspeed sensor (0: none)
    uint8_t fltmode_ch;         // FLTMODE_CH: the mode switch's channel, 1..8 (0: none)
    uint8_t fltmode[6];         // FLTMODE1..6: Mode of each switch position (ArduPlane's six bands)
    uint8_t rcmap[4];           // RCMAP_ROLL, _PITCH, _THROTTLE, _YAW: channel numbers 1..8
    uint8_t elevon_output;      // ELEVON_OUTPUT: 1 = elevons on OUT1 (left) and OUT2 (right)
    uint8_t vtail_output;       // VTAIL_OUTPUT: 1 = V-tail on OUT2 (left) and OUT4 (right)
    uint8_t rc_reversed;        // RCn_REVERSED: bit n-1
    uint8_t servo_reversed;     // SERVOn_REVERSED: bit n-1
    EndPoints rc[kChannels];    // RCn_MIN, _MAX, _TRIM
    EndPoints servo[kChannels]; // SERVOn_MIN, _MAX, _TRIM
    // The GPS and the estimator's use of it, the barometer's datum (ArduPilot's AP_GPS,
    // AP_AHRS and AP_Baro names).
    uint8_t gps_type;           // GPS_TYPE: 0 none, 1 auto, 2 u-blox, 5 NMEA
    uint8_t gps_navfilter;      // GPS_NAVFILTER: the u-blox's dynamic model (CFG-NAV5 dynModel)
    float ahrs_gps_gain;        // AHRS_GPS_GAIN: weight of the GPS acceleration in the gravity reference
    uint8_t ahrs_gps_use;       // AHRS_GPS_USE: 0 = the estimator ignores the GPS
    uint8_t ahrs_gps_minsats;   // AHRS_GPS_MINSATS: satellites a fix needs to be used
    float gnd_temp_c;           // GND_TEMP: the ground's air temperature, degC (0: the barometer's own)
};

// The channel map's roles (index into rcmap).
enum Role : uint8_t { kRoll = 0, kPitch = 1, kThrottle = 2, kYaw = 3 };

}  // namespace flight
