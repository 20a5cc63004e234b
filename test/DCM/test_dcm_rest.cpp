// SPDX-License-Identifier: GPL-3.0-or-later
// Rest detection and the gyro bias alone (Rest.h, GyroBias.h): when the rest test
// passes and what ends a rest (each of its inputs), and how the bias estimate follows
// the rest mean, integrates the tilt error and stays bounded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "GyroBias.h"
#include "Rest.h"
#include "dcm_test_support.h"

using linalg::Vector3f;
using linalg::Vector3i;
using linalg::Vector3l;

using dcm_test::float_form_coefficients;

namespace {

Vector3l units(const dcm::DcmCoefficients& k, const Vector3f& rate_rad_s) {
    return linalg::fixed_from_vector(rate_rad_s * k.units_per_rad_s, 0);
}

constexpr float kDegPerS = linalg::kRadPerDeg;

struct RestFixture {
    dcm::DcmCoefficients k = float_form_coefficients();
    dcm::RestDetector rest;
    Vector3l gyro_mean, accel_mean;
    RestFixture() {
        gyro_mean = units(k, Vector3f(1.0f, -0.5f, 0.3f) * kDegPerS);  // a bias, read at rest
        accel_mean = linalg::fixed_from_vector(Vector3f(0.0f, 0.0f, -9.81f) * k.accel_units_per_m_s2, 0);
        rest.reset(accel_mean);
        settle();
    }
    // A board that has been still a while: the 0.5 s means there (5 s of windows that are
    // not whole, so no rest is counted). A rest's clock starts once the gyro mean stops
    // moving (ASlowTurnIsNoRest).
    void settle() {
        for (int i = 0; i < 250; ++i) rest.update(gyro_mean, accel_mean, Vector3l(), false, true, k);
    }
    // Updates until the rest test passes; the number of updates it took (or -1).
    int updates_to_rest(const Vector3l& mean_off_bias, bool compass_watching, int limit = 400) {
        for (int i = 1; i <= limit; ++i)
            if (rest.update(gyro_mean, accel_mean, mean_off_bias, true, compass_watching, k)) return i;
        return -1;
    }
};

}  // namespace

TEST(DcmRest, StillForRestMinSecondsIsRest) {
    RestFixture f;
    EXPECT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
    EXPECT_EQ(f.k.rest_min_corrections, (uint16_t)(1.5f / 0.02f));
}

// Without a compass watching, a gyro mean far from the bias estimate is a slow turn,
// not rest; with one, the field decides (watch_field).
TEST(DcmRest, WithoutACompassTheMeanMustBeNearTheBiasEstimate) {
    RestFixture f;
    const Vector3l far_from_bias = units(f.k, Vector3f(0.0f, 0.0f, 5.0f * kDegPerS));
    EXPECT_EQ(f.updates_to_rest(far_from_bias, false), -1);
    EXPECT_GT(f.updates_to_rest(far_from_bias, true), 0);
    RestFixture g;
    const Vector3l near_bias = units(g.k, Vector3f(0.0f, 0.0f, 1.0f * kDegPerS));
    EXPECT_GT(g.updates_to_rest(near_bias, false), 0);
}

TEST(DcmRest, AMovingGyroOrAccelOrAShortWindowIsNoRest) {
    RestFixture f;
    int n = 0;
    for (int i = 0; i < 300; ++i) {  // a 3 deg/s swing every other update
        const Vector3l swing = units(f.k, Vector3f((i & 1) ? 6.0f * kDegPerS : 0.0f, 0.0f, 0.0f));
        n += f.rest.update(f.gyro_mean + swing, f.accel_mean, Vector3l(), true, true, f.k);
    }
    EXPECT_EQ(n, 0);
    RestFixture g;
    const Vector3l shove = linalg::fixed_from_vector(Vector3f(2.0f, 0.0f, 0.0f) * g.k.accel_units_per_m_s2, 0);
    for (int i = 0; i < 300; ++i) n += g.rest.update(g.gyro_mean, g.accel_mean + ((i & 1) ? shove : Vector3l()), Vector3l(), true, true, g.k);
    EXPECT_EQ(n, 0);
    RestFixture h;
    for (int i = 0; i < 300; ++i) n += h.rest.update(h.gyro_mean, h.accel_mean, Vector3l(), false, true, h.k);
    EXPECT_EQ(n, 0);
}

