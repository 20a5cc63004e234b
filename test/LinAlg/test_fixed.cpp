// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-point output path (lib/LinAlg/Fixed.h, dcm::euler_carried): conversions exact,
// atan2 and hypot within their stated error over the whole domain (every table entry
// is visited at its node and between nodes), and the Euler angles within 0.005 deg
// (half a count of the 0.01 deg the firmware prints) of the same formulas in double.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "Euler.h"
#include "Fixed.h"

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {

constexpr double kQ24 = 16777216.0;
constexpr double kQ30 = 1073741824.0;
constexpr double kPi = 3.14159265358979323846;

double angle_diff(double a, double b) {
    double d = std::fabs(a - b);
    if (d > kPi) d = std::fabs(d - 2.0 * kPi);
    return d;
}

struct Angles {
    double roll, pitch, yaw;
};

// R carried by theta (r' = r + r x theta) and its angles, in double: the reference.
Angles carried_in_double(const Matrix3f& r, const Vector3f& theta) {
    const double m[3][3] = {{r.a.x, r.a.y, r.a.z}, {r.b.x, r.b.y, r.b.z}, {r.c.x, r.c.y, r.c.z}};
    const double t[3] = {theta.x, theta.y, theta.z};
    double p[3][3];
    for (int k = 0; k < 3; ++k) {
        p[k][0] = m[k][0] + m[k][1] * t[2] - m[k][2] * t[1];
        p[k][1] = m[k][1] + m[k][2] * t[0] - m[k][0] * t[2];
        p[k][2] = m[k][2] + m[k][0] * t[1] - m[k][1] * t[0];
    }
    return Angles{std::atan2(p[2][1], p[2][2]), std::atan2(-p[2][0], std::hypot(p[2][1], p[2][2])),
                  std::atan2(p[1][0], p[0][0])};
}

double worst_difference(const dcm::EulerAngles& e, const Angles& exact) {
    return std::max({angle_diff(e.roll_rad, exact.roll), angle_diff(e.pitch_rad, exact.pitch),
                     angle_diff(e.yaw_rad, exact.yaw)});
}

}  // namespace

