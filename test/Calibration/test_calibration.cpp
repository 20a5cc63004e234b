// SPDX-License-Identifier: GPL-3.0-or-later
// Gyro-bias and magnetometer calibration (lib/Calibration).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Calibration.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;

namespace {
const Vector3f kLevel(0.0f, 0.0f, -9.80665f);
const Vector3f kBias(0.02f, -0.01f, 0.005f);

// Small deterministic noise in [-a, a].
float noise(uint32_t& s, float a) {
    s = s * 1664525u + 1013904223u;
    return a * ((float)(s >> 8) / 8388608.0f - 1.0f);
}
}  // namespace

TEST(Calibration, ApplyInOnePlace) {
    calib::Calibration c = calib::default_calibration();
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == kBias);
    c.gyro_bias_rad_s = kBias;
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == Vector3f());
    c.mag_offset_uT = Vector3f(10.0f, 0.0f, -5.0f);
    c.mag_scale = Vector3f(2.0f, 1.0f, 0.5f);
    EXPECT_TRUE(calib::apply_mag(c, Vector3f(11.0f, 3.0f, -1.0f)) == Vector3f(2.0f, 3.0f, 2.0f));
    // Cross terms: W is symmetric, rows (sx xy xz) (xy sy yz) (xz yz sz); then the
    // learned offset is subtracted.
    c.mag_cross = Vector3f(0.25f, 0.5f, -0.25f);
    c.mag_learned_uT = Vector3f(1.0f, -1.0f, 0.5f);
    EXPECT_TRUE(calib::apply_mag(c, Vector3f(11.0f, 3.0f, -1.0f)) ==
                Vector3f(2.0f + 0.75f + 2.0f - 1.0f, 0.25f + 3.0f - 1.0f + 1.0f, 0.5f - 0.75f + 2.0f - 0.5f));
    EXPECT_TRUE(calib::is_plausible(c));
    c.mag_scale.x = 5.0f;
    EXPECT_FALSE(calib::is_plausible(c));
    c.mag_scale.x = 1.0f;
    c.mag_cross.y = 0.7f;
    EXPECT_FALSE(calib::is_plausible(c));
    c.mag_cross.y = 0.0f;
    c.mag_learned_uT.z = std::nanf("");
    EXPECT_FALSE(calib::is_plausible(c));
}

TEST(Calibration, GyroBiasAtRestTakesOneSecond) {
    GyroCalibrator g;
    uint32_t s = 1;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    int n = 0;
    while (r != GyroCalibrator::Result::Done && n < 1000) {
        const Vector3f gyro = kBias + Vector3f(noise(s, 0.004f), noise(s, 0.004f), noise(s, 0.004f));
        const Vector3f acc = kLevel + Vector3f(noise(s, 0.05f), noise(s, 0.05f), noise(s, 0.05f));
        r = g.add(gyro, acc);
        ASSERT_NE(r, GyroCalibrator::Result::Moved);
        ++n;
    }
    EXPECT_EQ(n, calib::kGyroWindow);
    EXPECT_NEAR(g.bias().x, kBias.x, 0.001f);
    EXPECT_NEAR(g.bias().y, kBias.y, 0.001f);
    EXPECT_NEAR(g.bias().z, kBias.z, 0.001f);
    EXPECT_NEAR(g.mean_accel_m_s2().z, -9.80665f, 0.02f);
    EXPECT_EQ(g.restarts(), 0);
}

TEST(Calibration, GyroRestartsWhenTheBoardMoves) {
    GyroCalibrator g;
    for (int i = 0; i < 100; ++i) ASSERT_EQ(g.add(kBias, kLevel), GyroCalibrator::Result::Collecting);
    // A 10 deg/s twitch.
    EXPECT_EQ(g.add(kBias + Vector3f(0.0f, 0.0f, 0.17f), kLevel), GyroCalibrator::Result::Moved);
    EXPECT_EQ(g.restarts(), 1);
    EXPECT_EQ(g.count(), 0);
    // Then a full still second completes.
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(kBias, kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Done);
}

