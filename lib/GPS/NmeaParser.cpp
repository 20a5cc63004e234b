// SPDX-License-Identifier: GPL-3.0-or-later
#include "NmeaParser.h"

#include <math.h>

#include "Constants.h"
#include "UbxProtocol.h"

namespace gps {

namespace nmea {

bool parse_decimal(const char* s, uint8_t decimals, int32_t& out) {
    bool negative = false;
    if (*s == '-') {
        negative = true;
        ++s;
    }
    int32_t v = 0;
    uint8_t digits = 0, after_point = 0;
    bool point = false;
    for (; *s != '\0'; ++s) {
        if (*s == '.' && !point) {
            point = true;
            continue;
        }
        if (*s < '0' || *s > '9') return false;
        if (point && after_point == decimals) continue;  // extra decimals cut off
        if (++digits > 9) return false;
        v = v * 10 + (*s - '0');
        if (point) ++after_point;
    }
    if (digits == 0) return false;
    for (; after_point < decimals; ++after_point) {
        if (v > 214748363) return false;
        v *= 10;
    }
    out = negative ? -v : v;
    return true;
}

bool parse_angle_e7(const char* s, uint8_t deg_digits, int32_t& out) {
    int32_t degrees = 0;
    for (uint8_t i = 0; i < deg_digits; ++i) {
        if (s[i] < '0' || s[i] > '9') return false;
        degrees = degrees * 10 + (s[i] - '0');
    }
    int32_t minutes_e7;  // minutes * 1e7: < 60e7
    if (s[deg_digits] == '-' || !parse_decimal(s + deg_digits, 7, minutes_e7) || minutes_e7 >= 600000000) return false;
    out = degrees * 10000000 + (minutes_e7 + 30) / 60;
    return true;
}

}  // namespace nmea

namespace {

// "hhmmss[.ss]" as centiseconds of the day.
bool parse_time_cs(const char* s, uint32_t& out) {
    int32_t hhmmss_cs;
    if (!nmea::parse_decimal(s, 2, hhmmss_cs) || hhmmss_cs < 0) return false;
    const uint32_t t = (uint32_t)hhmmss_cs;
    const uint32_t cs = t % 100u, ss = t / 100u % 100u, mm = t / 10000u % 100u, hh = t / 1000000u;
    if (ss > 60u || mm > 59u || hh > 23u) return false;
    out = ((hh * 60u + mm) * 60u + ss) * 100u + cs;
    return true;
}

}  // namespace

NmeaParser::Message NmeaParser::feed(uint8_t byte) {
    if (byte == '$') {  // a start, wherever it comes (a sentence broken off is dropped)
        if (state_ != kIdle) ++counters_.malformed;
        state_ = kBody;
        kind_ = kUnknown;
        length_ = field_index_ = field_len_ = 0;
        xor_ = 0;
        field_overflow_ = false;
        v_ = Values{0, 0, 0, 0, 0, 0, 9999, 0, 0, 0, false, false, false, false, false, false};
        return Message::kNone;
    }
    switch (state_) {
        case kIdle: return Message::kNone;
        case kBody:
            if (byte == '*') {
                field_end();
                state_ = kCk1;
                return Message::kNone;
            }
            if (byte < 0x20 || byte > 0x7E || ++length_ > kMaxSentence) {
                ++counters_.malformed;
                state_ = kIdle;
                return Message::kNone;
            }
            xor_ = (uint8_t)(xor_ ^ byte);
            if (byte == ',') {
                field_end();
            } else if (field_len_ < kMaxField) {
                field_[field_len_++] = (char)byte;
            } else {
                field_overflow_ = true;
            }
            return Message::kNone;
        case kCk1: {
            const int8_t h = nmea::hex_value(byte);
            if (h < 0) {
                ++counters_.malformed;
                state_ = kIdle;
                return Message::kNone;
            }
            given_ = (uint8_t)(h << 4);
            state_ = kCk2;
            return Message::kNone;
        }
        case kCk2: {
            state_ = kIdle;
            const int8_t h = nmea::hex_value(byte);
            if (h < 0) {
                ++counters_.malformed;
                return Message::kNone;
            }
            if ((uint8_t)(given_ | (uint8_t)h) != xor_) {
                ++counters_.bad_checksum;
                return Message::kNone;
            }
            if (field_overflow_) {
                ++counters_.malformed;
                return Message::kNone;
            }
            ++counters_.sentences;
            return sentence_end();
        }
    }
    return Message::kNone;
}

// A field has ended: its value into v_ (an empty or malformed field leaves it unset).
void NmeaParser::field_end() {
    field_[field_len_] = '\0';
    const char* f = field_;
    const uint8_t i = field_index_++;
    field_len_ = 0;
    if (i == 0) {  // the address: a two-letter talker and the sentence
        if (f[0] == '\0' || f[1] == '\0' || f[2] == '\0' || f[3] == '\0' || f[4] == '\0') return;
        // (characters, not string literals: those would take the AVR's RAM)
        const char a = f[2], b = f[3], c = f[4];
        kind_ = f[5] != '\0'                          ? kUnknown
                : (a == 'G' && b == 'G' && c == 'A') ? kGga
                : (a == 'R' && b == 'M' && c == 'C') ? kRmc
                : (a == 'V' && b == 'T' && c == 'G') ? kVtg
                : (a == 'G' && b == 'S' && c == 'A') ? kGsa
                                                     : kUnknown;
        return;
    }
    int32_t x;
    switch (kind_) {
        case kGga:
            // time, lat, N/S, lon, E/W, quality, satellites, HDOP, height MSL, M, ...
            if (i == 1) v_.have_time = parse_time_cs(f, v_.time_cs);
            else if (i == 2) v_.have_pos = nmea::parse_angle_e7(f, 2, v_.lat_e7);
            else if (i == 3 && f[0] == 'S') v_.lat_e7 = -v_.lat_e7;
            else if (i == 3 && f[0] != 'N') v_.have_pos = false;
            else if (i == 4) v_.have_pos = v_.have_pos && nmea::parse_angle_e7(f, 3, v_.lon_e7);
            else if (i == 5 && f[0] == 'W') v_.lon_e7 = -v_.lon_e7;
            else if (i == 5 && f[0] != 'E') v_.have_pos = false;
            else if (i == 6 && nmea::parse_decimal(f, 0, x) && x >= 0 && x <= 9) v_.quality = (uint8_t)x;
            else if (i == 7 && nmea::parse_decimal(f, 0, x) && x >= 0 && x <= 99) v_.sats = (uint8_t)x;
            else if (i == 8 && nmea::parse_decimal(f, 2, x) && x >= 0 && x <= 9999) v_.hdop_cm = (uint16_t)x;
            else if (i == 9) v_.have_alt = nmea::parse_decimal(f, 3, v_.alt_mm);
            return;
        case kRmc:
            // time, status A/V, lat, N/S, lon, E/W, speed (knots), course (deg), date, ...
            if (i == 1) v_.have_time = parse_time_cs(f, v_.time_cs);
            else if (i == 2) v_.valid = f[0] == 'A' && f[1] == '\0';
            else if (i == 7 || (i == 5 && kind_ == kVtg)) {
                // knots * 1000 -> cm/s: 1 kn = 1852 m / 3600 s, so cm/s = milli-knots * 463 / 9000
                v_.have_speed = nmea::parse_decimal(f, 3, x) && x >= 0 && x < 5000000;
                if (v_.have_speed) v_.speed_cm_s = ((uint32_t)x * 463u + 4500u) / 9000u;
            } else if (i == 8) {
                v_.have_course = nmea::parse_decimal(f, 5, x) && x >= 0 && x <= 36000000;
                v_.course_e5 = x;
            }
            return;
        case kVtg:
            // course true, T, course magnetic, M, speed (knots), N, speed (km/h), K, mode
            if (i == 1) {
                v_.have_course = nmea::parse_decimal(f, 5, x) && x >= 0 && x <= 36000000;
                v_.course_e5 = x;
            } else if (i == 5) {
                v_.have_speed = nmea::parse_decimal(f, 3, x) && x >= 0 && x < 5000000;
                if (v_.have_speed) v_.speed_cm_s = ((uint32_t)x * 463u + 4500u) / 9000u;
            }
            return;
        case kGsa:
            // mode M/A, fix mode 1 none / 2 2D / 3 3D, ...
            if (i == 2 && nmea::parse_decimal(f, 0, x) && x >= 1 && x <= 3) v_.mode = (uint8_t)x;
            return;
        case kUnknown: return;
    }
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) NmeaParser::Message NmeaParser::sentence_end() {
    switch (kind_) {
        case kGga:
            if (!v_.have_time) return Message::kOther;
            gga_time_cs_ = v_.time_cs;
            quality_ = v_.have_pos ? v_.quality : 0u;
            if (quality_ != 0u) {
                fix_.lat_e7 = v_.lat_e7;
                fix_.lon_e7 = v_.lon_e7;
                if (v_.have_alt) fix_.alt_msl_mm = v_.alt_mm;
            }
            fix_.sats = v_.sats;
            fix_.hdop_cm = v_.hdop_cm;
            break;
        case kRmc:
        case kVtg:
            if (v_.have_speed) fix_.ground_speed_cm_s = v_.speed_cm_s;
            if (v_.have_course) fix_.course_e5 = v_.course_e5;
            if (kind_ == kVtg) return Message::kOther;
            if (!v_.have_time) return Message::kOther;
            rmc_time_cs_ = v_.time_cs;
            rmc_valid_ = v_.valid;
            break;
        case kGsa:
            if (v_.mode != 0u) mode_ = v_.mode;
            return Message::kOther;
        case kUnknown: return Message::kOther;
    }
    if (gga_time_cs_ != rmc_time_cs_) return Message::kOther;
    rmc_time_cs_ = 0xFFFFFFFEu;  // each pair once
    fix_.itow_ms = gga_time_cs_ * 10u;
    fix_.fix = (quality_ == 0u || !rmc_valid_ || mode_ < 2u) ? FixType::kNoFix
               : mode_ == 2u                                 ? FixType::k2D
                                                             : FixType::k3D;
    // North and east from speed and course (NMEA has no vertical velocity).
    const float course_rad = (float)fix_.course_e5 * 1e-5f * linalg::kRadPerDeg;
    const float speed = (float)fix_.ground_speed_cm_s;
    const float c = cosf(course_rad), s = sinf(course_rad);  // (avr-libc's are double = float)
    fix_.vel_ned_cm_s[0] = (int32_t)lroundf(speed * c);
    fix_.vel_ned_cm_s[1] = (int32_t)lroundf(speed * s);
    fix_.vel_ned_cm_s[2] = 0;
    fix_.have_vertical_velocity = false;
    fix_.h_acc_mm = 0;
    fix_.speed_acc_cm_s = 0;
    return Message::kFix;
}

}  // namespace gps