TEST(Fixed, FromFloatTruncatesAndSaturates) {
    EXPECT_EQ(linalg::fixed_from_float(1.0f, 30), 1 << 30);
    EXPECT_EQ(linalg::fixed_from_float(-0.5f, 30), -(1 << 29));
    EXPECT_EQ(linalg::fixed_from_float(0.0f, 30), 0);
    EXPECT_EQ(linalg::fixed_from_float(-0.0f, 30), 0);
    EXPECT_EQ(linalg::fixed_from_float(1e-12f, 30), 0);
    EXPECT_EQ(linalg::fixed_from_float(3.0f, 30), 0x7FFFFFFF);
    EXPECT_EQ(linalg::fixed_from_float(-INFINITY, 30), -0x7FFFFFFF);
    EXPECT_EQ(linalg::fixed_from_float(NAN, 30), 0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    for (int i = 0; i < 100000; ++i) {
        const float x = u(rng) * std::pow(2.0f, (float)(i % 20) * -1.0f);
        for (uint8_t q : {17, 24, 30}) {
            const double exact = std::trunc((double)x * std::ldexp(1.0, q));
            if (std::fabs(exact) >= 2147483647.0) continue;
            ASSERT_EQ(linalg::fixed_from_float(x, q), (int32_t)exact) << x << " Q" << (int)q;
        }
    }
}

TEST(Fixed, ToFloatScalesExactly) {
    EXPECT_EQ(linalg::float_from_fixed(0, 24), 0.0f);
    std::mt19937 rng(4);
    std::uniform_int_distribution<int32_t> q(-2147483647, 2147483647);
    for (int i = 0; i < 100000; ++i) {
        const int32_t v = q(rng) >> (i % 31);
        if (v == 0) continue;
        ASSERT_EQ(linalg::float_from_fixed(v, 24), (float)((double)v / kQ24)) << v;
    }
}

// mul_q14 is r x / 2^14 to within 4 units (its result in steps of 4) and mul_q14_unit
// the same product rounded to the unit, for a factor up to 1 (Q14) and |x| < 2^29 (the
// rest means' low-pass, whose step in 4-unit multiples stalls short of the mean).
TEST(Fixed, MulQ14WithinFourUnitsAndMulQ14UnitRoundedToTheUnit) {
    std::mt19937 rng(14);
    std::uniform_int_distribution<int32_t> factor(-16384, 16384);
    std::uniform_int_distribution<int32_t> value(-(1 << 29) + 1, (1 << 29) - 1);
    for (int i = 0; i < 200000; ++i) {
        const int16_t r = (int16_t)factor(rng);
        const int32_t x = value(rng) >> (i % 20);
        const double exact = (double)r * (double)x / 16384.0;
        ASSERT_LE(std::fabs((double)linalg::mul_q14(r, x) - exact), 4.0) << r << " * " << x;
        ASSERT_LE(std::fabs((double)linalg::mul_q14_unit(r, x) - exact), 0.5 + 1.0 / 16384.0) << r << " * " << x;
    }
    // A low-pass of 0.04 a step reaches its input to the unit by mul_q14_unit; by
    // mul_q14 it stops where the step rounds to 0 (input - 50 units and below).
    const int16_t alpha = 655;  // 0.04 in Q14
    int32_t mean_unit = 0, mean_coarse = 0;
    for (int i = 0; i < 1000; ++i) {
        mean_unit += linalg::mul_q14_unit(alpha, 1000 - mean_unit);
        mean_coarse += linalg::mul_q14(alpha, 1000 - mean_coarse);
    }
    EXPECT_NEAR(mean_unit, 1000, 12);
    EXPECT_LT(mean_coarse, 1000 - 40);
}

// Every reciprocal entry (the divisor's 8 bits after its leading one) and every
// t - atan(t) entry (the ratio's 8 bits), at the nodes and between them.
// mul_q30 is the product over 2^30 truncated toward zero, at most 1 below the exact
// floor of the magnitude (the partial products it drops are below 2^24 of its unit),
// over every magnitude the estimator's Q30 operands take and at the extremes.
TEST(Fixed, MulQ30WithinOneOfTheExactProduct) {
    std::mt19937 rng(8);
    std::uniform_int_distribution<int32_t> any(-2147483647, 2147483647);
    std::uniform_int_distribution<int32_t> q30(-(1 << 30), 1 << 30);
    auto check = [](int32_t a, int32_t x) {
        const int64_t exact = (int64_t)a * (int64_t)x;
        const int64_t floor_magnitude = (exact < 0 ? -exact : exact) >> 30;
        if (floor_magnitude > 0x7FFFFFFF) return;  // beyond the result's range
        const int64_t got = linalg::mul_q30(a, x);
        const int64_t got_magnitude = got < 0 ? -got : got;
        ASSERT_LE(got_magnitude, floor_magnitude) << a << " * " << x;
        ASSERT_GE(got_magnitude, floor_magnitude - 1) << a << " * " << x;
        ASSERT_TRUE(got == 0 || (got < 0) == (exact < 0)) << a << " * " << x;
    };
    for (int i = 0; i < 200000; ++i) {
        check(q30(rng), any(rng));
        check(q30(rng), q30(rng) >> (i % 24));
    }
    const int32_t edges[] = {0, 1, -1, 255, 256, 65535, 65536, -65536, 1 << 30, -(1 << 30), 2147483647, -2147483647};
    for (int32_t a : edges)
        for (int32_t x : edges) check(a, x);
}

TEST(Fixed, AtanOfRatioWithin1p2e5RadEverywhere) {
    double worst = 0.0;
    for (uint32_t i = 0; i < 256; ++i) {
        for (uint32_t sub : {0u, 0x2A5A5Bu, 0x400000u, 0x7FFFFFu}) {
            const uint32_t den = 0x80000000u + (i << 23) + sub;
            for (uint32_t j = 0; j <= 512; ++j) {
                const uint32_t num = (uint32_t)(((uint64_t)den * j) / 512u);
                uint32_t ratio;
                const int32_t a = linalg::atan_of_ratio_q24(num, den, &ratio);
                const double exact = std::atan((double)num / (double)den);
                worst = std::max(worst, std::fabs(a / kQ24 - exact));
                ASSERT_LE(ratio, 0x80000000u);
                ASSERT_NEAR(ratio / 2147483648.0, (double)num / (double)den, 2e-5);
            }
        }
    }
    EXPECT_LT(worst, 1.2e-5) << "rad";
    EXPECT_EQ(linalg::atan_of_ratio_q24(5, 0, nullptr), 0);
}

TEST(Fixed, Atan2Within1p5e5RadOverTheWholeDomain) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> angle(-kPi, kPi), log_r(-30.0, 0.99);
    double worst = 0.0;
    for (int i = 0; i < 1000000; ++i) {
        const double a = angle(rng), r = std::pow(2.0, log_r(rng));
        const int32_t y = (int32_t)std::llround(r * std::sin(a) * kQ30);
        const int32_t x = (int32_t)std::llround(r * std::cos(a) * kQ30);
        if (x == 0 && y == 0) continue;
        const int32_t q = linalg::atan2_q24(y < 0, linalg::magnitude(y), x < 0, linalg::magnitude(x));
        ASSERT_TRUE(q > -linalg::kPiQ24 && q <= linalg::kPiQ24);
        worst = std::max(worst, angle_diff(q / kQ24, std::atan2((double)y, (double)x)));
    }
    EXPECT_LT(worst, 1.5e-5) << "rad";  // 0.0009 deg
    // The axes, and the convention of fast_atan2 for a zero y.
    EXPECT_EQ(linalg::atan2_q24(false, 0, false, 5), 0);
    EXPECT_EQ(linalg::atan2_q24(true, 0, true, 5), linalg::kPiQ24);
    EXPECT_EQ(linalg::atan2_q24(false, 5, false, 0), linalg::kHalfPiQ24);
    EXPECT_EQ(linalg::atan2_q24(true, 5, true, 0), -linalg::kHalfPiQ24);
    EXPECT_EQ(linalg::atan2_q24(true, 0, true, 0), 0);
    EXPECT_NEAR(linalg::atan2_q24(false, 0xFFFFFFFFu, true, 0xFFFFFFFFu), linalg::kPiQ24 - linalg::kQuarterPiQ24, 200);
}