TEST(Calibration, GyroRestartsOnAccelChange) {
    GyroCalibrator g;
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Shaken: |a| 1.3 g.
    EXPECT_EQ(g.add(kBias, kLevel * 1.3f), GyroCalibrator::Result::Moved);
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Slowly tilting: |a| stays 1 g but an axis moves by 0.5 m/s^2.
    EXPECT_EQ(g.add(kBias, Vector3f(0.5f, 0.0f, -9.79f)), GyroCalibrator::Result::Moved);
    // NaN counts as movement, never as data.
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    EXPECT_EQ(g.add(Vector3f(std::nanf(""), 0.0f, 0.0f), kLevel), GyroCalibrator::Result::Moved);
    // So is a reading beyond the fine counts' range (16 m/s^2), held at the range's end,
    // even one whose counts would wrap round to the level board's: 32 m/s^2 above it.
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    EXPECT_EQ(g.add(kBias, Vector3f(kLevel.x, kLevel.y, kLevel.z + 32.0f)), GyroCalibrator::Result::Moved);
}

TEST(Calibration, SteadySpinIsNotABias) {
    GyroCalibrator g;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(Vector3f(0.0f, 0.0f, 1.0f), kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Moved);
    EXPECT_FALSE(g.done());
}

namespace {
using linalg::Matrix3f;

// Gaussian noise from a fixed seed (Box-Muller on the LCG above).
float gauss(uint32_t& s) {
    const float u1 = 0.5f * (noise(s, 1.0f) + 1.0f) + 1e-7f, u2 = 0.5f * (noise(s, 1.0f) + 1.0f);
    return sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
}

// A uniformly random direction.
Vector3f random_direction(uint32_t& s) {
    for (;;) {
        const Vector3f v(noise(s, 1.0f), noise(s, 1.0f), noise(s, 1.0f));
        const float n2 = v.length_squared();
        if (n2 > 0.01f && n2 <= 1.0f) return v * (1.0f / sqrtf(n2));
    }
}

// A compass with hard iron `offset` and a symmetric soft-iron distortion `s` (raw =
// s b + offset) turned through `n` random orientations of a `b_uT` field, noise_uT rms.
void feed_random(MagCalibrator& m, int n, const Vector3f& offset, const Matrix3f& s, float b_uT, float noise_uT,
                 uint32_t seed = 1) {
    for (int i = 0; i < n; ++i) {
        const Vector3f b = random_direction(seed) * b_uT;
        m.add(s * b + offset + Vector3f(gauss(seed), gauss(seed), gauss(seed)) * noise_uT);
    }
}

const Matrix3f kSoftIron(Vector3f(1.03f, 0.02f, -0.015f), Vector3f(0.02f, 0.98f, 0.01f),
                         Vector3f(-0.015f, 0.01f, 1.0f));

// W s must be a multiple of I: the calibrated field is a scaled copy of the true one,
// neither stretched nor turned.
void expect_undistorted(const calib::Calibration& c, const Matrix3f& s, float tol) {
    const Matrix3f w(Vector3f(c.mag_scale.x, c.mag_cross.x, c.mag_cross.y),
                     Vector3f(c.mag_cross.x, c.mag_scale.y, c.mag_cross.z),
                     Vector3f(c.mag_cross.y, c.mag_cross.z, c.mag_scale.z));
    const Matrix3f ws = w * s;
    const float k = (ws.a.x + ws.b.y + ws.c.z) / 3.0f;
    const Matrix3f e = ws * (1.0f / k) - Matrix3f::identity();
    for (const Vector3f& row : {e.a, e.b, e.c}) {
        EXPECT_NEAR(row.x, 0.0f, tol);
        EXPECT_NEAR(row.y, 0.0f, tol);
        EXPECT_NEAR(row.z, 0.0f, tol);
    }
}
}  // namespace

// The case: (8, -5, 3) uT of hard iron, 0.2 uT noise, 30 s at 75 Hz. The
// midpoint of the extremes gave (7.29, -5.13, 2.98); the fit must be within 0.3 uT.
TEST(Calibration, MagSphereFitWithNoise) {
    MagCalibrator m;
    m.restart(Vector3f());
    const Vector3f offset(8.0f, -5.0f, 3.0f);
    feed_random(m, 2250, offset, Matrix3f::identity(), 49.2f, 0.2f);
    calib::Calibration c = calib::default_calibration();
    c.gyro_bias_rad_s = kBias;
    c.mag_learned_uT = Vector3f(1.0f, 2.0f, 3.0f);
    ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok);
    EXPECT_NEAR(c.mag_offset_uT.x, 8.0f, 0.05f);
    EXPECT_NEAR(c.mag_offset_uT.y, -5.0f, 0.05f);
    EXPECT_NEAR(c.mag_offset_uT.z, 3.0f, 0.05f);
    EXPECT_NEAR(m.sphere_offset_uT().x, 8.0f, 0.05f);
    expect_undistorted(c, Matrix3f::identity(), 0.003f);
    EXPECT_NEAR(m.radius_uT(), 49.2f, 0.1f);
    // The residual is the noise seen along the radius: 0.2 uT.
    EXPECT_NEAR(m.residual_uT(), 0.2f, 0.03f);
    EXPECT_NEAR(m.sphere_residual_uT(), 0.2f, 0.03f);
    EXPECT_EQ(m.coverage_pct(), 100);
    EXPECT_TRUE(c.gyro_bias_rad_s == kBias);       // untouched
    EXPECT_TRUE(c.mag_learned_uT == Vector3f());  // the fit replaces what was learned
}

