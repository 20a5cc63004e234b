// SPDX-License-Identifier: GPL-3.0-or-later
// MagCalibrator (lib/Calibration): the compass's sphere and ellipsoid fits, their coverage
// and the fits it refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Calibration.h"
#include "calibration_test_support.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;
using namespace calib_test;

// The case: (8, -5, 3) uT of hard iron, 0.2 uT noise, 30 s at 75 Hz. The
// midpoint of the extremes gave (7.29, -5.13, 2.98); the fit must be within 0.3 uT.
TEST(MagCalibrator, MagSphereFitWithNoise) {
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

TEST(MagCalibrator, MagEllipsoidFitWithNoise) {
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
TEST(MagCalibrator, MagFitFloat32Precision) {
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

TEST(MagCalibrator, MagThinCoverageIsRefused) {
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

TEST(MagCalibrator, MagPoorOrImplausibleFitIsRefused) {
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

// The coverage is the share of the 26 direction cells seen kMagCellMinSamples times, in
// percent rounded to nearest: one cell is 4 % (3.85), three 12 (11.5), all 100.
TEST(MagCalibrator, MagCoverageIsTheShareOfCellsRounded) {
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
TEST(MagCalibrator, MagFitTakesFromExactlyItsMinimumSamples) {
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
TEST(MagCalibrator, MagCrossTermsAloneBeyondTheLimitAreRefused) {
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
TEST(MagCalibrator, MagCoverageCentreIsRefittedEachRefitSamples) {
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

// A sphere near the largest radius the Earth's field may have (90 uT: the quadric's
// terms in the fit's scale are below 1) fits as well as a small one.
TEST(MagCalibrator, MagLargeSphereFits) {
    MagCalibrator m;
    m.restart(Vector3f());
    feed_random(m, 2250, Vector3f(8.0f, -5.0f, 3.0f), Matrix3f::identity(), 90.0f, 0.2f, 31);
    calib::Calibration c = calib::default_calibration();
    ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok);
    EXPECT_NEAR(m.radius_uT(), 90.0f, 0.2f);
    EXPECT_NEAR(c.mag_offset_uT.x, 8.0f, 0.1f);
}