TEST(Fixed, HypotWithin2p5e5Relative) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> angle(0.0, kPi / 2), log_r(-10.0, 0.99);
    double worst = 0.0;
    for (int i = 0; i < 300000; ++i) {
        const double a = angle(rng), r = std::pow(2.0, log_r(rng));
        const uint32_t y = (uint32_t)std::llround(r * std::sin(a) * kQ30);
        const uint32_t x = (uint32_t)std::llround(r * std::cos(a) * kQ30);
        uint32_t ratio;
        linalg::atan2_q24(false, y, false, x, &ratio);
        const uint32_t h = linalg::hypot_from_ratio(x > y ? x : y, ratio);
        const double exact = std::hypot((double)x, (double)y);
        worst = std::max(worst, std::fabs(h - exact) / exact);
    }
    EXPECT_LT(worst, 2.5e-5);
    // The largest magnitudes do not wrap.
    uint32_t ratio;
    linalg::atan2_q24(false, 0x7FFFFFFFu, false, 0x7FFFFFFFu, &ratio);
    EXPECT_NEAR((double)linalg::hypot_from_ratio(0x7FFFFFFFu, ratio), std::sqrt(2.0) * 0x7FFFFFFF, 5e4);
}

// Every input of the core, then the Q30 and float forms over their ranges, against
// 1/sqrt in double.
TEST(Fixed, InverseSqrtWithinItsStatedError) {
    double worst = 0.0;
    for (uint32_t xn = 0x4000u; xn < 0x10000u; ++xn) {
        const double exact = 1.0 / std::sqrt(xn / 65536.0);
        worst = std::max(worst, std::fabs(linalg::inverse_sqrt_q15((uint16_t)xn) / 32768.0 - exact) / exact);
    }
    EXPECT_LT(worst, 6e-5);
    worst = 0.0;
    for (uint32_t x = 1; x < 70000u; ++x) {
        const double exact = 1073741824.0 / std::sqrt((double)x);
        worst = std::max(worst, std::fabs(linalg::inverse_sqrt_q30(x) - exact) / exact);
    }
    for (const uint32_t x : {0x10000u, 0x3FFFFu, 0x12345678u, 0xFFFFFFFFu}) {
        const double exact = 1073741824.0 / std::sqrt((double)x);
        worst = std::max(worst, std::fabs(linalg::inverse_sqrt_q30(x) - exact) / exact);
    }
    EXPECT_LT(worst, 1e-4);
    EXPECT_NEAR((double)linalg::inverse_sqrt_q30(1), 1073741824.0, 1073741824.0 * 1.6e-5);  // 2 in Q15 is 65535
    EXPECT_EQ(linalg::inverse_sqrt_q30(0), 0x7FFFFFFFu);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> log_x(-120.0, 120.0);
    worst = 0.0;
    for (int i = 0; i < 200000; ++i) {
        const float x = (float)std::pow(2.0, log_x(rng));
        const double exact = 1.0 / std::sqrt((double)x);
        worst = std::max(worst, std::fabs(linalg::inverse_sqrt(x) - exact) / exact);
    }
    EXPECT_LT(worst, 1e-4);
    EXPECT_NEAR(linalg::inverse_sqrt(4.0f), 0.5f, 0.5f * 1.6e-5f);
    for (const float bad : {0.0f, -1.0f, 1e-40f, INFINITY, NAN}) EXPECT_EQ(linalg::inverse_sqrt(bad), 0.0f) << bad;
}

