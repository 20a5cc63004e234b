// SPDX-License-Identifier: GPL-3.0-or-later
#include "Params.h"

#include <stddef.h>
#include <string.h>

#include "Constants.h"
#include "Modes.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define PARAM_TABLE PROGMEM
#define COPY_ROW(dst, src) memcpy_P((dst), (src), sizeof(Row))
#else
#define PARAM_TABLE
#define COPY_ROW(dst, src) memcpy((dst), (src), sizeof(Row))
#endif

// What a row means, beside it (ArduPilot's @DisplayName, @Units and @Description): the
// parameter reference, docs/parameters.md, is printed from these (tools/paramdoc, make
// docs). Only host builds keep the words: on the AVR the macro is empty, the row ends in
// a trailing comma, and the table in flash is what it would be without them.
#if defined(__AVR__)
#define PARAM_DOC(display_name, units, description)
#else
#define PARAM_DOC(display_name, units, description) display_name, units, description
#endif

namespace params {

namespace {

using settings::Settings;

// One row: a parameter, or `count` numbered ones whose name has '#' for the number
// (first, first+1, ...) and whose values lie `stride` bytes apart (Bit: bit i of the
// byte at offset).
struct Row {
    char name[kNameMax + 1];
    Type type;
    uint8_t first;
    uint8_t count;
    uint8_t stride;
    uint16_t offset;
    float min, max, def;
#if !defined(__AVR__)
    const char* display_name;  // a few words (ArduPilot's @DisplayName)
    const char* units;         // "" for none
    const char* description;   // what it does here, in a sentence or three
#endif
};

#define AT(member) ((uint16_t)offsetof(Settings, member))
constexpr uint8_t kEp = (uint8_t)sizeof(flight::EndPoints);
constexpr uint8_t kN = flight::kChannels;

// The ranges are ArduPilot's where it documents one, the widths' the PPM decoder's
// plausible ones. The defaults are ArduPlane's but for the integrator gains. Roll: ArduPlane
// 3's 0.04, not the 0.3 of its later releases, which also stores an upset's rate error and
// answers it with surface the other way once the upset is over; a lasting roll error is only
// an aileron out of trim. Pitch: ArduPlane's later 0.3, since the elevator a pitch needs
// moves with the airspeed and the power: at full power the speed doubles within seconds and
// the trim elevator pitches the nose up as it does. The integrator takes such an offset up
// with a time constant of P' / (TCONST I), P' / TCONST being the feed-forward's 0.77-0.9 deg
// of surface per deg of error: 22 s at 0.04, 2.6 s at 0.3, faster than the speed builds up
// (about 5 s), so that it follows the elevator the climb needs instead of lagging it.
// TCONST 0.5 s is slower than a trainer's roll and pitch response (a few tenths of a
// second), so the demanded rates are ones it can fly; P 1 and D 0.08 (roll), 0.04 (pitch)
// and IMAX 3000 (two thirds of the throw) are ArduPlane's, for models of this size.
const Row kRows[] PARAM_TABLE = {
    {"RLL2SRV_TCONST", Type::Float, 0, 1, 0, AT(flight.roll.tconst_s), 0.4f, 1.0f, 0.5f,
     PARAM_DOC("Roll time constant", "s",
               "How fast STABILIZE brings the bank to the one asked for: the roll error over this time is the "
               "demanded roll rate. 0.5 s suits most models; less than the aeroplane can achieve does not help.")},
    {"RLL2SRV_P", Type::Float, 0, 1, 0, AT(flight.roll.p), 0.1f, 4.0f, 1.0f,
     PARAM_DOC("Roll proportional gain", "deg/deg",
               "Degrees of aileron per degree of roll error, as ArduPilot's roll controller takes it: a "
               "feed-forward of (P - I TCONST) TCONST - D on the demanded roll rate. Higher answers harder; too "
               "high oscillates.")},
    {"RLL2SRV_I", Type::Float, 0, 1, 0, AT(flight.roll.i), 0.0f, 1.0f, 0.04f,
     PARAM_DOC("Roll integrator gain", "1/s",
               "Trims out a lasting roll error (an aileron out of trim, a steady moment): the roll-rate error "
               "times I TCONST is summed, within RLL2SRV_IMAX, and does not grow while the aileron is at full "
               "throw. 0: no integrator.")},
    {"RLL2SRV_D", Type::Float, 0, 1, 0, AT(flight.roll.d), 0.0f, 0.2f, 0.08f,
     PARAM_DOC("Roll damping gain", "deg/(deg/s)",
               "Degrees of aileron per deg/s of roll-rate error (the demanded rate less the gyro's): damps the "
               "roll. Higher resists turbulence; too high oscillates.")},
    {"RLL2SRV_IMAX", Type::Int16, 0, 1, 0, AT(flight.roll.imax_cd), 0.0f, 4500.0f, 3000.0f,
     PARAM_DOC("Roll integrator limit", "cdeg",
               "The most aileron the integrator may hold, in centi-degrees of surface: 4500 is full throw, 3000 "
               "two thirds of it.")},
    {"PTCH2SRV_TCONST", Type::Float, 0, 1, 0, AT(flight.pitch.tconst_s), 0.4f, 1.0f, 0.5f,
     PARAM_DOC("Pitch time constant", "s",
               "How fast STABILIZE brings the pitch to the one asked for: the pitch error over this time is the "
               "demanded pitch rate.")},
    {"PTCH2SRV_P", Type::Float, 0, 1, 0, AT(flight.pitch.p), 0.1f, 4.0f, 1.0f,
     PARAM_DOC("Pitch proportional gain", "deg/deg",
               "Degrees of elevator per degree of pitch error (a feed-forward on the demanded pitch rate, as "
               "RLL2SRV_P).")},
    {"PTCH2SRV_I", Type::Float, 0, 1, 0, AT(flight.pitch.i), 0.0f, 1.0f, 0.3f,
     PARAM_DOC("Pitch integrator gain", "1/s",
               "Trims out a lasting pitch error (an elevator out of trim, the elevator a faster or full-power flight "
               "needs): the pitch-rate error times I TCONST is "
               "summed, within PTCH2SRV_IMAX, and does not grow while the elevator is at full throw. 0: no "
               "integrator.")},
    {"PTCH2SRV_D", Type::Float, 0, 1, 0, AT(flight.pitch.d), 0.0f, 0.2f, 0.04f,
     PARAM_DOC("Pitch damping gain", "deg/(deg/s)",
               "Degrees of elevator per deg/s of pitch-rate error (the demanded rate less the gyro's): damps the "
               "pitch.")},
    {"PTCH2SRV_IMAX", Type::Int16, 0, 1, 0, AT(flight.pitch.imax_cd), 0.0f, 4500.0f, 3000.0f,
     PARAM_DOC("Pitch integrator limit", "cdeg",
               "The most elevator the integrator may hold, in centi-degrees of surface (4500: full throw).")},
    {"PTCH2SRV_RLL", Type::Float, 0, 1, 0, AT(flight.pitch_roll_ff), 0.7f, 1.5f, 1.0f,
     PARAM_DOC("Roll compensation", "",
               "Turn coordination in STABILIZE and the failsafe: the pitch rate a level turn needs at the present "
               "bank, g / V tan(bank) sin(bank) cos(pitch), times this gain, is added to the demanded pitch rate "
               "(V: the airspeed sensor's reading, at least ARSPD_FBW_MIN; without a sensor TRIM_ARSPD_CM, or the "
               "mean of ARSPD_FBW_MIN and ARSPD_FBW_MAX when that is 0). Raise it if the aeroplane loses height in "
               "turns.")},
    {"LIM_ROLL_CD", Type::Int16, 0, 1, 0, AT(flight.lim_roll_cd), 0.0f, 9000.0f, 4500.0f,
     PARAM_DOC("Maximum bank angle", "cdeg",
               "The bank that full roll stick asks for in STABILIZE, either way; the stick centred asks for the "
               "wings level.")},
    {"LIM_PITCH_MAX", Type::Int16, 0, 1, 0, AT(flight.lim_pitch_max_cd), 0.0f, 9000.0f, 2500.0f,
     PARAM_DOC("Maximum pitch angle", "cdeg", "The pitch that full up (back) stick asks for in STABILIZE.")},
    {"LIM_PITCH_MIN", Type::Int16, 0, 1, 0, AT(flight.lim_pitch_min_cd), -9000.0f, 0.0f, -2500.0f,
     PARAM_DOC("Minimum pitch angle", "cdeg",
               "The pitch that full down stick asks for in STABILIZE (negative: nose down).")},
    {"FS_GLIDE_PITCH", Type::Int16, 0, 1, 0, AT(flight.fs_pitch_cd), -3000.0f, 0.0f, -500.0f,
     PARAM_DOC("Failsafe glide pitch", "cdeg",
               "The pitch FAILSAFE holds, wings level, while the receiver is lost, from TRIM_PITCH_CD (negative: "
               "nose down of the trim, a gentle glide). This firmware's own name.")},
    {"THR_FS_VALUE", Type::UInt16, 0, 1, 0, AT(flight.thr_fs_value_us), 800.0f, 1100.0f, 950.0f,
     PARAM_DOC("Throttle failsafe value", "us",
               "A receiver frame whose throttle channel (RCMAP_THROTTLE, as received) is below this width is the "
               "PPM encoder's or the receiver's failsafe, not the pilot's: its mode switch is not read, and after "
               "0.5 s without a good frame the board enters FAILSAFE. Set the receiver's own failsafe below it.")},
    {"THR_FS_OUT", Type::UInt8, 0, 1, 0, AT(flight.thr_fs_pct), 0.0f, 100.0f, 0.0f,
     PARAM_DOC("Failsafe throttle", "%",
               "The throttle on OUT3 in FAILSAFE and from power-up until the receiver's first good frame, percent "
               "of SERVO3_MIN to SERVO3_MAX (0: the motor off). This firmware's own name.")},
    {"ARSPD_FBW_MIN", Type::UInt8, 0, 1, 0, AT(flight.arspd_min_m_s), 5.0f, 50.0f, 9.0f,
     PARAM_DOC("Minimum airspeed", "m/s",
               "The least airspeed the turn coordination (PTCH2SRV_RLL) takes from the airspeed sensor; without a "
               "sensor and with TRIM_ARSPD_CM 0 it assumes the mean of this and ARSPD_FBW_MAX.")},
    {"ARSPD_FBW_MAX", Type::UInt8, 0, 1, 0, AT(flight.arspd_max_m_s), 5.0f, 50.0f, 22.0f,
     PARAM_DOC("Maximum airspeed", "m/s",
               "With ARSPD_FBW_MIN, the airspeed the turn coordination (PTCH2SRV_RLL) assumes without a sensor "
               "and with TRIM_ARSPD_CM 0: the mean of the two.")},
    // TRIM_ARSPD_CM's default: the top of a 1-1.5 m trainer's cruise (12-15 m/s; ArduPlane's
    // 12). Too low a speed leaves part of a turn's centripetal acceleration in the gravity
    // the estimator levels on: it reads less bank than flown, STABILIZE banks further and
    // the turn tightens into a spiral. Too high a speed reads more bank than flown, and
    // STABILIZE banks less than asked: the safe side, so the default errs high.
    {"TRIM_ARSPD_CM", Type::UInt16, 0, 1, 0, AT(flight.trim_arspd_cm), 0.0f, 5000.0f, 1500.0f,
     PARAM_DOC("Cruise airspeed", "cm/s",
               "For a board without the airspeed sensor on A0: the speed the estimator takes for the centripetal "
               "acceleration of a turn (omega x V, taken off the accelerometer) while the throttle stick is above "
               "10 %, grown in a banked turn as the lift needs, V / sqrt(cos bank), and the turn coordination's "
               "airspeed. Set it to the model's cruise speed; if in doubt, higher rather than lower: a speed too "
               "low reads less bank than flown in a turn and STABILIZE tightens the turn, one too high banks less "
               "than asked. 0: no correction (sustained turns then spiral down); below 9 m/s none either. A fitted "
               "sensor's reading is used instead.")},
    {"FLTMODE_CH", Type::UInt8, 0, 1, 0, AT(flight.fltmode_ch), 0.0f, 8.0f, 8.0f,
     PARAM_DOC("Flight mode channel", "",
               "The receiver channel of the mode switch; its width picks one of FLTMODE1 to FLTMODE6 by "
               "ArduPlane's six bands. 0: no switch, the console's `flight` command only.")},
    {"FLTMODE1", Type::UInt8, 0, 1, 0, AT(flight.fltmode[0]), 0.0f, 5.0f, 0.0f,
     PARAM_DOC("Flight mode 1", "",
               "The mode of the switch's position 1 (up to 1230 us): 0 MANUAL, 2 STABILIZE, 5 FBWA (ArduPlane's "
               "numbers; FBWA flies as STABILIZE does). Any other number is refused.")},
    {"FLTMODE#", Type::UInt8, 2, 5, 1, AT(flight.fltmode[1]), 0.0f, 5.0f, 2.0f,
     PARAM_DOC("Flight mode n", "",
               "The mode of the switch's position n (2: 1231 to 1360 us, 3: to 1490, 4: to 1620, 5: to 1749, 6: "
               "above): 0 MANUAL, 2 STABILIZE, 5 FBWA; any other number is refused.")},
    {"RCMAP_ROLL", Type::UInt8, 0, 1, 0, AT(flight.rcmap[0]), 1.0f, 8.0f, 1.0f,
     PARAM_DOC("Roll channel", "", "The receiver channel of the roll (aileron) stick.")},
    {"RCMAP_PITCH", Type::UInt8, 0, 1, 0, AT(flight.rcmap[1]), 1.0f, 8.0f, 2.0f,
     PARAM_DOC("Pitch channel", "", "The receiver channel of the pitch (elevator) stick.")},
    {"RCMAP_THROTTLE", Type::UInt8, 0, 1, 0, AT(flight.rcmap[2]), 1.0f, 8.0f, 3.0f,
     PARAM_DOC("Throttle channel", "",
               "The receiver channel of the throttle stick, which THR_FS_VALUE watches.")},
    {"RCMAP_YAW", Type::UInt8, 0, 1, 0, AT(flight.rcmap[3]), 1.0f, 8.0f, 4.0f,
     PARAM_DOC("Yaw channel", "", "The receiver channel of the rudder stick.")},
    {"ELEVON_OUTPUT", Type::UInt8, 0, 1, 0, AT(flight.elevon_output), 0.0f, 1.0f, 0.0f,
     PARAM_DOC("Elevon output", "",
               "1: elevons, the left on OUT1 and the right on OUT2, each half of the elevator and half of the "
               "aileron command (ArduPlane's MIXING_GAIN 0.5): left (elevator - aileron) / 2, right (elevator + "
               "aileron) / 2. ArduPlane's values 1 to 4 choose the signs; here SERVO1_REVERSED and "
               "SERVO2_REVERSED do.")},
    {"VTAIL_OUTPUT", Type::UInt8, 0, 1, 0, AT(flight.vtail_output), 0.0f, 1.0f, 0.0f,
     PARAM_DOC("V-tail output", "",
               "1: a V-tail, the left ruddervator on OUT2 and the right on OUT4, each half of the elevator and "
               "half of the rudder command: left (elevator + rudder) / 2, right (elevator - rudder) / 2 (ArduPlane's: a right rudder raises the left trailing edge and lowers the right, and the nose yaws right).")},
    {"RC#_MIN", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].min_us), 800.0f, 2200.0f, 1000.0f,
     PARAM_DOC("RC minimum", "us",
               "Receiver channel n's width at the stick's low end (what `rc` shows there). With RCn_TRIM and "
               "RCn_MAX it turns a stick channel's width (one RCMAP_* names) into a command; the mode switch and "
               "the widths passed to OUT5 to OUT8 (channels 5 to 8) are used as received.")},
    {"RC#_MAX", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].max_us), 800.0f, 2200.0f, 2000.0f,
     PARAM_DOC("RC maximum", "us", "Receiver channel n's width at the stick's high end.")},
    {"RC#_TRIM", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].trim_us), 800.0f, 2200.0f, 1500.0f,
     PARAM_DOC("RC trim", "us",
               "Receiver channel n's width with the stick centred: no command (the throttle runs from RCn_MIN to "
               "RCn_MAX).")},
    {"RC#_REVERSED", Type::Bit, 1, kN, 0, AT(flight.rc_reversed), 0.0f, 1.0f, 0.0f,
     PARAM_DOC("RC reversed", "",
               "1: stick channel n is read the other way (for a radio that sends, say, nose up below its trim).")},
    {"SERVO#_MIN", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].min_us), 800.0f, 2200.0f, 1000.0f,
     PARAM_DOC("Servo minimum", "us",
               "Output n's shortest pulse: no pulse on OUTn is ever shorter. A surface's full throw one way; on "
               "OUT3 the throttle's zero.")},
    {"SERVO#_MAX", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].max_us), 800.0f, 2200.0f, 2000.0f,
     PARAM_DOC("Servo maximum", "us",
               "Output n's longest pulse: no pulse on OUTn is ever longer. A surface's full throw the other way; "
               "on OUT3 full throttle.")},
    {"SERVO#_TRIM", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].trim_us), 800.0f, 2200.0f, 1500.0f,
     PARAM_DOC("Servo trim", "us",
               "Output n's neutral: a surface with no command, centred with it; OUT5 to OUT8 are reversed about "
               "it. OUT3, the throttle, does not use it.")},
    {"SERVO#_REVERSED", Type::Bit, 1, kN, 0, AT(flight.servo_reversed), 0.0f, 1.0f, 0.0f,
     PARAM_DOC("Servo reversed", "",
               "1: output n moves the other way: a surface about its trim, the throttle from SERVO3_MAX down.")},
    // Rows added after version 3 of the record go here, after the flight rows before them
    // (Settings.h: an older record is then the new one's first part).
    {"TRIM_PITCH_CD", Type::Int16, 0, 1, 0, AT(flight.trim_pitch_cd), -4500.0f, 4500.0f, 0.0f,
     PARAM_DOC("Pitch trim", "cdeg",
               "The pitch STABILIZE holds with the stick centred, and the reference of the stick's pitch and of "
               "the failsafe glide (FS_GLIDE_PITCH is added to it), as ArduPlane adds it to every pitch it asks "
               "for. Find it in the set-up: trim the model for level cruise in MANUAL, read the pitch the board "
               "shows, set it here. 0 holds the board level, and a model whose trim is nose up then sinks.")},
    // Version 5: the GPS, the estimator's use of it, the barometer's datum.
    {"GPS_TYPE", Type::UInt8, 0, 1, 0, AT(flight.gps_type), 0.0f, 5.0f, 1.0f,
     PARAM_DOC("GPS type", "",
               "The receiver on the GPS port: 0 none (the port is left silent), 1 auto (a u-blox is looked for at "
               "38400, 57600, 9600, 115200 and 4800 baud and set to binary UBX at 5 Hz; a module that only "
               "speaks NMEA is taken as it is), 2 u-blox only, 5 NMEA only. 3 and 4 (ArduPilot's MediaTek "
               "receivers) are taken as 1.")},
    {"GPS_NAVFILTER", Type::UInt8, 0, 1, 0, AT(flight.gps_navfilter), 0.0f, 8.0f, 8.0f,
     PARAM_DOC("GPS navigation filter", "",
               "The u-blox's dynamic platform model (CFG-NAV5 dynModel), written to the module when it differs: "
               "8 airborne below 4 g (an aeroplane), 0 portable, 2 stationary, 3 pedestrian, 4 automotive, 5 "
               "sea, 6 airborne below 1 g, 7 airborne below 2 g.")},
    {"AHRS_GPS_GAIN", Type::Float, 0, 1, 0, AT(flight.ahrs_gps_gain), 0.0f, 10.0f, 1.0f,
     PARAM_DOC("AHRS GPS gain", "",
               "How strongly the estimator takes the acceleration measured by the GPS (the change of its "
               "velocity) out of the accelerometer's gravity reference: 1 wholly, 0 not at all.")},
    {"AHRS_GPS_USE", Type::UInt8, 0, 1, 0, AT(flight.ahrs_gps_use), 0.0f, 1.0f, 1.0f,
     PARAM_DOC("AHRS use GPS", "",
               "1: the estimator uses the GPS velocity (and its course when there is no compass); 0: it never "
               "does, as without a GPS.")},
    {"AHRS_GPS_MINSATS", Type::UInt8, 0, 1, 0, AT(flight.ahrs_gps_minsats), 0.0f, 10.0f, 6.0f,
     PARAM_DOC("AHRS GPS minimum satellites", "",
               "A 3D fix is used by the estimator, and may set home, only with at least this many satellites.")},
    {"GND_TEMP", Type::Float, 0, 1, 0, AT(flight.gnd_temp_c), -40.0f, 80.0f, 0.0f,
     PARAM_DOC("Ground temperature", "degC",
               "The air's temperature on the ground, for the height from the pressure: 0 takes the barometer's "
               "own at start-up (a chip inside a warm fuselage reads high: about 0.35 % of the height per "
               "degree).")},
    {"GND_ABS_PRESS", Type::Float, 0, 1, 0, AT(gnd_abs_press_pa), 0.0f, 120000.0f, 0.0f,
     PARAM_DOC("Ground pressure", "Pa",
               "The pressure at home, measured at each start while the gyro calibrates (0 until then): the "
               "height above home is taken from it. Not saved.")},
    {"COMPASS_DEC", Type::DeclRad, 0, 1, 0, AT(declination_centideg), -3.1416f, 3.1416f, 0.0f,
     PARAM_DOC("Compass declination", "rad",
               "The angle from true north to magnetic north, east positive, added to the heading the board "
               "reports: `decl` sets the same in degrees. Kept to a hundredth of a degree.")},
    // The second record's rows (settings::VehicleSettings), each feature under its heading.
    // Arming.
    {"ARMING_REQUIRE", Type::UInt8, 0, 1, 0, AT(vehicle.arming_require), 0.0f, 1.0f, 1.0f,
     PARAM_DOC("Require arming", "",
               "1: the throttle output holds its minimum until the board is armed (the surfaces stay live); 0: "
               "the throttle follows the stick from power-up and the board always reports armed.")},
    {"ARMING_CHECK", Type::UInt16, 0, 1, 0, AT(vehicle.arming_check), 0.0f, 8191.0f, 1.0f,
     PARAM_DOC("Arm checks to perform", "",
               "The pre-arm checks, ArduPilot's bitmask: 1 all; else 2 barometer (healthy if present), 4 compass "
               "(healthy and calibrated if found at start-up, not calibrating), 16 inertial sensors (the MPU6000 "
               "answering, the gyro calibrated, the estimator running), 32 parameters (the settings loaded, not "
               "defaults after an unreadable record), 64 receiver (a frame seen, no failsafe, the throttle at "
               "zero). 8 (GPS) and the others have nothing to check on this board. 0: none.")},
    // ARMING_RUDDER's default, ArduPlane's 1 (arm only): the board cannot tell it is flying
    // without a pitot or a GPS fix, and a full-left rudder with the throttle closed (a
    // spin's recovery, a glide's crosswind) must not cut the motor in the air.
    {"ARMING_RUDDER", Type::UInt8, 0, 1, 0, AT(vehicle.arming_rudder), 0.0f, 2.0f, 1.0f,
     PARAM_DOC("Rudder arming", "",
               "Arming by the rudder stick with the throttle at zero (within 3 % of RCn_MIN): 1 full right rudder "
               "for 3 s arms (if the pre-arm checks pass); 2 also full left for 3 s disarms, unless the pitot or "
               "the GPS says the aeroplane moves faster than 5 m/s; 0 no rudder arming.")},
    {"RC_OVERRIDE_TIME", Type::Float, 0, 1, 0, AT(vehicle.rc_override_time_s), -1.0f, 120.0f, 3.0f,
     PARAM_DOC("RC override timeout", "s",
               "How long a ground station's RC_CHANNELS_OVERRIDE holds a channel after its last message; then "
               "the receiver has it again. 0: overrides are ignored; -1: they never time out (until released "
               "with 0).")},

    // Board orientation, level, the accelerometer's calibration.

    // Compass.

    // Battery monitor and its failsafe.

    // Telemetry rates.

};
#undef AT
constexpr uint8_t kRowCount = (uint8_t)(sizeof kRows / sizeof kRows[0]);

