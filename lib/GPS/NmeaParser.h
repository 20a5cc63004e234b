// SPDX-License-Identifier: GPL-3.0-or-later
// NMEA 0183 sentences from a byte stream (GGA, RMC, VTG of any talker: $GP, $GN ...),
// into the same gps::Fix as the UBX parser (u-blox 6 Receiver Description, "NMEA
// Protocol"), fed a byte at a time. Nothing is stored but the field being read and the
// values decoded so far: a sentence's values count only once its checksum (the XOR of
// the characters between '$' and '*') is right. A sentence longer than kMaxSentence
// (NMEA 0183 allows 82 characters with "$", "*hh" and CR LF: 76 between; 3 more are
// tolerated), a field longer than kMaxField, or a sentence without "*hh" is dropped.
//
// Integer arithmetic throughout: latitude "ddmm.mmmmm" and longitude "dddmm.mmmmm" to
// 1e-7 degree (minutes to 7 decimals, divided by 60 with rounding), height to mm, speed
// from knots to cm/s, course to 1e-5 degree, HDOP to hundredths.
//
// A fix is complete when GGA (position, height, satellites, HDOP, quality) and RMC (speed
// and course; VTG also updates them) of the same UTC time have both arrived. It is a fix
// when GGA's quality is not 0 and RMC's status is 'A'; 2D or 3D as the last GSA's mode
// says (3D while no GSA was seen, as ArduPilot's NMEA driver assumes). NMEA carries no
// vertical velocity; the north and east velocity come from speed and course.
#pragma once

#include <stdint.h>

#include "GpsFix.h"

namespace gps {

class NmeaParser {
public:
    static constexpr uint8_t kMaxSentence = 79;  // characters between '$' and '*' (NMEA 0183: 76)
    static constexpr uint8_t kMaxField = 15;

    enum class Message : uint8_t {
        kNone,   // no sentence ended with this byte (or a bad one)
        kFix,    // a complete fix: fix()
        kOther,  // another valid sentence
    };
    struct Counters {
        uint32_t sentences = 0;     // valid (checksum good)
        uint16_t bad_checksum = 0;
        uint16_t malformed = 0;     // too long, a field too long, no "*hh"
    };

    // The working solution (see UbxParser); constexpr as UbxParser's.
    explicit constexpr NmeaParser(Fix& work) : field_{}, v_{}, fix_(work) {}

    Message feed(uint8_t byte);
    const Fix& fix() const { return fix_; }
    const Counters& counters() const { return counters_; }
    void reset() { state_ = kIdle; }

private:
    enum State : uint8_t { kIdle, kBody, kCk1, kCk2 };
    enum Kind : uint8_t { kUnknown, kGga, kRmc, kVtg, kGsa };
    void field_end();
    Message sentence_end();

    State state_ = kIdle;
    Kind kind_ = kUnknown;
    uint8_t length_ = 0;       // characters of the body so far
    uint8_t field_index_ = 0;
    uint8_t field_len_ = 0;
    uint8_t xor_ = 0, given_ = 0;
    bool field_overflow_ = false;
    char field_[kMaxField + 1];
    // The values of the sentence being read, committed at a good checksum.
    struct Values {
        uint32_t time_cs;          // UTC hhmmss.ss as centiseconds of the day
        int32_t lat_e7, lon_e7, alt_mm;
        uint32_t speed_cm_s;
        int32_t course_e5;
        uint16_t hdop_cm;
        uint8_t sats, quality, mode;  // GSA mode: 1 none, 2 2D, 3 3D
        bool valid : 1;            // RMC 'A'
        bool have_time : 1, have_pos : 1, have_alt : 1, have_course : 1, have_speed : 1;
    } v_;
    // The working solution, complete at kFix results.
    Fix& fix_;
    uint32_t gga_time_cs_ = 0xFFFFFFFFu, rmc_time_cs_ = 0xFFFFFFFEu;
    uint8_t quality_ = 0;
    uint8_t mode_ = 3;  // the last GSA's
    bool rmc_valid_ = false;
    Counters counters_;
};

namespace nmea {

// "[-]digits[.digits]" as value * 10^decimals, extra decimals cut off; false for an
// empty field, anything else, or more than 9 significant digits.
bool parse_decimal(const char* s, uint8_t decimals, int32_t& out);
// "ddmm.mmmm" (deg_digits 2) or "dddmm.mmmm" (3) as degrees * 1e7; false when malformed.
bool parse_angle_e7(const char* s, uint8_t deg_digits, int32_t& out);

}  // namespace nmea
}  // namespace gps