// Random attitudes: the fixed-point angles against atan2/hypot in double on the same
// float matrix. Up to 80 deg pitch: closer to the lock roll and yaw divide every error
// of the entries by cos(pitch) (a fast turn's theta, rounded to 3.8e-6 rad, makes
// 0.005 deg at 87 deg); there the round-trip tests of test_euler.cpp and the slow-turn
// test below apply.
TEST(Fixed, EulerWithinHalfAPrintedCountAwayFromTheLock) {
    std::mt19937 rng(8);
    std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f), lead(-0.03f, 0.03f);
    double worst_plain = 0.0, worst_carried = 0.0;
    for (int i = 0; i < 200000; ++i) {
        const float pitch = angle(rng) * (80.0f / 180.0f);  // |pitch| < 80 deg
        const Matrix3f r = dcm::dcm_from_euler(angle(rng), pitch, angle(rng));
        // theta up to 0.03 rad per axis: 10 rad/s (570 deg/s) over the 3 ms lead.
        const Vector3f theta(lead(rng), lead(rng), lead(rng));
        const double plain = worst_difference(dcm::euler_from_dcm(r), carried_in_double(r, Vector3f()));
        const double carried = worst_difference(dcm::euler_carried(r, theta), carried_in_double(r, theta));
        worst_plain = std::max(worst_plain, plain);
        worst_carried = std::max(worst_carried, carried);
    }
    const double half_count_rad = 0.005 * kPi / 180.0;
    EXPECT_LT(worst_plain, half_count_rad) << worst_plain * 180.0 / kPi << " deg";
    EXPECT_LT(worst_carried, half_count_rad) << worst_carried * 180.0 / kPi << " deg";
    std::printf("worst: plain %.5f deg, carried %.5f deg\n", worst_plain * 180.0 / kPi,
                worst_carried * 180.0 / kPi);
}