// A slow turn whose rate changes slowly passes the deviation test and, below 2 deg/s,
// the compass's; its mean moving from where the rest began tells it: a yaw rate ramping
// through zero at 2 deg/s^2 (a pendulum's twist turning back) is never rest, while the
// same board held still is, after the 0.5 s mean has come to the bias (the fixture).
TEST(DcmRest, ASlowTurnIsNoRest) {
    RestFixture f;
    const float ramp_deg_s2 = 2.0f, window_s = 0.02f;
    int rests = 0;
    for (int i = -150; i <= 150; ++i) {  // -6 .. +6 deg/s over 6 s
        const Vector3l rate = units(f.k, Vector3f(0.0f, 0.0f, ramp_deg_s2 * window_s * (float)i * kDegPerS));
        rests += f.rest.update(f.gyro_mean + rate, f.accel_mean, Vector3l(), true, true, f.k);
    }
    EXPECT_EQ(rests, 0);
    // A gentler ramp, 0.2 deg/s^2: the mean moves 0.5 deg/s in 2.5 s, so a rest (1.5 s)
    // can begin and lasts until it has moved that far, and begins again there.
    RestFixture g;
    float most_moved_deg_s = 0.0f, start_deg_s = 0.0f;
    bool at_rest = false;
    for (int i = -750; i <= 750; ++i) {  // -3 .. +3 deg/s over 30 s
        const float rate_deg_s = 0.2f * window_s * (float)i;
        const bool rest = g.rest.update(g.gyro_mean + units(g.k, Vector3f(0.0f, 0.0f, rate_deg_s * kDegPerS)),
                                        g.accel_mean, Vector3l(), true, true, g.k);
        const float mean_deg_s = (float)(g.rest.gyro_mean().z - g.gyro_mean.z) / g.k.units_per_rad_s / kDegPerS;
        if (rest && !at_rest) start_deg_s = mean_deg_s;
        if (rest) most_moved_deg_s = std::max(most_moved_deg_s, std::fabs(mean_deg_s - start_deg_s));
        at_rest = rest;
    }
    EXPECT_LT(most_moved_deg_s, 0.5f);
    // Still: rest after rest_min_s, and it lasts.
    RestFixture h;
    EXPECT_EQ(h.updates_to_rest(Vector3l(), true), h.k.rest_min_corrections + 1);
    for (int i = 0; i < 500; ++i) ASSERT_TRUE(h.rest.update(h.gyro_mean, h.accel_mean, Vector3l(), true, true, h.k)) << i;
}

// The mean may wander during a rest, on each axis, up to kRestMeanMove_rad_s (0.5 deg/s)
// from where the rest began: 0.3 deg/s keeps the rest, 0.7 ends it. A new accelerometer
// scale (the gyro's unchanged) leaves the rest's start where it was.
TEST(DcmRest, TheMeanMayMoveHalfADegreePerSecond) {
    for (int axis = 0; axis < 3; ++axis) {
        for (bool rescale : {false, true}) {
            RestFixture f;
            ASSERT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
            Vector3f step_rad_s;
            (axis == 0 ? step_rad_s.x : axis == 1 ? step_rad_s.y : step_rad_s.z) = 0.3f * kDegPerS;
            const Vector3l first = f.gyro_mean + units(f.k, step_rad_s);
            for (int i = 0; i < 250; ++i)  // 5 s: the mean is there
                ASSERT_TRUE(f.rest.update(first, f.accel_mean, Vector3l(), true, true, f.k)) << axis << " " << i;
            if (rescale) {
                f.rest.rescale(1.0f, 2.0f);
                f.accel_mean = linalg::fixed_from_vector(f.accel_mean.scaled(2.0f), 0);
            }
            const Vector3l second = f.gyro_mean + units(f.k, step_rad_s * (0.7f / 0.3f));
            int rest_steps = 0;
            for (int i = 0; i < 250; ++i) rest_steps += f.rest.update(second, f.accel_mean, Vector3l(), true, true, f.k);
            // The mean passes 0.5 deg/s within 0.5 s; the rest would come back after 1.5 s
            // more, counted from there: 3.5 of the 5 s at most.
            EXPECT_LT(rest_steps, 180) << "axis " << axis << (rescale ? ", rescaled" : "");
            EXPECT_GT(rest_steps, 100) << "axis " << axis << (rescale ? ", rescaled" : "");
        }
    }
}