constexpr float kRadPerCentideg = linalg::kPi / 18000.0f;

// The row holding index, and the instance within it; false past the end.
bool locate(uint16_t index, Row& row, uint8_t& instance) {
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        if (index < row.count) {
            instance = (uint8_t)index;
            return true;
        }
        index = (uint16_t)(index - row.count);
    }
    return false;
}

uint8_t* where(Settings& s, const Row& row, uint8_t instance) {
    return reinterpret_cast<uint8_t*>(&s) + row.offset + (uint16_t)row.stride * instance;
}

float read(const Settings& s, const Row& row, uint8_t instance) {
    const uint8_t* p = where(const_cast<Settings&>(s), row, instance);
    switch (row.type) {
        case Type::Float: { float v; memcpy(&v, p, sizeof v); return v; }
        case Type::Int16: { int16_t v; memcpy(&v, p, sizeof v); return (float)v; }
        case Type::UInt16: { uint16_t v; memcpy(&v, p, sizeof v); return (float)v; }
        case Type::UInt8: return (float)*p;
        case Type::Bit: return (float)((*p >> instance) & 1u);
        case Type::DeclRad: { int16_t v; memcpy(&v, p, sizeof v); return (float)v * kRadPerCentideg; }
    }
    return 0.0f;
}

// Stores a value already checked against the row's range.
void write(Settings& s, const Row& row, uint8_t instance, float value) {
    uint8_t* p = where(s, row, instance);
    const int32_t whole = (int32_t)(value >= 0.0f ? value + 0.5f : value - 0.5f);
    switch (row.type) {
        case Type::Float: memcpy(p, &value, sizeof value); break;
        case Type::Int16: { const int16_t v = (int16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt16: { const uint16_t v = (uint16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt8: *p = (uint8_t)whole; break;
        case Type::Bit:
            *p = whole != 0 ? (uint8_t)(*p | (1u << instance)) : (uint8_t)(*p & ~(1u << instance));
            break;
        case Type::DeclRad: {
            const float cd = value / kRadPerCentideg;
            int16_t v = (int16_t)(cd >= 0.0f ? cd + 0.5f : cd - 0.5f);
            if (v > settings::kDeclMaxCentideg) v = settings::kDeclMaxCentideg;
            if (v < settings::kDeclMinCentideg) v = settings::kDeclMinCentideg;
            memcpy(p, &v, sizeof v);
            break;
        }
    }
}

bool in_range(const Row& row, float v) {
    if (!(v >= row.min && v <= row.max)) return false;  // NaN fails too
    return !is_integer(row.type) || v == (float)(int32_t)v;
}

bool ends_in_order(const flight::EndPoints* eps) {
    for (uint8_t i = 0; i < flight::kChannels; ++i)
        if (!(eps[i].min_us <= eps[i].trim_us && eps[i].trim_us <= eps[i].max_us)) return false;
    return true;
}

char upper(char c) { return (c >= 'a' && c <= 'z') ? (char)(c - 'a' + 'A') : c; }

}  // namespace

bool is_integer(Type t) { return t != Type::Float && t != Type::DeclRad; }

uint16_t count() {
    uint16_t n = 0;
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        n = (uint16_t)(n + row.count);
    }
    return n;
}

bool info(uint16_t index, Info& out) {
    Row row;
    uint8_t instance;
    if (!locate(index, row, instance)) return false;
    uint8_t o = 0;
    for (uint8_t i = 0; row.name[i] != '\0' && o < kNameMax; ++i)
        out.name[o++] = row.name[i] == '#' ? (char)('0' + row.first + instance) : row.name[i];
    out.name[o] = '\0';
    out.type = row.type;
    out.min = row.min;
    out.max = row.max;
    out.def = row.def;
    return true;
}

// One pass over the rows (a numbered row matched by its prefix, one digit, its suffix),
// not info() for every index: MAVLink's PARAM_SET and PARAM_REQUEST_READ look names up
// between samples.
int16_t find(const char* name) {
    Row row;
    uint16_t index = 0;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        uint8_t i = 0, j = 0;  // row.name, name
        int16_t instance = 0;
        bool match = true;
        while (match && row.name[i] != '\0') {
            if (row.name[i] == '#') {
                const char c = name[j++];
                instance = (int16_t)(c - '0' - (char)row.first);
                match = c >= '0' && c <= '9' && instance >= 0 && instance < row.count;
            } else {
                match = upper(name[j++]) == row.name[i];
            }
            ++i;
        }
        if (match && name[j] == '\0') return (int16_t)(index + instance);
        index = (uint16_t)(index + row.count);
    }
    return -1;
}

float get(const Settings& s, uint16_t index) {
    Row row;
    uint8_t instance;
    return locate(index, row, instance) ? read(s, row, instance) : 0.0f;
}

namespace {
bool holds_flight_mode(const Row& row) {
    return row.offset >= offsetof(Settings, flight.fltmode) &&
           row.offset < offsetof(Settings, flight.fltmode) + sizeof(flight::FlightSettings::fltmode);
}
}  // namespace

bool is_flight_mode(uint16_t index) {
    Row row;
    uint8_t instance;
    return locate(index, row, instance) && holds_flight_mode(row);
}

bool set(Settings& s, uint16_t index, float value) {
    Row row;
    uint8_t instance;
    if (!locate(index, row, instance) || !in_range(row, value)) return false;
    // FLTMODEn: a mode the board has (a stored number it lacks still loads, and flies MANUAL).
    if (holds_flight_mode(row) && !flight::mode_known((uint8_t)value)) return false;
    const float before = read(s, row, instance);
    write(s, row, instance, value);
    if (ends_in_order(s.flight.rc) && ends_in_order(s.flight.servo)) return true;
    write(s, row, instance, before);
    return false;
}

void apply_defaults(Settings& s) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        for (uint8_t i = 0; i < row.count; ++i) write(s, row, i, row.def);
    }
}