TEST(Calibration, MagEllipsoidFitWithNoise) {
    MagCalibrator m;
    m.restart(Vector3f(10.0f, -10.0f, 30.0f));  // a pivot 10 uT from the centre
    const Vector3f offset(20.0f, -15.0f, 40.0f);
    feed_random(m, 2250, offset, kSoftIron, 49.2f, 0.2f, 7);
    calib::Calibration c = calib::default_calibration();
    ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok) << m.residual_uT();
    EXPECT_NEAR(c.mag_offset_uT.x, 20.0f, 0.05f);
    EXPECT_NEAR(c.mag_offset_uT.y, -15.0f, 0.05f);
    EXPECT_NEAR(c.mag_offset_uT.z, 40.0f, 0.05f);
    expect_undistorted(c, kSoftIron, 0.003f);
    EXPECT_NEAR(m.residual_uT(), 0.2f, 0.03f);
    // The sphere alone cannot follow the soft iron: its residual is larger.
    EXPECT_GT(m.sphere_residual_uT(), 2.0f * m.residual_uT());
    // Every calibrated sample has the same strength.
    for (const Vector3f& b : {Vector3f(49.2f, 0.0f, 0.0f), Vector3f(0.0f, -49.2f, 0.0f), Vector3f(0.0f, 28.4f, 40.2f)}) {
        const Vector3f f = calib::apply_mag(c, kSoftIron * b + offset);
        EXPECT_NEAR(f.length(), m.radius_uT(), 0.05f);
        EXPECT_NEAR(f.dot(b) / (f.length() * b.length()), 1.0f, 1e-5f);  // not turned
    }
}

// The sums are float32 (AVR's double is 32-bit): centred on the pivot and scaled,
// they keep the fit exact to a few hundredths of a uT even with the pivot 80 uT from
// the centre and 60 000 samples (over 13 minutes at 75 Hz).
TEST(Calibration, MagFitFloat32Precision) {
    for (const int n : {2250, 60000}) {
        MagCalibrator m;
        m.restart(Vector3f());
        const Vector3f offset(60.0f, -40.0f, 35.0f);
        feed_random(m, n, offset, kSoftIron, 49.2f, 0.0f, 3);
        calib::Calibration c = calib::default_calibration();
        ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok) << n;
        EXPECT_NEAR(c.mag_offset_uT.x, 60.0f, 0.03f) << n;
        EXPECT_NEAR(c.mag_offset_uT.y, -40.0f, 0.03f) << n;
        EXPECT_NEAR(c.mag_offset_uT.z, 35.0f, 0.03f) << n;
        expect_undistorted(c, kSoftIron, 0.002f);
        EXPECT_LT(m.residual_uT(), 0.15f) << n;  // a far pivot costs the residual (a difference of sums) ~0.1 uT
    }
}