// A field that moves starts the count from zero, as any other end of a rest does.
TEST(DcmRest, AFieldMoveStartsTheCountFromZero) {
    RestFixture f;
    const Vector3i field(20 * 32, 0, 45 * 32);  // uT Q5
    f.rest.watch_field(field);
    ASSERT_GT(f.updates_to_rest(Vector3l(), true), 0);
    f.rest.watch_field(Vector3i(field.x + 48, field.y, field.z));  // 1.5 uT
    EXPECT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
}

// The gyro mean starts from the first window after reset, as the accelerometer's does:
// a board still from its start with a 3 deg/s reading is rest after rest_min_s, not
// after the mean has crept up from zero.
TEST(DcmRest, TheFirstWindowIsTheGyroMean) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::RestDetector rest;
    const Vector3l gyro = units(k, Vector3f(3.0f, 0.0f, -2.0f) * kDegPerS);
    const Vector3l accel = linalg::fixed_from_vector(Vector3f(0.0f, 0.0f, -9.81f) * k.accel_units_per_m_s2, 0);
    rest.reset(accel);
    rest.rescale(2.0f, 1.0f);  // a new scale before the first window: still unknown
    int n = 0;
    while (n < 400 && !rest.update(gyro, accel, Vector3l(), true, true, k)) ++n;
    EXPECT_EQ(n, k.rest_min_corrections + 1);
    EXPECT_NEAR((double)rest.gyro_mean().x, (double)gyro.x, 2.0);
    // Only the first: a board moving from its start (10 deg/s more on the second window,
    // no rest) moves the mean by the low-pass's factor, not to the window.
    dcm::RestDetector moving;
    moving.reset(accel);
    moving.update(gyro, accel, Vector3l(), true, true, k);
    const Vector3l faster = gyro + units(k, Vector3f(10.0f, 0.0f, 0.0f) * kDegPerS);
    EXPECT_FALSE(moving.update(faster, accel, Vector3l(), true, true, k));
    const double alpha = (double)k.rest_alpha_q14 / 16384.0;
    EXPECT_NEAR((double)moving.gyro_mean().x, (double)gyro.x + alpha * (double)(faster.x - gyro.x), 4.0);
}

// The field moving by more than 1 uT in body axes ends a rest; the HMC5883L's noise
// (0.2 uT) does not.
TEST(DcmRest, AFieldThatMovesEndsTheRest) {
    RestFixture f;
    const Vector3i field(20 * 32, 0, 45 * 32);  // uT Q5
    f.rest.watch_field(field);
    ASSERT_GT(f.updates_to_rest(Vector3l(), true), 0);
    f.rest.watch_field(Vector3i(field.x + 6, field.y - 6, field.z));  // 0.27 uT
    EXPECT_TRUE(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k));
    f.rest.watch_field(Vector3i(field.x + 48, field.y, field.z));  // 1.5 uT
    EXPECT_FALSE(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k));
    f.rest.interrupt();
    EXPECT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
}

