// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Flight's end points: receiver widths to commands and commands to output widths
// (RCn_*, SERVOn_*), reverse and limits; the mode switch's bands.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "Flight.h"

TEST(EndPoints, PassThroughIsExactWithDefaultsAndWithin1usOtherwise) {
    const flight::EndPoints def{1000, 2000, 1500}, odd{1090, 1930, 1521};
    for (uint16_t w = 1000; w <= 2000; ++w) {
        const int16_t a = flight::width_to_angle(w, def, false);
        EXPECT_EQ(flight::angle_to_width(a, def, false), w);
        const int16_t t = flight::width_to_throttle(w, def, false);
        EXPECT_EQ(flight::throttle_to_width(t, def, false), w);
        const int16_t b = flight::width_to_angle(w, odd, false);
        const int back = flight::angle_to_width(b, odd, false);
        if (w >= 1090 && w <= 1930) {
            EXPECT_LE(std::abs(back - (int)w), 1) << w;
        }
    }
    EXPECT_EQ(flight::width_to_angle(2000, def, false), 4500);
    EXPECT_EQ(flight::width_to_angle(2000, def, true), -4500);
    EXPECT_EQ(flight::width_to_angle(2100, def, false), 4500);  // clamped
    EXPECT_EQ(flight::angle_to_width(4500, def, true), 1000);
    EXPECT_EQ(flight::throttle_to_width(1000, def, true), 1000);
    const flight::EndPoints narrow{1100, 1800, 1450};
    for (int a = -4500; a <= 4500; a += 7) {
        const uint16_t w = flight::angle_to_width((int16_t)a, narrow, (a & 1) != 0);
        EXPECT_GE(w, 1100);
        EXPECT_LE(w, 1800);
    }
}

TEST(EndPoints, ModeSwitchBandsAreArduPlanes) {
    EXPECT_EQ(flight::switch_position(1000), 1);
    EXPECT_EQ(flight::switch_position(1230), 1);
    EXPECT_EQ(flight::switch_position(1231), 2);
    EXPECT_EQ(flight::switch_position(1500), 4);
    EXPECT_EQ(flight::switch_position(1750), 6);
    EXPECT_EQ(flight::switch_position(2000), 6);
    // Every band's edges: the last width of a band and the first of the next.
    const uint16_t last[5] = {1230, 1360, 1490, 1620, 1749};
    for (uint8_t band = 0; band < 5; ++band) {
        EXPECT_EQ(flight::switch_position(last[band]), band + 1) << last[band];
        EXPECT_EQ(flight::switch_position((uint16_t)(last[band] + 1)), band + 2) << last[band] + 1;
    }
    EXPECT_EQ(flight::switch_position(0), 1);
    EXPECT_EQ(flight::switch_position(65535), 6);
}