TEST(Calibration, MagThinCoverageIsRefused) {
    calib::Calibration c = calib::default_calibration();
    const calib::Calibration before = c;
    MagCalibrator m;
    m.restart(Vector3f());
    for (int i = 0; i < 10; ++i) m.add(Vector3f((float)i, 0.0f, 0.0f));
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::TooFewSamples);

    // Only turned about z (level, yawing): a ring of directions.
    m.restart(Vector3f());
    for (int i = 0; i < 2250; ++i) {
        const float a = (float)i * 0.01f;
        m.add(Vector3f(20.0f * cosf(a), 20.0f * sinf(a), 45.0f));
    }
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::ThinCoverage);
    EXPECT_LT(m.coverage_pct(), 50);

    // Only the upper half of the sphere.
    m.restart(Vector3f());
    uint32_t seed = 5;
    for (int i = 0; i < 2250; ++i) {
        Vector3f b = random_direction(seed) * 49.2f;
        if (b.z < 0.0f) b.z = -b.z;
        m.add(b);
    }
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::ThinCoverage);
    EXPECT_LT(m.coverage_pct(), calib::kMagMinCoveragePct);

    EXPECT_TRUE(c.mag_offset_uT == before.mag_offset_uT);
    EXPECT_TRUE(c.mag_scale == before.mag_scale);

    // Non-finite samples are ignored.
    m.restart(Vector3f());
    m.add(Vector3f(std::nanf(""), 0.0f, 0.0f));
    EXPECT_EQ(m.count(), 0);
}

TEST(Calibration, MagPoorOrImplausibleFitIsRefused) {
    calib::Calibration c = calib::default_calibration();
    const calib::Calibration before = c;
    MagCalibrator m;
    // A magnet moved half way through: two spheres 6 uT apart.
    m.restart(Vector3f());
    feed_random(m, 1100, Vector3f(8.0f, -5.0f, 3.0f), Matrix3f::identity(), 49.2f, 0.2f, 11);
    feed_random(m, 1100, Vector3f(14.0f, -5.0f, 3.0f), Matrix3f::identity(), 49.2f, 0.2f, 12);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::PoorFit);
    EXPECT_GT(m.residual_uT(), calib::kMagMaxResidual_uT);

    // Noise of 3 uT: a compass next to a motor.
    m.restart(Vector3f());
    feed_random(m, 2250, Vector3f(), Matrix3f::identity(), 49.2f, 3.0f, 13);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::PoorFit);

    // Not the Earth's field: 110 uT.
    m.restart(Vector3f());
    feed_random(m, 2250, Vector3f(), Matrix3f::identity(), 110.0f, 0.2f, 14);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::NotEarthField);

    // Soft iron far beyond ArduPilot's limits: one axis 1.5 times the others.
    m.restart(Vector3f());
    feed_random(m, 2250, Vector3f(), Matrix3f(Vector3f(1.5f, 0.0f, 0.0f), Vector3f(0.0f, 1.0f, 0.0f),
                                               Vector3f(0.0f, 0.0f, 1.0f)), 40.0f, 0.2f, 15);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::SoftIronTooLarge);

    EXPECT_TRUE(c.mag_offset_uT == before.mag_offset_uT);
    EXPECT_TRUE(c.mag_scale == before.mag_scale);
    EXPECT_TRUE(c.mag_cross == before.mag_cross);
}

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

// The coverage is the share of the 26 direction cells seen kMagCellMinSamples times, in
// percent rounded to nearest: one cell is 4 % (3.85), three 12 (11.5), all 100.
TEST(Calibration, MagCoverageIsTheShareOfCellsRounded) {
    MagCalibrator m;
    m.restart(Vector3f());
    int seen = 0;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z) {
                if (x == 0 && y == 0 && z == 0) continue;
                const Vector3f direction = Vector3f((float)x, (float)y, (float)z);
                for (int i = 0; i < calib::kMagCellMinSamples; ++i) m.add(direction * (50.0f / direction.length()));
                ++seen;
                EXPECT_EQ(m.coverage_pct(), (int)std::lround(seen * 100.0 / 26.0)) << seen << " cells";
            }
    EXPECT_EQ(seen, 26);
}

// A fit takes kMagCalMinSamples samples: one fewer is too few, that many enough.
TEST(Calibration, MagFitTakesFromExactlyItsMinimumSamples) {
    for (int n : {calib::kMagCalMinSamples - 1, (int)calib::kMagCalMinSamples}) {
        MagCalibrator m;
        m.restart(Vector3f());
        feed_random(m, n, Vector3f(8.0f, -5.0f, 3.0f), Matrix3f::identity(), 49.2f, 0.2f);
        calib::Calibration c = calib::default_calibration();
        EXPECT_EQ(m.finish(c), n < calib::kMagCalMinSamples ? MagCalibrator::Quality::TooFewSamples
                                                            : MagCalibrator::Quality::Ok)
            << n;
    }
}