// Every axis counts, alone or together: a 1.5 uT move along x, y or z ends a rest, and so
// does one of 0.81 uT along two axes at once (1.15 uT in all, no axis beyond 1 uT); 0.5 uT
// along two (0.71 uT) does not. (A mutant that checked only x and y lived before this.)
TEST(DcmRest, AFieldMoveOnAnyAxisOrAcrossTwoEndsTheRest) {
    // Off magnetic north: a field on every axis, so that a difference taken as a sum on
    // one of them would show.
    const Vector3i field(20 * 32, -5 * 32, 45 * 32);  // uT Q5
    struct Move {
        int16_t dx, dy, dz;
        bool ends;
    };
    const Move moves[] = {{48, 0, 0, true}, {0, 48, 0, true}, {0, 0, 48, true},
                          {26, 0, -26, true}, {0, 26, 26, true}, {16, 0, 16, false}};
    for (const Move& m : moves) {
        RestFixture f;
        f.rest.watch_field(field);
        ASSERT_GT(f.updates_to_rest(Vector3l(), true), 0);
        f.rest.watch_field(Vector3i((int16_t)(field.x + m.dx), (int16_t)(field.y + m.dy), (int16_t)(field.z + m.dz)));
        EXPECT_EQ(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k), !m.ends)
            << m.dx << " " << m.dy << " " << m.dz << " (uT x 32)";
    }
}

// A field that jumps across most of the range on every axis at once (a magnet slapped
// on, a broken read) moves: its squares summed would pass 2^31, so each axis decides.
TEST(DcmRest, AFieldJumpAcrossTheRangeEndsTheRest) {
    for (int16_t sign : {1, -1}) {
        const Vector3i from((int16_t)(-sign * 450 * 32), (int16_t)(-sign * 450 * 32), (int16_t)(-sign * 450 * 32));
        const Vector3i to((int16_t)(sign * 450 * 32), (int16_t)(sign * 450 * 32), (int16_t)(sign * 450 * 32));
        RestFixture f;
        f.rest.watch_field(from);
        ASSERT_GT(f.updates_to_rest(Vector3l(), true), 0);
        f.rest.watch_field(to);
        EXPECT_FALSE(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k)) << sign;
    }
}

TEST(DcmGyroBias, FollowsTheRestMeanWithRestBiasSeconds) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GyroBias bias;
    const Vector3f truth(0.02f, -0.01f, 0.015f);  // rad/s
    const Vector3l mean = units(k, truth);
    // One rest_bias_s (1 s) of corrections: 1 - 1/e of the way.
    const int corrections = (int)std::lround(1.0f / 0.02f);
    for (int i = 0; i < corrections; ++i) bias.follow_rest_mean(mean, k);
    const Vector3f got = bias.estimate_rad_s(k);
    EXPECT_NEAR(got.x / truth.x, 1.0f - std::exp(-1.0f), 0.01f);
    EXPECT_NEAR(got.z / truth.z, 1.0f - std::exp(-1.0f), 0.01f);
    for (int i = 0; i < 20 * corrections; ++i) bias.follow_rest_mean(mean, k);
    EXPECT_NEAR(bias.estimate_rad_s(k).y, truth.y, 1e-6f);
}

TEST(DcmGyroBias, StaysWithinTheLimitAndComposesTheOffset) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GyroBias bias;
    const float limit = dcm::kDefaultDcmSettings.bias_limit_rad_s;
    bias.set_estimate_rad_s(Vector3f(1.0f, -1.0f, 0.05f), k);
    EXPECT_NEAR(bias.estimate_rad_s(k).x, limit, 1e-5f);
    EXPECT_NEAR(bias.estimate_rad_s(k).y, -limit, 1e-5f);
    EXPECT_NEAR(bias.estimate_rad_s(k).z, 0.05f, 1e-5f);
    for (int i = 0; i < 100000; ++i) bias.integrate_tilt_error(-16384, 16384, 0, k);  // 1 rad of error
    EXPECT_NEAR(bias.estimate_rad_s(k).x, limit, 1e-5f);
    EXPECT_NEAR(bias.estimate_rad_s(k).y, -limit, 1e-5f);
    // A rest mean far beyond the limit (a broken gyro, a turn the rest test took): held too.
    for (int i = 0; i < 1000; ++i) bias.follow_rest_mean(units(k, Vector3f(-2.0f, 2.0f, 0.05f)), k);
    EXPECT_NEAR(bias.estimate_rad_s(k).x, -limit, 1e-5f);
    EXPECT_NEAR(bias.estimate_rad_s(k).y, limit, 1e-5f);
    bias.set_sensor_rad_s(Vector3f(0.01f, 0.0f, 0.0f), k);
    const Vector3l correction(5, 6, 7);
    const Vector3l offset = bias.offset_units(correction);
    EXPECT_EQ(offset.x, bias.sensor_units().x + bias.units().x - 5);
    EXPECT_EQ(offset.z, bias.units().z - 7);
    EXPECT_EQ(bias.sensor_units().x, units(k, Vector3f(0.01f, 0.0f, 0.0f)).x);
}