namespace {

// The factors as the header defines them: num / span rounded, 0 for a span of none (or
// less) and for a factor beyond 16 bits.
uint16_t ratio(double num, int span) {
    if (span <= 0) return 0;
    const long f = std::lround(num / span);
    return f > 0xFFFF ? 0 : (uint16_t)f;
}
// (x f) / 2^shift rounded to the nearest, for x >= 0.
int32_t rounded(int32_t x, uint16_t f, int shift) {
    return (int32_t)(((int64_t)x * f + ((int64_t)1 << (shift - 1))) >> shift);
}

// The four maps as the header states them, from the factors: receiver widths to commands
// (a width beyond the end points clamps), commands to output widths within min..max.
int32_t angle_of(int32_t w, const flight::EndPoints& ep, bool rev) {
    const flight::Scale sc = flight::angle_input_scale(ep);
    const int32_t d = w - ep.trim_us;
    int32_t a = d >= 0 ? rounded(std::min(d, 2200), sc.up, 8) : -rounded(std::min(-d, 2200), sc.down, 8);
    a = std::max(-4500, std::min(4500, a));
    return rev ? -a : a;
}
int32_t throttle_of(int32_t w, const flight::EndPoints& ep, bool rev) {
    const int32_t d = std::max(0, std::min(2200, w - ep.min_us));
    const int32_t t = std::min(1000, rounded(d, flight::throttle_input_scale(ep).up, 8));
    return rev ? 1000 - t : t;
}
int32_t width_of_angle(int32_t a, const flight::EndPoints& ep, bool rev) {
    const flight::Scale sc = flight::angle_output_scale(ep);
    a = std::max(-4500, std::min(4500, rev ? -a : a));
    const int32_t d = a >= 0 ? rounded(a, sc.up, 16) : -rounded(-a, sc.down, 16);
    return std::max<int32_t>(ep.min_us, std::min<int32_t>(ep.max_us, ep.trim_us + d));
}
int32_t width_of_throttle(int32_t t, const flight::EndPoints& ep, bool rev) {
    t = std::max(0, std::min(1000, t));
    if (rev) t = 1000 - t;
    const int32_t w = ep.min_us + rounded(t, flight::throttle_output_scale(ep).up, 15);
    return std::max<int32_t>(ep.min_us, std::min<int32_t>(ep.max_us, w));
}

// End points off the defaults: sides of different lengths, trims off centre, spans that
// make no factor exact.
const flight::EndPoints kOdd[] = {{1090, 1930, 1521}, {800, 2200, 1700}, {1234, 1877, 1301}, {1100, 1900, 1500},
                                  {950, 2050, 1499}, {1000, 2000, 1000}, {1000, 2000, 2000}};

}  // namespace

TEST(EndPoints, FactorsAreTheSpansRounded) {
    for (int span = 1; span <= 1400; ++span) {
        const uint16_t a = ratio(4500.0 * 256.0, span);
        const flight::Scale in = flight::angle_input_scale(flight::EndPoints{(uint16_t)(1500 - span), (uint16_t)(1500 + span), 1500});
        EXPECT_EQ(in.up, a) << span;
        EXPECT_EQ(in.down, a) << span;
        const flight::Scale lopsided = flight::angle_input_scale(flight::EndPoints{1500, (uint16_t)(1500 + span), 1500});
        EXPECT_EQ(lopsided.up, a) << span;
        EXPECT_EQ(lopsided.down, 0) << span;
        const flight::Scale thr = flight::throttle_input_scale(flight::EndPoints{800, (uint16_t)(800 + span), 1500});
        EXPECT_EQ(thr.up, ratio(1000.0 * 256.0, span)) << span;
        EXPECT_EQ(thr.down, 0) << span;
        const flight::Scale out = flight::angle_output_scale(flight::EndPoints{(uint16_t)(1500 - span), 2200, 1500});
        EXPECT_EQ(out.down, ratio(span * 65536.0, 4500)) << span;
        EXPECT_EQ(out.up, ratio(700 * 65536.0, 4500)) << span;
        EXPECT_EQ(flight::throttle_output_scale(flight::EndPoints{800, (uint16_t)(800 + span), 1500}).up,
                  ratio(span * 32768.0, 1000))
            << span;
    }
    // A side under 18 us has no factor (it would not fit 16 bits): its commands are 0.
    EXPECT_EQ(flight::angle_input_scale(flight::EndPoints{1483, 1517, 1500}).up, 0);
    EXPECT_EQ(flight::angle_input_scale(flight::EndPoints{1482, 1518, 1500}).up, 64000);
    // No span, or end points the wrong way round: no factor.
    const flight::EndPoints inverted{1900, 1100, 1500};
    EXPECT_EQ(flight::angle_input_scale(inverted).up, 0);
    EXPECT_EQ(flight::angle_input_scale(inverted).down, 0);
    EXPECT_EQ(flight::throttle_input_scale(inverted).up, 0);
    EXPECT_EQ(flight::angle_output_scale(inverted).up, 0);
    EXPECT_EQ(flight::angle_output_scale(inverted).down, 0);
    EXPECT_EQ(flight::throttle_output_scale(inverted).up, 0);
    EXPECT_EQ(flight::throttle_output_scale(flight::EndPoints{1500, 1500, 1500}).up, 0);
}

