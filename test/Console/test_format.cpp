// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-point formatting of the output lines (lib/Console/Format, Text).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "Format.h"
#include "Text.h"

namespace {

std::string plot(float r, float p, float y) {
    char buf[fmt::kLineMax];
    const uint8_t n = fmt::format_plot_line(buf, r, p, y);
    return std::string(buf, n);
}

std::string csv(uint32_t t, float r, float p, float y) {
    char buf[fmt::kLineMax];
    const uint8_t n = fmt::format_csv_line(buf, t, r, p, y);
    return std::string(buf, n);
}

std::string centi(int32_t c) {
    char buf[16];
    return std::string(buf, text::format_centi(buf, c));
}

}  // namespace

TEST(Format, PlotLineMatchesTheContract) {
    EXPECT_EQ(plot(-1.23f, 4.56f, 271.8f), "roll:-1.23 pitch:4.56 yaw:271.80\n");
    EXPECT_EQ(plot(0.0f, 0.0f, 0.0f), "roll:0.00 pitch:0.00 yaw:0.00\n");
    EXPECT_EQ(plot(-180.0f, -90.0f, 359.99f), "roll:-180.00 pitch:-90.00 yaw:359.99\n");
}

TEST(Format, RoundsHalfAwayFromZeroAndNeverPrintsMinusZero) {
    EXPECT_EQ(plot(0.004f, -0.004f, 1.006f), "roll:0.00 pitch:0.00 yaw:1.01\n");
    EXPECT_EQ(plot(-0.006f, 0.996f, 10.0f), "roll:-0.01 pitch:1.00 yaw:10.00\n");
    EXPECT_EQ(plot(-0.05f, 0.05f, 0.5f), "roll:-0.05 pitch:0.05 yaw:0.50\n");
}

TEST(Format, HeadingThatRoundsTo360IsZero) {
    EXPECT_EQ(plot(0.0f, 0.0f, 359.996f), "roll:0.00 pitch:0.00 yaw:0.00\n");
}

TEST(Format, NonFiniteOrAbsurdAnglesAreNotPrinted) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_EQ(plot(nan, 0.0f, 0.0f), "");
    EXPECT_EQ(plot(0.0f, inf, 0.0f), "");
    EXPECT_EQ(plot(0.0f, 0.0f, -inf), "");
    EXPECT_EQ(plot(1000.0f, 0.0f, 0.0f), "");
    EXPECT_EQ(csv(5, 0.0f, 0.0f, nan), "");
}

TEST(Format, CsvRow) {
    EXPECT_EQ(csv(0, 1.0f, -2.5f, 90.125f), "0,1.00,-2.50,90.13\n");
    EXPECT_EQ(csv(123456, -179.999f, 89.999f, 0.0f), "123456,-180.00,90.00,0.00\n");
    EXPECT_EQ(csv(4294967295u, 0.0f, 0.0f, 0.0f), "4294967295,0.00,0.00,0.00\n");
    EXPECT_EQ(csv(1000000000u, 0.0f, 0.0f, 0.0f), "1000000000,0.00,0.00,0.00\n");
}

TEST(Format, LongestLinesFit) {
    EXPECT_LE(plot(-179.99f, -89.99f, 359.99f).size(), fmt::kLineMax);
    EXPECT_LE(csv(4294967295u, -179.99f, -89.99f, 359.99f).size(), fmt::kLineMax);
}

TEST(Format, CentiAndInt) {
    EXPECT_EQ(centi(0), "0.00");
    EXPECT_EQ(centi(5), "0.05");
    EXPECT_EQ(centi(-5), "-0.05");
    EXPECT_EQ(centi(-123456), "-1234.56");
    EXPECT_EQ(centi(INT32_MIN), "-21474836.48");
    char buf[12];
    EXPECT_EQ(std::string(buf, text::format_int(buf, INT32_MIN)), "-2147483648");
    EXPECT_EQ(std::string(buf, text::format_int(buf, 7)), "7");
}

TEST(Format, ToCentiRejectsNonFinite) {
    int32_t c = 42;
    EXPECT_FALSE(text::to_centi(std::numeric_limits<float>::quiet_NaN(), c));
    EXPECT_FALSE(text::to_centi(3e7f, c));
    EXPECT_EQ(c, 42);
    EXPECT_TRUE(text::to_centi(-2.345f, c));
    EXPECT_EQ(c, -235);  // -234.5 (float: -234.49997) rounds to nearest
}

namespace {
void sink_write(void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }
}  // namespace

