// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Flight's mixer (flight::mix): the plain aeroplane, elevons and V-tail on OUT1-4, the
// aux channels on OUT5-8, reverse and limits.
#include <gtest/gtest.h>

#include <cstdlib>

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
    EXPECT_EQ(out[1], 1600);  // left ruddervator: (900 + 900) / 2, trailing edge up
    EXPECT_EQ(out[3], 1500);  // right: (900 - 900) / 2
    // Yaw right alone: the left trailing edge up, the right down (docs/flight.md).
    flight::mix(s.flight, flight::scales_of(s.flight), flight::Surfaces{0, 0, 0, 900}, nullptr, out);
    EXPECT_EQ(out[1], 1550);
    EXPECT_EQ(out[3], 1450);
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

namespace {

// Outputs off the defaults: each its own end points, some reversed.
settings::Settings odd_outputs() {
    settings::Settings s = defaults();
    s.flight.servo[0] = flight::EndPoints{1050, 1950, 1480};
    s.flight.servo[1] = flight::EndPoints{1100, 2000, 1530};
    s.flight.servo[2] = flight::EndPoints{1020, 1980, 1500};
    s.flight.servo[3] = flight::EndPoints{990, 2010, 1510};
    return s;
}

const int16_t kCommands[] = {-4500, -3001, -900, -1, 0, 1, 77, 901, 2999, 4500};

}  // namespace

TEST(Mixer, PlainAeroplaneEachSurfaceOnItsOutput) {
    for (uint8_t reversed : {0x00, 0x0F, 0x05, 0x0A}) {
        settings::Settings s = odd_outputs();
        s.flight.servo_reversed = reversed;
        const flight::Scales sc = flight::scales_of(s.flight);
        uint16_t out[8];
        for (int16_t a : kCommands)
            for (int16_t e : {-4500, -450, 0, 1333}) {
                const int16_t r = (int16_t)(-a / 2), t = (int16_t)(500 + a / 10);
                flight::mix(s.flight, sc, flight::Surfaces{a, e, t, r}, nullptr, out);
                EXPECT_EQ(out[0], flight::angle_to_width(a, s.flight.servo[0], (reversed & 1) != 0));
                EXPECT_EQ(out[1], flight::angle_to_width(e, s.flight.servo[1], (reversed & 2) != 0));
                EXPECT_EQ(out[2], flight::throttle_to_width(t, s.flight.servo[2], (reversed & 4) != 0));
                EXPECT_EQ(out[3], flight::angle_to_width(r, s.flight.servo[3], (reversed & 8) != 0));
            }
    }
}

