// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MS5611/Ms5611Math.h against the MS5611-01BA03 datasheet: its worked example, the
// second-order branches (the expected values computed with Python's exact integers from
// the datasheet's formulas, test/e2e/gps_baro_models.py's ms5611_compensate), AN520's CRC-4.
#include <gtest/gtest.h>

#include "Ms5611Math.h"

namespace {

const uint16_t kExample[8] = {0, 40127, 36924, 23317, 23282, 33464, 28312, 0};

TEST(Ms5611Math, TheDatasheetsWorkedExample) {
    const ms5611::Terms t = ms5611::terms(kExample, 8569150);
    EXPECT_EQ(t.temp_c100, 2007);
    EXPECT_EQ(ms5611::pressure_pa(t, 9085466), 100009);
    // The intermediate values the datasheet prints: OFF 2420281617, SENS 1315097036.
    EXPECT_EQ(t.off, 2420281617LL);
    EXPECT_EQ(t.sens, 1315097036LL);
}

TEST(Ms5611Math, TwentyDegreesExactlyIsFirstOrder) {
    // dT = 0: TEMP 2000, no second-order terms.
    const ms5611::Terms t = ms5611::terms(kExample, 33464u * 256u);
    EXPECT_EQ(t.temp_c100, 2000);
    EXPECT_EQ(ms5611::pressure_pa(t, 9085466), 99993);
}

TEST(Ms5611Math, BelowTwentyDegreesTheSecondOrder) {
    // 9.6 degC: T2, OFF2 and SENS2 (TEMP - 2000 squared).
    const ms5611::Terms t = ms5611::terms(kExample, 8270494);
    EXPECT_EQ(t.temp_c100, 961);
    EXPECT_EQ(ms5611::pressure_pa(t, 9085466), 97981);
}

TEST(Ms5611Math, BelowMinusFifteenDegreesTheColdTerms) {
    // -33 degC and -21 degC: OFF2 and SENS2 grow by the (TEMP + 1500)^2 terms.
    const ms5611::Terms cold = ms5611::terms(kExample, 7233784);
    EXPECT_EQ(cold.temp_c100, -3325);
    EXPECT_EQ(ms5611::pressure_pa(cold, 8500000), 79123);
    const ms5611::Terms cool = ms5611::terms(kExample, 7500000);
    EXPECT_EQ(cool.temp_c100, -2129);
    EXPECT_EQ(ms5611::pressure_pa(cool, 8000000), 72933);
}

TEST(Ms5611Math, Crc4OfAn520) {
    // The simulator's PROM (the datasheet's C1..C6, a factory word and a serial): CRC 3.
    uint16_t prom[8] = {0x0C4D, 40127, 36924, 23317, 23282, 33464, 28312, 0x5A33};
    EXPECT_EQ(ms5611::crc4(prom), 3u);
    EXPECT_EQ(ms5611::check_prom(prom), ms5611::PromStatus::Ok);
    // Word 7's low byte does not count (it holds the CRC).
    prom[7] = 0x5AFF;
    EXPECT_EQ(ms5611::crc4(prom), 3u);
    EXPECT_EQ(ms5611::check_prom(prom), ms5611::PromStatus::BadCrc);
    prom[7] = 0x5A33;
    // Any one bit flipped in the words it covers: another CRC.
    for (int w = 0; w < 8; ++w) {
        for (int bit = (w == 7 ? 8 : 0); bit < 16; ++bit) {
            uint16_t bad[8];
            for (int i = 0; i < 8; ++i) bad[i] = prom[i];
            bad[w] = (uint16_t)(bad[w] ^ (1u << bit));
            EXPECT_EQ(ms5611::check_prom(bad), ms5611::PromStatus::BadCrc) << w << ":" << bit;
        }
    }
}

TEST(Ms5611Math, ABlankPromIsNoChip) {
    // All zero has CRC-4 0, so the CRC alone would take it: it is refused on its own.
    uint16_t zeros[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(ms5611::crc4(zeros), 0u);
    EXPECT_EQ(ms5611::check_prom(zeros), ms5611::PromStatus::Blank);
    uint16_t ones[8];
    for (uint16_t& w : ones) w = 0xFFFF;
    EXPECT_EQ(ms5611::check_prom(ones), ms5611::PromStatus::Blank);
}

}  // namespace