bool all_valid(const Settings& s) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        for (uint8_t i = 0; i < row.count; ++i)
            if (!in_range(row, read(s, row, i))) return false;
    }
    return ends_in_order(s.flight.rc) && ends_in_order(s.flight.servo);
}

#if !defined(__AVR__)
uint8_t row_count() { return kRowCount; }

bool row_doc(uint8_t row, RowDoc& out) {
    if (row >= kRowCount) return false;
    const Row& r = kRows[row];
    out = RowDoc{r.name, r.first, r.count, r.type, r.min, r.max, r.def, r.display_name, r.units, r.description};
    return true;
}
#endif

namespace {

uint8_t stored_bytes(Type t) {
    switch (t) {
        case Type::Float: return 4;
        case Type::Int16:
        case Type::UInt16:
        case Type::DeclRad: return 2;
        default: return 1;
    }
}

// Calls f(pointer to the value's bytes, their count) for every stored value of the
// flight settings, in the record's order.
template <typename F>
void each_flight_value(const Settings& s, F f) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        if (row.offset < offsetof(Settings, flight) || row.offset >= offsetof(Settings, vehicle)) continue;
        const uint8_t n = row.type == Type::Bit ? 1 : row.count;
        for (uint8_t i = 0; i < n; ++i) f(where(const_cast<Settings&>(s), row, i), stored_bytes(row.type));
    }
}

}  // namespace

