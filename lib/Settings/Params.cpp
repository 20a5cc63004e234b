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
#define ROW_BYTE(r, member) ((uint8_t)pgm_read_byte(&kRows[(r)].member))
#define AT_BYTE(row_ptr, member) ((uint8_t)pgm_read_byte(&(row_ptr)->member))
#define ROW_WORD(r, member) ((uint16_t)pgm_read_word(&kRows[(r)].member))
#define ROW_FLOAT(dst, r, member) memcpy_P((dst), &kRows[(r)].member, sizeof(float))
#else
#define PARAM_TABLE
#define COPY_ROW(dst, src) memcpy((dst), (src), sizeof(Row))
#define ROW_BYTE(r, member) ((uint8_t)kRows[(r)].member)
#define AT_BYTE(row_ptr, member) ((uint8_t)(row_ptr)->member)
#define ROW_WORD(r, member) ((uint16_t)kRows[(r)].member)
#define ROW_FLOAT(dst, r, member) memcpy((dst), &kRows[(r)].member, sizeof(float))
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
// A row numbered X, Y, Z ("COMPASS_OFS_#"): the number's character is '0' + first + instance.
constexpr uint8_t kLetterX = (uint8_t)('X' - '0');

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
constexpr Row kRows[] PARAM_TABLE = {
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
    {"FLTMODE1", Type::UInt8, 0, 1, 0, AT(flight.fltmode[0]), 0.0f, 15.0f, 0.0f,
     PARAM_DOC("Flight mode 1", "",
               "The mode of the switch's position 1 (up to 1230 us): 0 MANUAL, 1 CIRCLE, 2 STABILIZE, 5 FBWA, 6 "
               "FBWB, 7 CRUISE, 10 AUTO, 11 RTL, 12 LOITER, 15 GUIDED (ArduPlane's numbers; FBWA flies as "
               "STABILIZE does). Any other number is refused. A mode that cannot run when the switch picks it (no 3D fix, no home, no "
               "mission) is refused with its reason and the mode before flies on.")},
    {"FLTMODE#", Type::UInt8, 2, 5, 1, AT(flight.fltmode[1]), 0.0f, 15.0f, 2.0f,
     PARAM_DOC("Flight mode n", "",
               "The mode of the switch's position n (2: 1231 to 1360 us, 3: to 1490, 4: to 1620, 5: to 1749, 6: "
               "above), numbered as FLTMODE1's; any other number is refused.")},
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
    {"AHRS_ORIENTATION", Type::UInt8, 0, 1, 0, AT(vehicle.ahrs_orientation), 0.0f, 37.0f, 0.0f,
     PARAM_DOC("Board orientation", "",
               "How the board is mounted in the airframe, as ArduPilot's rotation numbers: 0 as its arrow says, "
               "1..7 yawed 45..315 deg, 8 upside down (ROLL_180), 9..15 upside down and yawed, 12 PITCH_180, "
               "16..23 ROLL_90/ROLL_270 and their yaws, 24..37 the pitch 90/180/270 combinations. The gyro, "
               "accelerometer and compass are turned by it before the estimator; a change restarts the "
               "estimator and the gyro calibration (keep the board still).")},
    {"AHRS_TRIM_X", Type::Float, 0, 1, 0, AT(vehicle.ahrs_trim_x_rad), -0.1745f, 0.1745f, 0.0f,
     PARAM_DOC("Roll trim", "rad",
               "The board's roll when the airframe is level (set by the level calibration, MAV_CMD_PREFLIGHT_"
               "CALIBRATION param5 2 or `cal level`): taken off the roll reported and flown.")},
    {"AHRS_TRIM_Y", Type::Float, 0, 1, 0, AT(vehicle.ahrs_trim_y_rad), -0.1745f, 0.1745f, 0.0f,
     PARAM_DOC("Pitch trim", "rad",
               "The board's pitch when the airframe is level (set by the level calibration): taken off the "
               "pitch reported and flown.")},
    {"INS_ACCOFFS_X", Type::Float, 0, 1, 0, AT(vehicle.ins_accoffs_m_s2[0]), -3.5f, 3.5f, 0.0f,
     PARAM_DOC("Accelerometer offset X", "m/s/s",
               "Subtracted from the accelerometer's x axis (the board's) before its scale; set by the "
               "six-position calibration.")},
    {"INS_ACCOFFS_Y", Type::Float, 0, 1, 0, AT(vehicle.ins_accoffs_m_s2[1]), -3.5f, 3.5f, 0.0f,
     PARAM_DOC("Accelerometer offset Y", "m/s/s", "As INS_ACCOFFS_X, the y axis.")},
    {"INS_ACCOFFS_Z", Type::Float, 0, 1, 0, AT(vehicle.ins_accoffs_m_s2[2]), -3.5f, 3.5f, 0.0f,
     PARAM_DOC("Accelerometer offset Z", "m/s/s", "As INS_ACCOFFS_X, the z axis.")},
    {"INS_ACCSCAL_X", Type::Float, 0, 1, 0, AT(vehicle.ins_accscal[0]), 0.8f, 1.2f, 1.0f,
     PARAM_DOC("Accelerometer scale X", "",
               "The accelerometer's x axis, less its offset, is multiplied by this; set by the six-position "
               "calibration.")},
    {"INS_ACCSCAL_Y", Type::Float, 0, 1, 0, AT(vehicle.ins_accscal[1]), 0.8f, 1.2f, 1.0f,
     PARAM_DOC("Accelerometer scale Y", "", "As INS_ACCSCAL_X, the y axis.")},
    {"INS_ACCSCAL_Z", Type::Float, 0, 1, 0, AT(vehicle.ins_accscal[2]), 0.8f, 1.2f, 1.0f,
     PARAM_DOC("Accelerometer scale Z", "", "As INS_ACCSCAL_X, the z axis.")},

    // Compass. The `cal mag` result as ArduPilot's AP_Compass names it: rows into Settings::cal
    // (saved in the first record with the calibration, not in `flight` or `vehicle`). Both
    // correct a field as M (m + COMPASS_OFS), M the symmetric matrix of COMPASS_DIA_* and
    // COMPASS_ODI_*. The ranges are calib::is_plausible's: a saved calibration stays valid.
    {"COMPASS_DEC", Type::DeclRad, 0, 1, 0, AT(vehicle.compass_dec_rad), -3.1416f, 3.1416f, 0.0f,
     PARAM_DOC("Compass declination", "rad",
               "The angle from true north to magnetic north, east positive, added to the heading the board "
               "reports: `decl` sets the same in degrees. Kept as the float sent; the output lines show the "
               "heading to a hundredth of a degree.")},
    {"COMPASS_OFS_#", Type::MagOfs, kLetterX, 3, 4, AT(cal.mag_offset_uT), -2000.0f, 2000.0f, 0.0f,
     PARAM_DOC("Compass offsets", "mGauss",
               "The hard iron along the board's x (forward), y (right) or z (down) axis, n X, Y or Z, as "
               "ArduPilot's: added to the field before COMPASS_DIA_* and COMPASS_ODI_* (the `cal mag` offset in uT "
               "with its sign turned, times 10). Set by `cal mag` and by the ground station's compass calibration; "
               "a value set here is in use at once, marks the compass calibrated and clears the offset learned in "
               "motion, which otherwise comes on top of it (`status`).")},
    {"COMPASS_DIA_#", Type::Float, kLetterX, 3, 4, AT(cal.mag_scale), 0.5f, 2.0f, 1.0f,
     PARAM_DOC("Compass soft-iron diagonal", "",
               "The soft-iron matrix's diagonal, n X, Y or Z, as ArduPilot's: the field's x, y or z component, "
               "offset corrected, is scaled by it (with COMPASS_ODI_* a symmetric matrix; after `cal mag` its "
               "determinant is 1). 1 and COMPASS_ODI_* 0: no soft iron.")},
    {"COMPASS_ODI_#", Type::Float, kLetterX, 3, 4, AT(cal.mag_cross), -0.5f, 0.5f, 0.0f,
     PARAM_DOC("Compass soft-iron off-diagonal", "",
               "The soft-iron matrix's off-diagonal terms, as ArduPilot's: X the xy and yx term, Y xz and zx, Z yz "
               "and zy.")},
    {"COMPASS_USE", Type::UInt8, 0, 1, 0, AT(vehicle.compass_use), 0.0f, 1.0f, 1.0f,
     PARAM_DOC("Use compass for yaw", "",
               "1: the heading is corrected by the compass; 0: the compass is read (and `cal mag` works) but the "
               "heading is the gyro's, or the GPS course when moving, as without a compass.")},
    {"COMPASS_LEARN", Type::UInt8, 0, 1, 0, AT(vehicle.compass_learn), 0.0f, 1.0f, 1.0f,
     PARAM_DOC("Learn compass offsets", "",
               "1: the hard iron is learned in motion, from the field's change against the gyro's turn, and used on "
               "top of COMPASS_OFS_* once it clearly differs (`status` shows it); 0: not learned (the offset "
               "learned so far is kept until `cal mag` or a COMPASS_OFS_* change clears it).")},

    // Battery monitor and its failsafe.
    {"BATT_MONITOR", Type::UInt8, 0, 1, 0, AT(vehicle.battery.monitor), 0.0f, 4.0f, 0.0f,
     PARAM_DOC("Battery monitoring", "",
               "0: off (a board without a power module: nothing reported, SYS_STATUS says not measured); 3: the "
               "voltage; 4: the voltage and the current (the 3DR power module); 1 and 2 monitor nothing, as in "
               "ArduPilot. Off by default: unconnected analog inputs read whatever floats there.")},
    {"BATT_VOLT_PIN", Type::UInt8, 0, 1, 0, AT(vehicle.battery.volt_pin), 0.0f, 15.0f, 13.0f,
     PARAM_DOC("Battery voltage pin", "",
               "The analog input (A0..A15) of the pack's voltage: 13 for the 3DR power module on the APM 2.5. A0 "
               "is the airspeed sensor's.")},
    {"BATT_CURR_PIN", Type::UInt8, 0, 1, 0, AT(vehicle.battery.curr_pin), 0.0f, 15.0f, 12.0f,
     PARAM_DOC("Battery current pin", "", "The analog input (A0..A15) of the current: 12 for the 3DR power module.")},
    {"BATT_VOLT_MULT", Type::Float, 0, 1, 0, AT(vehicle.battery.volt_mult), 0.1f, 100.0f, 10.1f,
     PARAM_DOC("Voltage multiplier", "",
               "The pack's volts per volt on the voltage pin: 10.1 for the 3DR power module. Set it so that the "
               "reported voltage matches a voltmeter's.")},
    {"BATT_AMP_PERVOLT", Type::Float, 0, 1, 0, AT(vehicle.battery.amp_per_volt), 0.0f, 1000.0f, 17.0f,
     PARAM_DOC("Amps per volt", "A/V",
               "Amps per volt on the current pin above BATT_AMP_OFFSET: 17 for the 3DR power module. ArduPlane "
               "3's name (later ArduPilot: BATT_AMP_PERVLT).")},
    {"BATT_AMP_OFFSET", Type::Float, 0, 1, 0, AT(vehicle.battery.amp_offset_v), -5.0f, 5.0f, 0.0f,
     PARAM_DOC("Amps offset", "V", "The current pin's voltage at zero current.")},
    {"BATT_CAPACITY", Type::UInt16, 0, 1, 0, AT(vehicle.battery.capacity_mah), 0.0f, 30000.0f, 3300.0f,
     PARAM_DOC("Battery capacity", "mAh",
               "The full pack's charge: the remaining percentage is what is left of it after the charge used "
               "since power-up (so plug in a full pack).")},
    {"FS_BATT_VOLTAGE", Type::Float, 0, 1, 0, AT(vehicle.battery.fs_voltage_v), 0.0f, 100.0f, 0.0f,
     PARAM_DOC("Failsafe battery voltage", "V",
               "The battery failsafe when the voltage stays below this for 10 s (a short sag under load does "
               "not count); 0: off. ArduPlane's action, RTL, needs navigation: until then the board says "
               "\"Low battery\" and keeps its mode.")},
    {"FS_BATT_MAH", Type::UInt16, 0, 1, 0, AT(vehicle.battery.fs_mah), 0.0f, 30000.0f, 0.0f,
     PARAM_DOC("Failsafe battery mAh", "mAh",
               "The battery failsafe when less than this is left of BATT_CAPACITY (BATT_MONITOR 4 only); 0: off.")},

    // Telemetry rates. ArduPilot's SR0_ (0..50 Hz), the stream groups of ArduPlane's
    // GCS_Mavlink.cpp; the defaults are the rates the board sent before them (lib/MavLink/
    // StreamRates.h, docs/mavlink.md), but for EXT_STAT: ArduPlane's 1, SYS_STATUS's rate
    // before (GPS_RAW_INT, 2 Hz before, goes with it).
    {"SR0_RAW_SENS", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[0]), 0.0f, 50.0f, 5.0f,
     PARAM_DOC("Raw sensor stream rate", "Hz",
               "SCALED_PRESSURE (the barometer) a second to the ground station; 0 none. A ground station's "
               "REQUEST_DATA_STREAM sets it (and saves it when it changes); every rate is capped by what the "
               "115200-baud link carries (docs/mavlink.md).")},
    {"SR0_EXT_STAT", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[1]), 0.0f, 50.0f, 1.0f,
     PARAM_DOC("Extended status stream rate", "Hz", "SYS_STATUS and GPS_RAW_INT a second; 0 none.")},
    {"SR0_RC_CHAN", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[2]), 0.0f, 50.0f, 5.0f,
     PARAM_DOC("RC channel stream rate", "Hz", "RC_CHANNELS and SERVO_OUTPUT_RAW a second; 0 none.")},
    {"SR0_POSITION", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[3]), 0.0f, 50.0f, 4.0f,
     PARAM_DOC("Position stream rate", "Hz", "GLOBAL_POSITION_INT a second (after the first fix); 0 none.")},
    {"SR0_EXTRA1", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[4]), 0.0f, 50.0f, 50.0f,
     PARAM_DOC("Extra data type 1 stream rate", "Hz",
               "ATTITUDE a second, at most one an output line (the console's `rate`, 50 by default); 0 none.")},
    {"SR0_EXTRA2", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[5]), 0.0f, 50.0f, 4.0f,
     PARAM_DOC("Extra data type 2 stream rate", "Hz", "VFR_HUD a second; 0 none.")},
    {"SR0_EXTRA3", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[6]), 0.0f, 50.0f, 1.0f,
     PARAM_DOC("Extra data type 3 stream rate", "Hz",
               "SYSTEM_TIME and BATTERY_STATUS (with BATT_MONITOR set) a second; 0 none.")},
    {"SR0_PARAMS", Type::UInt8, 0, 1, 0, AT(vehicle.sr0_hz[7]), 0.0f, 50.0f, 10.0f,
     PARAM_DOC("Parameter stream rate", "Hz",
               "Kept for the ground stations that set it; the parameter list goes as fast as the link has room "
               "(about 200 a second), as ArduPilot's queued parameters do. REQUEST_DATA_STREAM's ALL leaves it.")},

    // Serial port.
    {"SERIAL0_PROTOCOL", Type::UInt8, 0, 1, 0, AT(vehicle.serial0_protocol), 0.0f, 2.0f, 0.0f,
     PARAM_DOC("USB console protocol", "",
               "0: the text console of the README (the Arduino Serial Monitor's), switched to MAVLink by a "
               "ground station's first HEARTBEAT; 1 or 2 (ArduPilot's MAVLink1/MAVLink2): MAVLink from "
               "power-up, so a ground station that only listens hears the board (the frames are MAVLink 2 "
               "for either). Three returns in a row in MAVLink give the text console until the next start.")},

    // Navigation (settings::NavSettings): AP_L1_Control's, AP_TECS's, the mission's, the
    // throttle's and the long failsafe's, ArduPlane 3.x's names, ranges and defaults
    // (docs/navigation.md). The Scaled8 rows keep ArduPlane's step in a byte: their stride
    // is the steps per unit.
    {"NAVL1_PERIOD", Type::UInt8, 0, 1, 0, AT(vehicle.nav.navl1_period_s), 1.0f, 60.0f, 20.0f,
     PARAM_DOC("L1 control period", "s",
               "The period of the oscillation the lateral guidance (L1) flies back to the track with in AUTO, RTL, "
               "LOITER and CRUISE: shorter follows the track more tightly and turns harder; too short weaves. "
               "ArduPlane 3.x's 20; lower it a step at a time.")},
    {"NAVL1_DAMPING", Type::Scaled8, 0, 1, 100, AT(vehicle.nav.navl1_damping_c), 0.6f, 1.0f, 0.75f,
     PARAM_DOC("L1 control damping ratio", "",
               "The damping of that oscillation: higher overshoots the track less. Kept in hundredths.")},
    {"TECS_CLMB_MAX", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_clmb_max_d), 0.1f, 20.0f, 5.0f,
     PARAM_DOC("Maximum climb rate", "m/s",
               "The climb the aeroplane makes at THR_MAX and its cruise speed: TECS asks for no faster climb. Too "
               "high a value slows the aeroplane in climbs. Kept in tenths.")},
    {"TECS_SINK_MIN", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_sink_min_d), 0.1f, 10.0f, 2.0f,
     PARAM_DOC("Minimum sink rate", "m/s",
               "The sink at THR_MIN and the cruise speed (the throttle's feed-forward range). Kept in tenths.")},
    {"TECS_TIME_CONST", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_time_const_d), 3.0f, 10.0f, 5.0f,
     PARAM_DOC("Controller time constant", "s",
               "How fast TECS corrects the height and speed: smaller is tighter, too small oscillates. Kept in "
               "tenths.")},
    {"TECS_THR_DAMP", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_thr_damp_d), 0.1f, 1.0f, 0.5f,
     PARAM_DOC("Throttle damping", "", "Damps the throttle's answer to the total energy's rate error.")},
    {"TECS_INTEG_GAIN", Type::Scaled8, 0, 1, 100, AT(vehicle.nav.tecs_integ_gain_c), 0.0f, 0.5f, 0.1f,
     PARAM_DOC("Integrator gain", "",
               "The throttle's and pitch's integrators: they take out a wrong TRIM_THROTTLE or a steady error. Kept "
               "in hundredths.")},
    {"TECS_VERT_ACC", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_vert_acc_d), 1.0f, 10.0f, 7.0f,
     PARAM_DOC("Vertical acceleration limit", "m/s/s", "Limits how fast the pitch demand may change.")},
    {"TECS_HGT_OMEGA", Type::Scaled8, 0, 1, 20, AT(vehicle.nav.tecs_hgt_omega_t), 1.0f, 5.0f, 3.0f,
     PARAM_DOC("Height complementary filter frequency", "rad/s",
               "The crossover of the filter that takes the height from the barometer and the vertical "
               "acceleration. Kept in twentieths.")},
    {"TECS_SPD_OMEGA", Type::Scaled8, 0, 1, 100, AT(vehicle.nav.tecs_spd_omega_c), 0.5f, 2.0f, 2.0f,
     PARAM_DOC("Speed complementary filter frequency", "rad/s",
               "The crossover of the airspeed filter (with the pitot). Kept in hundredths.")},
    {"TECS_RLL2THR", Type::UInt8, 0, 1, 0, AT(vehicle.nav.tecs_rll2thr), 5.0f, 30.0f, 10.0f,
     PARAM_DOC("Bank angle compensation gain", "",
               "The extra throttle a turn's induced drag needs: the energy rate a 60-degree bank costs, m^2/s^3.")},
    {"TECS_SPDWEIGHT", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_spdweight_d), 0.0f, 2.0f, 1.0f,
     PARAM_DOC("Weighting applied to speed control", "",
               "The pitch loop's balance: 0 the height first, 2 the speed first, 1 both. Without an airspeed sensor "
               "0 is taken whatever is set.")},
    {"TECS_PTCH_DAMP", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_ptch_damp_d), 0.0f, 1.0f, 0.0f,
     PARAM_DOC("Controller pitch damping", "", "Damps the pitch loop's answer to the energy balance's rate.")},
    {"TECS_SINK_MAX", Type::Scaled8, 0, 1, 10, AT(vehicle.nav.tecs_sink_max_d), 0.0f, 20.0f, 5.0f,
     PARAM_DOC("Maximum descent rate", "m/s", "The steepest sink TECS asks for. Kept in tenths.")},
    {"WP_RADIUS", Type::Int16, 0, 1, 0, AT(vehicle.nav.wp_radius_m), 1.0f, 32767.0f, 30.0f,
     PARAM_DOC("Waypoint radius", "m",
               "A waypoint is reached within this distance, or earlier for a gentle turn (the L1 turn distance), or "
               "once passed; also RTL's radius at home.")},
    {"WP_LOITER_RAD", Type::Int16, 0, 1, 0, AT(vehicle.nav.wp_loiter_rad_m), -32767.0f, 32767.0f, 60.0f,
     PARAM_DOC("Waypoint loiter radius", "m",
               "The circle of LOITER, RTL at home and the mission's loiters: positive clockwise, negative "
               "counter-clockwise.")},
    {"ALT_HOLD_RTL", Type::Int16, 0, 1, 0, AT(vehicle.nav.alt_hold_rtl_cm), -1.0f, 32767.0f, 10000.0f,
     PARAM_DOC("RTL altitude", "cm",
               "The height above home RTL returns and circles at; -1: the height RTL starts at. At most 327 m here "
               "(ArduPlane's is wider).")},
    {"GLIDE_SLOPE_MIN", Type::UInt16, 0, 1, 0, AT(vehicle.nav.glide_slope_min_m), 0.0f, 1000.0f, 15.0f,
     PARAM_DOC("Glide slope minimum", "m",
               "A change of height to the next waypoint of this or more is spread along the leg (a slope); a "
               "smaller one is asked for at once. 0: every change spread.")},
    {"THR_MIN", Type::UInt8, 0, 1, 0, AT(vehicle.nav.thr_min_pct), 0.0f, 100.0f, 0.0f,
     PARAM_DOC("Minimum throttle", "%",
               "The least throttle the navigation modes (FBWB, CRUISE, AUTO, RTL, LOITER, CIRCLE) ask for. "
               "ArduPlane's negative values (reverse thrust) are not taken.")},
    {"THR_MAX", Type::UInt8, 0, 1, 0, AT(vehicle.nav.thr_max_pct), 0.0f, 100.0f, 75.0f,
     PARAM_DOC("Maximum throttle", "%", "The most throttle the navigation modes ask for.")},
    {"TRIM_THROTTLE", Type::UInt8, 0, 1, 0, AT(vehicle.nav.trim_throttle_pct), 0.0f, 100.0f, 45.0f,
     PARAM_DOC("Throttle cruise", "%",
               "The throttle of level flight at the cruise speed: the navigation modes' throttle starts from it "
               "(without an airspeed sensor it is the throttle held on the level).")},
    {"FBWB_CLIMB_RATE", Type::UInt8, 0, 1, 0, AT(vehicle.nav.fbwb_climb_rate_m_s), 1.0f, 10.0f, 2.0f,
     PARAM_DOC("Fly by wire B altitude change rate", "m/s",
               "In FBWB and CRUISE, full pitch stick moves the height held by this much a second.")},
    {"FS_LONG_ACTN", Type::UInt8, 0, 1, 0, AT(vehicle.nav.fs_long_actn), 0.0f, 2.0f, 0.0f,
     PARAM_DOC("Long failsafe action", "",
               "What the board does FS_LONG_TIMEOUT after the receiver is lost: 0 RTL, but AUTO, RTL, LOITER and "
               "GUIDED go on; 1 RTL in every mode; 2 the failsafe glide (wings level, FS_GLIDE_PITCH). RTL needs "
               "home and a 3D fix, else the glide goes on.")},
    {"FS_LONG_TIMEOUT", Type::UInt16, 0, 1, 0, AT(vehicle.nav.fs_long_timeout_s), 1.0f, 300.0f, 20.0f,
     PARAM_DOC("Long failsafe timeout", "s",
               "How long the receiver must be lost for FS_LONG_ACTN. Whole seconds here.")},
    {"ARSPD_OFFSET", Type::UInt16, 0, 1, 0, AT(vehicle.arspd_offset), 0.0f, 4095.0f, 0.0f,
     PARAM_DOC("Airspeed offset", "",
               "The airspeed sensor's zero, the reading of the pitot in still air, in ArduPilot's unit: 4096ths of "
               "the 5 V supply (A0's 10-bit reading times 4; 2048 at the nominal 2.5 V). Measured at every start "
               "the board is still and saved when it moved by more than 8 (2 counts: the reading's noise); a start "
               "in motion (a restart in flight) uses it instead of measuring, when a still sensor reads it "
               "(2.0 to 3.0 V). While the sensor is in use, setting it moves its zero at once. 0: none measured yet.")},

};
#undef AT
constexpr uint8_t kRowCount = (uint8_t)(sizeof kRows / sizeof kRows[0]);
// The parameters' count, summed when compiled (a walk over the rows' counts in flash took
// ~2 000 cycles, and a PARAM_SET asked for it twice).
constexpr uint16_t counts_from(uint8_t r) {
    return r == kRowCount ? (uint16_t)0 : (uint16_t)(kRows[r].count + counts_from((uint8_t)(r + 1u)));
}
constexpr uint16_t kParamCount = counts_from(0);
// find() matches a name's first character before the rest: no row may start with its number.
constexpr bool no_name_starts_numbered(uint8_t r) {
    return r == kRowCount || (kRows[r].name[0] != '#' && no_name_starts_numbered((uint8_t)(r + 1u)));
}
static_assert(no_name_starts_numbered(0), "a row's name starts with '#': find() would miss it");

