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

// --- With body rates ----------------------------------------------------------------------
//
// The default-like gains (TCONST 0.5 s, P 1, I 0, D 0.08) as the step takes them: 1/tau =
// 2/s (8192 in Q12), P' = P tau - D = 0.42 (1720 in Q12), D = 0.08 (1311 in Q14). Each case
// worked out by hand in degrees: the demanded rate is the error over tau, the surface P' x
// the demanded rate + D x (demanded - measured rate).

namespace {

flight::AxisTerms pd_terms() { return flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.0f, 0.08f, 3000}, 0.02f); }

// The integrator (centi-degrees of surface, Q16) as integrator_deg() gives it.
float deg_of_q16(int32_t q16) { return (float)q16 * (1.0f / 65536.0f / 100.0f); }

}  // namespace

TEST(AxisController, TermsAreTheGainsInFixedPointRounded) {
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.04f, 0.08f, 3000}, 0.02f);
    EXPECT_EQ(t.inv_tau_q12, 8192);
    EXPECT_EQ(t.kp_ff_q12, 1679);  // ((1 - 0.04 x 0.5) x 0.5 - 0.08) x 4096 = 1679.4
    EXPECT_EQ(t.kd_q14, 1311);     // 0.08 x 16384 = 1310.7: rounded up
    EXPECT_EQ(t.ki_dt_q16, 26);    // 0.04 x 0.5 x 0.02 x 65536 = 26.2
    EXPECT_EQ(t.imax_cd, 3000);
    // A factor beyond 16 bits is held at the largest; a negative P' (D beyond P tau) is 0.
    const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{0.1f, 4.0f, 0.0f, 2.5f, 4500}, 0.02f);
    EXPECT_EQ(big.inv_tau_q12, 32767);
    EXPECT_EQ(big.kd_q14, 32767);
    EXPECT_EQ(big.kp_ff_q12, 0);
    // Half a unit rounds up: D = 2^-15 is exactly half of Q14's unit.
    EXPECT_EQ(flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.0f, 1.0f / 32768.0f, 0}, 0.02f).kd_q14, 1);
    EXPECT_EQ(flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.0f, 1.0f / 65536.0f, 0}, 0.02f).kd_q14, 0);
}

TEST(AxisController, MeasuredRatesDampAndTheDemandedRateLeads) {
    const flight::AxisTerms t = pd_terms();
    ASSERT_EQ(t.kp_ff_q12, 1720);
    ASSERT_EQ(t.kd_q14, 1311);
    flight::AxisController c;
    // 10 deg of error demands 20 deg/s; rolling toward it at 30 deg/s: 0.42 x 20 + 0.08 x
    // (20 - 30) = 8.4 - 0.8 = 7.6 deg.
    EXPECT_EQ(c.step(t, 1000, 0, 3000), 760);
    // ... at 20 deg/s, the demanded rate: the feed-forward alone, 8.4 deg.
    EXPECT_EQ(c.step(t, 1000, 0, 2000), 840);
    // ... away from it at 10 deg/s: 8.4 + 0.08 x 30 = 10.8 deg.
    EXPECT_EQ(c.step(t, 1000, 0, -1000), 1080);
    // No error, rolling right at 50 deg/s: D alone opposes it, -4 deg.
    EXPECT_EQ(c.step(t, 0, 0, 5000), -400);
    EXPECT_EQ(c.step(t, 0, 0, -5000), 400);
    // A rate offset (the turn's pitch rate, 10 deg/s) is demanded as the error's is: 4.2
    // deg of feed-forward, and 0.8 of D while the rate is not there yet.
    EXPECT_EQ(c.step(t, 0, 1000, 0), 500);
    EXPECT_EQ(c.step(t, 0, 1000, 1000), 420);
    // Mirror images: a left and a right upset get the same surface, opposite signs.
    flight::AxisController m;
    for (int32_t e : {-2500, -333, -1, 1, 77, 1000})
        for (int32_t r : {-12345, -101, 0, 99, 4000}) EXPECT_EQ(c.step(t, e, 0, r), -m.step(t, -e, 0, -r)) << e << " " << r;
}

namespace {

// The step as the header defines it, in 64 bits: each product's operand held within its
// bound (the error 36000 cd, the demanded rate 120000 cd/s in P', the rate error 400000
// cd/s), each rounded to the nearest, half away from zero; the integrator sums I tau dt x
// the rate error, held within imax and frozen the way the last output was saturated.
struct ReferenceAxis {
    int64_t integrator_q16 = 0;
    int saturation = 0;

