// SPDX-License-Identifier: GPL-3.0-or-later
// The persistent settings: output rate, declination, output mode, the sensor
// calibration and the flight settings, stored in EEPROM as one record:
//
//   offset 0  'A' 'T'           magic
//          2  version           kSettingsVersion; any other value: defaults
//          3  payload length    kPayloadLength
//          4  payload           little-endian fields, floats as IEEE-754 bytes:
//             4  rate, 5 decl (int16: COMPASS_DEC's hundredths of a degree), 7 mode, 8 flags,
//             9  calibration (15 floats)
//             69 the flight settings (version 3 on): params::encode_flight, the parameter
//                table's rows in order (a Bit row's eight bits one byte), kFlightBytes
//          4+len  CRC-16/CCITT-FALSE of bytes 0 .. 3+len, little-endian
//
// encode/decode are explicit byte by byte, so the layout is the same on the AVR and
// the host (no struct padding or endianness in the record). GND_ABS_PRESS is measured at
// each start and lives before `flight`: not in the record. `vehicle` is the second
// record's (VehicleRecord.h). No EEPROM access here: the firmware copies kRecordSize bytes
// to and from EEPROM.
//
// A version 2 record (a 65-byte payload, no flight settings) still loads: its rate,
// declination, mode and calibration are kept, the flight settings are the defaults and
// kFlagUpgraded says so (the firmware tells the user, `save` writes this version).
// A version 3 or 4 record is this version's first kV3FlightBytes or kV4FlightBytes of flight
// settings: it loads whole, and the rows added since (at the table's end) take their defaults, as ArduPilot
// gives a new parameter its default.
#pragma once

#include <stdint.h>

#include "Constants.h"
#include "SensorCalibration.h"
#include "FlightSettings.h"
#include "OutputMode.h"
#include "VehicleSettings.h"

namespace settings {

constexpr uint8_t kMagic0 = 'A';
constexpr uint8_t kMagic1 = 'T';
// 2: the compass calibration gained the soft-iron cross terms and the learned offset.
// 3: the flight settings (ArduPlane's parameters, the parameter table: Params.h).
// 4: TRIM_PITCH_CD after the version 3 rows.
// 5: the GPS's and the barometer's rows (GPS_TYPE .. GND_TEMP) after version 4's.
constexpr uint8_t kSettingsVersion = 5;
constexpr uint8_t kV2PayloadLength = 65;  // rate(1) + decl(2) + mode(1) + flags(1) + 15 floats(60)
constexpr uint8_t kFlightBytes = 180;     // params::encode_flight (checked by params' tests)
constexpr uint8_t kV4FlightBytes = 168;   // version 4's flight settings: the rows before GPS_TYPE
constexpr uint8_t kV3FlightBytes = 166;   // version 3's flight settings: the rows before TRIM_PITCH_CD
constexpr uint8_t kPayloadLength = kV2PayloadLength + kFlightBytes;
constexpr uint8_t kRecordSize = 4 + kPayloadLength + 2;
constexpr uint8_t kV3PayloadLength = kV2PayloadLength + kV3FlightBytes;
constexpr uint8_t kV3RecordSize = 4 + kV3PayloadLength + 2;
constexpr uint8_t kV4PayloadLength = kV2PayloadLength + kV4FlightBytes;
constexpr uint8_t kV4RecordSize = 4 + kV4PayloadLength + 2;
constexpr uint16_t kEepromAddress = 0;

constexpr uint8_t kRateMinHz = 1;
constexpr uint8_t kRateMaxHz = 100;
constexpr uint8_t kRateDefaultHz = 50;
constexpr int16_t kDeclMinCentideg = -18000;  // -180.00 .. 180.00 degrees, east positive
constexpr int16_t kDeclMaxCentideg = 18000;

enum Flags : uint8_t {
    kFlagGyroCalibrated = 0x01,  // cal.gyro_bias was measured (used when start-up calibration fails)
    kFlagMagCalibrated = 0x02,   // cal.mag_offset/scale/cross came from `cal mag`
    kFlagUpgraded = 0x04,        // loaded from a version 2 record: flight settings at defaults (never stored)
};

struct Settings {
    uint8_t rate_hz;               // output lines per second, 1..100
    int16_t declination_centideg;  // COMPASS_DEC rounded to hundredths of a degree (set_declination_*)
    fmt::OutputMode mode;
    uint8_t flags;                 // Flags
    calib::Calibration cal;
    float gnd_abs_press_pa;        // GND_ABS_PRESS: the ground's pressure, measured at each start (not stored)
    flight::FlightSettings flight;  // Params.h has their names, ranges and defaults
    VehicleSettings vehicle;        // the second record's (VehicleSettings.h)

    float declination_rad() const { return vehicle.compass_dec_rad; }
    float declination_deg() const { return vehicle.compass_dec_rad * linalg::kDegPerRad; }
};

// The declination (COMPASS_DEC) is the float a ground station sent, vehicle.compass_dec_rad
// (the second record); declination_centideg is it rounded to hundredths of a degree: the
// first record's copy (what a firmware before the second record reads) and the integer
// heading's (the output lines print hundredths). Both are set together, here only.
// East positive; the hundredths clamped to -18000..18000.
int16_t centideg_of_rad(float rad);
void set_declination_rad(Settings& s, float rad);
void set_declination_centideg(Settings& s, int16_t centideg);  // `decl`; the first record alone

Settings defaults();

enum class LoadResult : uint8_t {
    Ok,
    Blank,        // erased EEPROM (all 0xFF) or never written
    BadMagic,     // something else lives there
    OldVersion,   // written by another firmware version
    BadCrc,       // corrupted
    BadValue,     // CRC fine but a value is out of range (a bug, or a crafted record)
};

uint16_t crc16(const uint8_t* data, uint16_t len);
// The same CRC a byte at a time: crc16(d, n) is crc16_update(...(kCrc16Init, d[0])..., d[n-1]).
constexpr uint16_t kCrc16Init = 0xFFFFu;
uint16_t crc16_update(uint16_t crc, uint8_t byte);
// Where the flight settings start in the record.
constexpr uint8_t kFlightOffset = 4 + kV2PayloadLength;
// Byte i of encode(s)'s record, for i < kFlightOffset (the header and calibration).
uint8_t record_byte(const Settings& s, uint8_t i);
// Bytes from..from+n-1 of encode(s)'s record, within 4 + kPayloadLength (all but the
// record's CRC): a record written a part at a time needs no copy of it.
void record_part(const Settings& s, uint8_t from, uint8_t n, uint8_t* out);

void encode(const Settings& s, uint8_t out[kRecordSize]);
// On anything but Ok, `out` is set to defaults(): never garbage.
LoadResult decode(const uint8_t in[kRecordSize], Settings& out);
// Range check of every field (what decode applies after the CRC).
bool is_valid(const Settings& s);

}  // namespace settings