TEST(Mixer, ElevonsCarryTheElevatorInTheirSumAndTheAileronInTheirDifference) {
    // Left = (elevator - aileron) / 2 on OUT1, right = (elevator + aileron) / 2 on OUT2:
    // right + left is the elevator, right - left the aileron (to the halving's rounding
    // toward zero); OUT3 and OUT4 as the plain aeroplane's.
    settings::Settings s = odd_outputs();
    s.flight.elevon_output = 1;
    const flight::Scales sc = flight::scales_of(s.flight);
    uint16_t out[8];
    for (int16_t a : kCommands)
        for (int16_t e : kCommands) {
            flight::mix(s.flight, sc, flight::Surfaces{a, e, 250, 300}, nullptr, out);
            const int left = (e - a) / 2, right = (e + a) / 2;
            ASSERT_LE(std::abs(right + left - e), 1);
            ASSERT_LE(std::abs(right - left - a), 1);
            EXPECT_EQ(out[0], flight::angle_to_width((int16_t)left, s.flight.servo[0], false)) << a << " " << e;
            EXPECT_EQ(out[1], flight::angle_to_width((int16_t)right, s.flight.servo[1], false)) << a << " " << e;
            EXPECT_EQ(out[2], flight::throttle_to_width(250, s.flight.servo[2], false));
            EXPECT_EQ(out[3], flight::angle_to_width(300, s.flight.servo[3], false));
        }
    // Full elevator and full aileron together: one elevon at full throw, the other at trim.
    flight::mix(s.flight, sc, flight::Surfaces{4500, 4500, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1480);
    EXPECT_EQ(out[1], 2000);
    flight::mix(s.flight, sc, flight::Surfaces{4500, -4500, 0, 0}, nullptr, out);
    EXPECT_EQ(out[0], 1050);
    EXPECT_EQ(out[1], 1530);
}

TEST(Mixer, VtailCarriesTheElevatorInItsSumAndTheRudderInItsDifference) {
    // Left = (elevator + rudder) / 2 on OUT2, right = (elevator - rudder) / 2 on OUT4 (as
    // ArduPlane's vtail_left and vtail_right): right + left is the elevator, left - right the
    // rudder (to the halving's rounding toward zero); the aileron stays on OUT1.
    settings::Settings s = odd_outputs();
    s.flight.vtail_output = 1;
    s.flight.servo_reversed = 0x02;  // the left ruddervator's servo mounted the other way
    const flight::Scales sc = flight::scales_of(s.flight);
    uint16_t out[8];
    for (int16_t r : kCommands)
        for (int16_t e : kCommands) {
            flight::mix(s.flight, sc, flight::Surfaces{-700, e, 250, r}, nullptr, out);
            const int left = (e + r) / 2, right = (e - r) / 2;
            ASSERT_LE(std::abs(right + left - e), 1);
            ASSERT_LE(std::abs(left - right - r), 1);
            EXPECT_EQ(out[0], flight::angle_to_width(-700, s.flight.servo[0], false));
            EXPECT_EQ(out[1], flight::angle_to_width((int16_t)left, s.flight.servo[1], true)) << r << " " << e;
            EXPECT_EQ(out[3], flight::angle_to_width((int16_t)right, s.flight.servo[3], false)) << r << " " << e;
        }
}

TEST(Mixer, AuxOutputsAreTheirChannelsReversedAboutTheirTrimWithinLimits) {
    settings::Settings s = defaults();
    for (uint8_t i = 4; i < 8; ++i) s.flight.servo[i] = flight::EndPoints{1100, 1900, (uint16_t)(1480 + 20 * (i - 4))};
    s.flight.servo_reversed = 0x50;  // OUT5 and OUT7
    const flight::Scales sc = flight::scales_of(s.flight);
    uint16_t out[8];
    const uint16_t aux[4] = {1700, 1700, 1000, 2000};
    flight::mix(s.flight, sc, flight::Surfaces{0, 0, 0, 0}, aux, out);
    EXPECT_EQ(out[4], 2 * 1480 - 1700);
    EXPECT_EQ(out[5], 1700);
    EXPECT_EQ(out[6], 1900) << "2 x 1520 - 1000, held at the maximum";
    EXPECT_EQ(out[7], 1900) << "held at the maximum";
    const uint16_t low[4] = {1950, 1050, 1888, 1111};
    flight::mix(s.flight, sc, flight::Surfaces{0, 0, 0, 0}, low, out);
    EXPECT_EQ(out[4], 1100) << "2 x 1480 - 1950, held at the minimum";
    EXPECT_EQ(out[5], 1100);
    EXPECT_EQ(out[6], 2 * 1520 - 1888);
    EXPECT_EQ(out[7], 1111);
    // No receiver: each at its trim, reversed or not.
    flight::mix(s.flight, sc, flight::Surfaces{0, 0, 0, 0}, nullptr, out);
    for (uint8_t i = 4; i < 8; ++i) EXPECT_EQ(out[i], 1480 + 20 * (i - 4)) << (int)i;
}

TEST(Mixer, EveryAirframeEveryReverseToTheMicrosecondAtTheLimits) {
    // Each airframe's outputs worked out from docs/flight.md's equations, not through the
    // library's own maps: the default end points (1000-2000 us about 1500) put a command of
    // 9k cd at 1500 + k us, exactly (500 us for 4500 cd), below 1500 when the output is
    // reversed; the throttle 0-1000 at 1000 + t us (2000 - t reversed). Commands are
    // multiples of 18 cd, so that each half is a multiple of 9; full throw both ways. Aux
    // outputs keep their channels whatever the airframe.
    //   plain    OUT1 aileron, OUT2 elevator, OUT4 rudder
    //   elevons  OUT1 (e - a) / 2 (left), OUT2 (e + a) / 2 (right), OUT4 rudder
    //   V-tail   OUT1 aileron, OUT2 (e + r) / 2 (left), OUT4 (e - r) / 2 (right)
    const int16_t commands[] = {-4500, -2250, -18, 0, 18, 1422, 4500};
    const uint16_t aux[4] = {1111, 1234, 1789, 1999};
    for (int airframe = 0; airframe < 3; ++airframe)
        for (uint8_t reversed = 0; reversed < 16; ++reversed) {
            settings::Settings s = defaults();
            s.flight.elevon_output = airframe == 1 ? 1 : 0;
            s.flight.vtail_output = airframe == 2 ? 1 : 0;
            s.flight.servo_reversed = reversed;
            const flight::Scales sc = flight::scales_of(s.flight);
            uint16_t out[8];
            for (int16_t a : commands)
                for (int16_t e : commands)
                    for (int16_t r : commands) {
                        const int16_t t = (int16_t)(500 + a / 9);
                        flight::mix(s.flight, sc, flight::Surfaces{a, e, t, r}, aux, out);
                        int cmd[4] = {a, e, 0, r};
                        if (airframe == 1) cmd[0] = (e - a) / 2, cmd[1] = (e + a) / 2;
                        if (airframe == 2) cmd[1] = (e + r) / 2, cmd[3] = (e - r) / 2;
                        for (int i : {0, 1, 3}) {
                            const int sign = (reversed >> i) & 1 ? -1 : 1;
                            ASSERT_EQ(out[i], 1500 + sign * cmd[i] / 9)
                                << "airframe " << airframe << " reversed " << (int)reversed << " OUT" << i + 1 << ": a "
                                << a << " e " << e << " r " << r;
                        }
                        ASSERT_EQ(out[2], (reversed & 4) ? 2000 - t : 1000 + t);
                        for (int i = 4; i < 8; ++i) ASSERT_EQ(out[i], aux[i - 4]);
                    }
            // To the centi-degree: end points of 1 us a cd about 5000 us (exact within
            // +-2180 cd), odd commands, whose halves C's division rounds toward zero.
            for (int i : {0, 1, 3}) s.flight.servo[i] = flight::EndPoints{501, 9499, 5000};
            const flight::Scales probe = flight::scales_of(s.flight);
            const int16_t fine[] = {-2180, -1001, -3, -1, 0, 1, 2, 777, 2179};
            for (int16_t a : fine)
                for (int16_t e : fine)
                    for (int16_t r : fine) {
                        flight::mix(s.flight, probe, flight::Surfaces{a, e, 0, r}, nullptr, out);
                        int cmd[4] = {a, e, 0, r};
                        if (airframe == 1) cmd[0] = (e - a) / 2, cmd[1] = (e + a) / 2;
                        if (airframe == 2) cmd[1] = (e + r) / 2, cmd[3] = (e - r) / 2;
                        for (int i : {0, 1, 3}) {
                            const int sign = (reversed >> i) & 1 ? -1 : 1;
                            ASSERT_EQ(out[i], 5000 + sign * cmd[i])
                                << "airframe " << airframe << " reversed " << (int)reversed << " OUT" << i + 1 << ": a "
                                << a << " e " << e << " r " << r;
                        }
                    }
        }
}