    static int64_t held(int64_t v, int64_t limit) { return std::max(-limit, std::min(limit, v)); }
    static int64_t product(int64_t x, int64_t f, int shift, int64_t limit) {
        const int64_t p = held(x, limit) * f;
        const int64_t half = shift > 0 ? (int64_t)1 << (shift - 1) : 0;
        return p >= 0 ? (p + half) >> shift : -((-p + half) >> shift);
    }
    int step(const flight::AxisTerms& t, int64_t error, int64_t offset, int64_t rate) {
        const int64_t desired = product(error, t.inv_tau_q12, 12, 36000) + offset;
        const int64_t rate_error = held(desired - rate, 400000);
        if (t.ki_dt_q16 > 0) {
            int64_t delta = product(rate_error, t.ki_dt_q16, 0, 400000);
            if ((saturation > 0 && delta > 0) || (saturation < 0 && delta < 0)) delta = 0;
            integrator_q16 = held(integrator_q16 + delta, (int64_t)t.imax_cd << 16);
        } else {
            integrator_q16 = 0;
        }
        // The integrator's whole centi-degrees: rounded down, as an arithmetic shift.
        const int64_t whole = integrator_q16 >= 0 ? integrator_q16 / 65536 : -((-integrator_q16 + 65535) / 65536);
        const int64_t out = product(desired, t.kp_ff_q12, 12, 120000) + product(rate_error, t.kd_q14, 14, 400000) + whole;
        saturation = out >= 4500 ? 1 : (out <= -4500 ? -1 : 0);
        return (int)held(out, 4500);
    }
};

}  // namespace

TEST(AxisController, EveryStepIsTheDefinitionToTheCentiDegree) {
    // Gains across their ranges, errors, offsets and rates drawn over and beyond their
    // bounds: each output and the integrator as the 64-bit definition gives them.
    uint32_t seed = 12345u;
    auto draw = [&seed](int32_t lo, int32_t hi) {
        seed = seed * 1664525u + 1013904223u;
        return lo + (int32_t)((seed >> 8) % (uint32_t)(hi - lo + 1));
    };
    for (int gains = 0; gains < 40; ++gains) {
        const flight::AxisGains g{0.4f + 0.015f * (float)draw(0, 40), 0.1f + 0.1f * (float)draw(0, 39),
                                  0.025f * (float)draw(0, 40), 0.005f * (float)draw(0, 40), (int16_t)draw(0, 4500)};
        const flight::AxisTerms t = flight::axis_terms(g, 0.02f);
        flight::AxisController c;
        ReferenceAxis ref;
        for (int i = 0; i < 300; ++i) {
            const bool wide = i % 10 == 0;
            const int32_t error = wide ? draw(-60000, 60000) : draw(-3000, 3000);
            const int32_t offset = i % 3 == 0 ? draw(-3000, 3000) : 0;
            const int32_t rate = wide ? draw(-500000, 500000) : draw(-20000, 20000);
            ASSERT_EQ(c.step(t, error, offset, rate), ref.step(t, error, offset, rate))
                << "gains " << gains << " step " << i << ": " << error << " " << offset << " " << rate;
            ASSERT_EQ(c.integrator_deg(), (float)ref.integrator_q16 * (1.0f / 65536.0f / 100.0f));
        }
    }
}

TEST(AxisController, OperandsAreHeldAtTheirBounds) {
    // With I = 1 unit (Q16) a step, P' and D zero, the integrator counts the rate error
    // itself: the error is held at 360 deg (1/tau = 1/s: a demand of 360 deg/s) and the
    // rate error at 4000 deg/s.
    const flight::AxisTerms counter{4096, 0, 0, 1, 4500};
    flight::AxisController c;
    c.step(counter, 50000, 0, 0);
    EXPECT_EQ(c.integrator_deg(), deg_of_q16(36000));
    c.reset();
    c.step(counter, -50000, 0, 0);
    EXPECT_EQ(c.integrator_deg(), deg_of_q16(-36000));
    c.reset();
    c.step(counter, 0, 0, -450000);
    EXPECT_EQ(c.integrator_deg(), deg_of_q16(400000));
    c.reset();
    c.step(counter, 0, 0, 450000);
    EXPECT_EQ(c.integrator_deg(), deg_of_q16(-400000));
    // P' and D nearly cancel at their bounds: a demanded rate of 5000 deg/s (an offset) is
    // held at 1200 deg/s in P' (1.0918: 1310.16 deg), the rate error of -9000 deg/s at
    // -4000 deg/s in D (0.3276: -1310.55 deg): -0.39 deg in all, where one count more of
    // either bound would show.
    const flight::AxisTerms cancel{4096, 4472, 5368, 0, 0};
    flight::AxisController d;
    EXPECT_EQ(d.step(cancel, 0, 500000, 900000), -39);
    EXPECT_EQ(d.step(cancel, 0, -500000, -900000), 39);
}