TEST(EndPoints, MapsAreExactAtOddEndPoints) {
    for (const flight::EndPoints& ep : kOdd)
        for (bool rev : {false, true}) {
            for (int32_t w = 0; w <= 3000; ++w) {
                ASSERT_EQ(flight::width_to_angle((uint16_t)w, ep, rev), angle_of(w, ep, rev)) << w << " " << ep.trim_us;
                ASSERT_EQ(flight::width_to_throttle((uint16_t)w, ep, rev), throttle_of(w, ep, rev)) << w << " " << ep.min_us;
            }
            for (int32_t a = -6000; a <= 6000; ++a)
                ASSERT_EQ(flight::angle_to_width((int16_t)a, ep, rev), width_of_angle(a, ep, rev)) << a << " " << ep.trim_us;
            for (int32_t t = -200; t <= 1200; ++t)
                ASSERT_EQ(flight::throttle_to_width((int16_t)t, ep, rev), width_of_throttle(t, ep, rev)) << t << " " << ep.min_us;
        }
}

TEST(EndPoints, MapsAreTheEndPointsStraightLines) {
    // Whatever the rounding: on the straight line through the end points within the
    // factor's rounding (half a unit of Q8 over the span: a receiver width) and half a
    // count, the ends themselves exact, and clamped beyond them.
    for (const flight::EndPoints& ep : kOdd) {
        const double up = ep.max_us - ep.trim_us, down = ep.trim_us - ep.min_us, span = ep.max_us - ep.min_us;
        for (int32_t w = ep.min_us; w <= ep.max_us; ++w) {
            const double side = w >= ep.trim_us ? up : down;
            const double ideal = side > 0 ? 4500.0 * (w - ep.trim_us) / side : 0.0;
            EXPECT_LE(std::fabs(flight::width_to_angle((uint16_t)w, ep, false) - ideal), 0.5 + side / 512.0 + 0.01) << w;
            EXPECT_LE(std::fabs(flight::width_to_throttle((uint16_t)w, ep, false) - 1000.0 * (w - ep.min_us) / span),
                      0.5 + span / 512.0 + 0.01)
                << w;
            EXPECT_EQ(flight::width_to_throttle((uint16_t)w, ep, true), 1000 - flight::width_to_throttle((uint16_t)w, ep, false));
        }
        for (int32_t a = -4500; a <= 4500; a += 9) {
            const double ideal = ep.trim_us + (a >= 0 ? up : down) * a / 4500.0;
            EXPECT_LE(std::fabs(flight::angle_to_width((int16_t)a, ep, false) - ideal), 1.0) << a;
        }
        for (int32_t t = 0; t <= 1000; t += 7)
            EXPECT_LE(std::fabs(flight::throttle_to_width((int16_t)t, ep, true) - (ep.max_us - span * t / 1000.0)), 1.0) << t;
        EXPECT_EQ(flight::width_to_throttle((uint16_t)(ep.min_us - 5), ep, false), 0) << "below the minimum: none";
        EXPECT_EQ(flight::width_to_throttle((uint16_t)(ep.max_us + 5), ep, false), 1000);
        EXPECT_EQ(flight::throttle_to_width(0, ep, false), ep.min_us);
        EXPECT_EQ(flight::throttle_to_width(1000, ep, false), ep.max_us);
        EXPECT_EQ(flight::throttle_to_width(-50, ep, false), ep.min_us);
        EXPECT_EQ(flight::throttle_to_width(1050, ep, true), ep.min_us);
        EXPECT_EQ(flight::angle_to_width(4500, ep, false), ep.max_us);
        EXPECT_EQ(flight::angle_to_width(-4500, ep, false), ep.min_us);
        EXPECT_EQ(flight::angle_to_width(0, ep, true), ep.trim_us);
    }
}
