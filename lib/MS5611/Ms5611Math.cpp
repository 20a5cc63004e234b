// SPDX-License-Identifier: GPL-3.0-or-later
#include "Ms5611Math.h"

namespace ms5611 {

uint8_t crc4(const uint16_t prom[kPromWords]) {
    // AN520: the 16 bytes MSB first, polynomial 0x3000 over a 16-bit remainder.
    uint16_t rem = 0;
    for (uint8_t cnt = 0; cnt < 2u * kPromWords; ++cnt) {
        uint16_t word = prom[cnt >> 1];
        if ((cnt >> 1) == kPromWords - 1u) word &= 0xFF00u;  // the CRC byte taken as 0
        rem ^= (cnt & 1u) ? (uint16_t)(word & 0x00FFu) : (uint16_t)(word >> 8);
        for (uint8_t bit = 8; bit > 0; --bit)
            rem = (rem & 0x8000u) ? (uint16_t)((uint16_t)(rem << 1) ^ 0x3000u) : (uint16_t)(rem << 1);
    }
    return (uint8_t)((rem >> 12) & 0x000Fu);
}

PromStatus check_prom(const uint16_t prom[kPromWords]) {
    // A silent bus reads all 0 (whose CRC-4 is 0 too) or all 1: not a chip.
    bool zeros = true, ones = true;
    for (uint8_t i = 0; i < kPromWords; ++i) {
        zeros = zeros && prom[i] == 0x0000u;
        ones = ones && prom[i] == 0xFFFFu;
    }
    if (zeros || ones) return PromStatus::Blank;
    return crc4(prom) == (prom[kPromWords - 1u] & 0x000Fu) ? PromStatus::Ok : PromStatus::BadCrc;
}

// The datasheet's "Calculate temperature compensated pressure" and "Second order
// temperature compensation" with the same integers, in less code: avr-gcc expands each
// int64_t operation inline (a signed division by 2^n is a sign test, a bias and a library
// shift; a 64 x 64 multiply is __muldi3), so the 64-bit products and divisions are done
// by two helpers called, not expanded, and what fits 32 bits over the datasheet's ranges
// (dT, TEMP, T2, OFF2, SENS2) is 32-bit.
namespace {

// The two halves of a 64-bit value (AVR and the hosts are little-endian).
union Wide {
    int64_t s;
    struct {
        uint32_t lo, hi;
    } w;
};
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "Wide's halves are little-endian");

// x * b, 32 x 32 -> 64 bits (libgcc's __mulsidi3, ~240 cycles; its 64 x 64 __muldi3
// takes ~430), at one call site rather than expanded at each use.
__attribute__((noinline)) int64_t mul_wide(int32_t x, int32_t b) { return (int64_t)x * b; }

// x / 2^n rounded toward zero as C's division (the datasheet's, and an arithmetic shift
// is not: it rounds toward minus infinity): the magnitude shifted (libgcc's __lshrdi3,
// whole bytes then bits) and the sign put back.
__attribute__((noinline)) int64_t div_pow2(int64_t x, uint8_t n) {
    return x < 0 ? -(int64_t)((uint64_t)(-x) >> n) : (int64_t)((uint64_t)x >> n);
}

constexpr int32_t kColdestC100 = -4000;  // datasheet: TEMP's minimum, -40 degC

}  // namespace

Terms terms(const uint16_t prom[kPromWords], uint32_t d2) {
    // dT = D2 - C5 * 2^8: 25 bits (-16776960..16777215, the datasheet's range);
    // TEMP = 2000 + dT * C6 / 2^23 (dT * C6: 41 bits; TEMP itself fits 18 bits).
    const int32_t dt = (int32_t)d2 - (int32_t)((uint32_t)prom[5] << 8);
    int32_t temp = 2000 + (int32_t)div_pow2(mul_wide(dt, prom[6]), 23);
    // OFF = C2 * 2^16 + C4 * dT / 2^7, SENS = C1 * 2^15 + C3 * dT / 2^8: 35 bits each
    // (C2 * 2^16 and C1 * 2^15 alone fit 32 unsigned bits).
    int64_t off = (int64_t)((uint32_t)prom[2] << 16) + div_pow2(mul_wide(dt, prom[4]), 7);
    int64_t sens = (int64_t)((uint32_t)prom[1] << 15) + div_pow2(mul_wide(dt, prom[3]), 8);
    if (temp < 2000) {
        // Second order, below 20 degC (TEMP < 2000 only with dT < 0): T2 = dT^2 / 2^31
        // (dT^2: 48 bits; T2 < 2^17), exact for every D2 so that the sequencer's range
        // check sees the datasheet's TEMP - T2 whatever the chip sends.
        const uint32_t dt_abs = (uint32_t)(-dt);
        const int32_t t2 = (int32_t)div_pow2(mul_wide((int32_t)dt_abs, (int32_t)dt_abs), 31);
        // OFF2 = 5 (TEMP-2000)^2 / 2, SENS2 = 5 (TEMP-2000)^2 / 4; below -15 degC
        // OFF2 += 7 (TEMP+1500)^2, SENS2 += 11 (TEMP+1500)^2 / 2. In the datasheet's
        // TEMP range (>= -4000) all fit 31 bits and are >= 0: shifts are the divisions.
        // Below it (a broken chip, rejected on temp_c100) the -40 degC terms are taken.
        const int32_t cold = temp < kColdestC100 ? kColdestC100 : temp;
        const int32_t low = (cold - 2000) * (cold - 2000);  // <= 3.6e7
        int32_t off2 = (5 * low) >> 1;
        int32_t sens2 = (5 * low) >> 2;
        if (cold < -1500) {
            const int32_t very_low = (cold + 1500) * (cold + 1500);  // <= 6.25e6
            off2 += 7 * very_low;
            sens2 += (11 * very_low) >> 1;
        }
        temp -= t2;
        off -= off2;
        sens -= sens2;
    }
    return Terms{temp, off, sens};
}

int32_t pressure_pa(const Terms& t, uint32_t d1) {
    // P = (D1 * SENS / 2^21 - OFF) / 2^15, once per D1; D1 * SENS < 2^59 (24 + 35 bits).
    // As a 64 x 64 product (__muldi3) it takes ~430 cycles; SENS's high word is 0 for a
    // working chip (SENS ~ C1 * 2^15 < 2^31), so it is a 32 x 32 -> 64 one, the high
    // word's product (any sign: two's complement, mod 2^64) added above it otherwise.
    Wide sens;
    sens.s = t.sens;
    int64_t product = (int64_t)((uint64_t)d1 * sens.w.lo);
    if (sens.w.hi != 0) product += (int64_t)((uint64_t)(d1 * sens.w.hi) << 32);
    return (int32_t)div_pow2(div_pow2(product, 21) - t.off, 15);
}

}  // namespace ms5611
