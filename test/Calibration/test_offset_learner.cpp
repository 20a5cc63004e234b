// SPDX-License-Identifier: GPL-3.0-or-later
// OffsetLearner (lib/Calibration): the compass offsets learned in motion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Calibration.h"
#include "calibration_test_support.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;
using namespace calib_test;

// ---------------------------------------------------------------------------
// Hard-iron learning in motion (OffsetLearner).
namespace {

// exp([theta x]): the rotation by |theta| about theta.
Matrix3f rotation(const Vector3f& theta) {
    const float a = theta.length();
    if (a < 1e-9f) return Matrix3f::identity();
    const Matrix3f k = Matrix3f::skew(theta * (1.0f / a));
    return Matrix3f::identity() + k * sinf(a) + (k * k) * (1.0f - cosf(a));
}

struct LearnRun {
    Vector3f learned;   // the offset in use
    Vector3f estimate;  // the learner's estimate
    uint16_t updates = 0;
    uint16_t rejected = 0;
    float largest_step_uT = 0.0f;  // of the estimate
    int first_use_sample = -1;     // the compass sample at which an offset first went in use
};

// A board turning at rate_rad_s about an axis that itself wanders (body frame),
// its compass reading the (20, 0, 45) uT earth field plus `offset` plus noise at
// 75 Hz; the learner is fed that field (no learned offset removed: it works from its
// own estimate) and the gyro's turn (with 0.03 deg/s of noise); `learned` is the offset
// it puts in use.
// (reused: a learner to restart and use, else a new one; nan_turns: before every third
// sample, a garbage one whose turn is not finite, given no steps.)
LearnRun run_learner(const Vector3f& offset, float seconds, float rate_rad_s, bool z_only, float noise_uT,
                     float prior_uT = calib::kLearnPriorUncalibrated_uT, calib::OffsetLearner* reused = nullptr,
                     bool nan_turns = false, bool as_constructed = false) {
    const Vector3f earth(20.0f, 0.0f, 45.0f);
    calib::OffsetLearner own;
    calib::OffsetLearner& learner = reused ? *reused : own;
    if (!as_constructed) learner.restart(prior_uT, Vector3f());
    LearnRun run;
    Matrix3f r;
    uint32_t seed = 21;
    uint16_t since = 0;
    Vector3f turn;
    const int steps = (int)(seconds * 200.0f);
    for (int i = 0; i < steps; ++i) {
        const float t = (float)i * 0.005f;
        const Vector3f axis = z_only ? Vector3f(0.0f, 0.0f, 1.0f)
                                     : Vector3f(sinf(0.31f * t), cosf(0.23f * t), sinf(0.17f * t + 1.0f)).normalized();
        r = r * rotation(axis * (rate_rad_s * 0.005f));
        turn += axis * (rate_rad_s * 0.005f) + Vector3f(gauss(seed), gauss(seed), gauss(seed)) * (0.0005f * 0.005f);
        ++since;
        if (i % 8 == 0 || i % 8 == 3 || i % 8 == 5) {  // 75 Hz
            const Vector3f raw = r.mul_transpose(earth) + offset +
                                 Vector3f(gauss(seed), gauss(seed), gauss(seed)) * noise_uT;
            if (nan_turns && i % 24 == 3) learner.add(Vector3f(500.0f, -500.0f, 500.0f), Vector3f(NAN, 0.0f, 0.0f), 0, run.learned);
            const Vector3f before = learner.estimate_uT();
            learner.add(raw, turn, since, run.learned);
            if (run.first_use_sample < 0 && !(run.learned == Vector3f())) run.first_use_sample = i;
            turn = Vector3f();
            const float step = (learner.estimate_uT() - before).length();
            if (step > run.largest_step_uT) run.largest_step_uT = step;
            since = 0;
        }
    }
    run.updates = learner.updates();
    run.rejected = learner.rejected();
    run.estimate = learner.estimate_uT();
    return run;
}
}  // namespace

// The board: (8, -5, 3) uT of hard iron, never calibrated, tumbled at 90 deg/s.
TEST(OffsetLearner, FindsTheHardIronWhileTurning) {
    const Vector3f offset(8.0f, -5.0f, 3.0f);
    const LearnRun run = run_learner(offset, 30.0f, 1.57f, false, 0.2f);
    EXPECT_GT(run.updates, 60);
    EXPECT_NEAR(run.learned.x, offset.x, 0.3f);
    EXPECT_NEAR(run.learned.y, offset.y, 0.3f);
    EXPECT_NEAR(run.learned.z, offset.z, 0.3f);
    // Most of it within 10 s (the axis has wandered by ~60 deg): the gain starts near 1 for an
    // uncalibrated compass.
    const LearnRun early = run_learner(offset, 10.0f, 1.57f, false, 0.2f);
    EXPECT_LT((early.learned - offset).length(), 1.0f);
}

