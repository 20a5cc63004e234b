// SPDX-License-Identifier: GPL-3.0-or-later
#include "Settings.h"

#include <string.h>

#include "Fixed.h"
#include "Params.h"

namespace settings {

constexpr float kRadPerCentideg = linalg::kPi / 18000.0f;

int16_t centideg_of_rad(float rad) {
    const float cd = rad * (18000.0f / linalg::kPi);
    if (!(cd > (float)kDeclMinCentideg)) return kDeclMinCentideg;  // NaN too: never reached (params' range)
    if (cd >= (float)kDeclMaxCentideg) return kDeclMaxCentideg;
    return (int16_t)(cd >= 0.0f ? cd + 0.5f : cd - 0.5f);
}

void set_declination_rad(Settings& s, float rad) {
    s.vehicle.compass_dec_rad = rad;
    s.declination_centideg = centideg_of_rad(rad);
}

void set_declination_centideg(Settings& s, int16_t centideg) {
    s.vehicle.compass_dec_rad = (float)centideg * kRadPerCentideg;
    s.declination_centideg = centideg;
}

Settings defaults() {
    Settings s;
    s.rate_hz = kRateDefaultHz;
    set_declination_centideg(s, 0);
    s.mode = fmt::OutputMode::Plot;
    s.flags = 0;
    s.cal = calib::default_calibration();
    params::apply_defaults(s);  // the flight settings (and the declination again: 0)
    return s;
}

// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF): check value 0x29B1 for "123456789".
// A byte at once, not a bit: x is the top byte's feedback, and 0x1021 = 2^12 + 2^5 + 1
// makes the shifted copies of x (x ^= x >> 4 folds in the feedback of x's own high
// nibble). The same CRC as eight bit steps, several times faster on the AVR (a `save`
// takes two CRCs of the record in one loop iteration).
uint16_t crc16_update(uint16_t crc, uint8_t byte) {
    uint8_t x = (uint8_t)((crc >> 8) ^ byte);
    x = (uint8_t)(x ^ (x >> 4));
    return (uint16_t)((uint16_t)(crc << 8) ^ (uint16_t)((uint16_t)x << 12) ^ (uint16_t)((uint16_t)x << 5) ^ x);
}

uint16_t crc16(const uint8_t* data, uint16_t len) {
    uint16_t crc = kCrc16Init;
    for (uint16_t i = 0; i < len; ++i) crc = crc16_update(crc, data[i]);
    return crc;
}

// The payload: rate, declination (2), mode, flags, then the calibration's fifteen floats
// (IEEE-754, little-endian on both the AVR and x86/ARM hosts: memcpy is the layout).
static_assert(sizeof(calib::Calibration) == 60, "Calibration is fifteen packed floats");
static_assert(kV2PayloadLength == 5 + sizeof(calib::Calibration), "version 2 payload = header bytes + calibration");
static_assert(kRecordSize <= 255, "the record's size is a byte");

uint8_t record_byte(const Settings& s, uint8_t i) {
    switch (i) {
        case 0: return kMagic0;
        case 1: return kMagic1;
        case 2: return kSettingsVersion;
        case 3: return kPayloadLength;
        case 4: return s.rate_hz;
        case 5: return (uint8_t)((uint16_t)s.declination_centideg & 0xFFu);
        case 6: return (uint8_t)((uint16_t)s.declination_centideg >> 8);
        case 7: return (uint8_t)s.mode;
        case 8: return (uint8_t)(s.flags & ~kFlagUpgraded);
        default: break;
    }
    return ((const uint8_t*)&s.cal)[i - 9u];
}

void record_part(const Settings& s, uint8_t from, uint8_t n, uint8_t* out) {
    uint8_t i = from;
    for (; i < kFlightOffset && (uint8_t)(i - from) < n; ++i) out[i - from] = record_byte(s, i);
    if ((uint8_t)(i - from) < n) params::flight_part(s, (uint8_t)(i - kFlightOffset), (uint8_t)(n - (i - from)), out + (i - from));
}

void encode(const Settings& s, uint8_t out[kRecordSize]) {
    record_part(s, 0, (uint8_t)(4u + kPayloadLength), out);  // the bytes a save writes in parts
    const uint16_t crc = crc16(out, (uint16_t)(4u + kPayloadLength));
    out[4 + kPayloadLength] = (uint8_t)(crc & 0xFFu);
    out[5 + kPayloadLength] = (uint8_t)(crc >> 8);
}

bool is_valid(const Settings& s) {
    return s.rate_hz >= kRateMinHz && s.rate_hz <= kRateMaxHz &&
           s.declination_centideg >= kDeclMinCentideg && s.declination_centideg <= kDeclMaxCentideg &&
           s.declination_centideg == centideg_of_rad(s.vehicle.compass_dec_rad) &&
           (uint8_t)s.mode <= (uint8_t)fmt::kLastOutputMode && (s.flags & ~0x07u) == 0u &&
           calib::is_plausible(s.cal) && params::all_valid(s);
}

// Out of line (FIXED_COLD): inlined into slots::load, its locals made load's frame too
// deep for ldd/std.
FIXED_COLD LoadResult decode(const uint8_t in[kRecordSize], Settings& out) {
    out = defaults();
    bool blank = true;
    for (uint8_t i = 0; i < kRecordSize; ++i) blank = blank && (in[i] == 0xFFu || in[i] == 0x00u);
    if (blank) return LoadResult::Blank;
    if (in[0] != kMagic0 || in[1] != kMagic1) return LoadResult::BadMagic;
    // Version 2's payload is this version's first part: read it, flight settings at
    // defaults. Versions 3 and 4 lack only the rows added since: they keep their defaults.
    const bool v2 = in[2] == 2u && in[3] == kV2PayloadLength;
    const bool v3 = in[2] == 3u && in[3] == kV3PayloadLength;
    const bool v4 = in[2] == 4u && in[3] == kV4PayloadLength;
    if (!v2 && !v3 && !v4 && (in[2] != kSettingsVersion || in[3] != kPayloadLength)) return LoadResult::OldVersion;
    const uint8_t len = in[3];
    const uint16_t crc = (uint16_t)(in[4 + len] | (uint16_t)((uint16_t)in[5 + len] << 8));
    if (crc != crc16(in, (uint16_t)(4u + len))) return LoadResult::BadCrc;
    // Into `out` itself (a copy would be a Settings more of stack), defaults again when
    // a value is out of range.
    out.rate_hz = in[4];
    // The declination's float from the hundredths: the second record, when it pairs, has it as sent.
    set_declination_centideg(out, (int16_t)(uint16_t)(in[5] | (uint16_t)((uint16_t)in[6] << 8)));
    out.mode = (fmt::OutputMode)in[7];
    out.flags = in[8];
    memcpy(&out.cal, in + 9, sizeof out.cal);
    if (v2) out.flags = (uint8_t)(out.flags | kFlagUpgraded);
    else params::decode_flight(in + 4 + kV2PayloadLength, (uint8_t)(len - kV2PayloadLength), out);
    if ((in[8] & kFlagUpgraded) != 0u || !is_valid(out)) {
        out = defaults();
        return LoadResult::BadValue;
    }
    return LoadResult::Ok;
}

}  // namespace settings