// Once the calibration at this start measured the bias, the estimate is the gyro's drift
// since: a quarter of the limit (2.5 deg/s), from gravity's integral and from a rest
// alike. A rest's measurement alone keeps the whole limit: the sensor's bias may then be
// the chip's whole zero-rate output.
TEST(DcmGyroBias, ACalibratedBiasStaysWithinAQuarterOfTheLimit) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    const float limit = dcm::kDefaultDcmSettings.bias_limit_rad_s;
    dcm::GyroBias calibrated;
    calibrated.set_calibrated();
    EXPECT_TRUE(calibrated.measured());
    for (int i = 0; i < 100000; ++i) calibrated.integrate_tilt_error(-16384, 16384, 0, k);  // 1 rad of error
    EXPECT_NEAR(calibrated.estimate_rad_s(k).x, 0.25f * limit, 1e-5f);
    EXPECT_NEAR(calibrated.estimate_rad_s(k).y, -0.25f * limit, 1e-5f);
    for (int i = 0; i < 1000; ++i) calibrated.follow_rest_mean(units(k, Vector3f(-2.0f, 2.0f, 0.01f)), k);
    EXPECT_NEAR(calibrated.estimate_rad_s(k).x, -0.25f * limit, 1e-5f);
    EXPECT_NEAR(calibrated.estimate_rad_s(k).z, 0.01f, 1e-5f);  // within: as measured
    dcm::GyroBias rested;
    rested.set_measured();
    EXPECT_TRUE(rested.measured());
    for (int i = 0; i < 100000; ++i) rested.integrate_tilt_error(-16384, 16384, 0, k);
    EXPECT_NEAR(rested.estimate_rad_s(k).x, limit, 1e-5f);
    EXPECT_NEAR(rested.estimate_rad_s(k).y, -limit, 1e-5f);
    // A calibration after a rest narrows it too (the pipeline's calibration finishing
    // while the estimator runs).
    rested.set_calibrated();
    rested.integrate_tilt_error(0, 0, 0, k);
    EXPECT_NEAR(rested.estimate_rad_s(k).x, 0.25f * limit, 1e-5f);
}

// The tilt error's integral: ki_rp_1_s2 * error * dt per correction, against the error.
TEST(DcmGyroBias, IntegratesTheTiltErrorAgainstIt) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GyroBias bias;
    const int16_t error_q14 = 164;  // 0.01 rad
    for (int i = 0; i < 50; ++i) bias.integrate_tilt_error(error_q14, 0, -error_q14, k);  // 1 s
    const float expected = -dcm::kDefaultDcmSettings.ki_rp_1_s2 * 0.01f * 1.0f;
    EXPECT_NEAR(bias.estimate_rad_s(k).x, expected, 0.02f * std::fabs(expected));
    EXPECT_NEAR(bias.estimate_rad_s(k).z, -expected, 0.02f * std::fabs(expected));
}

// Once the bias was measured still, the same error teaches ki_rp_measured_1_s2 instead
// (DcmSettings.h: a third as much false bias from a sustained acceleration).
TEST(DcmGyroBias, AMeasuredBiasIntegratesWithTheMeasuredGain) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GyroBias bias;
    EXPECT_FALSE(bias.measured());
    bias.set_measured();
    EXPECT_TRUE(bias.measured());
    const int16_t error_q14 = 164;  // 0.01 rad
    for (int i = 0; i < 50; ++i) bias.integrate_tilt_error(error_q14, -error_q14, 0, k);  // 1 s
    const float expected = -dcm::kDefaultDcmSettings.ki_rp_measured_1_s2 * 0.01f * 1.0f;
    EXPECT_NEAR(bias.estimate_rad_s(k).x, expected, 0.02f * std::fabs(expected));
    EXPECT_NEAR(bias.estimate_rad_s(k).y, -expected, 0.02f * std::fabs(expected));
    EXPECT_LT(dcm::kDefaultDcmSettings.ki_rp_measured_1_s2, dcm::kDefaultDcmSettings.ki_rp_1_s2);
}