TEST(Format, WriterChains) {
    std::string s;
    const text::Sink sink{&s, sink_write};
    text::Writer(&sink).str(TXT("# x=")).i32(-12).chr(' ').u32(4000000000u).chr(' ').hex8(0x6A)
        .chr(' ').fixed2(3.14159f).chr(' ').fixed2(std::nanf("")).end();
    EXPECT_EQ(s, "# x=-12 4000000000 6A 3.14 ?\n");
    text::Writer(nullptr).str(TXT("silent")).i32(3).end();  // a null sink is a no-op
}

TEST(Format, DegreesWithSevenDecimals) {
    std::string s;
    const text::Sink sink{&s, sink_write};
    text::Writer(&sink).degrees_e7(71350450).chr(' ').degrees_e7(-731194210).chr(' ').degrees_e7(-5).chr(' ')
        .degrees_e7(1800000000).chr(' ').degrees_e7(INT32_MIN);
    EXPECT_EQ(s, "7.1350450 -73.1194210 -0.0000005 180.0000000 -214.7483648");
}

namespace {

std::string quat(float w, float x, float y, float z) {
    char buf[fmt::kLineMax];
    return std::string(buf, fmt::format_quat_line(buf, linalg::Quaternion{w, x, y, z}));
}

std::string raw(const linalg::Vector3f& g, const linalg::Vector3f& a, const linalg::Vector3f& m) {
    char buf[fmt::kRawLineMax];
    return std::string(buf, fmt::format_raw_line(buf, g, a, m));
}

}  // namespace

TEST(Format, QuatLineHasFourDecimalsInLabelValueForm) {
    EXPECT_EQ(quat(0.70710678f, 0.0f, -0.70710678f, 0.00004f), "qw:0.7071 qx:0.0000 qy:-0.7071 qz:0.0000\n");
    EXPECT_EQ(quat(1.0f, -0.00005f, 0.12345f, -0.99995f), "qw:1.0000 qx:-0.0001 qy:0.1235 qz:-1.0000\n");
    EXPECT_EQ(quat(-1.0f, -1.0f, -1.0f, -1.0f).size(), 44u);
    EXPECT_LE(quat(-1.0f, -1.0f, -1.0f, -1.0f).size(), (size_t)fmt::kLineMax);
}

TEST(Format, QuatLineRefusesWhatIsNotAUnitQuaternionComponent) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(quat(nan, 0.0f, 0.0f, 0.0f), "");
    EXPECT_EQ(quat(1.0f, 0.0f, std::numeric_limits<float>::infinity(), 0.0f), "");
    EXPECT_EQ(quat(1.01f, 0.0f, 0.0f, 0.0f), "");
    EXPECT_EQ(quat(1.0f, 0.0f, 0.0f, -1.01f), "");
}

TEST(Format, RawLineHasTheCalibratedValuesWithTheirUnitsResolution) {
    using linalg::Vector3f;
    EXPECT_EQ(raw(Vector3f(0.123f, -0.061f, 0.0f), Vector3f(0.0124f, -0.0031f, -1.0006f), Vector3f(20.14f, 0.26f, 45.25f)),
              "gx:0.12 gy:-0.06 gz:0.00 ax:0.012 ay:-0.003 az:-1.001 mx:20.1 my:0.3 mz:45.3\n");
    EXPECT_EQ(raw(Vector3f(-2000.0f, 1999.99f, 5.0f), Vector3f(8.0f, -8.0f, 0.5f), Vector3f(-810.0f, 0.0f, 1.0f)),
              "gx:-2000.00 gy:1999.99 gz:5.00 ax:8.000 ay:-8.000 az:0.500 mx:-810.0 my:0.0 mz:1.0\n");
}

TEST(Format, RawLongestLineFitsAndBeyondTheSensorsIsRefused) {
    using linalg::Vector3f;
    const std::string longest =
        raw(Vector3f(-9999.0f, -9999.0f, -9999.0f), Vector3f(-40.0f, -40.0f, -40.0f), Vector3f(-999.9f, -999.9f, -999.9f));
    EXPECT_EQ(longest.size(), 99u);
    EXPECT_LE(longest.size(), (size_t)fmt::kRawLineMax);
    const Vector3f z;
    EXPECT_EQ(raw(Vector3f(10000.0f, 0.0f, 0.0f), z, z), "");
    EXPECT_EQ(raw(z, Vector3f(0.0f, -40.5f, 0.0f), z), "");
    EXPECT_EQ(raw(z, z, Vector3f(0.0f, 0.0f, 1000.0f)), "");
    EXPECT_EQ(raw(z, z, Vector3f(0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f)), "");
}

