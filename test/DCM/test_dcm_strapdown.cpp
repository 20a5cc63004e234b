// SPDX-License-Identifier: GPL-3.0-or-later
// The strapdown part alone (Strapdown.h): integration with its coning term, the halves
// of the turn, renormalisation and its second pass; and the heavy-part schedule
// (Schedule.h).
#include <gtest/gtest.h>

#include <cmath>

#include "Schedule.h"
#include "Strapdown.h"
#include "dcm_test_support.h"

using namespace dcm_test;
using linalg::Vector3l;

namespace {

float largest_entry(const Matrix3f& d) {
    const float v[9] = {d.a.x, d.a.y, d.a.z, d.b.x, d.b.y, d.b.z, d.c.x, d.c.y, d.c.z};
    float worst = 0.0f;
    for (float x : v) worst = std::fabs(x) > worst ? std::fabs(x) : worst;
    return worst;
}

bool same(const Vector3l& a, const Vector3l& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// exp([theta x]) by Rodrigues: I + sin a K + (1 - cos a) K^2. The strapdown turns R
// by R <- R exp([theta x]), so from I it is this.
Matrix3f rotation_of(const Vector3f& theta) {
    const float a = theta.length();
    const Matrix3f k = Matrix3f::skew(theta * (1.0f / a));
    return Matrix3f::identity() + k * std::sin(a) + (k * k) * (1.0f - std::cos(a));
}

// The largest entry of a - b (angle_between_deg's float acos cannot resolve 1e-4 deg).
float max_difference(const Matrix3f& a, const Matrix3f& b) { return largest_entry(a - b); }

// A turn (rad) in the turn sums' units.
Vector3l units_of(const dcm::DcmCoefficients& k, const Vector3f& turn_rad) {
    const float per = 1.0f / k.turn_rad_per_unit();
    return Vector3l((int32_t)std::lround(turn_rad.x * per), (int32_t)std::lround(turn_rad.y * per),
                    (int32_t)std::lround(turn_rad.z * per));
}

// Two halves A and B over one integration: each half's turn on its first step.
Matrix3f integrate_halves(const Vector3f& a_rad, const Vector3f& b_rad) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    for (int step = 0; step < dcm::kIntegrationSteps; ++step) {
        if (step == 0) s.add_turn(units_of(k, a_rad));
        if (step == dcm::kIntegrationSteps / 2) s.add_turn(units_of(k, b_rad));
        s.end_step();
    }
    EXPECT_EQ(s.pending_steps(), dcm::kIntegrationSteps);
    s.integrate(k);
    EXPECT_EQ(s.pending_steps(), 0);
    EXPECT_TRUE(same(s.pending_units(), Vector3l()));
    return linalg::matrix_from_q30(s.r());
}

}  // namespace

TEST(DcmStrapdown, IntegratesOneTurnAsRodriguesRotation) {
    const Vector3f theta(0.3f, -0.2f, 0.4f);
    const Matrix3f got = integrate_halves(theta, Vector3f());
    EXPECT_LT(max_difference(got, rotation_of(theta)), 2e-6f);
    EXPECT_LT(orthonormality_error(got), 1e-6f);
}

// Savage's two-sample coning term: a turn A then a turn B is the rotation vector
// A + B + (2/3) A x B (to second order), not A + B: with A about x and B about y the
// difference is about z, 0.027 rad here; the sign decides which way.
TEST(DcmStrapdown, ConingTermTurnsAboutAcrossB) {
    const Vector3f a(0.2f, 0.0f, 0.0f), b(0.0f, 0.2f, 0.0f);
    const Matrix3f got = integrate_halves(a, b);
    const Vector3f with_coning = a + b + a.cross(b) * (2.0f / 3.0f);
    const Vector3f flipped = a + b - a.cross(b) * (2.0f / 3.0f);
    EXPECT_LT(angle_between_deg(got, rotation_of(with_coning)), 0.01f);
    EXPECT_GT(angle_between_deg(got, rotation_of(flipped)), 2.0f);
}

TEST(DcmStrapdown, ConstantRateForOneSecondTurnsOneRadian) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    const Vector3l per_step = units_of(k, Vector3f(0.0f, 0.0f, 1.0f * k.step_s));
    const int steps = (int)std::lround(1.0f / k.step_s);
    for (int i = 0; i < steps; ++i) {
        s.add_turn(per_step);
        s.end_step();
        if (s.pending_steps() == dcm::kIntegrationSteps) s.integrate(k);
    }
    const dcm::EulerAngles e = dcm::euler_from_dcm(linalg::matrix_from_q30(s.r()));
    EXPECT_NEAR(e.yaw_rad, 1.0f, 1e-4f);
    EXPECT_NEAR(e.roll_rad, 0.0f, 1e-5f);
}