// The AVR and every host this builds on are little-endian: a value's bytes are its
// record bytes.
void encode_flight(const Settings& s, uint8_t out[settings::kFlightBytes]) {
    flight_part(s, 0, settings::kFlightBytes, out);
}

void decode_flight(const uint8_t* in, uint8_t len, Settings& s) {
    uint16_t at = 0;
    each_flight_value(s, [&](uint8_t* p, uint8_t n) {
        if (at + n <= len && at + n <= settings::kFlightBytes) memcpy(p, in + at, n);
        at = (uint16_t)(at + n);
    });
}

void flight_part(const Settings& s, uint8_t from, uint8_t n, uint8_t* out) {
    uint16_t at = 0;
    const uint16_t to = (uint16_t)(from + n);
    each_flight_value(s, [&](uint8_t* p, uint8_t len) {
        for (uint8_t j = 0; j < len; ++j) {
            const uint16_t k = (uint16_t)(at + j);
            if (k >= from && k < to) out[k - from] = p[j];
        }
        at = (uint16_t)(at + len);
    });
}

namespace {

// Calls f(pointer to the value's bytes, their count) for every stored value of the
// second record (Settings::vehicle), in the record's order.
template <typename F>
void each_vehicle_value(const Settings& s, F f) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        if (row.offset < offsetof(Settings, vehicle)) continue;
        const uint8_t n = row.type == Type::Bit ? 1 : row.count;
        for (uint8_t i = 0; i < n; ++i) f(where(const_cast<Settings&>(s), row, i), stored_bytes(row.type));
    }
}

}  // namespace

void vehicle_part(const Settings& s, uint8_t from, uint8_t n, uint8_t* out) {
    uint16_t at = 0;
    const uint16_t to = (uint16_t)(from + n);
    each_vehicle_value(s, [&](uint8_t* p, uint8_t len) {
        for (uint8_t j = 0; j < len; ++j) {
            const uint16_t k = (uint16_t)(at + j);
            if (k >= from && k < to) out[k - from] = p[j];
        }
        at = (uint16_t)(at + len);
    });
}

void decode_vehicle(const uint8_t* in, uint8_t len, Settings& s) {
    uint16_t at = 0;
    each_vehicle_value(s, [&](uint8_t* p, uint8_t n) {
        if (at + n <= len) memcpy(p, in + at, n);
        at = (uint16_t)(at + n);
    });
}

uint16_t vehicle_bytes() {
    uint16_t at = 0;
    const Settings s{};
    each_vehicle_value(s, [&](uint8_t*, uint8_t n) { at = (uint16_t)(at + n); });
    return at;
}

uint16_t flight_bytes() {
    uint16_t at = 0;
    const Settings s{};
    each_flight_value(s, [&](uint8_t*, uint8_t n) { at = (uint16_t)(at + n); });
    return at;
}

}  // namespace params
