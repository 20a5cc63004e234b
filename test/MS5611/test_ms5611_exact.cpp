// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MS5611/Ms5611Math.cpp's compensation (32-bit where it fits, two 64-bit helpers)
// against a straightforward int64_t transcription of the MS5611-01BA03 datasheet ("Calculate
// temperature compensated pressure", "Second order temperature compensation"), kept here
// only: the same integers on the worked example, the range's extremes and a few hundred
// thousand random PROMs and codes (fixed seed).
#include <gtest/gtest.h>

#include <random>

#include "Ms5611Math.h"

namespace {

struct Ref {
    int32_t temp;        // TEMP - T2
    int32_t temp_first;  // TEMP before the second order
    int64_t off, sens;
};

// The datasheet, line by line, in int64_t (C's division truncates, as the datasheet's).
Ref reference_terms(const uint16_t c[8], uint32_t d2) {
    const int64_t dt = (int64_t)d2 - (int64_t)c[5] * 256;
    int64_t temp = 2000 + dt * c[6] / 8388608;
    int64_t off = (int64_t)c[2] * 65536 + (int64_t)c[4] * dt / 128;
    int64_t sens = (int64_t)c[1] * 32768 + (int64_t)c[3] * dt / 256;
    const int32_t first = (int32_t)temp;
    if (temp < 2000) {
        const int64_t t2 = dt * dt / 2147483648LL;
        int64_t off2 = 5 * (temp - 2000) * (temp - 2000) / 2;
        int64_t sens2 = 5 * (temp - 2000) * (temp - 2000) / 4;
        if (temp < -1500) {
            off2 += 7 * (temp + 1500) * (temp + 1500);
            sens2 += 11 * (temp + 1500) * (temp + 1500) / 2;
        }
        temp -= t2;
        off -= off2;
        sens -= sens2;
    }
    return Ref{(int32_t)temp, first, off, sens};
}

int64_t reference_pressure(const Ref& r, uint32_t d1) { return ((int64_t)d1 * r.sens / 2097152 - r.off) / 32768; }

const uint16_t kExample[8] = {0, 40127, 36924, 23317, 23282, 33464, 28312, 0};
constexpr uint32_t kCodeMax = 0xFFFFFFu;  // D1, D2: 24 bits

bool in_range(const Ref& r) { return r.temp_first >= -4000 && r.temp_first <= 8500; }

// Every value of one case; false (with a message) at the first difference.
::testing::AssertionResult same(const uint16_t c[8], uint32_t d2, uint32_t d1) {
    const Ref r = reference_terms(c, d2);
    const ms5611::Terms t = ms5611::terms(c, d2);
    auto fail = [&](const char* what) {
        return ::testing::AssertionFailure() << what << " differs: C1..C6 " << c[1] << " " << c[2] << " " << c[3]
                                             << " " << c[4] << " " << c[5] << " " << c[6] << ", D2 " << d2
                                             << ", D1 " << d1;
    };
    if (t.temp_c100 != r.temp) return fail("TEMP");
    if (!in_range(r)) return ::testing::AssertionSuccess();  // only TEMP is promised there
    if (t.off != r.off) return fail("OFF");
    if (t.sens != r.sens) return fail("SENS");
    if (ms5611::pressure_pa(t, d1) != reference_pressure(r, d1)) return fail("P");
    return ::testing::AssertionSuccess();
}

TEST(Ms5611Exact, TheWorkedExampleAndTheBranchesAsTheReference) {
    // The datasheet's example (TEMP 2007, P 100009) and test/MS5611's other cases.
    EXPECT_TRUE(same(kExample, 8569150, 9085466));
    EXPECT_EQ(reference_terms(kExample, 8569150).temp, 2007);
    EXPECT_EQ(reference_pressure(reference_terms(kExample, 8569150), 9085466), 100009);
    for (uint32_t d2 : {33464u * 256u, 8270494u, 7500000u, 7233784u})
        for (uint32_t d1 : {0u, 8000000u, 8500000u, 9085466u, kCodeMax}) EXPECT_TRUE(same(kExample, d2, d1));
}

TEST(Ms5611Exact, TheExtremesOfTheRanges) {
    // PROM words 0 and 0xFFFF, D1 and D2 0 and 2^24 - 1: dT at both ends of
    // -16776960..16777215, TEMP at and around -4000, -1500, 2000 and 8500.
    const uint16_t words[] = {0, 1, 0x7FFF, 0x8000, 0xFFFE, 0xFFFF};
    uint16_t c[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (uint16_t w1 : words)
        for (uint16_t w5 : words)
            for (uint16_t w6 : words) {
                c[1] = c[2] = c[3] = c[4] = w1;
                c[5] = w5;
                c[6] = w6;
                for (uint32_t d2 : {0u, 1u, (uint32_t)w5 << 8, kCodeMax - 1u, kCodeMax})
                    for (uint32_t d1 : {0u, 1u, kCodeMax}) EXPECT_TRUE(same(c, d2, d1));
            }
    // D2 for each TEMP of interest (C6 = 0xFFFF: one step of dT is < 0.01 degC).
    uint16_t e[8] = {0, 0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF, 0x8000, 0xFFFF, 0};
    int checked = 0;
    for (int32_t target : {-4000, -3999, -1501, -1500, -1499, 1999, 2000, 2001, 8499, 8500}) {
        const int64_t dt = ((int64_t)target - 2000) * 8388608 / 0xFFFF;
        for (int64_t d = dt - 300; d <= dt + 300; ++d) {
            const uint32_t d2 = (uint32_t)(0x8000 * 256 + d);
            for (uint32_t d1 : {0u, kCodeMax}) EXPECT_TRUE(same(e, d2, d1));
            checked += in_range(reference_terms(e, d2));
        }
    }
    EXPECT_GT(checked, 4000);
}

TEST(Ms5611Exact, RandomPromsAndCodesAsTheReference) {
    std::mt19937 rng(20261207u);
    auto bits = [&rng](int n) { return (uint32_t)(rng() >> (32 - n)); };
    int in = 0, cold = 0, very_cold = 0, failures = 0;
    for (int i = 0; i < 300000 && failures < 10; ++i) {
        uint16_t c[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        for (int w = 1; w <= 6; ++w) c[w] = (uint16_t)bits(16);
        uint32_t d2;
        if (i % 4 == 0) {
            d2 = bits(24);  // any code: TEMP mostly out of range (only TEMP compared)
        } else {
            // A D2 whose TEMP is within -4000..8500 (a little beyond, by the rounding).
            const int64_t target = -4000 + (int64_t)(rng() % 12501u);
            const int64_t dt = c[6] ? (target - 2000) * 8388608 / c[6] : (int64_t)bits(24) - 8388608;
            int64_t code = (int64_t)c[5] * 256 + dt;
            d2 = code < 0 ? 0u : code > (int64_t)kCodeMax ? kCodeMax : (uint32_t)code;
        }
        const uint32_t d1 = bits(24);
        const ::testing::AssertionResult r = same(c, d2, d1);
        if (!r) ++failures;
        EXPECT_TRUE(r);
        const Ref ref = reference_terms(c, d2);
        if (in_range(ref)) {
            ++in;
            cold += ref.temp_first < 2000;
            very_cold += ref.temp_first < -1500;
        }
    }
    // The cases covered each branch many times.
    EXPECT_GT(in, 150000);
    EXPECT_GT(cold, 50000);
    EXPECT_GT(very_cold, 20000);
}

// Out of the datasheet's TEMP range the sequencer rejects the temperature: TEMP - T2 is
// still the datasheet's there, so it is rejected exactly when it was.
TEST(Ms5611Exact, TemperatureIsExactForEveryD2) {
    std::mt19937 rng(7u);
    for (int i = 0; i < 100000; ++i) {
        uint16_t c[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        for (int w = 1; w <= 6; ++w) c[w] = (uint16_t)(rng() >> 16);
        const uint32_t d2 = rng() >> 8;
        ASSERT_EQ(ms5611::terms(c, d2).temp_c100, reference_terms(c, d2).temp) << d2;
    }
}

}  // namespace
