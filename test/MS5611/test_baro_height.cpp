// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MS5611/BaroHeight.h: the barometric formula against the International Standard
// Atmosphere, and the height and climb filter on a climb.
#include <gtest/gtest.h>

#include <cmath>

#include "BaroHeight.h"
#include "Geodesy.h"

namespace {

TEST(BaroHeight, TheFormulaMatchesTheStandardAtmosphere) {
    // Ground at the thesis' field (1028 m), its ISA temperature; 0..500 m above it.
    const double ground_alt = 1028.0;
    ms5611::BaroHeight h;
    h.set_ground((float)sim::isa_pressure_pa(ground_alt), (float)sim::isa_temperature_c(ground_alt));
    for (double up : {0.0, 10.0, 50.0, 100.0, 300.0, 500.0, -50.0}) {
        const float p = (float)sim::isa_pressure_pa(ground_alt + up);
        // The standard atmosphere both ways: within float's rounding (+- 0.05 m).
        EXPECT_NEAR(h.raw_height_m(p), up, 0.05) << up;
    }
}

TEST(BaroHeight, TheGroundTemperatureScalesTheHeight) {
    // h is proportional to T0 (K): 30 degC against 0 degC, 303.15 / 273.15; near the
    // ground it is the isothermal ln(p0 / p) T0 R / g (ArduPilot's APM2 formula).
    ms5611::BaroHeight cold, warm;
    cold.set_ground(90000.0f, 0.0f);
    warm.set_ground(90000.0f, 30.0f);
    const float p = 89000.0f;
    EXPECT_NEAR(warm.raw_height_m(p) / cold.raw_height_m(p), 303.15f / 273.15f, 1e-4);
    EXPECT_NEAR(cold.raw_height_m(p), std::log(90000.0 / 89000.0) * 273.15 * 29.271267, 0.2);
}

TEST(BaroHeight, TracksAClimbWithoutLagAndFindsItsRate) {
    ms5611::BaroHeight h;
    const double ground_alt = 200.0;
    h.set_ground((float)sim::isa_pressure_pa(ground_alt), (float)sim::isa_temperature_c(ground_alt));
    EXPECT_EQ(h.height_m(), 0.0f);
    // Still for 2 s, then 3 m/s up for 10 s, at 10 Hz.
    double up = 0.0;
    for (int k = 0; k < 120; ++k) {
        if (k >= 20) up += 0.3;
        h.update((float)sim::isa_pressure_pa(ground_alt + up), 0.1f);
    }
    EXPECT_NEAR(h.climb_m_s(), 3.0, 0.05);
    EXPECT_NEAR(h.height_m(), up, 0.1);
    // Level again: the rate returns to 0.
    for (int k = 0; k < 100; ++k) h.update((float)sim::isa_pressure_pa(ground_alt + up), 0.1f);
    EXPECT_NEAR(h.climb_m_s(), 0.0, 0.05);
    EXPECT_NEAR(h.height_m(), up, 0.1);
}

TEST(BaroHeight, NoGroundNoHeightAndBadInputChangesNothing) {
    ms5611::BaroHeight h;
    h.update(90000.0f, 0.1f);
    EXPECT_FALSE(h.have_ground());
    EXPECT_EQ(h.height_m(), 0.0f);
    h.set_ground(90000.0f, 15.0f);
    h.update(89900.0f, 0.1f);
    const float was = h.height_m();
    EXPECT_GT(was, 5.0f);
    h.update(0.0f, 0.1f);
    h.update(NAN, 0.1f);
    h.update(-5.0f, 0.1f);
    EXPECT_EQ(h.height_m(), was);
    EXPECT_TRUE(std::isfinite(h.climb_m_s()));
    // A gap (dt 5 s): the height restarts at the measurement, the rate at 0.
    h.update(89800.0f, 5.0f);
    EXPECT_NEAR(h.height_m(), h.raw_height_m(89800.0f), 1e-3);
    EXPECT_EQ(h.climb_m_s(), 0.0f);
}

}  // namespace
