// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Flight's end points: receiver widths to commands and commands to output widths
// (RCn_*, SERVOn_*), reverse and limits; the mode switch's bands.
#include <gtest/gtest.h>

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
}