// A learner as constructed is one restarted for an uncalibrated compass with no offset in
// use: the same offsets put in use, step for step.
TEST(OffsetLearner, AsConstructedItIsRestartedForAnUncalibratedCompass) {
    for (const Vector3f offset : {Vector3f(8.0f, -5.0f, 3.0f), Vector3f(-6.0f, 4.0f, -5.0f)}) {
        const LearnRun restarted = run_learner(offset, 10.0f, 1.57f, false, 0.2f);
        const LearnRun constructed =
            run_learner(offset, 10.0f, 1.57f, false, 0.2f, calib::kLearnPriorUncalibrated_uT, nullptr, false, true);
        ASSERT_GE(restarted.first_use_sample, 0) << offset.x;
        EXPECT_EQ(constructed.first_use_sample, restarted.first_use_sample);
        EXPECT_EQ(constructed.learned.x, restarted.learned.x);
        EXPECT_EQ(constructed.learned.y, restarted.learned.y);
        EXPECT_EQ(constructed.learned.z, restarted.learned.z);
        EXPECT_EQ(constructed.updates, restarted.updates);
    }
}

TEST(OffsetLearner, StillBoardLearnsNothing) {
    const LearnRun run = run_learner(Vector3f(8.0f, -5.0f, 3.0f), 60.0f, 0.0f, false, 0.2f);
    EXPECT_EQ(run.updates, 0);
    EXPECT_TRUE(run.learned == Vector3f());
    // Turning too slowly to reach 20 deg within a pair (2 s): nothing either.
    const LearnRun slow = run_learner(Vector3f(8.0f, -5.0f, 3.0f), 60.0f, 0.15f, false, 0.2f);
    EXPECT_EQ(slow.updates, 0);
}

// Turning about z says nothing about the offset along z: only x and y are learned.
TEST(OffsetLearner, LearnsOnlyAcrossTheRotationAxis) {
    const LearnRun run = run_learner(Vector3f(8.0f, -5.0f, 3.0f), 30.0f, 1.0f, true, 0.2f);
    EXPECT_NEAR(run.learned.x, 8.0f, 0.3f);
    EXPECT_NEAR(run.learned.y, -5.0f, 0.3f);
    EXPECT_NEAR(run.learned.z, 0.0f, 0.3f);  // only the gyro noise turns about x and y
}

// A calibrated compass (prior 1 uT) with no offset left: what the noise makes it learn
// stays small.
TEST(OffsetLearner, CalibratedCompassStaysPut) {
    const LearnRun run = run_learner(Vector3f(), 60.0f, 1.57f, false, 0.2f, calib::kLearnPriorCalibrated_uT);
    EXPECT_GT(run.updates, 100);
    EXPECT_LT(run.estimate.length(), 0.15f);
    EXPECT_TRUE(run.learned == Vector3f());  // not significant: nothing put in use
}

// An offset within what the pairs' systematic error (kLearnSystematic_uT) could make is
// estimated but not put in use: the learner cannot tell it from zero, and a wrong one
// costs heading.
TEST(OffsetLearner, OffsetItCannotTellFromZeroIsNotApplied) {
    const Vector3f small(1.5f, -1.0f, 0.5f);
    const LearnRun run = run_learner(small, 60.0f, 1.57f, false, 0.2f);
    EXPECT_NEAR(run.estimate.x, small.x, 0.3f);
    EXPECT_NEAR(run.estimate.y, small.y, 0.3f);
    EXPECT_TRUE(run.learned == Vector3f());
}

// A field that changes by more than the pair noise from pair to pair (a magnet near the
// compass, its field not fixed in the body) is not a hard iron: most pairs are dropped
// and nothing is put in use, whatever the estimate did early on.
TEST(OffsetLearner, FieldNoHardIronExplainsIsNotApplied) {
    const LearnRun run = run_learner(Vector3f(8.0f, -5.0f, 3.0f), 60.0f, 1.57f, false, 8.0f);
    EXPECT_GT(run.rejected, run.updates / 5);
    EXPECT_TRUE(run.learned == Vector3f());
}