// Soft iron whose cross terms alone are beyond kMagMaxCross (0.3 between x and y: the
// diagonal stays within kMagMinDiag..kMagMaxDiag) is refused too.
TEST(Calibration, MagCrossTermsAloneBeyondTheLimitAreRefused) {
    MagCalibrator m;
    m.restart(Vector3f());
    const Matrix3f s(Vector3f(1.0f, 0.3f, 0.0f), Vector3f(0.3f, 1.0f, 0.0f), Vector3f(0.0f, 0.0f, 1.0f));
    feed_random(m, 2250, Vector3f(), s, 40.0f, 0.2f, 16);
    calib::Calibration c = calib::default_calibration();
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::SoftIronTooLarge);
    // What decided: the cross terms, not the diagonal.
    c = calib::default_calibration();
    m.result(c);
    EXPECT_GT(std::fabs(c.mag_cross.x), calib::kMagMaxCross);
    for (float diag : {c.mag_scale.x, c.mag_scale.y, c.mag_scale.z}) {
        EXPECT_GT(diag, calib::kMagMinDiag);
        EXPECT_LT(diag, calib::kMagMaxDiag);
    }
}

// The coverage cells' centre is the sphere fit of the samples so far, refitted at every
// kCoverageRefitSamples'th sample: after a second sphere's samples follow the first's,
// it stays at the first's centre until the next multiple, then moves towards the second.
TEST(Calibration, MagCoverageCentreIsRefittedEachRefitSamples) {
    const int n = calib::kCoverageRefitSamples;
    const Vector3f first(8.0f, -5.0f, 3.0f), second(28.0f, -5.0f, 3.0f);
    MagCalibrator m;
    m.restart(Vector3f());
    feed_random(m, n, first, Matrix3f::identity(), 49.2f, 0.0f, 21);
    EXPECT_NEAR(m.sphere_offset_uT().x, first.x, 0.01f);
    feed_random(m, n - 1, second, Matrix3f::identity(), 49.2f, 0.0f, 22);
    EXPECT_NEAR(m.sphere_offset_uT().x, first.x, 0.01f);
    feed_random(m, 1, second, Matrix3f::identity(), 49.2f, 0.0f, 23);
    EXPECT_GT(m.sphere_offset_uT().x, first.x + 5.0f);
    EXPECT_LT(m.sphere_offset_uT().x, second.x - 5.0f);
}

// A gyro or accel axis may spread by exactly its limit in counts (the limit over the
// scale, truncated) and the window is still; one count more and the board moved.
TEST(Calibration, GyroSpreadUpToItsLimitExactlyIsStill) {
    const float gyro_scale = 0.001f, accel_scale = 0.005f;  // rad/s and m/s^2 per count
    const int16_t gyro_limit = (int16_t)(calib::kGyroSpreadMax_rad_s / gyro_scale);
    const int16_t accel_limit = (int16_t)(calib::kAccelSpreadMax_m_s2 / accel_scale);
    const int16_t g_counts = (int16_t)std::lround(9.80665f / accel_scale);
    for (int axis = 0; axis < 6; ++axis) {
        for (int16_t beyond : {0, 1}) {
            const int16_t step = (int16_t)((axis < 3 ? gyro_limit : accel_limit) + beyond);
            GyroCalibrator cal;
            GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
            for (int i = 0; i < calib::kGyroWindow && r == GyroCalibrator::Result::Collecting; ++i) {
                int16_t v[6] = {0, 0, 0, 0, 0, g_counts};
                if (i & 1) v[axis] = (int16_t)(v[axis] + step);
                r = cal.add(linalg::Vector3i(v[0], v[1], v[2]), linalg::Vector3i(v[3], v[4], v[5]), gyro_scale, accel_scale);
            }
            EXPECT_EQ(r, beyond ? GyroCalibrator::Result::Moved : GyroCalibrator::Result::Done) << axis << " " << beyond;
        }
    }
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

// A sphere near the largest radius the Earth's field may have (90 uT: the quadric's
// terms in the fit's scale are below 1) fits as well as a small one.
TEST(Calibration, MagLargeSphereFits) {
    MagCalibrator m;
    m.restart(Vector3f());
    feed_random(m, 2250, Vector3f(8.0f, -5.0f, 3.0f), Matrix3f::identity(), 90.0f, 0.2f, 31);
    calib::Calibration c = calib::default_calibration();
    ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok);
    EXPECT_NEAR(m.radius_uT(), 90.0f, 0.2f);
    EXPECT_NEAR(c.mag_offset_uT.x, 8.0f, 0.1f);
}
