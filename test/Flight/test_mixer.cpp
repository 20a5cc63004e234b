// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Flight's mixer (flight::mix): the plain aeroplane, elevons and V-tail on OUT1-4, the
// aux channels on OUT5-8, reverse and limits.
#include <gtest/gtest.h>

#include "Flight.h"
#include "Settings.h"

namespace {

settings::Settings defaults() { return settings::defaults(); }

}  // namespace

TEST(Mixer, PlainElevonAndVtail) {
    settings::Settings s = defaults();
    uint16_t out[8];
    const uint16_t aux[4] = {2000, 1000, 1500, 1750};
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, -900, 500, 450}, aux, out);
    EXPECT_EQ(out[0], 1600);  // aileron: +900 cd of 4500 = +100 us
    EXPECT_EQ(out[1], 1400);  // elevator
    EXPECT_EQ(out[2], 1500);  // throttle 50 %
    EXPECT_EQ(out[3], 1550);  // rudder
    EXPECT_EQ(out[4], 2000);
    EXPECT_EQ(out[5], 1000);
    EXPECT_EQ(out[6], 1500);
    EXPECT_EQ(out[7], 1750);
    s.flight.elevon_output = 1;
    // Elevons: left = (elevator - aileron) / 2, right = (elevator + aileron) / 2 (trailing
    // edge up positive): roll right lowers the left trailing edge and raises the right.
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, 0, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1450);
    EXPECT_EQ(out[1], 1550);
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{0, 900, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1550);
    EXPECT_EQ(out[1], 1550);
    EXPECT_EQ(out[4], 1500);  // aux at trim without aux commands
    s.flight.elevon_output = 0;
    s.flight.vtail_output = 1;
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{900, 900, 0, 900}, nullptr, out);
    EXPECT_EQ(out[0], 1600);  // the aileron stays on OUT1
    EXPECT_EQ(out[1], 1500);  // left ruddervator: (900 - 900) / 2
    EXPECT_EQ(out[3], 1600);  // right: (900 + 900) / 2
    // Reverse and limits.
    s.flight.vtail_output = 0;
    s.flight.servo_reversed = 0x01;
    s.flight.servo[0] = flight::EndPoints{1100, 1900, 1500};
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{4500, 0, 0, 0}, aux, out);
    EXPECT_EQ(out[0], 1100);
    s.flight.servo_reversed = 0x10;  // an aux output reversed about its trim
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{0, 0, 0, 0}, aux, out);
    EXPECT_EQ(out[4], 1000);
    EXPECT_EQ(out[5], 1000);
}