// The estimate's steps and size are bounded; an estimate at the bound is a magnet, not a
// hard iron to learn: it is not put in use.
TEST(OffsetLearner, StepsAndOffsetAreBounded) {
    const LearnRun run = run_learner(Vector3f(120.0f, 0.0f, 0.0f), 30.0f, 1.57f, false, 0.2f);
    EXPECT_LE(run.largest_step_uT, calib::kLearnMaxStep_uT * 1.7321f + 1e-4f);  // per axis
    EXPECT_NEAR(run.estimate.x, calib::kLearnMaxOffset_uT, 1e-4f);
    EXPECT_TRUE(run.learned == Vector3f());
}

// The learner as it was written first, straightforwardly: the turn composed as a 3x3
// matrix at every sample, the pair solved at once when it completes. The learner
// composes a quaternion and solves a pair in parts (the AVR's step cannot carry the
// whole solve); both must give the same estimates but for float rounding.
namespace {
struct ReferenceLearner {
    Matrix3f turn;
    Vector3f field_ref, estimate, start;
    float info[6] = {};
    float prior_info = 1.0f;
    float reject_share = 0.0f;
    uint16_t age = 0, updates = 0, rejected = 0;
    uint8_t significant_run = 0;
    bool have_ref = false;

    void restart(float prior_uT, const Vector3f& in_use) {
        have_ref = false;
        prior_info = 1.0f / (prior_uT * prior_uT);
        for (float& v : info) v = 0.0f;
        estimate = start = in_use;
        reject_share = 0.0f;
        significant_run = 0;
    }
    // exp([t x]) exactly; then the pair's update as Premerlani's eq. 11 in information form.
    bool add(const Vector3f& f2, const Vector3f& t, uint16_t steps, Vector3f& in_use) {
        age = (uint16_t)std::min<int>(age + steps, calib::kLearnMaxPairSteps);
        if (!have_ref || age >= calib::kLearnMaxPairSteps) {
            turn = Matrix3f::identity();
            field_ref = f2;
            age = 0;
            have_ref = true;
            return false;
        }
        turn = turn * rotation(t);
        const Matrix3f p = turn;
        if (0.5f * (p.a.x + p.b.y + p.c.z - 1.0f) > calib::kLearnMinCos) return false;
        turn = Matrix3f::identity();
        const Vector3f f1 = field_ref;
        field_ref = f2;
        age = 0;
        const Vector3f r = p * (f2 - estimate) - (f1 - estimate);
        const Vector3f across = p.mul_transpose(r) - r;  // H^T r
        const float fade = 1.0f - 1.0f / calib::kLearnMemoryPairs;
        const float inv_noise = 1.0f / (calib::kLearnPairNoise_uT * calib::kLearnPairNoise_uT);
        const Matrix3f hth = Matrix3f::identity() * 2.0f - p - p.transposed();
        float a[6] = {hth.a.x, hth.b.y, hth.c.z, hth.a.y, hth.a.z, hth.b.z};
        for (int e = 0; e < 6; ++e) a[e] = info[e] * fade + a[e] * inv_noise;
        const Matrix3f info_new(Vector3f(a[0] + prior_info, a[3], a[4]), Vector3f(a[3], a[1] + prior_info, a[5]),
                                Vector3f(a[4], a[5], a[2] + prior_info));
        const float det = info_new.determinant();
        if (!(det > 0.0f)) return false;
        // C = A^-1 by Cramer's rule: the cross products of A's rows are its cofactors.
        const Matrix3f cof(info_new.b.cross(info_new.c), info_new.c.cross(info_new.a), info_new.a.cross(info_new.b));
        const Matrix3f c = cof.transposed() * (1.0f / det);
        Vector3f step = c * across * inv_noise;
        const Vector3f n(p.c.y - p.b.z, p.a.z - p.c.x, p.b.x - p.a.y);  // 2 sin(theta) axis
        step -= n * (n.dot(step) / n.length_squared());
        const bool consistent = r.length_squared() - across.dot(step) <
                                calib::kLearnGate * calib::kLearnGate * calib::kLearnPairNoise_uT *
                                    calib::kLearnPairNoise_uT;
        reject_share = reject_share * fade + (consistent ? 0.0f : 1.0f / calib::kLearnMemoryPairs);
        if (!consistent) {
            ++rejected;
            return false;
        }
        const float s[3] = {step.x, step.y, step.z};
        const float var[3] = {c.a.x, c.b.y, c.c.z};
        float* o = &estimate.x;
        const float* o0 = &start.x;
        bool cut = false, at_bound = false, significant = false;
        for (int i = 0; i < 3; ++i) {
            const float lim = calib::kLearnMaxStep_uT, bound = calib::kLearnMaxOffset_uT;
            cut = cut || std::fabs(s[i]) >= lim;
            o[i] = std::min(bound, std::max(-bound, o[i] + std::min(lim, std::max(-lim, s[i]))));
            at_bound = at_bound || std::fabs(o[i]) >= bound - lim;
            const float sig = calib::kLearnSignificance, sys = calib::kLearnSystematic_uT;
            significant = significant || (o[i] - o0[i]) * (o[i] - o0[i]) > sig * sig * (var[i] + sys * sys);
        }
        if (!cut)
            for (int e = 0; e < 6; ++e) info[e] = a[e];
        ++updates;
        if (cut) return false;
        const bool following = !(in_use == start);
        significant_run = significant ? (uint8_t)std::min(significant_run + 1, 255) : 0;
        const bool hard_iron = !at_bound && reject_share <= calib::kLearnMaxRejectShare;
        const Vector3f use =
            hard_iron && (significant_run >= calib::kLearnConfirmPairs || following) ? estimate : start;
        if (use == in_use) return false;
        in_use = use;
        return true;
    }
};

struct Compared {
    float worst_estimate_uT = 0.0f;  // largest |x - x_ref| after a sample
    float worst_in_use_uT = 0.0f;
    int samples = 0, calls_over_one_part = 0;
    uint16_t updates = 0, updates_ref = 0, rejected = 0, rejected_ref = 0;
    Vector3f in_use;
};

// run_learner's board, fed to both learners; the learner's solve is run a part per call
// between samples, as the Pipeline runs it (or left to the next add(), parts_between false).
// rate_scale and steps_per_sample make the turn between samples longer (a fast spin).
Compared compare_with_reference(const Vector3f& offset, float noise_uT, float seconds, bool parts_between,
                                float rate_scale = 1.0f, int steps_per_sample = 8) {
    const Vector3f earth(20.0f, 0.0f, 45.0f);
    calib::OffsetLearner learner;
    ReferenceLearner ref;
    learner.restart(calib::kLearnPriorUncalibrated_uT, Vector3f());
    ref.restart(calib::kLearnPriorUncalibrated_uT, Vector3f());
    Compared out;
    Vector3f in_use, in_use_ref, turn;
    Matrix3f r;
    uint32_t seed = 5;
    uint16_t since = 0;
    for (int i = 0; i < (int)(seconds * 200.0f); ++i) {
        const float t = (float)i * 0.005f;
        const Vector3f axis = Vector3f(sinf(0.31f * t), cosf(0.23f * t), sinf(0.17f * t + 1.0f)).normalized();
        const float rate_rad_s = rate_scale * 1.57f * (1.0f + 0.8f * sinf(0.7f * t));  // 18..160 deg/s
        r = r * rotation(axis * (rate_rad_s * 0.005f));
        turn += axis * (rate_rad_s * 0.005f);
        ++since;
        if (i % steps_per_sample != 0) continue;  // the Pipeline's 25 Hz
        const Vector3f raw = r.mul_transpose(earth) + offset + Vector3f(gauss(seed), gauss(seed), gauss(seed)) * noise_uT;
        learner.add(raw, turn, since, in_use);
        ref.add(raw, turn, since, in_use_ref);
        if (parts_between) {
            int parts = 0;
            while (learner.solving()) {
                learner.solve_part(in_use);
                ++parts;
            }
            if (parts > 0 && parts != calib::OffsetLearner::kSolveParts) ++out.calls_over_one_part;
            out.worst_estimate_uT = std::max(out.worst_estimate_uT, (learner.estimate_uT() - ref.estimate).length());
            out.worst_in_use_uT = std::max(out.worst_in_use_uT, (in_use - in_use_ref).length());
        }
        turn = Vector3f();
        since = 0;
        ++out.samples;
    }
    while (learner.solving()) learner.solve_part(in_use);
    out.worst_estimate_uT = std::max(out.worst_estimate_uT, (learner.estimate_uT() - ref.estimate).length());
    out.worst_in_use_uT = std::max(out.worst_in_use_uT, (in_use - in_use_ref).length());
    out.updates = learner.updates();
    out.updates_ref = ref.updates;
    out.rejected = learner.rejected();
    out.rejected_ref = ref.rejected;
    out.in_use = in_use;
    return out;
}
}  // namespace