// New sample scales during a rest (a new calibration): the means follow the ratios, so
// the same motion read at the new scales is still rest; with means left at the old
// scales the rest would end.
TEST(DcmRest, ANewScaleKeepsTheRest) {
    // A coarser gyro range (x2), a coarser accelerometer (x2), a finer gyro range (x0.5).
    for (int axis = 0; axis < 3; ++axis) {
        RestFixture f;
        f.gyro_mean = units(f.k, Vector3f(4.0f, -3.0f, 3.0f) * kDegPerS);  // a bias read at rest
        for (int i = 0; i < 400; ++i) f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k);
        ASSERT_TRUE(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), true, true, f.k));
        const float gyro_ratio = axis == 0 ? 2.0f : (axis == 2 ? 0.5f : 1.0f), accel_ratio = axis == 1 ? 2.0f : 1.0f;
        const Vector3l mean_before = f.rest.gyro_mean();
        f.rest.rescale(gyro_ratio, accel_ratio);
        EXPECT_NEAR(f.rest.gyro_mean().x, mean_before.x * gyro_ratio, 1) << axis;
        const Vector3l gyro = linalg::fixed_from_vector(f.gyro_mean.scaled(gyro_ratio), 0);
        const Vector3l accel = linalg::fixed_from_vector(f.accel_mean.scaled(accel_ratio), 0);
        EXPECT_TRUE(f.rest.update(gyro, accel, Vector3l(), true, true, f.k)) << axis;
    }
}

// The rest means follow every axis at the same low-pass factor: a step in the
// accelerometer's y alone moves the y mean as x's step moves x.
TEST(DcmRest, TheAccelMeanFollowsEachAxisAlike) {
    for (int axis = 0; axis < 3; ++axis) {
        RestFixture f;
        Vector3l accel = f.accel_mean;
        (axis == 0 ? accel.x : axis == 1 ? accel.y : accel.z) += 40000;  // 0.15 g: ends the rest
        for (int i = 0; i < 400; ++i) f.rest.update(f.gyro_mean, accel, Vector3l(), true, true, f.k);
        // After 400 corrections (8 s, the means' time constant is 0.5 s) the mean is there,
        // so the same sample again is still.
        EXPECT_TRUE(f.rest.update(f.gyro_mean, accel, Vector3l(), true, true, f.k)) << axis;
    }
}

// A window that is not whole (or not still) ends a rest, and the count starts again
// from zero: rest again after exactly rest_min_corrections + 1 still windows.
TEST(DcmRest, AShortWindowRestartsTheCountFromZero) {
    RestFixture f;
    ASSERT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
    EXPECT_FALSE(f.rest.update(f.gyro_mean, f.accel_mean, Vector3l(), false, true, f.k));
    EXPECT_EQ(f.updates_to_rest(Vector3l(), true), f.k.rest_min_corrections + 1);
}

// The rest mean's difference from the bias is saturated alike on both sides: a mean
// far below the estimate moves it down exactly as far as one far above moves it up
// (never a wrapped difference that moves it the wrong way).
TEST(DcmGyroBias, AFarRestMeanMovesTheBiasAlikeOnBothSides) {
    const dcm::DcmCoefficients k = float_form_coefficients();
    for (int32_t far_units : {1L << 23, 3L << 23, 1L << 26}) {
        dcm::GyroBias up, down;
        up.follow_rest_mean(Vector3l(far_units, 0, 0), k);
        down.follow_rest_mean(Vector3l(-far_units, 0, 0), k);
        EXPECT_GT(up.units().x, 0) << far_units;
        EXPECT_EQ(down.units().x, -up.units().x) << far_units;
    }
}
