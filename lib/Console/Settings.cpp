#include "Settings.h"

#include <string.h>

namespace settings {

using linalg::Vector3f;

Settings defaults() {
    Settings s;
    s.rate_hz = kRateDefaultHz;
    s.declination_centideg = 0;
    s.mode = fmt::OutputMode::Plot;
    s.flags = 0;
    s.cal = calib::default_calibration();
    return s;
}

// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF): check value 0x29B1 for "123456789".
uint16_t crc16(const uint8_t* data, uint16_t len) {
    uint16_t crc = 0xFFFFu;
    for (uint16_t i = 0; i < len; ++i) {
        crc = (uint16_t)(crc ^ (uint16_t)((uint16_t)data[i] << 8));
        for (uint8_t b = 0; b < 8; ++b)
            crc = (crc & 0x8000u) ? (uint16_t)((uint16_t)(crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
    }
    return crc;
}

namespace {

struct Out {
    uint8_t* p;
    void u8(uint8_t v) { *p++ = v; }
    void u16(uint16_t v) { u8((uint8_t)(v & 0xFFu)); u8((uint8_t)(v >> 8)); }
    void f32(float v) {
        uint8_t b[4];
        memcpy(b, &v, 4);  // IEEE-754 little-endian on both the AVR and x86/ARM hosts
        for (uint8_t i = 0; i < 4; ++i) u8(b[i]);
    }
    void vec(const Vector3f& v) { f32(v.x); f32(v.y); f32(v.z); }
};

struct In {
    const uint8_t* p;
    uint8_t u8() { return *p++; }
    uint16_t u16() { const uint8_t lo = u8(); return (uint16_t)(lo | (uint16_t)((uint16_t)u8() << 8)); }
    float f32() {
        uint8_t b[4];
        for (uint8_t i = 0; i < 4; ++i) b[i] = u8();
        float v;
        memcpy(&v, b, 4);
        return v;
    }
    Vector3f vec() { const float x = f32(); const float y = f32(); return Vector3f(x, y, f32()); }
};

}  // namespace

void encode(const Settings& s, uint8_t out[kRecordSize]) {
    Out o{out};
    o.u8(kMagic0);
    o.u8(kMagic1);
    o.u8(kSettingsVersion);
    o.u8(kPayloadLength);
    o.u8(s.rate_hz);
    o.u16((uint16_t)s.declination_centideg);
    o.u8((uint8_t)s.mode);
    o.u8(s.flags);
    o.vec(s.cal.gyro_bias_rad_s);
    o.vec(s.cal.mag_offset_uT);
    o.vec(s.cal.mag_scale);
    o.u16(crc16(out, (uint16_t)(4u + kPayloadLength)));
}

bool is_valid(const Settings& s) {
    return s.rate_hz >= kRateMinHz && s.rate_hz <= kRateMaxHz &&
           s.declination_centideg >= kDeclMinCentideg && s.declination_centideg <= kDeclMaxCentideg &&
           (uint8_t)s.mode <= (uint8_t)fmt::OutputMode::Quiet && (s.flags & ~0x03u) == 0u &&
           calib::is_plausible(s.cal);
}

LoadResult decode(const uint8_t in[kRecordSize], Settings& out) {
    out = defaults();
    bool blank = true;
    for (uint8_t i = 0; i < kRecordSize; ++i) blank = blank && (in[i] == 0xFFu || in[i] == 0x00u);
    if (blank) return LoadResult::Blank;
    if (in[0] != kMagic0 || in[1] != kMagic1) return LoadResult::BadMagic;
    if (in[2] != kSettingsVersion || in[3] != kPayloadLength) return LoadResult::OldVersion;
    In r{in + 4 + kPayloadLength};
    if (r.u16() != crc16(in, (uint16_t)(4u + kPayloadLength))) return LoadResult::BadCrc;
    In p{in + 4};
    Settings s;
    s.rate_hz = p.u8();
    s.declination_centideg = (int16_t)p.u16();
    s.mode = (fmt::OutputMode)p.u8();
    s.flags = p.u8();
    s.cal.gyro_bias_rad_s = p.vec();
    s.cal.mag_offset_uT = p.vec();
    s.cal.mag_scale = p.vec();
    if (!is_valid(s)) return LoadResult::BadValue;
    out = s;
    return LoadResult::Ok;
}

}  // namespace settings