TEST(Format, FixedPointAtEveryPrecision) {
    char buf[20];
    EXPECT_EQ(std::string(buf, text::format_fixed(buf, -12345, 4)), "-1.2345");
    EXPECT_EQ(std::string(buf, text::format_fixed(buf, 5, 3)), "0.005");
    EXPECT_EQ(std::string(buf, text::format_fixed(buf, 7, 1)), "0.7");
    EXPECT_EQ(std::string(buf, text::format_fixed(buf, -42, 0)), "-42");
    EXPECT_EQ(std::string(buf, text::format_fixed(buf, INT32_MIN, 4)), "-214748.3648");
    int32_t v = 7;
    EXPECT_TRUE(text::to_fixed(-0.00005f, 4, v));
    EXPECT_EQ(v, -1);
    EXPECT_TRUE(text::to_fixed(1.23456f, 3, v));
    EXPECT_EQ(v, 1235);
    v = 7;
    EXPECT_FALSE(text::to_fixed(3e5f, 4, v));  // 3e9 does not fit
    EXPECT_FALSE(text::to_fixed(1.0f, 5, v));
    EXPECT_EQ(v, 7);
}

// The hundredths come from the angle's bits in Q15: the printed value is the exact
// angle rounded half away from zero, except within the Q15 truncation (3.1e-5 deg,
// 0.0031 of a count) of a half count.
TEST(Format, HundredthsAreTheExactAngleRounded) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> deg(-360.0f, 360.0f);
    int checked = 0;
    for (int i = 0; i < 200000; ++i) {
        const float a = deg(rng) * std::pow(2.0f, -(float)(i % 12));
        const double exact = (double)a * 100.0;
        const double frac = std::fabs(exact) - std::floor(std::fabs(exact));
        if (std::fabs(frac - 0.5) < 0.0032) continue;
        const long expected = (long)(exact >= 0.0 ? std::floor(exact + 0.5) : -std::floor(-exact + 0.5));
        const std::string line = csv(0, a, 0.0f, 0.0f);
        ASSERT_FALSE(line.empty()) << a;
        const std::string field = line.substr(2, line.find(',', 2) - 2);
        char buf[16];
        ASSERT_EQ(field, std::string(buf, text::format_centi(buf, (int32_t)expected))) << a;
        ++checked;
    }
    EXPECT_GT(checked, 190000);
}

// The integer path's lines (angles already in hundredths): the same bytes as the float
// lines of those hundredths, 36000 as a heading written 0.00, beyond a turn refused.
TEST(Format, CentidegLinesAreTheFloatLinesOfTheSameHundredths) {
    const auto plot_cd = [](int32_t r, int32_t p, int32_t y) {
        char buf[fmt::kLineMax];
        return std::string(buf, fmt::format_plot_line_centideg(buf, r, p, y));
    };
    const auto csv_cd = [](uint32_t t, int32_t r, int32_t p, int32_t y) {
        char buf[fmt::kLineMax];
        return std::string(buf, fmt::format_csv_line_centideg(buf, t, r, p, y));
    };
    EXPECT_EQ(plot_cd(-123, 456, 27180), "roll:-1.23 pitch:4.56 yaw:271.80\n");
    EXPECT_EQ(plot_cd(-18000, -9000, 35999), "roll:-180.00 pitch:-90.00 yaw:359.99\n");
    EXPECT_EQ(plot_cd(-5, 5, 36000), "roll:-0.05 pitch:0.05 yaw:0.00\n");
    EXPECT_EQ(csv_cd(4294967295u, 0, -1, 1), "4294967295,0.00,-0.01,0.01\n");
    EXPECT_EQ(plot_cd(36001, 0, 0), "");
    EXPECT_EQ(plot_cd(0, -36001, 0), "");
    EXPECT_EQ(csv_cd(1, 0, 0, 36001), "");
    std::mt19937 rng(21);
    std::uniform_int_distribution<int32_t> c(-18000, 18000), h(0, 35999);
    for (int i = 0; i < 20000; ++i) {
        const int32_t r = c(rng), p = c(rng) / 2, y = h(rng);
        ASSERT_EQ(plot_cd(r, p, y), plot(r * 0.01f, p * 0.01f, y * 0.01f));
        ASSERT_EQ(csv_cd((uint32_t)i * 20u, r, p, y), csv((uint32_t)i * 20u, r * 0.01f, p * 0.01f, y * 0.01f));
    }
}