// A turn sum beyond any gyro's range over an integration (a corrupt one) is saturated at
// kMaxTurnAxisQ26, the same on both sides: never a turn of the other sign.
TEST(DcmStrapdown, ATurnBeyondAnyGyroIsSaturatedOnBothSides) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    ASSERT_NE(k.theta_factor_q30, 0) << "the integer path";
    const int32_t limit = k.theta_units_limit;
    const int32_t far = limit > 1000000000L ? 2000000000L : limit * 2;
    const Vector3l beyond = k.theta_q26(Vector3l(far, -far, 0));
    const Vector3l at = k.theta_q26(Vector3l(limit, -limit, 0));
    EXPECT_EQ(beyond.x, at.x);
    EXPECT_EQ(beyond.y, at.y);
    EXPECT_NEAR((double)beyond.x, (double)dcm::kMaxTurnAxisQ26, dcm::kMaxTurnAxisQ26 * 1e-6);
    EXPECT_NEAR((double)beyond.y, -(double)dcm::kMaxTurnAxisQ26, dcm::kMaxTurnAxisQ26 * 1e-6);
    EXPECT_EQ(beyond.z, 0);
}

TEST(DcmStrapdown, TheFirstHalfIsKeptApartAtHalfTheSteps) {
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    s.add_turn(Vector3l(100, 0, 0));
    s.end_step();
    s.add_turn(Vector3l(0, 200, 0));
    s.end_step();  // half: the first half holds both
    s.add_turn(Vector3l(0, 0, 300));
    EXPECT_TRUE(same(s.pending_units(), Vector3l(100, 200, 300)));
}

// A skew of 0.05 between rows a and b: one pass leaves ~(0.05)^2 / 4 of it, the second
// pass takes it below 1e-5 (the renormalisation's contract after a large error).
TEST(DcmStrapdown, RenormalisationTakesALargeSkewAwayInTwoPasses) {
    dcm::Strapdown s;
    const Matrix3f skewed(Vector3f(1.0f, 0.0f, 0.0f), Vector3f(0.05f, 1.001f, 0.0f), Vector3f(0.0f, 0.0f, 1.0f));
    s.reset(linalg::q30_from_matrix(skewed));
    EXPECT_TRUE(s.renormalise());
    const Matrix3f r = linalg::matrix_from_q30(s.r());
    EXPECT_LT(orthonormality_error(r), 1e-5f);
    EXPECT_GT(r.c.z, 0.99f);  // right-handed: c = a x b
    EXPECT_FALSE(s.renormalisation_due());
}

TEST(DcmStrapdown, RenormalisationReportsAHopelessMatrix) {
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f(Vector3f(1.6f, 0.0f, 0.0f), Vector3f(0.0f, 1.0f, 0.0f), Vector3f(0.0f, 0.0f, 1.0f))));
    EXPECT_FALSE(s.renormalise());
    // An entry beyond +-1.4 on any axis of a row (its square beyond Q30's 2).
    s.reset(linalg::q30_from_matrix(Matrix3f(Vector3f(0.0f, 0.0f, 1.5f), Vector3f(0.0f, 1.0f, 0.0f), Vector3f(1.0f, 0.0f, 0.0f))));
    EXPECT_FALSE(s.renormalise());
    s.reset(linalg::q30_from_matrix(Matrix3f::zero()));
    EXPECT_FALSE(s.renormalise());
}

TEST(DcmStrapdown, RenormalisationFallsDueAfterKRenormaliseEveryIntegrations) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    for (int i = 0; i < dcm::kRenormaliseEvery; ++i) {
        EXPECT_FALSE(s.renormalisation_due()) << i;
        s.integrate(k);
    }
    EXPECT_TRUE(s.renormalisation_due());
}

