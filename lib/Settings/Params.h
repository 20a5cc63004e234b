// SPDX-License-Identifier: GPL-3.0-or-later
// The settings as one table of named, typed parameters: what the console's `set`,
// `get` and `params` use and what MAVLink's PARAM_* protocol iterates by index. Names
// are ArduPilot's where it has one (RLL2SRV_P, SERVO3_MIN, COMPASS_DEC ...), units too
// (COMPASS_DEC in radians, LIM_ROLL_CD in centi-degrees).
//
// The table (Params.cpp, in flash) has one row per parameter or per group of numbered
// ones ("RC#_MIN": RC1_MIN .. RC8_MIN); an index runs over the expanded parameters,
// 0 .. count()-1, in table order. Each row says where the value lives in
// settings::Settings (offset, stride), its type, range and default: the flight
// settings' defaults come from here and nowhere else (apply_defaults).
#pragma once

#include <stdint.h>

#include "Settings.h"

namespace params {

// How a value is stored (MAVLink's MAV_PARAM_TYPE follows: Float and DeclRad are REAL32,
// the others their integer types).
enum class Type : uint8_t {
    Float,    // float
    Int16,    // int16_t
    UInt16,   // uint16_t
    UInt8,    // uint8_t
    Bit,      // bit n of a uint8_t (n = the instance), 0 or 1
    DeclRad,  // the declination: a float in radians (ArduPilot's COMPASS_DEC), set with its hundredths (Settings.h)
    // The compass's hard-iron offset: a float in uT that calib::apply_mag subtracts from the
    // field, shown as ArduPilot's COMPASS_OFS_*, which AP_Compass adds to the field, in
    // milligauss: its negation times 10 (1 uT = 10 mGauss), rounded to 0.01 mGauss so that
    // a value sent comes back as sent.
    MagOfs,
    // A uint8_t holding the value times the row's `stride` (10: tenths, 20: twentieths, 100:
    // hundredths; a single row's stride is otherwise unused): ArduPlane's float parameters
    // of a small range and a coarse step (NAVL1_DAMPING, TECS_*) in a byte. A value set is
    // rounded to the nearest step; shown as byte / stride, the nearest float to the decimal.
    Scaled8,
};

constexpr uint8_t kNameMax = 16;  // MAVLink's param_id length

struct Info {
    char name[kNameMax + 1];  // NUL-terminated, upper case
    Type type;
    float min, max, def;
};

// How many parameters there are (< 255: an index fits a byte).
uint16_t count();
// The parameter at index; false past the end.
bool info(uint16_t index, Info& out);
// The index of a name (case-insensitive), or -1.
int16_t find(const char* name);
bool is_integer(Type t);
// The value as a float (MAVLink's PARAM_VALUE carries every type so).
float get(const settings::Settings& s, uint16_t index);
// Sets a value: false (nothing changed) when index is past the end, the value is NaN,
// out of range, not whole for an integer type, not a mode the board has (FLTMODEn), or
// leaves an end point pair out of order
// (RCn/SERVOn: MIN <= TRIM <= MAX). *changed (when given): the value stored now differs
// from the one before (one walk to the row for MAVLink's PARAM_SET, not three).
bool set(settings::Settings& s, uint16_t index, float value, bool* changed = nullptr);
// ArduPilot's COMPASS_OFS (mGauss, added to the field) of a `cal mag` offset (uT, subtracted
// from the field): 1 uT = 10 mGauss, rounded to 0.01 mGauss (the nearest float to that
// decimal, so that the value a ground station sets comes back as sent).
constexpr float kMilliGaussPerMicroTesla = 10.0f;
float compass_ofs_mgauss(float offset_uT);
// True for the rows of the compass calibration (COMPASS_OFS_*, _DIA_*, _ODI_*: Settings::cal's
// offset and soft iron): a change is a new calibration (the pipeline takes it as `cal mag`'s).
bool is_compass_calibration(uint16_t index);
// FLTMODE1..6: set() takes only a mode the board has (flight::mode_known).
bool is_flight_mode(uint16_t index);
// The parameters stored in Settings bytes [from, to) (offsetof values): the first one's
// index and how many follow it (they are consecutive in the table); count 0 when none.
// A calibration announces what it changed with it (PARAM_VALUE, as ArduPilot's
// AP_Param::notify), and a PARAM_SET checks an index against it without a table walk.
struct Rows {
    uint16_t first;
    uint8_t count;
    bool holds(uint16_t index) const { return (uint16_t)(index - first) < count; }
};
Rows rows_within(uint16_t from, uint16_t to);
// COMPASS_OFS/DIA/ODI_*: rows_within of the compass calibration, found once.
Rows compass_calibration_rows();
// Every parameter to its default.
void apply_defaults(settings::Settings& s);
// The flight settings in the EEPROM record (settings::encode): the rows that live in
// Settings::flight, in table order, each value little-endian in its type's size, a Bit
// row's eight bits as one byte: settings::kFlightBytes bytes. A new row changes the
// record: it needs a new record version, and goes after the flight rows there are (an
// older record is then the new one's first part: Settings.h).
void encode_flight(const settings::Settings& s, uint8_t out[settings::kFlightBytes]);
// Bytes from..from+n-1 (within kFlightBytes) of what encode_flight writes.
void flight_part(const settings::Settings& s, uint8_t from, uint8_t n, uint8_t* out);
// The first n bytes (an older record's, n <= kFlightBytes): the values they hold whole
// are read, the others left as they are.
void decode_flight(const uint8_t* in, uint8_t n, settings::Settings& s);
// What encode_flight writes (a test holds it to settings::kFlightBytes).
uint16_t flight_bytes();
// The second record's values (Settings::vehicle: the rows after GND_ABS_PRESS), in table
// order as encode_flight's: vehicle_bytes() of them. A record with fewer (an older
// firmware's) is this one's first part: decode_vehicle reads the values it holds whole
// and leaves the others as they are (their defaults).
void vehicle_part(const settings::Settings& s, uint8_t from, uint8_t n, uint8_t* out);
void decode_vehicle(const uint8_t* in, uint8_t n, settings::Settings& s);
uint16_t vehicle_bytes();
// crc brought on (settings::crc16_update) over the vehicle_bytes() bytes vehicle_part gives,
// in one walk of the table (vehicle_part walks it once a part).
uint16_t vehicle_crc(const settings::Settings& s, uint16_t crc);
// Every parameter within its range and the end points in order (settings::is_valid).
bool all_valid(const settings::Settings& s);

#if !defined(__AVR__)
// A row of the table as written, with its words: what the parameter reference
// (docs/parameters.md, printed by tools/paramdoc) is made of. Host builds only: the
// firmware keeps no text.
struct RowDoc {
    const char* name;          // '#' stands for the number in a numbered row
    uint8_t first, count;      // the numbers: first .. first + count - 1 (count 1: a single one)
    Type type;
    float min, max, def;
    const char* display_name;  // a few words (ArduPilot's @DisplayName)
    const char* units;         // "" for none (ArduPilot's @Units)
    const char* description;   // what it does in this firmware (ArduPilot's @Description)
};
uint8_t row_count();
// Row `row` of the table (0 .. row_count()-1); false past the end.
bool row_doc(uint8_t row, RowDoc& out);
#endif

}  // namespace params
