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

Terms terms(const uint16_t prom[kPromWords], uint32_t d2) {
    // dT = D2 - C5 * 2^8 fits 25 bits; TEMP = 2000 + dT * C6 / 2^23 (dT * C6: 41 bits).
    const int32_t dt = (int32_t)d2 - (int32_t)((uint32_t)prom[5] << 8);
    int32_t temp = 2000 + (int32_t)((int64_t)dt * prom[6] / 8388608);
    // OFF = C2 * 2^16 + C4 * dT / 2^7, SENS = C1 * 2^15 + C3 * dT / 2^8.
    int64_t off = ((int64_t)prom[2] << 16) + (int64_t)prom[4] * dt / 128;
    int64_t sens = ((int64_t)prom[1] << 15) + (int64_t)prom[3] * dt / 256;
    if (temp < 2000) {
        // Second order, below 20 degC: T2 = dT^2 / 2^31, OFF2 = 5 (TEMP-2000)^2 / 2,
        // SENS2 = 5 (TEMP-2000)^2 / 4; below -15 degC OFF2 += 7 (TEMP+1500)^2,
        // SENS2 += 11 (TEMP+1500)^2 / 2.
        const int32_t t2 = (int32_t)((int64_t)dt * dt / 2147483648LL);
        const int64_t low = (int64_t)(temp - 2000) * (temp - 2000);
        int64_t off2 = 5 * low / 2;
        int64_t sens2 = 5 * low / 4;
        if (temp < -1500) {
            const int64_t very_low = (int64_t)(temp + 1500) * (temp + 1500);
            off2 += 7 * very_low;
            sens2 += 11 * very_low / 2;
        }
        temp -= t2;
        off -= off2;
        sens -= sens2;
    }
    return Terms{temp, off, sens};
}

int32_t pressure_pa(const Terms& t, uint32_t d1) {
    return (int32_t)(((int64_t)d1 * t.sens / 2097152 - t.off) / 32768);
}

}  // namespace ms5611