// The row holding index, and the instance within it; false past the end. Only the counts
// are read on the way and the one row copied: a walk copying every row (35 bytes from
// flash each) took a PARAM_SET of a row near the table's end past its task's budget.
bool locate(uint16_t index, Row& row, uint8_t& instance) {
    for (const Row* r = kRows; r != kRows + kRowCount; ++r) {  // a pointer: no multiply a row
        const uint8_t n = AT_BYTE(r, count);
        if (index < n) {
            COPY_ROW(&row, r);
            instance = (uint8_t)index;
            return true;
        }
        index = (uint16_t)(index - n);
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
        case Type::DeclRad: { float v; memcpy(&v, p, sizeof v); return v; }
        case Type::MagOfs: { float v; memcpy(&v, p, sizeof v); return compass_ofs_mgauss(v); }
        case Type::Scaled8: return (float)*p / (float)row.stride;
    }
    return 0.0f;
}

// Stores a value already checked against the row's range.
void write(Settings& s, const Row& row, uint8_t instance, float value) {
    uint8_t* p = where(s, row, instance);
    // Rounded for the integer types only (two float operations a value: the defaults'
    // walk writes every one between samples).
    const int32_t whole = is_integer(row.type) ? (int32_t)(value >= 0.0f ? value + 0.5f : value - 0.5f) : 0;
    switch (row.type) {
        case Type::Float: memcpy(p, &value, sizeof value); break;
        case Type::Int16: { const int16_t v = (int16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt16: { const uint16_t v = (uint16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt8: *p = (uint8_t)whole; break;
        case Type::Bit:
            *p = whole != 0 ? (uint8_t)(*p | (1u << instance)) : (uint8_t)(*p & ~(1u << instance));
            break;
        case Type::DeclRad: settings::set_declination_rad(s, value); break;  // with the first record's copy
        case Type::MagOfs: {
            const float uT = value / -kMilliGaussPerMicroTesla;
            memcpy(p, &uT, sizeof uT);
            break;
        }
        case Type::Scaled8: *p = (uint8_t)(value * (float)row.stride + 0.5f); break;  // in range: >= 0
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

float compass_ofs_mgauss(float offset_uT) {
    const float centi = offset_uT * (-100.0f * kMilliGaussPerMicroTesla);
    // Divided, not multiplied by 0.01f: the nearest float to the decimal.
    if (!(centi > -1e7f && centi < 1e7f)) return centi / 100.0f;  // NaN or absurd: as it is
    return (float)(int32_t)(centi >= 0.0f ? centi + 0.5f : centi - 0.5f) / 100.0f;
}

bool is_integer(Type t) {
    return t != Type::Float && t != Type::DeclRad && t != Type::MagOfs && t != Type::Scaled8;
}

Rows compass_calibration_rows() {
    static Rows rows{0, 0};  // the table is constant: walked once
    if (rows.count == 0u)
        rows = rows_within(offsetof(Settings, cal.mag_offset_uT), offsetof(Settings, cal.mag_learned_uT));
    return rows;
}

bool is_compass_calibration(uint16_t index) { return compass_calibration_rows().holds(index); }

Rows rows_within(uint16_t from, uint16_t to) {
    Rows rows{0, 0};
    uint16_t index = 0;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        const uint8_t n = ROW_BYTE(r, count);
        const uint16_t offset = ROW_WORD(r, offset);
        if (offset >= from && offset < to) {
            if (rows.count == 0u) rows.first = index;
            rows.count = (uint8_t)(rows.count + n);
        } else if (rows.count != 0u) {
            break;  // the block ended
        }
        index = (uint16_t)(index + n);
    }
    return rows;
}

uint16_t count() { return kParamCount; }

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
    const char first = upper(name[0]);
    uint16_t index = 0;
    for (const Row* r = kRows; r != kRows + kRowCount; ++r) {  // a pointer: no multiply a row
        const uint8_t count = AT_BYTE(r, count);
        // The first character rules out all rows but a few (none starts with '#': static_assert).
        if (AT_BYTE(r, name[0]) == (uint8_t)first) {
            uint8_t i = 1, j = 1;  // the row's name (read from flash a character at a time), name
            int16_t instance = 0;
            bool match = true;
            for (char rc = (char)AT_BYTE(r, name[1]); match && rc != '\0'; rc = (char)AT_BYTE(r, name[++i])) {
                if (rc == '#') {
                    // A digit, or a letter (X, Y, Z): '0' + first + instance, whatever its case.
                    const char c = upper(name[j++]);
                    instance = (int16_t)(c - '0' - (char)AT_BYTE(r, first));
                    match = instance >= 0 && instance < count;
                } else {
                    match = upper(name[j++]) == rc;
                }
            }
            if (match && name[j] == '\0') return (int16_t)(index + instance);
        }
        index = (uint16_t)(index + count);
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

bool set(Settings& s, uint16_t index, float value, bool* changed) {
    if (changed != nullptr) *changed = false;
    Row row;
    uint8_t instance;
    if (!locate(index, row, instance) || !in_range(row, value)) return false;
    // FLTMODEn: a mode the board has (a stored number it lacks still loads, and flies MANUAL).
    if (holds_flight_mode(row) && !flight::mode_known((uint8_t)value)) return false;
    const float before = read(s, row, instance);
    write(s, row, instance, value);
    if (ends_in_order(s.flight.rc) && ends_in_order(s.flight.servo)) {
        if (changed != nullptr) *changed = read(s, row, instance) != before;
        return true;
    }
    write(s, row, instance, before);
    return false;
}

// Only the fields write() reads are copied from flash (10 of a row's 35 bytes): a ground
// station's PREFLIGHT_STORAGE defaults runs this between samples, and with the SR0_ rows
// the whole-row copy took its pass past the task's budget (a sample missed).
void apply_defaults(Settings& s) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        // The fields write() needs, not the whole row (its name is half of it): the walk
        // runs between samples (PREFLIGHT_STORAGE's defaults).
        row.type = (Type)ROW_BYTE(r, type);
        row.count = ROW_BYTE(r, count);
        row.stride = ROW_BYTE(r, stride);
        row.offset = ROW_WORD(r, offset);
        ROW_FLOAT(&row.def, r, def);
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
        case Type::Float:
        case Type::DeclRad:
        case Type::MagOfs: return 4;
        case Type::Int16:
        case Type::UInt16: return 2;
        default: return 1;  // UInt8, Bit, Scaled8
    }
}

// Calls f(pointer to the value's bytes, their count) for every stored value of the
// flight settings, in the record's order.
// ... of the rows whose values lie at offsets from .. to-1 of Settings. The settings store
// calls this for every part of a record it writes, between samples: only the bytes it needs
// are read from each row (copying each whole row from flash took the store's task past its
// budget as rows were added).
template <typename F>
void each_value_at(const Settings& s, uint16_t from, uint16_t to, F f) {
    for (uint8_t r = 0; r < kRowCount; ++r) {
        const uint16_t offset = ROW_WORD(r, offset);
        if (offset < from || offset >= to) continue;
        const Type type = (Type)ROW_BYTE(r, type);
        const uint8_t n = type == Type::Bit ? 1 : ROW_BYTE(r, count);
        const uint8_t stride = ROW_BYTE(r, stride);
        uint8_t* p = reinterpret_cast<uint8_t*>(&const_cast<Settings&>(s)) + offset;
        for (uint8_t i = 0; i < n; ++i) f(p + (uint16_t)stride * i, stored_bytes(type));
    }
}

template <typename F>
void each_flight_value(const Settings& s, F f) {
    each_value_at(s, offsetof(Settings, flight), offsetof(Settings, vehicle), f);
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
    each_value_at(s, offsetof(Settings, vehicle), 0xFFFFu, f);
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

uint16_t vehicle_crc(const Settings& s, uint16_t crc) {
    each_vehicle_value(s, [&](uint8_t* p, uint8_t n) {
        for (uint8_t j = 0; j < n; ++j) crc = settings::crc16_update(crc, p[j]);
    });
    return crc;
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
