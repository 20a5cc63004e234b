// SPDX-License-Identifier: GPL-3.0-or-later
// Text output seam: a tiny function-pointer sink plus a writer that formats integers
// and fixed-point numbers without printf or float printing.
//
// On AVR a string literal lives in SRAM unless it is put in flash (PROGMEM), and the
// firmware has < 2 KB of static RAM to spend: every message is written TXT("...")
// (flash on AVR, an ordinary literal on the host); Writer::str reads it byte by byte,
// expands the shared fragments (TXT_WARN ...) and hands the text to the sink's write.
// No Arduino include: the firmware implements the sink with its UART, the host tests
// with a std::string, the replay tool with stderr (a null sink is silent).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
// Through a function, not Flash{PSTR(s)}: avr-gcc 5.4's LTO crashes (internal compiler
// error in lto_output_varpool_node) on PSTR's statement expression inside a braced
// initialiser.
#define TXT(s) (::text::flash(PSTR(s)))
#else
#define TXT(s) (::text::flash(s))
#endif

// Fragments that many messages share, each one control byte inside a TXT string and
// expanded by Writer::str (flash spent once, not in every message). Write them as
// separate literals, TXT(TXT_WARN TXT_MPU " spike"): "\x03" "spike" cannot swallow the
// following hex digits. Codes 1..8 only: '\t' and '\n' are text.
#define TXT_WARN "\x01"    // "# warn: "
#define TXT_ERROR "\x02"   // "# error: "
#define TXT_MPU "\x03"     // "MPU6000"
#define TXT_HMC "\x04"     // "HMC5883L"
#define TXT_EEPROM "\x05"    // "EEPROM"
#define TXT_DEFAULTS "\x06"  // ": default settings"
#define TXT_HELP "\x07"      // " (type help)"

namespace text {

// A NUL-terminated string in program memory on AVR (ordinary memory on the host).
struct Flash {
    const char* p;
};
inline Flash flash(const char* p) { return Flash{p}; }
// One byte of a TXT string.
inline uint8_t flash_byte(const char* p) {
#ifdef __AVR__
    return pgm_read_byte(p);
#else
    return (uint8_t)*p;
#endif
}

struct Sink {
    void* ctx;
    void (*write)(void* ctx, const char* data, uint8_t len);  // bytes in RAM
};

// Decimal digits of v into buf (no NUL); returns the count (<= 10).
uint8_t format_u32(char* buf, uint32_t v);
// Decimal digits of v into buf (no NUL); returns the count (<= 11).
uint8_t format_int(char* buf, int32_t v);
// scaled / 10^decimals with exactly `decimals` (0..4) decimals ("-1.2345", "0.05");
// returns the count (<= 16).
uint8_t format_fixed(char* buf, int32_t scaled, uint8_t decimals);
// v/100 with exactly two decimals ("-1.23", "0.05"); returns the count (<= 14).
uint8_t format_centi(char* buf, int32_t centi);
// Nearest x * 10^decimals (0..4), rounding half away from zero. False (out untouched)
// when x is NaN, infinite or |x * 10^decimals| > 2e9, so nothing non-finite ever
// reaches the text.
bool to_fixed(float x, uint8_t decimals, int32_t& out);
// to_fixed(x, 2, out): false beyond +-2e7.
bool to_centi(float x, int32_t& out);

// Chained writes to a sink; every call is a no-op when the sink is null.
class Writer {
public:
    explicit Writer(const Sink* sink) : sink_(sink) {}
    // A TXT string, its fragment codes expanded.
    Writer& str(Flash s);
    Writer& str(const char* ram, uint8_t len);
    Writer& chr(char c) { return str(&c, 1); }
    Writer& i32(int32_t v);
    Writer& u32(uint32_t v);
    // Two decimals; a non-finite value prints as "?" (never "nan").
    Writer& fixed2(float v);
    // "x y z", each times `scale` with two decimals (fixed2).
    Writer& vec(const linalg::Vector3f& v, float scale = 1.0f);
    Writer& hex8(uint8_t v);  // two upper-case hex digits, no prefix
    // Degrees x 1e7 (a GPS latitude or longitude) with seven decimals: "-73.1194210".
    Writer& degrees_e7(int32_t v);
    Writer& end() { return chr('\n'); }

private:
    const Sink* sink_;
};

}  // namespace text
