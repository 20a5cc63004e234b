// SPDX-License-Identifier: GPL-3.0-or-later
// The heading's parts alone (Heading.h): the earth-frame field mean, and the magnetic
// disturbance gate's verdicts (the learned field, a disturbance, a new steady field
// adopted only while the board turns, a forgotten reference).
#include <gtest/gtest.h>

#include <cmath>

#include "Heading.h"
#include "dcm_test_support.h"

using linalg::Vector3f;
using linalg::Vector3l;

using dcm_test::float_form_coefficients;

namespace {

// A field in the earth-frame sum's units (uT * 2^17) and a squared strength in the
// norm sum's (uT^2 * 2^6).
Vector3l earth_units(const Vector3f& uT) { return linalg::fixed_from_vector(uT * 131072.0f, 0); }
uint32_t norm2_units(const Vector3f& uT) { return (uint32_t)(uT.length_squared() * 64.0f); }

constexpr float kEarthNorm = 49.24f, kEarthDown = 45.0f / 49.24f;  // 20 uT north, 45 down
constexpr uint16_t kMeanSteps = dcm::kHeadingSteps;
constexpr float kMeanDt = 0.005f * kMeanSteps;

struct Gate {
    dcm::DcmCoefficients k = float_form_coefficients();
    dcm::MagneticGate gate;
    Gate() { gate.learn(kEarthNorm, kEarthDown); }
    dcm::FieldVerdict judge(float norm, float down, float rate_rad_s = 0.0f) {
        const Vector3l rate_units = linalg::fixed_from_vector(Vector3f(0.0f, 0.0f, rate_rad_s * k.units_per_rad_s), 0);
        return gate.judge(norm, down, kMeanSteps, kMeanDt, rate_units, dcm::kDefaultDcmSettings, k);
    }
    // Means of one field until the verdict is not kDisturbed; the seconds it took (or -1).
    float seconds_to_adopt(float norm, float down, float rate_rad_s, float limit_s = 60.0f) {
        for (float t = kMeanDt; t <= limit_s; t += kMeanDt)
            if (judge(norm, down, rate_rad_s) != dcm::FieldVerdict::kDisturbed) return t;
        return -1.0f;
    }
    // One mean of a single step (5 ms) while the board turns at 1 rad/s: the finest
    // count the gate keeps.
    dcm::FieldVerdict judge_one_step(float norm) {
        const Vector3l turning = linalg::fixed_from_vector(Vector3f(0.0f, 0.0f, 1.0f * k.units_per_rad_s), 0);
        return gate.judge(norm, kEarthDown, 1, 0.005f, turning, dcm::kDefaultDcmSettings, k);
    }
    // One-step means of one field until the verdict is not kDisturbed: how many it took.
    int one_step_means_to_adopt(float norm) {
        int means = 1;
        while (judge_one_step(norm) == dcm::FieldVerdict::kDisturbed && means < 100000) ++means;
        return means;
    }
};

}  // namespace

// A sample's integer form (made once where it arrives): uT * 32 truncated toward zero
// as the step always took it, its squared strength in the norm sum's units, and no
// integer form for NaN or an axis at 1 000 uT or beyond (no compass reads that).
TEST(DcmHeading, AFieldSampleIsTakenInSixteenBitsOrNotAtAll) {
    linalg::Vector3i q5;
    ASSERT_TRUE(dcm::field_q5_of(Vector3f(20.0f, -3.51f, 45.0f), q5));
    EXPECT_EQ(q5.x, 640);
    EXPECT_EQ(q5.y, -112);  // -112.32 toward zero
    EXPECT_EQ(q5.z, 1440);
    EXPECT_EQ(dcm::field_norm2(q5), (640u * 640u >> 4) + (112u * 112u >> 4) + (1440u * 1440u >> 4));  // each axis >> 4
    EXPECT_NEAR(dcm::field_norm2(q5) * dcm::kFieldNorm2PerUnit_uT2, 20.0f * 20.0f + 3.51f * 3.51f + 45.0f * 45.0f, 1.0f);
    const Vector3f back = dcm::field_uT_of(q5);
    EXPECT_NEAR(back.y, -3.5f, 1e-6f);
    EXPECT_TRUE(dcm::field_q5_of(Vector3f(999.9f, 0.0f, -999.9f), q5));
    for (const Vector3f bad : {Vector3f(1000.0f, 0.0f, 0.0f), Vector3f(0.0f, -1000.0f, 0.0f), Vector3f(0.0f, 0.0f, NAN),
                               Vector3f(INFINITY, 0.0f, 0.0f)}) {
        EXPECT_FALSE(dcm::field_q5_of(bad, q5)) << bad.x << " " << bad.y << " " << bad.z;
    }
}