TEST(AxisController, IntegratorGrowsByITauDtPerStepBothWays) {
    // I 0.5, TCONST 0.5: 0.005 x 65536 = 328 (Q16) per cd/s of rate error a step. A steady
    // 2 deg error demands 4 deg/s: 2.0 cd a step, P' = 0.375 gives 1.5 deg.
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.5f, 0.0f, 1000}, 0.02f);
    ASSERT_EQ(t.ki_dt_q16, 328);
    ASSERT_EQ(t.kp_ff_q12, 1536);
    flight::AxisController up, down;
    EXPECT_EQ(up.integrator_deg(), 0.0f) << "as constructed";
    EXPECT_EQ(up.step(t, 200, 0, 0), 152);
    EXPECT_EQ(down.step(t, -200, 0, 0), -153);  // the integrator's -2.002 cd rounded down
    for (int i = 1; i < 10; ++i) {
        up.step(t, 200, 0, 0);
        down.step(t, -200, 0, 0);
    }
    EXPECT_EQ(up.integrator_deg(), deg_of_q16(10 * 400 * 328));
    EXPECT_EQ(down.integrator_deg(), deg_of_q16(-10 * 400 * 328));
    EXPECT_EQ(up.step(t, 200, 0, 0), 150 + 22);  // 11 x 2.0 cd
    // Held at IMAX (10 deg) either way.
    for (int i = 0; i < 600; ++i) {
        up.step(t, 200, 0, 0);
        down.step(t, -200, 0, 0);
    }
    EXPECT_EQ(up.integrator_deg(), deg_of_q16(1000 << 16));
    EXPECT_EQ(down.integrator_deg(), deg_of_q16(-(1000 << 16)));
    // I = 0 empties it at the next step.
    const flight::AxisTerms no_i = flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.0f, 0.0f, 1000}, 0.02f);
    EXPECT_EQ(up.step(no_i, 200, 0, 0), 200);
    EXPECT_EQ(up.integrator_deg(), 0.0f);
}

TEST(AxisController, IntegratorFrozenWhenSaturatedDownAndUnwindsUp) {
    const flight::AxisTerms big = flight::axis_terms(flight::AxisGains{0.5f, 4.0f, 0.2f, 0.0f, 4500}, 0.02f);
    flight::AxisController s;
    EXPECT_EQ(s.step(big, -9000, 0, 0), -4500);  // saturates: this step's part counts
    const float before = s.integrator_deg();
    EXPECT_LT(before, 0.0f);
    for (int i = 0; i < 50; ++i) EXPECT_EQ(s.step(big, -9000, 0, 0), -4500);
    EXPECT_EQ(s.integrator_deg(), before);
    s.step(big, 100, 0, 0);
    EXPECT_GT(s.integrator_deg(), before) << "unwinds at once";
    // A reset forgets the saturation as well as the sum: a small negative error then
    // integrates at once.
    s.step(big, -9000, 0, 0);
    s.step(big, -9000, 0, 0);
    s.reset();
    EXPECT_EQ(s.integrator_deg(), 0.0f);
    s.step(big, -10, 0, 0);
    EXPECT_LT(s.integrator_deg(), 0.0f);
    flight::AxisController p;
    p.step(big, 9000, 0, 0);
    p.step(big, 9000, 0, 0);
    p.reset();
    p.step(big, 10, 0, 0);
    EXPECT_GT(p.integrator_deg(), 0.0f);
}

TEST(AxisController, FullThrowExactlyIsSaturated) {
    // 1/tau 1, P' 1, I one unit a step: 45 deg of error gives exactly 4500 cd with the
    // integrator's first part (under 1 cd, rounded down); at 4500 the output is
    // saturated, and the integrator stays where it is. Down, -44.99 deg and the part's
    // rounding down make exactly -4500.
    const flight::AxisTerms t{4096, 4096, 0, 1, 4500};
    flight::AxisController up, down;
    EXPECT_EQ(up.step(t, 4500, 0, 0), 4500);
    EXPECT_EQ(down.step(t, -4499, 0, 0), -4500);
    up.step(t, 4500, 0, 0);
    down.step(t, -4499, 0, 0);
    EXPECT_EQ(up.integrator_deg(), deg_of_q16(4500));
    EXPECT_EQ(down.integrator_deg(), deg_of_q16(-4499));
    // Saturated, even the least part the pinned way is held: a rate error of 1 cd/s.
    up.step(t, 1, 0, 0);
    down.step(t, -1, 0, 0);
    EXPECT_EQ(up.integrator_deg(), deg_of_q16(4500));
    EXPECT_EQ(down.integrator_deg(), deg_of_q16(-4499));
}