// A hard iron learned (and put in use), a magnet's field that is dropped pair after
// pair, an offset beyond the bound (steps cut short): the split learner follows the
// reference pair for pair, to float rounding (0.001 uT is 0.004 deg of a 15 uT field).
TEST(OffsetLearner, SplitSolveGivesTheReferenceEstimates) {
    struct Case {
        Vector3f offset;
        float noise_uT;
    } cases[] = {{Vector3f(8.0f, -5.0f, 3.0f), 0.2f}, {Vector3f(8.0f, -5.0f, 3.0f), 8.0f}, {Vector3f(120.0f, 0.0f, 0.0f), 0.2f}};
    for (const Case& c : cases) {
        for (bool parts_between : {true, false}) {
            const Compared k = compare_with_reference(c.offset, c.noise_uT, 60.0f, parts_between);
            SCOPED_TRACE(testing::Message() << "offset x " << c.offset.x << ", noise " << c.noise_uT << " uT, parts "
                                            << (parts_between ? "between samples" : "in add()"));
            EXPECT_GT(k.updates_ref + k.rejected_ref, 100);  // pairs completed
            EXPECT_EQ(k.updates, k.updates_ref);
            EXPECT_EQ(k.rejected, k.rejected_ref);
            EXPECT_LT(k.worst_estimate_uT, 1e-3f);
            EXPECT_LT(k.worst_in_use_uT, 1e-3f);
            EXPECT_EQ(k.calls_over_one_part, 0);  // every solve took exactly kSolveParts calls
        }
    }
    // A fast spin, 180..1 600 deg/s with a sample every 60 ms: turns of up to 1.7 rad
    // between samples (as when a sample waits for a step with room for the learner), which
    // the learner halves to the short turn its series is exact for and squares back.
    for (bool parts_between : {true, false}) {
        const Compared k = compare_with_reference(Vector3f(8.0f, -5.0f, 3.0f), 0.2f, 30.0f, parts_between, 10.0f, 12);
        EXPECT_GT(k.updates_ref, 100);
        EXPECT_EQ(k.updates, k.updates_ref);
        EXPECT_EQ(k.rejected, k.rejected_ref);
        EXPECT_LT(k.worst_estimate_uT, 1e-3f);
        EXPECT_LT(k.worst_in_use_uT, 1e-3f);
    }
    // The first case puts the hard iron in use, the third never (at the bound).
    EXPECT_NEAR(compare_with_reference(Vector3f(8.0f, -5.0f, 3.0f), 0.2f, 60.0f, true).in_use.x, 8.0f, 0.3f);
    EXPECT_TRUE(compare_with_reference(Vector3f(120.0f, 0.0f, 0.0f), 0.2f, 60.0f, true).in_use == Vector3f());
}

