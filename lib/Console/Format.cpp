// SPDX-License-Identifier: GPL-3.0-or-later
#include "Format.h"

#include "Fixed.h"
#include "Text.h"

namespace fmt {

namespace {

// Hundredths of an angle, rounded half away from zero, in integers: the angle read in
// Q15 from its bits (|deg| < 360.005: < 2^24), times 100 (< 2^31), rounded (integer
// shifts and one 32-bit multiply where a float multiply, add and conversion would be
// library calls on the 2560; the Q15 truncation, < 3.1e-5 deg, moves a value only within
// 0.003 % of a half count). False for NaN,
// infinities and anything beyond a full turn (|c| > 36000), which is not an attitude
// angle.
bool centi_angle(float deg, int32_t& out) {
    if (!(deg > -360.005f && deg < 360.005f)) return false;  // NaN fails both
    const int32_t q15 = linalg::fixed_from_float(deg, 15);
    const uint32_t m = linalg::magnitude(q15) * 100u + 0x4000u;
    // m >> 15 from whole bytes and one bit (the result is <= 36001).
    const uint16_t c = (uint16_t)((uint16_t)((uint16_t)(m >> 16) << 1) | (uint16_t)((uint16_t)m >> 15));
    out = q15 < 0 ? -(int32_t)c : (int32_t)c;
    return out >= -36000 && out <= 36000;
}

bool angles_centi(float roll_deg, float pitch_deg, float heading_deg, int32_t c[3]) {
    return centi_angle(roll_deg, c[0]) && centi_angle(pitch_deg, c[1]) && centi_angle(heading_deg, c[2]);
}

// The hundredths as printed: false beyond a full turn (not an attitude angle); a
// heading of 360.00 (359.996 rounds to it) is the same heading as 0.00.
bool within_turn(int32_t c) { return c >= -36000 && c <= 36000; }
bool printable(int32_t roll, int32_t pitch, int32_t& heading) {
    if (!within_turn(roll) || !within_turn(pitch) || !within_turn(heading)) return false;
    if (heading == 36000) heading = 0;
    return true;
}

// One decimal digit of m at the power `pw` by subtraction (no division on the AVR).
char digit(uint16_t& m, uint16_t pw) {
    char d = '0';
    while (m >= pw) {
        m = (uint16_t)(m - pw);
        ++d;
    }
    return d;
}

// |c| <= 36000 hundredths as "[-]d.dd" (no leading zeros); returns the end.
char* put_centi(char* p, int32_t c) {
    if (c < 0) {
        *p++ = '-';
        c = -c;
    }
    uint16_t m = (uint16_t)c;  // <= 36000: 16-bit arithmetic from here
    char d = digit(m, 10000);
    bool lead = d != '0';
    if (lead) *p++ = d;
    d = digit(m, 1000);
    lead = lead || d != '0';
    if (lead) *p++ = d;
    *p++ = digit(m, 100);
    *p++ = '.';
    *p++ = digit(m, 10);
    *p++ = (char)('0' + m);
    return p;
}

// A label from flash (TXT: in SRAM the four formats' labels would hold RAM for good).
char* put(char* p, text::Flash s) {
    for (const char* q = s.p;; ++q) {
        const char ch = (char)text::flash_byte(q);
        if (ch == '\0') return p;
        *p++ = ch;
    }
}

}  // namespace

uint8_t format_plot_line_centideg(char buf[kLineMax], int32_t roll_centideg, int32_t pitch_centideg,
                                  int32_t heading_centideg) {
    if (!printable(roll_centideg, pitch_centideg, heading_centideg)) return 0;
    char* p = put(buf, TXT("roll:"));
    p = put_centi(p, roll_centideg);
    p = put(p, TXT(" pitch:"));
    p = put_centi(p, pitch_centideg);
    p = put(p, TXT(" yaw:"));
    p = put_centi(p, heading_centideg);
    *p++ = '\n';
    return (uint8_t)(p - buf);
}

uint8_t format_csv_line_centideg(char buf[kLineMax], uint32_t t_ms, int32_t roll_centideg, int32_t pitch_centideg,
                                 int32_t heading_centideg) {
    if (!printable(roll_centideg, pitch_centideg, heading_centideg)) return 0;
    char* p = buf + text::format_u32(buf, t_ms);
    const int32_t c[3] = {roll_centideg, pitch_centideg, heading_centideg};
    for (uint8_t i = 0; i < 3; ++i) {
        *p++ = ',';
        p = put_centi(p, c[i]);
    }
    *p++ = '\n';
    return (uint8_t)(p - buf);
}

uint8_t format_plot_line(char buf[kLineMax], float roll_deg, float pitch_deg, float heading_deg) {
    int32_t c[3];
    if (!angles_centi(roll_deg, pitch_deg, heading_deg, c)) return 0;
    return format_plot_line_centideg(buf, c[0], c[1], c[2]);
}

uint8_t format_csv_line(char buf[kLineMax], uint32_t t_ms, float roll_deg, float pitch_deg,
                        float heading_deg) {
    int32_t c[3];
    if (!angles_centi(roll_deg, pitch_deg, heading_deg, c)) return 0;
    return format_csv_line_centideg(buf, t_ms, c[0], c[1], c[2]);
}

namespace {

// "label:value" with `decimals` decimals; false if v is not finite or |v| > limit.
bool put_field(char*& p, text::Flash label, float v, uint8_t decimals, float limit) {
    int32_t scaled;
    if (!(v >= -limit && v <= limit) || !text::to_fixed(v, decimals, scaled)) return false;
    p = put(p, label);
    p += text::format_fixed(p, scaled, decimals);
    return true;
}

}  // namespace

uint8_t format_quat_line(char buf[kLineMax], const linalg::Quaternion& q) {
    char* p = buf;
    if (!put_field(p, TXT("qw:"), q.w, 4, 1.0001f) || !put_field(p, TXT(" qx:"), q.x, 4, 1.0001f) ||
        !put_field(p, TXT(" qy:"), q.y, 4, 1.0001f) || !put_field(p, TXT(" qz:"), q.z, 4, 1.0001f))
        return 0;
    *p++ = '\n';
    return (uint8_t)(p - buf);
}

uint8_t format_raw_line(char buf[kRawLineMax], const linalg::Vector3f& gyro_dps, const linalg::Vector3f& accel_g,
                        const linalg::Vector3f& field_uT) {
    constexpr float kGyroMaxDps = 9999.0f, kAccelMaxG = 40.0f, kFieldMaxUt = 999.9f;
    char* p = buf;
    if (!put_field(p, TXT("gx:"), gyro_dps.x, 2, kGyroMaxDps) ||
        !put_field(p, TXT(" gy:"), gyro_dps.y, 2, kGyroMaxDps) ||
        !put_field(p, TXT(" gz:"), gyro_dps.z, 2, kGyroMaxDps) ||
        !put_field(p, TXT(" ax:"), accel_g.x, 3, kAccelMaxG) ||
        !put_field(p, TXT(" ay:"), accel_g.y, 3, kAccelMaxG) ||
        !put_field(p, TXT(" az:"), accel_g.z, 3, kAccelMaxG) ||
        !put_field(p, TXT(" mx:"), field_uT.x, 1, kFieldMaxUt) ||
        !put_field(p, TXT(" my:"), field_uT.y, 1, kFieldMaxUt) ||
        !put_field(p, TXT(" mz:"), field_uT.z, 1, kFieldMaxUt))
        return 0;
    *p++ = '\n';
    return (uint8_t)(p - buf);
}

}  // namespace fmt