// --- Turn coordination's tables ------------------------------------------------------------

namespace {

constexpr double kPi = 3.14159265358979;

// The tables' entries as their comment defines them: tan(x) sin(x) in Q12 and cos(x) in
// Q15 (0 past 90 deg) at x = 5.12 deg steps, rounded.
int32_t tan_sin_q12(int i) {
    const double x = i * 5.12 * kPi / 180.0;
    return (int32_t)std::lround(std::tan(x) * std::sin(x) * 4096.0);
}
int32_t cos_q15(int i) {
    const double x = i * 5.12 * kPi / 180.0;
    return std::max<int32_t>(0, (int32_t)std::lround(std::cos(x) * 32768.0));
}
// Linearly between two entries, frac of 512, rounded down (an arithmetic shift).
int32_t between(int32_t y0, int32_t y1, int32_t frac) {
    const int32_t d = (y1 - y0) * frac;
    return y0 + (d >= 0 ? d / 512 : -((-d + 511) / 512));
}

}  // namespace

TEST(AxisController, TurnCoordinationTablesEntryByEntry) {
    // A gain of 4096 cd/s and a level nose give tan(bank) sin(bank) in Q12 itself.
    for (int i = 0; i <= 15; ++i) {
        EXPECT_EQ(flight::turn_rate_offset_cds(512 * i, 0, 4096), tan_sin_q12(i)) << i;
        EXPECT_EQ(flight::turn_rate_offset_cds(-512 * i, 0, 4096), tan_sin_q12(i)) << -i;
        EXPECT_EQ(flight::turn_rate_offset_cds(512 * i + 200, 0, 4096), between(tan_sin_q12(i), tan_sin_q12(i + 1), 200)) << i;
    }
    // 80 deg, the bank's limit, lies between the last two entries.
    const int32_t at80 = between(tan_sin_q12(15), tan_sin_q12(16), 8000 - 15 * 512);
    EXPECT_EQ(flight::turn_rate_offset_cds(8000, 0, 4096), at80);
    EXPECT_EQ(flight::turn_rate_offset_cds(9000, 0, 4096), at80);
    EXPECT_EQ(flight::turn_rate_offset_cds(-9000, 0, 4096), at80);
    EXPECT_EQ(flight::turn_rate_offset_cds(9001, 0, 4096), 0);
    EXPECT_EQ(flight::turn_rate_offset_cds(-9001, 0, 4096), 0);
    EXPECT_EQ(flight::turn_rate_offset_cds(1, 0, 4096), 0);
    EXPECT_EQ(flight::turn_rate_offset_cds(-1, 0, 4096), 0);
    // The pitch's cosine at 80 deg of bank: at80 x (cos in Q15 / 2) / 2^14.
    auto with_pitch = [at80](int32_t cos15) { return (at80 * (cos15 >> 1)) >> 14; };
    for (int j = 0; j <= 17; ++j) {
        EXPECT_EQ(flight::turn_rate_offset_cds(8000, 512 * j, 4096), with_pitch(cos_q15(j))) << j;
        EXPECT_EQ(flight::turn_rate_offset_cds(8000, -512 * j, 4096), with_pitch(cos_q15(j))) << -j;
        if (j < 17) {
            EXPECT_EQ(flight::turn_rate_offset_cds(8000, 512 * j + 300, 4096),
                      with_pitch(between(cos_q15(j), cos_q15(j + 1), 300)))
                << j;
        }
    }
    EXPECT_EQ(flight::turn_rate_offset_cds(8000, -1, 4096), with_pitch(between(cos_q15(0), cos_q15(1), 1)));
    // Every pitch between: an entry one off shows somewhere between its neighbours even
    // where the halving (Q15 to Q14) hides it at the entry itself.
    for (int32_t pitch = 0; pitch <= 9000; ++pitch) {
        const int j = pitch / 512;
        ASSERT_EQ(flight::turn_rate_offset_cds(8000, pitch, 4096), with_pitch(between(cos_q15(j), cos_q15(j + 1), pitch % 512)))
            << pitch;
    }
    // Beyond 90 deg of pitch, 90.
    const int32_t at90 = with_pitch(between(cos_q15(17), cos_q15(18), 9000 - 17 * 512));
    EXPECT_EQ(flight::turn_rate_offset_cds(8000, 9000, 4096), at90);
    EXPECT_EQ(flight::turn_rate_offset_cds(8000, 9500, 4096), at90);
    EXPECT_EQ(flight::turn_rate_offset_cds(8000, -12000, 4096), at90);
}