TEST(DcmHeading, TheMeanIsInEarthAxesOverKHeadingSteps) {
    dcm::EarthFieldMean mean;
    const Vector3f a(20.0f, 1.0f, 45.0f), b(20.0f, -1.0f, 45.0f), c(21.0f, 0.0f, 44.0f);
    mean.add(earth_units(a), norm2_units(a), 3);
    mean.add(earth_units(b), norm2_units(b), kMeanSteps - 5);
    EXPECT_FALSE(mean.complete());
    EXPECT_TRUE(mean.complete_after(1));
    EXPECT_FALSE(mean.complete_after(0));
    mean.add(earth_units(c), norm2_units(c), 2);
    ASSERT_TRUE(mean.complete());
    EXPECT_EQ(mean.steps(), kMeanSteps);
    Vector3f field;
    float norm2 = 0.0f;
    mean.take(field, norm2);
    const Vector3f expected = (a + b + c) * (1.0f / 3.0f);
    EXPECT_NEAR(field.x, expected.x, 1e-4f);
    EXPECT_NEAR(field.y, expected.y, 1e-4f);
    EXPECT_NEAR(field.z, expected.z, 1e-4f);
    EXPECT_NEAR(norm2, (a.length_squared() + b.length_squared() + c.length_squared()) / 3.0f, 0.05f);
    EXPECT_EQ(mean.steps(), 0);
    // After a restart the next sample closes a mean alone, and stands for the steps a
    // whole mean would (the correction's size and the gate's time follow them); before
    // it there is nothing to take.
    mean.restart_with_one_sample();
    EXPECT_FALSE(mean.complete());
    mean.add(earth_units(a), norm2_units(a), 1);
    EXPECT_TRUE(mean.complete());
    EXPECT_EQ(mean.steps(), dcm::kHeadingSteps);
    // ... and that mean is the sample itself: the sums taken and forgotten before it
    // count for nothing.
    mean.take(field, norm2);
    EXPECT_NEAR(field.x, a.x, 1e-4f);
    EXPECT_NEAR(field.y, a.y, 1e-4f);
    EXPECT_NEAR(field.z, a.z, 1e-4f);
    EXPECT_NEAR(norm2, a.length_squared(), 0.05f);
}

// Whatever the compass's rate against the step's, the mean is the sum over the samples
// taken: one sample a step (a faster compass, or steps caught up after a stall) puts up
// to kHeadingSteps of them in a mean.
TEST(DcmHeading, TheMeanDividesByTheSamplesTaken) {
    for (uint8_t n = 1; n <= dcm::kHeadingSteps; ++n) {
        dcm::EarthFieldMean mean;
        Vector3f expected;
        for (uint8_t i = 0; i < n; ++i) {
            const Vector3f field(20.0f + (float)i, 0.5f * (float)i, 45.0f - (float)i);
            mean.add(earth_units(field), norm2_units(field), 1);
            expected += field * (1.0f / (float)n);
        }
        Vector3f field;
        float norm2 = 0.0f;
        mean.take(field, norm2);
        EXPECT_NEAR(field.x, expected.x, 1e-3f) << (int)n;
        EXPECT_NEAR(field.y, expected.y, 1e-3f) << (int)n;
        EXPECT_NEAR(field.z, expected.z, 1e-3f) << (int)n;
    }
}

