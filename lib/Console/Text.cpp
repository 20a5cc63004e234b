// SPDX-License-Identifier: GPL-3.0-or-later
#include "Text.h"

#include "LinAlg.h"

namespace text {

uint8_t format_u32(char* buf, uint32_t v) {
    char tmp[10];
    uint8_t n = 0;
    do {
        const uint32_t q = v / 10u;  // one __udivmodsi4 gives both
        tmp[n++] = (char)('0' + (uint8_t)(v - q * 10u));
        v = q;
    } while (v != 0u);
    for (uint8_t i = 0; i < n; ++i) buf[i] = tmp[n - 1u - i];
    return n;
}

uint8_t format_int(char* buf, int32_t v) {
    // The magnitude as uint32 so INT32_MIN does not overflow.
    if (v >= 0) return format_u32(buf, (uint32_t)v);
    buf[0] = '-';
    return (uint8_t)(1u + format_u32(buf + 1, (uint32_t)0 - (uint32_t)v));
}

namespace {
// 10^d for d <= 4 (a loop, not a table: a table would sit in the AVR's SRAM).
uint16_t pow10(uint8_t d) {
    uint16_t p = 1u;
    while (d-- > 0u) p = (uint16_t)(p * 10u);
    return p;
}
}  // namespace

uint8_t format_fixed(char* buf, int32_t scaled, uint8_t decimals) {
    if (decimals > 4u) decimals = 4u;
    const uint16_t unit = pow10(decimals);
    const uint32_t mag = scaled < 0 ? (uint32_t)0 - (uint32_t)scaled : (uint32_t)scaled;
    uint8_t len = 0;
    if (scaled < 0) buf[len++] = '-';
    const uint32_t whole = mag / unit;
    len = (uint8_t)(len + format_u32(buf + len, whole));
    if (decimals == 0u) return len;
    uint16_t frac = (uint16_t)(mag - whole * unit);
    buf[len++] = '.';
    for (uint8_t i = decimals; i > 0u; --i) {  // leading zeros kept: 5 at 2 decimals is "0.05"
        const uint16_t pw = pow10((uint8_t)(i - 1u));
        char d = '0';
        while (frac >= pw) {
            frac = (uint16_t)(frac - pw);
            ++d;
        }
        buf[len++] = d;
    }
    return len;
}

uint8_t format_centi(char* buf, int32_t centi) { return format_fixed(buf, centi, 2); }

bool to_fixed(float x, uint8_t decimals, int32_t& out) {
    if (!linalg::is_finite(x) || decimals > 4u) return false;
    const float scaled = x * (float)pow10(decimals);
    if (scaled > 2.0e9f || scaled < -2.0e9f) return false;
    out = (int32_t)(scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f);
    return true;
}

bool to_centi(float x, int32_t& out) { return to_fixed(x, 2, out); }

namespace {
#ifdef __AVR__
#define TEXT_PROGMEM PROGMEM
#else
#define TEXT_PROGMEM
#endif
// The fragments of Text.h, NUL-separated, in flash: code k is the k-th.
constexpr uint8_t kFragmentCount = 7;
const char kFragments[] TEXT_PROGMEM =
    "# warn: \0# error: \0MPU6000\0HMC5883L\0EEPROM\0: default settings\0 (type help)";
}  // namespace

Writer& Writer::str(Flash s) {
    if (sink_ == nullptr || s.p == nullptr) return *this;
    char buf[16];  // runs of plain text go to the sink in pieces of up to 16 bytes
    uint8_t n = 0;
    for (const char* p = s.p;; ++p) {
        const uint8_t c = flash_byte(p);
        const bool fragment = c != 0u && c <= kFragmentCount;
        if (c == 0u || fragment || n == sizeof buf) {
            str(buf, n);
            n = 0;
        }
        if (c == 0u) return *this;
        if (fragment) {
            const char* f = kFragments;
            for (uint8_t k = c; --k != 0u;)
                while (flash_byte(f++) != 0u) {}
            str(Flash{f});
        } else {
            buf[n++] = (char)c;
        }
    }
}

Writer& Writer::str(const char* ram, uint8_t len) {
    if (sink_ != nullptr && len > 0) sink_->write(sink_->ctx, ram, len);
    return *this;
}

Writer& Writer::i32(int32_t v) {
    char buf[12];
    return str(buf, format_int(buf, v));
}

Writer& Writer::u32(uint32_t v) {
    char buf[10];
    return str(buf, format_u32(buf, v));
}

Writer& Writer::fixed2(float v) {
    int32_t c;
    if (!to_centi(v, c)) return chr('?');
    char buf[14];
    return str(buf, format_centi(buf, c));
}

Writer& Writer::vec(const linalg::Vector3f& v, float scale) {
    return fixed2(v.x * scale).chr(' ').fixed2(v.y * scale).chr(' ').fixed2(v.z * scale);
}

Writer& Writer::degrees_e7(int32_t v) {
    if (v < 0) chr('-');
    const uint32_t a = v < 0 ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
    u32(a / 10000000u).chr('.');
    char digits[7];
    uint32_t frac = a % 10000000u;
    for (uint8_t i = 7; i-- > 0;) {
        digits[i] = (char)('0' + frac % 10u);
        frac /= 10u;
    }
    return str(digits, 7);
}

Writer& Writer::hex8(uint8_t v) {
    const uint8_t hi = (uint8_t)(v >> 4), lo = (uint8_t)(v & 0x0Fu);
    const char buf[2] = {(char)(hi < 10u ? '0' + hi : 'A' + hi - 10u),
                         (char)(lo < 10u ? '0' + lo : 'A' + lo - 10u)};
    return str(buf, 2);
}

}  // namespace text