// Near the lock the lead's own rounding counts (roll and yaw divide it by cos(pitch)):
// a slow turn (|theta| < 2^-10 rad, the board resting nose up) uses the fine step.
TEST(Fixed, SlowTurnNearTheLockWithinHalfAPrintedCount) {
    std::mt19937 rng(10);
    std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f), near(85.0f, 89.9f), lead(-9e-4f, 9e-4f);
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        const float pitch = near(rng) * (i % 2 ? 1.0f : -1.0f) * 0.0174532925f;
        const Matrix3f r = dcm::dcm_from_euler(angle(rng), pitch, angle(rng));
        const Vector3f theta(lead(rng), lead(rng), lead(rng));
        worst = std::max(worst, worst_difference(dcm::euler_carried(r, theta), carried_in_double(r, theta)));
    }
    EXPECT_LT(worst, 0.005 * kPi / 180.0) << worst * 180.0 / kPi << " deg";
}

TEST(Fixed, CarriedByZeroIsThePlainExtraction) {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f);
    for (int i = 0; i < 10000; ++i) {
        const Matrix3f r = dcm::dcm_from_euler(angle(rng), angle(rng) * 0.5f, angle(rng));
        const dcm::EulerAngles a = dcm::euler_from_dcm(r), b = dcm::euler_carried(r, Vector3f());
        ASSERT_EQ(a.roll_rad, b.roll_rad);
        ASSERT_EQ(a.pitch_rad, b.pitch_rad);
        ASSERT_EQ(a.yaw_rad, b.yaw_rad);
    }
    // Beyond its clamp theta acts as +-0.25 rad; garbage stays finite.
    const Matrix3f bad(Vector3f(NAN, 1e30f, 0), Vector3f(0, INFINITY, 0), Vector3f(-1e30f, 0, NAN));
    const dcm::EulerAngles e = dcm::euler_carried(bad, Vector3f(NAN, 1e9f, -1e9f));
    EXPECT_TRUE(linalg::is_finite(e.roll_rad) && linalg::is_finite(e.pitch_rad) && linalg::is_finite(e.yaw_rad));
}

// The printed hundredths straight from Q24 radians: the Q24 angle itself rounded (half
// away from zero), except where it lies within 2^-15 of a count of a half (the
// constant's rounding), over the whole range atan2_q24 gives and beyond.
TEST(Fixed, CentidegIsTheQ24AngleRounded) {
    std::mt19937 rng(11);
    std::uniform_int_distribution<int32_t> q(-(1 << 26) + 1, (1 << 26) - 1);
    int near_half = 0;
    for (int i = 0; i < 2000000; ++i) {
        const int32_t a = i < 2000 ? i - 1000 : q(rng);
        const double exact = a / kQ24 * 18000.0 / kPi;  // hundredths
        const double m = std::fabs(exact);
        const int32_t c = linalg::centideg_from_q24(a);
        if (std::fabs(m - std::floor(m) - 0.5) < 1.0 / 32768.0) {
            ++near_half;
            ASSERT_LE(std::fabs(c - exact), 0.5 + 1.0 / 32768.0) << a;
            continue;
        }
        const double rounded = std::floor(m + 0.5);
        ASSERT_EQ(c, (int32_t)(exact < 0 ? -rounded : rounded)) << a;
    }
    EXPECT_LT(near_half, 2000000 / 1000);  // the exception is rare: ~2^-14 of the values
    EXPECT_EQ(linalg::centideg_from_q24(linalg::kPiQ24), 18000);
    EXPECT_EQ(linalg::centideg_from_q24(-linalg::kHalfPiQ24), -9000);
    EXPECT_EQ(linalg::centideg_from_q24(linalg::kQuarterPiQ24), 4500);
    EXPECT_EQ(linalg::centideg_from_q24(0), 0);
}