TEST(DcmHeading, TheLearnedFieldPassesAndADisturbanceDoesNot) {
    Gate g;
    EXPECT_EQ(g.judge(kEarthNorm, kEarthDown), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(g.judge(kEarthNorm * 1.05f, kEarthDown + 0.05f), dcm::FieldVerdict::kEarthField);  // within 10 %
    EXPECT_EQ(g.judge(kEarthNorm * 1.2f, kEarthDown), dcm::FieldVerdict::kDisturbed);            // strength
    EXPECT_EQ(g.judge(kEarthNorm, kEarthDown - 0.2f), dcm::FieldVerdict::kDisturbed);           // dip
    EXPECT_EQ(g.judge(kEarthNorm * 0.8f, kEarthDown), dcm::FieldVerdict::kDisturbed);            // weaker
    EXPECT_EQ(g.judge(kEarthNorm, kEarthDown), dcm::FieldVerdict::kEarthField);
}

// The dip's test both ways. At 66 deg (down 0.914) no real field is steeper by the
// tolerance (0.1 of the sine): a gate learned at 30 deg (down 0.5), as nearer the equator.
TEST(DcmHeading, AFieldSteeperOrShallowerByTheDipToleranceIsADisturbance) {
    Gate g;
    g.gate.learn(kEarthNorm, 0.5f);
    EXPECT_EQ(g.judge(kEarthNorm, 0.55f), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(g.judge(kEarthNorm, 0.45f), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(g.judge(kEarthNorm, 0.65f), dcm::FieldVerdict::kDisturbed);  // steeper
    EXPECT_EQ(g.judge(kEarthNorm, 0.35f), dcm::FieldVerdict::kDisturbed);  // shallower
    EXPECT_EQ(g.judge(kEarthNorm, 0.5f), dcm::FieldVerdict::kEarthField);
}

// A different field that stays the same becomes the reference after mag_recover_s,
// but only once the board has turned as far as 20 deg/s for that time (VQF's rule): at
// rest any disturbance is steady too, and at 10 deg/s it takes twice as long.
TEST(DcmHeading, ANewSteadyFieldIsAdoptedOnlyWhileTurning) {
    const float recover_s = dcm::kDefaultDcmSettings.mag_recover_s;
    Gate at_rest;
    EXPECT_LT(at_rest.seconds_to_adopt(kEarthNorm * 1.3f, kEarthDown, 0.0f), 0.0f);
    Gate slow;
    EXPECT_NEAR(slow.seconds_to_adopt(kEarthNorm * 1.3f, kEarthDown, 10.0f * linalg::kRadPerDeg), 2.0f * recover_s, 0.2f);
    Gate turning;
    const float t = turning.seconds_to_adopt(kEarthNorm * 1.3f, kEarthDown, 30.0f * linalg::kRadPerDeg);
    EXPECT_NEAR(t, recover_s, 0.2f);
    // Now it is the reference.
    EXPECT_EQ(turning.judge(kEarthNorm * 1.3f, kEarthDown), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(turning.judge(kEarthNorm, kEarthDown), dcm::FieldVerdict::kDisturbed);
}

TEST(DcmHeading, AForgottenReferenceIsRelearned) {
    Gate g;
    g.gate.forget(true);  // a new calibration: its heading at once
    EXPECT_EQ(g.judge(kEarthNorm * 1.3f, kEarthDown), dcm::FieldVerdict::kNewField);
    EXPECT_EQ(g.judge(kEarthNorm * 1.3f, kEarthDown), dcm::FieldVerdict::kEarthField);
    g.gate.forget(false);  // a small offset change: strength and dip only
    EXPECT_EQ(g.judge(kEarthNorm, kEarthDown), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(g.judge(kEarthNorm * 1.3f, kEarthDown), dcm::FieldVerdict::kDisturbed);
}

// The steadiness count starts afresh at a field that is not steady, and a new field is
// taken after exactly mag_recover_s of it (here means of one step each, while turning).
TEST(DcmHeading, ANewFieldIsAdoptedAfterExactlyItsRecoverSteps) {
    Gate g;
    // A disturbance held long enough for the candidate to follow it (53 ms), not to be taken.
    for (int i = 0; i < 200; ++i) ASSERT_EQ(g.judge_one_step(kEarthNorm * 1.3f), dcm::FieldVerdict::kDisturbed);
    // One mean of another field breaks the steadiness (the candidate moves only a little).
    ASSERT_EQ(g.judge_one_step(kEarthNorm * 1.6f), dcm::FieldVerdict::kDisturbed);
    // The disturbance again: steady from the first mean, taken at the recover_steps'th.
    EXPECT_EQ(g.one_step_means_to_adopt(kEarthNorm * 1.3f), (int)g.k.mag_recover_steps);
}

// A field that leaves the learned one's tolerance from a sample at its edge is steady
// against that sample (the candidate) from its first mean: it counts its recover steps
// from zero as any other.
TEST(DcmHeading, AFieldLeavingFromTheEdgeCountsFromZero) {
    Gate g;
    const float tolerance = dcm::kDefaultDcmSettings.mag_norm_tolerance;
    ASSERT_EQ(g.judge_one_step(kEarthNorm * (1.0f + 0.9f * tolerance)), dcm::FieldVerdict::kEarthField);
    EXPECT_EQ(g.one_step_means_to_adopt(kEarthNorm * (1.0f + 1.1f * tolerance)), (int)g.k.mag_recover_steps);
}

// The turn that proves a new field fixed in the earth frame counts only while that field
// stays the same: a field steady for 10 s while the board turned (too short to be
// adopted), a different one for a moment, then the first again at rest is never
// adopted: the turn before the break does not count.
TEST(DcmHeading, OnlyTheTurnDuringTheSteadyFieldCounts) {
    Gate g;
    const float rate = 45.0f * linalg::kRadPerDeg;  // 10 s of it: more than mag_new_min_turn
    ASSERT_GT(rate * 10.0f, g.k.mag_new_min_turn_rad);
    for (float t = 0.0f; t < 10.0f; t += kMeanDt) ASSERT_EQ(g.judge(kEarthNorm * 1.3f, kEarthDown, rate), dcm::FieldVerdict::kDisturbed);
    g.judge(kEarthNorm * 1.6f, kEarthDown, rate);
    EXPECT_LT(g.seconds_to_adopt(kEarthNorm * 1.3f, kEarthDown, 0.0f, 60.0f), 0.0f);
}

// A start (init) counts a new field's steadiness again from zero: after the restart the
// field that was already steady is taken after exactly mag_recover_steps more means.
TEST(DcmHeading, ARestartCountsTheSteadinessFromZero) {
    Gate g;
    for (int i = 0; i < 200; ++i) ASSERT_EQ(g.judge_one_step(kEarthNorm * 1.3f), dcm::FieldVerdict::kDisturbed);
    g.gate.restart_steady_count();
    EXPECT_EQ(g.one_step_means_to_adopt(kEarthNorm * 1.3f), (int)g.k.mag_recover_steps);
}

// The learned field tracks slow changes of the local field (temperature, location) with
// 1.32 s: each mean of the earth field moves the strength and the dip by dt / 1.32 s of
// their difference.
TEST(DcmHeading, TheLearnedFieldFollowsWithItsTimeConstant) {
    Gate g;
    const float alpha = kMeanDt / 1.32f;
    const float norm = kEarthNorm * 1.05f, down = kEarthDown + 0.05f;
    ASSERT_EQ(g.judge(norm, down), dcm::FieldVerdict::kEarthField);
    EXPECT_NEAR(g.gate.ref_norm(), kEarthNorm + alpha * (norm - kEarthNorm), 1e-5f);
    EXPECT_NEAR(g.gate.ref_down(), kEarthDown + alpha * (down - kEarthDown), 1e-6f);
}
