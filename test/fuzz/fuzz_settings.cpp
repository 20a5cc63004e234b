// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: the EEPROM settings record (lib/Console/Settings).
// Built by mk/fuzz.mk with clang -fsanitize=fuzzer,address,undefined.
//
// 1. decode() on any kRecordSize bytes (the input, padded with 0xFF as erased EEPROM):
//    anything but Ok leaves exactly defaults(); Ok gives valid settings whose encode()
//    is the input record byte for byte (nothing in the record is ignored).
// 2. Round trip: settings built from the input within every field's range encode and
//    decode back to the same bytes; one flipped bit of that record (a position from the
//    input) is never Ok (CRC-16 catches every single-bit error) and gives defaults.
#include <stddef.h>
#include <stdint.h>

#include <cstdlib>
#include <cstring>

#include "FuzzAssert.h"
#include "Settings.h"

namespace {

bool is_defaults(const settings::Settings& s) {
    uint8_t a[settings::kRecordSize], b[settings::kRecordSize];
    settings::encode(s, a);
    settings::encode(settings::defaults(), b);
    return std::memcmp(a, b, sizeof a) == 0;
}

// Reads input bytes in turn (0 once exhausted).
struct Bytes {
    const uint8_t* p;
    size_t n;
    uint8_t u8() { return n > 0 ? (--n, *p++) : 0; }
    uint16_t u16() { return (uint16_t)(u8() | (uint16_t)(u8() << 8)); }
    float in(float lo, float hi) { return lo + (hi - lo) * (float)u16() / 65535.0f; }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // 1. decode on arbitrary bytes.
    uint8_t rec[settings::kRecordSize];
    std::memset(rec, 0xFF, sizeof rec);
    std::memcpy(rec, data, size < sizeof rec ? size : sizeof rec);
    settings::Settings s;
    std::memset(&s, 0xA5, sizeof s);  // garbage in: decode must overwrite it
    const settings::LoadResult r = settings::decode(rec, s);
    if (r == settings::LoadResult::Ok) {
        fuzz_assert(settings::is_valid(s));
        uint8_t again[settings::kRecordSize];
        settings::encode(s, again);
        if ((s.flags & settings::kFlagUpgraded) != 0u) {
            // A version 2 record: saved again as version 3, the same settings.
            settings::Settings t;
            fuzz_assert(settings::decode(again, t) == settings::LoadResult::Ok);
            uint8_t twice[settings::kRecordSize];
            settings::encode(t, twice);
            fuzz_assert(std::memcmp(again, twice, sizeof again) == 0);
        } else {
            fuzz_assert(std::memcmp(again, rec, sizeof rec) == 0);
        }
    } else {
        fuzz_assert(is_defaults(s));
    }

    // 2. Round trip of settings within range, and a flipped bit.
    Bytes in{data, size};
    settings::Settings v = settings::defaults();
    v.rate_hz = (uint8_t)(settings::kRateMinHz + in.u8() % (settings::kRateMaxHz - settings::kRateMinHz + 1));
    settings::set_declination_centideg(
        v, (int16_t)(settings::kDeclMinCentideg +
                     (int32_t)(in.u16() % (settings::kDeclMaxCentideg - settings::kDeclMinCentideg + 1))));
    v.mode = (fmt::OutputMode)(in.u8() % 3u);
    v.flags = (uint8_t)(in.u8() & 0x03u);
    const float bias = calib::kGyroBiasMax_rad_s;
    v.cal.gyro_bias_rad_s = linalg::Vector3f(in.in(-bias, bias), in.in(-bias, bias), in.in(-bias, bias));
    v.cal.mag_offset_uT = linalg::Vector3f(in.in(-200.0f, 200.0f), in.in(-200.0f, 200.0f), in.in(-200.0f, 200.0f));
    v.cal.mag_scale = linalg::Vector3f(in.in(0.5f, 2.0f), in.in(0.5f, 2.0f), in.in(0.5f, 2.0f));
    fuzz_assert(settings::is_valid(v));
    uint8_t good[settings::kRecordSize], back[settings::kRecordSize];
    settings::encode(v, good);
    settings::Settings w;
    fuzz_assert(settings::decode(good, w) == settings::LoadResult::Ok);
    settings::encode(w, back);
    fuzz_assert(std::memcmp(good, back, sizeof good) == 0);

    const unsigned bit = in.u16() % (settings::kRecordSize * 8u);
    good[bit / 8u] = (uint8_t)(good[bit / 8u] ^ (1u << (bit % 8u)));
    fuzz_assert(settings::decode(good, w) != settings::LoadResult::Ok);
    fuzz_assert(is_defaults(w));
    return 0;
}