// One heavy part a step: over many steps without a line, exactly one integration and
// one gravity correction every kIntegrationSteps (= kCorrectionDivider) steps, never on
// the same step, and the renormalisation only on a step left free.
TEST(DcmSchedule, OneHeavyPartAStepAndEachAtItsPace) {
    static_assert(dcm::kIntegrationSteps == dcm::kCorrectionDivider, "the test counts both by four");
    dcm::HeavySchedule schedule;
    uint8_t pending = 0, integrations_since_renormalise = 0;
    int integrations = 0, corrections = 0, renormalisations = 0;
    const int steps = 400;
    for (int i = 0; i < steps; ++i) {
        const bool line_due = (i % 4) == 1;  // a line every fourth step, as at 50 Hz
        const dcm::HeavyPart part =
            schedule.next(pending, integrations_since_renormalise >= dcm::kRenormaliseEvery, line_due);
        schedule.count_step();
        ++pending;
        if (part == dcm::HeavyPart::kIntegration) {
            ++integrations;
            pending = 0;
            ++integrations_since_renormalise;
        } else if (part == dcm::HeavyPart::kGravity) {
            ++corrections;
            schedule.gravity_done();
        } else if (part == dcm::HeavyPart::kRenormalisation) {
            EXPECT_FALSE(line_due) << i;
            ++renormalisations;
            integrations_since_renormalise = 0;
        }
        EXPECT_LE(pending, dcm::kIntegrationSteps) << i;
    }
    EXPECT_NEAR(integrations, steps / dcm::kIntegrationSteps, 1);
    EXPECT_NEAR(corrections, steps / dcm::kCorrectionDivider, 1);
    EXPECT_NEAR(renormalisations, steps / (dcm::kIntegrationSteps * dcm::kRenormaliseEvery), 1);
    EXPECT_TRUE(dcm::HeavySchedule::blocks(dcm::HeavyPart::kIntegration));
    EXPECT_TRUE(dcm::HeavySchedule::blocks(dcm::HeavyPart::kGravity));
    EXPECT_FALSE(dcm::HeavySchedule::blocks(dcm::HeavyPart::kRenormalisation));
}

// A line due with two or more steps summed integrates them first (the output is then
// carried over at most one step).
TEST(DcmSchedule, ALineIntegratesTwoOrMoreWaitingSteps) {
    dcm::HeavySchedule schedule;
    EXPECT_EQ(schedule.next(1, false, true), dcm::HeavyPart::kIntegration);
    EXPECT_NE(schedule.next(0, false, true), dcm::HeavyPart::kIntegration);
    EXPECT_NE(schedule.next(1, false, false), dcm::HeavyPart::kIntegration);
    EXPECT_EQ(schedule.next(0, true, false), dcm::HeavyPart::kRenormalisation);
    EXPECT_EQ(schedule.next(0, true, true), dcm::HeavyPart::kNone);
}

// A reset starts the integration afresh: the steps summed before it are gone.
TEST(DcmStrapdown, AResetForgetsThePendingSteps) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::Strapdown s;
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    for (int step = 0; step < dcm::kIntegrationSteps - 1; ++step) {
        s.add_turn(units_of(k, Vector3f(0.01f, 0.0f, 0.0f)));
        s.end_step();
    }
    ASSERT_EQ(s.pending_steps(), dcm::kIntegrationSteps - 1);
    s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
    EXPECT_EQ(s.pending_steps(), 0);
    EXPECT_TRUE(same(s.pending_units(), Vector3l()));
}

// A row twice a unit long or more (its entries each within Q30's +-1.4) is no rotation
// to rescale: reported, like a row too short.
TEST(DcmStrapdown, RenormalisationReportsARowTwiceTooLong) {
    dcm::Strapdown s;
    const float h = std::sqrt(0.5f);
    // a . b = 0: the orthogonalisation leaves the rows as they are. |a|^2 = 4.92 and
    // 4.19: beyond what unsigned Q30 holds (they would read 0.92 and 0.19).
    s.reset(linalg::q30_from_matrix(Matrix3f(Vector3f(1.4f, 1.4f, 1.0f), Vector3f(h, -h, 0.0f), Vector3f(0.0f, 0.0f, 1.0f))));
    EXPECT_FALSE(s.renormalise());
    s.reset(linalg::q30_from_matrix(Matrix3f(Vector3f(1.3f, 1.3f, 0.9f), Vector3f(h, -h, 0.0f), Vector3f(0.0f, 0.0f, 1.0f))));
    EXPECT_FALSE(s.renormalise());
    // ... while 3.6 is rescaled to a unit row.
    s.reset(linalg::q30_from_matrix(Matrix3f(Vector3f(1.2f, 1.2f, 0.9f), Vector3f(h, -h, 0.0f), Vector3f(0.0f, 0.0f, 1.0f))));
    EXPECT_TRUE(s.renormalise());
    EXPECT_LT(orthonormality_error(linalg::matrix_from_q30(s.r())), 1e-4f);
}

