// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionCommand.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define CODE_TABLE PROGMEM
#define CODE_BYTE(p) ((uint8_t)pgm_read_byte(&(p)))
#else
#define CODE_TABLE
#define CODE_BYTE(p) ((uint8_t)(p))
#endif

namespace mission {

namespace {

// The code in byte 0 of each supported id (its index here). Bytes: every id is below 256
// (8 bytes, not 16). In flash on the AVR (CODE_BYTE reads it): only read, by index, and a
// constexpr array indexed at run time is otherwise copied into RAM at start-up.
const uint8_t kCodes[] CODE_TABLE = {kNavWaypoint,       kNavLoiterUnlim, kNavLoiterTurns, kNavLoiterTime,
                                   kNavReturnToLaunch, kNavTakeoff,     kDoJump,         kDoChangeSpeed};
constexpr uint8_t kCodeCount = sizeof kCodes / sizeof kCodes[0];
constexpr uint8_t kRelativeBit = 0x10u;
constexpr uint8_t kCcwBit = 0x20u;

int8_t code_of(uint16_t id) {
    for (uint8_t i = 0; i < kCodeCount; ++i)
        if (CODE_BYTE(kCodes[i]) == id) return (int8_t)i;
    return -1;
}

void put_le(uint8_t* out, uint32_t v, uint8_t n) {
    for (uint8_t i = 0; i < n; ++i) out[i] = (uint8_t)(v >> (8u * i));
}
uint32_t get_le(const uint8_t* in, uint8_t n) {
    // From the last byte down, a whole byte's shift each time: on the AVR a uint32_t
    // shifted by a variable count is a loop of single-bit shifts.
    uint32_t v = 0;
    while (n > 0) v = (v << 8) | in[--n];
    return v;
}

}  // namespace

bool is_supported(uint16_t id) { return code_of(id) >= 0; }

bool is_nav(uint16_t id) { return is_supported(id) && id < kDoJump; }

void pack(const Command& c, uint8_t out[kCommandBytes]) {
    const int8_t code = code_of(c.id);
    out[0] = (uint8_t)((code < 0 ? 0x0Fu : (uint8_t)code) | (c.relative_alt ? kRelativeBit : 0u) |
                       (c.loiter_ccw ? kCcwBit : 0u));
    put_le(out + 1, c.p1, 2);
    const int32_t alt = c.alt_cm > kAltMaxCm ? kAltMaxCm : (c.alt_cm < -kAltMaxCm ? -kAltMaxCm : c.alt_cm);
    put_le(out + 3, (uint32_t)alt, 3);
    put_le(out + 6, (uint32_t)c.lat_e7, 4);
    put_le(out + 10, (uint32_t)c.lon_e7, 4);
}

bool unpack(const uint8_t in[kCommandBytes], Command& c) {
    const uint8_t code = in[0] & 0x0Fu;
    if (code >= kCodeCount || (in[0] & 0xC0u) != 0) return false;
    c.id = CODE_BYTE(kCodes[code]);
    c.relative_alt = (in[0] & kRelativeBit) != 0;
    c.loiter_ccw = (in[0] & kCcwBit) != 0;
    c.p1 = (uint16_t)get_le(in + 1, 2);
    uint32_t alt = get_le(in + 3, 3);
    if (alt & 0x800000u) alt |= 0xFF000000u;  // sign of the int24
    c.alt_cm = (int32_t)alt;
    c.lat_e7 = (int32_t)get_le(in + 6, 4);
    c.lon_e7 = (int32_t)get_le(in + 10, 4);
    return true;
}

}  // namespace mission
