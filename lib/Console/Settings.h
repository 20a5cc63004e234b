// SPDX-License-Identifier: GPL-3.0-or-later
// The persistent settings: output rate, declination, output mode and the sensor
// calibration, stored in EEPROM as one record:
//
//   offset 0  'A' 'T'           magic
//          2  version           kSettingsVersion; any other value: defaults
//          3  payload length    kPayloadLength
//          4  payload           little-endian fields, floats as IEEE-754 bytes
//          4+len  CRC-16/CCITT-FALSE of bytes 0 .. 3+len, little-endian
//
// encode/decode are explicit byte by byte, so the layout is the same on the AVR and
// the host (no struct padding or endianness in the record). No EEPROM access here:
// the firmware copies kRecordSize bytes to and from EEPROM.
#pragma once

#include <stdint.h>

#include "Calibration.h"
#include "Format.h"

namespace settings {

constexpr uint8_t kMagic0 = 'A';
constexpr uint8_t kMagic1 = 'T';
// 2: the compass calibration gained the soft-iron cross terms and the learned offset.
constexpr uint8_t kSettingsVersion = 2;
// rate(1) + decl(2) + mode(1) + flags(1) + 15 floats(60)
constexpr uint8_t kPayloadLength = 65;
constexpr uint8_t kRecordSize = 4 + kPayloadLength + 2;
constexpr uint16_t kEepromAddress = 0;

constexpr uint8_t kRateMinHz = 1;
constexpr uint8_t kRateMaxHz = 100;
constexpr uint8_t kRateDefaultHz = 50;
constexpr int16_t kDeclMinCentideg = -18000;  // -180.00 .. 180.00 degrees, east positive
constexpr int16_t kDeclMaxCentideg = 18000;

enum Flags : uint8_t {
    kFlagGyroCalibrated = 0x01,  // cal.gyro_bias was measured (used when start-up calibration fails)
    kFlagMagCalibrated = 0x02,   // cal.mag_offset/scale/cross came from `cal mag`
};

struct Settings {
    uint8_t rate_hz;               // output lines per second, 1..100
    int16_t declination_centideg;  // magnetic declination, east positive, hundredths of a degree
    fmt::OutputMode mode;
    uint8_t flags;                 // Flags
    calib::Calibration cal;

    float declination_deg() const { return (float)declination_centideg * 0.01f; }
};

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

void encode(const Settings& s, uint8_t out[kRecordSize]);
// On anything but Ok, `out` is set to defaults(): never garbage.
LoadResult decode(const uint8_t in[kRecordSize], Settings& out);
// Range check of every field (what decode applies after the CRC).
bool is_valid(const Settings& s);

}  // namespace settings
