// SPDX-License-Identifier: GPL-3.0-or-later
// The fixed-point tables and bit fields of Fixed.h exactly as their formulas say (the
// atan2 and hypot bounds in test_fixed.cpp let a table entry one count off through),
// and the heading's fold into [0, 360) (Euler.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "Euler.h"
#include "Fixed.h"

namespace {

uint16_t table_entry(const uint16_t* table, int i) { return linalg::fixed_detail::entry(table, (uint16_t)i); }

}  // namespace

// 1/d - 1 in Q16 at d = (1 + i/256)/2, i.e. (1 - u)/(1 + u) with u = i/256; the first
// entry (65536) is stored as 65535.
TEST(FixedTables, ReciprocalTableIsItsFormulaRounded) {
    for (int i = 0; i <= 256; ++i) {
        const double u = i / 256.0;
        const long expected = std::lround(65536.0 * (1.0 - u) / (1.0 + u));
        EXPECT_EQ((long)table_entry(linalg::fixed_detail::kReciprocalMinusOne, i), i == 0 ? 65535L : expected)
            << "entry " << i;
    }
}

// t - atan(t) in Q18 at t = j/256.
TEST(FixedTables, TMinusAtanTableIsItsFormulaRounded) {
    for (int j = 0; j <= 256; ++j) {
        const double t = j / 256.0;
        EXPECT_EQ((long)table_entry(linalg::fixed_detail::kTMinusAtan, j), std::lround(262144.0 * (t - std::atan(t))))
            << "entry " << j;
    }
}

// sqrt(1 + t^2) - 1 in Q16 at t = j/128.
TEST(FixedTables, HypotTableIsItsFormulaRounded) {
    for (int j = 0; j <= 128; ++j) {
        const double t = j / 128.0;
        EXPECT_EQ((long)table_entry(linalg::fixed_detail::kHypotMinusOne, j),
                  std::lround(65536.0 * (std::sqrt(1.0 + t * t) - 1.0)))
            << "entry " << j;
    }
}

// The bit fields read from bytes are the plain shifts, for every bit pattern.
TEST(FixedTables, BitFieldsAreThePlainShifts) {
    std::mt19937 rng(7);
    for (int k = 0; k < 100000; ++k) {
        const uint32_t x = (uint32_t)rng();
        ASSERT_EQ(linalg::fixed_detail::bits_23_to_30(x), (uint8_t)((x >> 23) & 0xFFu)) << x;
        ASSERT_EQ(linalg::fixed_detail::bits_7_to_22(x), (uint16_t)(x >> 7)) << x;
    }
    for (uint8_t n = 0; n < 8; ++n) EXPECT_EQ(linalg::fixed_detail::power_of_two(n), 1u << n);
}

// The heading in [0, 360): yaw and declination of either sign fold once or twice.
TEST(FixedTables, HeadingFoldsIntoAFullTurn) {
    EXPECT_NEAR(dcm::heading_deg(-170.0f * linalg::kRadPerDeg, -20.0f), 170.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(-10.0f * linalg::kRadPerDeg, 0.0f), 350.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(170.0f * linalg::kRadPerDeg, 30.0f), 200.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(-170.0f * linalg::kRadPerDeg, -170.0f), 20.0f, 1e-3f);
    EXPECT_NEAR(dcm::heading_deg(90.0f * linalg::kRadPerDeg, 0.0f), 90.0f, 1e-3f);
    EXPECT_EQ(dcm::heading_deg(NAN, 0.0f), 0.0f);
}

// The printed heading in hundredths: north is 0, never 36000; just west of north 35999.
TEST(FixedTables, HeadingCentidegFoldsAtNorth) {
    EXPECT_EQ(dcm::heading_centideg(0, 0), 0);
    EXPECT_EQ(dcm::heading_centideg(0, -1), 35999);
    EXPECT_EQ(dcm::heading_centideg(0, 1), 1);
    EXPECT_EQ(dcm::heading_centideg(-linalg::kHalfPiQ24, 0), 27000);
}

// hypot at the end of its table (the two sides equal: ratio 1, or beyond by rounding).
TEST(FixedTables, HypotOfEqualSidesIsRootTwoTimesTheSide) {
    for (uint32_t ratio : {0x80000000u, 0xFFFFFFFFu}) {
        const uint32_t h = linalg::hypot_from_ratio(1000000000u, ratio);
        EXPECT_NEAR((double)h, 1000000000.0 * std::sqrt(2.0), 1000000000.0 * 2.5e-5) << ratio;
    }
}