// heading_deg's convention in integers: 0 <= h < 36000 with the declination, and the
// float heading within a count of it.
TEST(Fixed, HeadingCentidegFoldsWithTheDeclination) {
    const auto q24 = [](double deg) { return (int32_t)std::llround(deg * kPi / 180.0 * kQ24); };
    EXPECT_EQ(dcm::heading_centideg(q24(-90.0), 0), 27000);
    EXPECT_EQ(dcm::heading_centideg(q24(175.0), 1000), 18500);
    EXPECT_EQ(dcm::heading_centideg(q24(-5.0), 1000), 500);
    EXPECT_EQ(dcm::heading_centideg(q24(5.0), -1000), 35500);
    EXPECT_EQ(dcm::heading_centideg(q24(0.0), 350), 350);
    EXPECT_EQ(dcm::heading_centideg(-1, 0), 0);  // rounds to -0.00: north, never 360.00
    EXPECT_EQ(dcm::heading_centideg(linalg::kPiQ24, 18000), 0);
    EXPECT_EQ(dcm::heading_centideg(-linalg::kPiQ24 + 1, -18000), 0);
    std::mt19937 rng(12);
    std::uniform_int_distribution<int32_t> yaw(-linalg::kPiQ24 + 1, linalg::kPiQ24);
    std::uniform_int_distribution<int> decl(-18000, 18000);
    for (int i = 0; i < 200000; ++i) {
        const int32_t y = yaw(rng);
        const int16_t d = (int16_t)decl(rng);
        const int32_t h = dcm::heading_centideg(y, d);
        ASSERT_TRUE(h >= 0 && h < 36000) << y << " " << d;
        double diff = std::fabs(h * 0.01 - dcm::heading_deg((float)(y / kQ24), (float)(d * 0.01)));
        if (diff > 180.0) diff = 360.0 - diff;
        ASSERT_LT(diff, 0.0051) << y << " " << d;
    }
}

// The lead in Q26 is the float lead after fixed_from_float: the same angles, bit for bit,
// and the integer path's hundredths are those angles rounded.
TEST(Fixed, CarriedByAQ26LeadIsTheFloatOne) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f), lead(-0.3f, 0.3f), small(-9e-4f, 9e-4f);
    for (int i = 0; i < 20000; ++i) {
        const Matrix3f r = dcm::dcm_from_euler(angle(rng), angle(rng) * 0.5f, angle(rng));
        const Vector3f theta = i % 2 ? Vector3f(lead(rng), lead(rng), lead(rng)) : Vector3f(small(rng), small(rng), small(rng));
        const dcm::EulerAngles a = dcm::euler_carried(r, theta);
        const dcm::EulerQ24 q = dcm::euler_carried_q24(r, linalg::fixed_from_float(theta.x, 26),
                                                       linalg::fixed_from_float(theta.y, 26),
                                                       linalg::fixed_from_float(theta.z, 26));
        const dcm::EulerAngles b = dcm::euler_in_rad(q);
        ASSERT_EQ(a.roll_rad, b.roll_rad);
        ASSERT_EQ(a.pitch_rad, b.pitch_rad);
        ASSERT_EQ(a.yaw_rad, b.yaw_rad);
        const dcm::AnglesCentideg c = dcm::angles_centideg(q, 0);
        ASSERT_NEAR(c.roll_centideg, q.roll_q24 / kQ24 * 18000.0 / kPi, 0.5001);
        ASSERT_NEAR(c.pitch_centideg, q.pitch_q24 / kQ24 * 18000.0 / kPi, 0.5001);
    }
}

// At the gimbal lock the carried path reads R12 and R22 (formed only there): the same
// convention as the plain extraction, roll 0.
TEST(Fixed, CarriedAtTheLockFoldsRollIntoYaw) {
    const double d = kPi / 180.0;
    for (double pitch_deg : {90.0, -90.0}) {
        const Matrix3f r = dcm::dcm_from_euler((float)(30 * d), (float)(pitch_deg * d), (float)(50 * d));
        const dcm::EulerAngles plain = dcm::euler_from_dcm(r), carried = dcm::euler_carried(r, Vector3f());
        EXPECT_EQ(carried.roll_rad, 0.0f);
        EXPECT_EQ(plain.yaw_rad, carried.yaw_rad);
        EXPECT_EQ(plain.pitch_rad, carried.pitch_rad);
        // The whole heading in yaw: psi - phi nose up, psi + phi nose down (R = Rz Ry Rx).
        EXPECT_NEAR(carried.yaw_rad, (pitch_deg > 0 ? 20.0 : 80.0) * d, 1e-4) << pitch_deg;
    }
}