// A restart forgets what was learned (the information, the estimate, the pair): a learner
// that learned one board and is restarted learns the next exactly as a new one does.
TEST(OffsetLearner, ARestartForgetsWhatWasLearned) {
    calib::OffsetLearner used;
    const LearnRun first = run_learner(Vector3f(30.0f, -20.0f, 10.0f), 20.0f, 1.57f, false, 0.2f,
                                       calib::kLearnPriorUncalibrated_uT, &used);
    ASSERT_GT(first.updates, 20);
    const Vector3f offset(8.0f, -5.0f, 3.0f);
    const LearnRun again = run_learner(offset, 10.0f, 1.57f, false, 0.2f, calib::kLearnPriorUncalibrated_uT, &used);
    const LearnRun fresh = run_learner(offset, 10.0f, 1.57f, false, 0.2f);
    EXPECT_TRUE(again.estimate == fresh.estimate);
    EXPECT_TRUE(again.learned == fresh.learned);
    EXPECT_NEAR(again.learned.x, offset.x, 1.0f);
}

// A sample whose turn is not finite (a broken gyro read) is not used: given between the
// samples, it changes nothing the learner does.
TEST(OffsetLearner, ASampleWithANonFiniteTurnIsNotUsed) {
    const Vector3f offset(8.0f, -5.0f, 3.0f);
    const float prior = calib::kLearnPriorUncalibrated_uT;
    const LearnRun plain = run_learner(offset, 20.0f, 1.57f, false, 0.2f, prior);
    const LearnRun interrupted = run_learner(offset, 20.0f, 1.57f, false, 0.2f, prior, nullptr, true);
    ASSERT_GT(plain.updates, 20);
    EXPECT_TRUE(interrupted.estimate == plain.estimate);
    EXPECT_TRUE(interrupted.learned == plain.learned);
    EXPECT_EQ(interrupted.updates, plain.updates);
}