TEST(AxisController, TurnGainIsGOverVInCentiDegreesHeldInRange) {
    // g / V x 180 / pi x 100 x PTCH2SRV_RLL, rounded: 15.5 m/s -> 3625 cd/s.
    EXPECT_EQ(flight::turn_gain_cds(15.5f, 1.0f), 3625);
    EXPECT_EQ(flight::turn_gain_cds(15.5f, 1.5f), 5438);
    EXPECT_EQ(flight::turn_gain_cds(0.0f, 1.0f), 0) << "no airspeed, no coordination";
    EXPECT_EQ(flight::turn_gain_cds(-3.0f, 1.0f), 0);
    EXPECT_EQ(flight::turn_gain_cds(1.0f, 1.0f), 32767) << "held at 16 bits";
    EXPECT_EQ(flight::turn_gain_cds(15.5f, -1.0f), 0) << "never negative";
}

TEST(AxisController, IntegratorSumsTheRateErrorSoAMatchedRateLeavesIt) {
    // The integrator sums I TCONST dt x (demanded - measured rate), not the angle error
    // (docs/flight.md): I 0.5, TCONST 0.5, dt 0.02 s is 0.005 a step, 328 in Q16 per cd/s.
    // 10 deg of error demands 20 deg/s (2000 cd/s); P' = (1 - 0.25) 0.5 = 0.375, D 0.
    const flight::AxisTerms t = flight::axis_terms(flight::AxisGains{0.5f, 1.0f, 0.5f, 0.0f, 4500}, 0.02f);
    ASSERT_EQ(t.ki_dt_q16, 328);
    ASSERT_EQ(t.kp_ff_q12, 1536);
    // Already rolling at the demanded rate: no rate error, the integrator stays at 0 and the
    // surface is the feed-forward alone, 0.375 x 20 = 7.5 deg, however long.
    flight::AxisController matched;
    for (int i = 0; i < 200; ++i) ASSERT_EQ(matched.step(t, 1000, 0, 2000), 750) << i;
    EXPECT_EQ(matched.integrator_deg(), 0.0f);
    // Faster than demanded (30 deg/s): -10 deg/s of rate error, -1000 x 328 a step; the
    // surface has the integrator's whole centi-degrees (rounded down): -5.005 -> -6.
    flight::AxisController fast;
    EXPECT_EQ(fast.step(t, 1000, 0, 3000), 750 - 6);
    for (int i = 1; i < 10; ++i) fast.step(t, 1000, 0, 3000);
    EXPECT_EQ(fast.integrator_deg(), deg_of_q16(-10 * 1000 * 328));
    EXPECT_EQ(fast.step(t, 1000, 0, 3000), 750 - 56) << "-55.06 cd";
    // Rolling away at 10 deg/s: +30 deg/s of rate error, 3 x as fast the other way.
    flight::AxisController away;
    for (int i = 0; i < 10; ++i) away.step(t, 1000, 0, -1000);
    EXPECT_EQ(away.integrator_deg(), deg_of_q16(10 * 3000 * 328));
    // No angle error and no motion: nothing to sum, whatever the integrator held.
    const float held = away.integrator_deg();
    for (int i = 0; i < 10; ++i) EXPECT_EQ(away.step(t, 0, 0, 0), (int16_t)(10 * 3000 * 328 >> 16));
    EXPECT_EQ(away.integrator_deg(), held);
    // A rate offset (the turn's pitch rate) flown as measured is no error either; not
    // flown (the nose not following the turn), it is summed as the error's own would be.
    flight::AxisController turning, lagging;
    for (int i = 0; i < 10; ++i) {
        EXPECT_EQ(turning.step(t, 0, 1000, 1000), 375);
        lagging.step(t, 0, 1000, 0);
    }
    EXPECT_EQ(turning.integrator_deg(), 0.0f);
    EXPECT_EQ(lagging.integrator_deg(), deg_of_q16(10 * 1000 * 328));
}
