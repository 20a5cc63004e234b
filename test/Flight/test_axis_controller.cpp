// SPDX-License-Identifier: GPL-3.0-or-later
// The attitude controller of one axis (lib/Flight AxisController, axis_terms) and the
// pitch axis's turn coordination (turn_rate_offset_cds).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Flight.h"

TEST(AxisController, PGainIsDegreesOfSurfacePerDegreeOfError) {
    flight::AxisController c;
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.0f, 0.02f, 3000}, 0.02f);
    // 10 deg of error, no rate: (P - I tau) x 10 deg = 4 deg = 400 cd (to the fixed point's 1 cd).
    EXPECT_NEAR(c.step(t, 1000, 0, 0), 400, 1);
    // A measured rate toward the demand damps: D x 20 deg/s = 0.4 deg less.
    EXPECT_NEAR(c.step(t, 1000, 0, 2000), 360, 1);
    // Full throw at most.
    EXPECT_EQ(c.step(t, 18000, 0, 0), 4500);
    EXPECT_EQ(c.step(t, -18000, 0, 0), -4500);
    // Gains over their whole ranges, errors and rates at their ends: no overflow, the
    // sign of the error, within full throw.
    for (float p : {0.1f, 4.0f})
        for (float d : {0.0f, 0.2f})
            for (float tau : {0.4f, 1.0f}) {
                const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{tau, p, 0.0f, d, 4500}, 0.02f);
                flight::AxisController e, f;
                const int16_t up = e.step(big, 36000, 0, -200000), down = f.step(big, -36000, 0, 200000);
                EXPECT_GT(up, 0);
                EXPECT_LE(up, 4500);
                EXPECT_EQ(down, -up);
            }
}

TEST(AxisController, StepResponseOfAModelAircraftSettles) {
    // A roll axis as a first-order rate response to the surface (rate -> k x surface with
    // a 0.2 s lag): the default gains bring a 20 deg demand within 1 deg in 3 s, no
    // overshoot beyond 10 %.
    flight::AxisController c;
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.04f, 0.02f, 3000}, 0.02f);
    float angle_deg = 0.0f, rate_deg_s = 0.0f, peak = 0.0f;
    for (int i = 0; i < 250; ++i) {
        const int16_t out = c.step(t, (int32_t)lroundf((20.0f - angle_deg) * 100.0f), 0, (int32_t)lroundf(rate_deg_s * 100.0f));
        const float target_rate = 15.0f * (float)out / 100.0f;  // 15 deg/s per deg of surface
        rate_deg_s += (target_rate - rate_deg_s) * 0.02f / 0.2f;
        angle_deg += rate_deg_s * 0.02f;
        peak = std::max(peak, angle_deg);
        if (i == 150) {
            EXPECT_NEAR(angle_deg, 20.0f, 1.0f);
        }
    }
    EXPECT_NEAR(angle_deg, 20.0f, 0.5f);
    EXPECT_LT(peak, 22.0f);
}

TEST(AxisController, IntegratorLimitedAndFrozenWhenSaturated) {
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 0.4f, 0.5f, 0.0f, 1000}, 0.02f);  // imax 10 deg
    flight::AxisController c;
    // A steady 2 deg error, no motion: the integrator grows to its limit and stops there.
    for (int i = 0; i < 2000; ++i) c.step(t, 200, 0, 0);
    EXPECT_FLOAT_EQ(c.integrator_deg(), 10.0f);
    // Saturated (a huge error): the integrator may not grow the way the output is pinned.
    flight::AxisController s;
    const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{0.5f, 4.0f, 0.2f, 0.0f, 4500}, 0.02f);
    s.step(big, 9000, 0, 0);  // saturates
    const float before = s.integrator_deg();
    for (int i = 0; i < 50; ++i) EXPECT_EQ(s.step(big, 9000, 0, 0), 4500);
    EXPECT_FLOAT_EQ(s.integrator_deg(), before);
    // ... but it unwinds at once when the error turns.
    s.step(big, -100, 0, 0);
    EXPECT_LT(s.integrator_deg(), before);
}

TEST(AxisController, TurnCoordinationPitchesUpInABankEitherWay) {
    // 30 deg bank at 15.5 m/s: g/V tan sin = 9.81/15.5 x 0.577 x 0.5 rad/s = 10.5 deg/s
    // (the tables at 5.12 deg steps: within 1 %).
    const int16_t k = flight::turn_gain_cds(15.5f, 1.0f);
    const int32_t r = flight::turn_rate_offset_cds(3000, 0, k);
    EXPECT_NEAR((double)r, 5729.578 * 9.80665 / 15.5 * std::tan(0.5236) * std::sin(0.5236), 0.01 * 1046.0);
    EXPECT_EQ(flight::turn_rate_offset_cds(-3000, 0, k), r);
    EXPECT_EQ(flight::turn_rate_offset_cds(0, 0, k), 0);
    // Between the table's points, and with the pitch's cosine.
    EXPECT_NEAR((double)flight::turn_rate_offset_cds(4250, 3000, k),
                5729.578 * 9.80665 / 15.5 * std::tan(0.74176) * std::sin(0.74176) * std::cos(0.5236), 0.01 * r + 3.0);
    // Limited at 80 deg, none inverted.
    EXPECT_EQ(flight::turn_rate_offset_cds(8900, 0, k), flight::turn_rate_offset_cds(8000, 0, k));
    EXPECT_EQ(flight::turn_rate_offset_cds(17000, 0, k), 0);
    // The largest gain at the largest bank fits.
    EXPECT_GT(flight::turn_rate_offset_cds(8000, 0, flight::turn_gain_cds(5.0f, 1.5f)), 0);
}
