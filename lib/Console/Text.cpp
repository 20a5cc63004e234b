#include "Text.h"

#include "LinAlg.h"

namespace text {

uint8_t format_int(char* buf, int32_t v) {
    // Work on the magnitude as uint32 so INT32_MIN does not overflow.
    uint32_t mag = v < 0 ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
    char tmp[10];
    uint8_t n = 0;
    do {
        tmp[n++] = (char)('0' + (uint8_t)(mag % 10u));
        mag /= 10u;
    } while (mag != 0u);
    uint8_t len = 0;
    if (v < 0) buf[len++] = '-';
    while (n > 0) buf[len++] = tmp[--n];
    return len;
}

uint8_t format_centi(char* buf, int32_t centi) {
    uint32_t mag = centi < 0 ? (uint32_t)0 - (uint32_t)centi : (uint32_t)centi;
    uint8_t len = 0;
    if (centi < 0) buf[len++] = '-';
    len = (uint8_t)(len + format_int(buf + len, (int32_t)(mag / 100u)));
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

Writer& Writer::str(Flash s) {
    if (sink_ != nullptr && s.p != nullptr) sink_->write_flash(sink_->ctx, s.p);
    return *this;
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
    char tmp[10];
    uint8_t n = 0;
    do {
        tmp[n++] = (char)('0' + (uint8_t)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    char buf[10];
    for (uint8_t i = 0; i < n; ++i) buf[i] = tmp[n - 1u - i];
    return str(buf, n);
}

Writer& Writer::fixed2(float v) {
    int32_t c;
    if (!to_centi(v, c)) return chr('?');
    char buf[14];
    return str(buf, format_centi(buf, c));
}

Writer& Writer::hex8(uint8_t v) {
    const uint8_t hi = (uint8_t)(v >> 4), lo = (uint8_t)(v & 0x0Fu);
    const char buf[2] = {(char)(hi < 10u ? '0' + hi : 'A' + hi - 10u),
                         (char)(lo < 10u ? '0' + lo : 'A' + lo - 10u)};
    return str(buf, 2);
}

}  // namespace text
