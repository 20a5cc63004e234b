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

uint8_t format_centi(char* buf, int32_t centi) {
    const uint32_t mag = centi < 0 ? (uint32_t)0 - (uint32_t)centi : (uint32_t)centi;
    uint8_t len = 0;
    if (centi < 0) buf[len++] = '-';
    len = (uint8_t)(len + format_u32(buf + len, mag / 100u));
    const uint8_t frac = (uint8_t)(mag % 100u);
    buf[len++] = '.';
    buf[len++] = (char)('0' + frac / 10u);
    buf[len++] = (char)('0' + frac % 10u);
    return len;
}

bool to_centi(float x, int32_t& out) {
    if (!linalg::is_finite(x) || x > 2.0e7f || x < -2.0e7f) return false;
    const float scaled = x * 100.0f;
    out = (int32_t)(scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f);
    return true;
}

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

Writer& Writer::hex8(uint8_t v) {
    const uint8_t hi = (uint8_t)(v >> 4), lo = (uint8_t)(v & 0x0Fu);
    const char buf[2] = {(char)(hi < 10u ? '0' + hi : 'A' + hi - 10u),
                         (char)(lo < 10u ? '0' + lo : 'A' + lo - 10u)};
    return str(buf, 2);
}

}  // namespace text