// Rows 2.5 % too long or short are outside the first-order factor's window (its
// residual 3/8 (r.r - 1)^2 would be 2e-4): they take the exact factor and come out of
// one pass at unit length.
TEST(DcmStrapdown, RenormalisationRescalesRowsFarFromUnitExactly) {
    // (and 1.00125: |r|^2 1.0025, just outside the window, where the first order would
    // leave 2.3e-6)
    for (float scale : {1.025f, 0.975f, 1.00125f}) {
        dcm::Strapdown s;
        s.reset(linalg::q30_from_matrix(Matrix3f::identity() * scale));
        ASSERT_TRUE(s.renormalise());
        const Matrix3f r = linalg::matrix_from_q30(s.r());
        EXPECT_NEAR(r.a.length_squared(), 1.0f, 1e-6f) << scale;
        EXPECT_NEAR(r.b.length_squared(), 1.0f, 1e-6f) << scale;
    }
}

// The gravity correction runs on the step its window completes (it "falls due with this
// step"), not a step later: three steps counted, the fourth is the correction's.
TEST(DcmSchedule, TheCorrectionRunsOnTheStepItsWindowCompletes) {
    dcm::HeavySchedule schedule;
    for (int i = 0; i < dcm::kCorrectionDivider - 2; ++i) {
        schedule.count_step();
        EXPECT_EQ(schedule.next(0, false, false), dcm::HeavyPart::kNone) << i;
    }
    schedule.count_step();
    EXPECT_EQ(schedule.next(0, false, false), dcm::HeavyPart::kGravity);
}

// x c / 2^15 by two 16x16 products, rounded toward zero, for any 31-bit x and 16-bit c
// whose product fits 31 bits (the latency turn's and the gravity window's factor):
// against 64-bit arithmetic.
TEST(DcmCoefficients, ScaleQ15IsTheProductToAUnit) {
    const int32_t xs[] = {0, 1, -1, 0x1FFFF, -0x1FFFF, 0x7FFFFFFF - 1, -0x7FFFFFFF, 123456789, -98765, 65535, 65536};
    const uint16_t cs[] = {0, 1, 2621, 32768, 45698, 65535};
    for (int32_t x : xs) {
        for (uint16_t c : cs) {
            const int64_t exact = (int64_t)x * c / 32768;  // toward zero
            if (exact > 0x7FFFFFFF || exact < -0x7FFFFFFF) continue;
            EXPECT_NEAR((double)dcm::scale_q15(x, c), (double)exact, 1.0) << x << " x " << c;
        }
    }
}

// Within 0.2 % of unit length (|r|^2 within 1 -+ 0.002) a row takes the first-order
// factor (3 - r.r)/2 in Q30, to the bit; just outside, the exact one.
TEST(DcmStrapdown, RescaleTakesTheFirstOrderFactorInsideItsWindow) {
    const int32_t one = linalg::kOneQ30;
    for (const double length2 : {0.9985, 0.9995, 1.0, 1.0005, 1.0019}) {
        const int32_t x = (int32_t)std::lround(std::sqrt(length2 * 0.5) * one);
        const linalg::Vector3l row(x, -x, 0);
        const uint32_t l2 = (uint32_t)linalg::mul_q30(x, x) * 2u;
        const int32_t factor = one + one / 2 - (int32_t)(l2 / 2);
        linalg::Vector3l out;
        ASSERT_TRUE(dcm::Strapdown::rescale(row, out)) << length2;
        EXPECT_EQ(out.x, linalg::mul_q30(factor, x)) << length2;
        EXPECT_EQ(out.y, linalg::mul_q30(factor, -x)) << length2;
        EXPECT_EQ(out.z, 0);
    }
    // Outside the window: unit length from the exact factor (the first order would leave
    // 3/8 (r.r - 1)^2 = 1.5e-5 here).
    const int32_t x = (int32_t)std::lround(std::sqrt(1.01 * 0.5) * one);
    linalg::Vector3l out;
    ASSERT_TRUE(dcm::Strapdown::rescale(linalg::Vector3l(x, x, 0), out));
    const double l = std::sqrt(2.0 * (double)out.x * out.x) / one;
    EXPECT_NEAR(l, 1.0, 2e-7);
}
