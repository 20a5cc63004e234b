// SPDX-License-Identifier: GPL-3.0-or-later
// The estimator's exact promises, each checked to the unit against its definition (a
// double or a 64-bit reference, or the formula the code states): limits, clamps,
// roundings and which series runs where. Each is what a mutant of `make mutate`
// (issue 25) changed while every other test passed.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>

#include "Centripetal.h"
#include "Gravity.h"
#include "Strapdown.h"
#include "dcm_test_support.h"

using namespace dcm_test;
using linalg::Vector3l;

namespace {

// c0 - a2 (c1 - a2 (c2 - ...)) in Q30 (Horner, innermost first): the series of
// sin(a)/a or (1 - cos a)/a^2 in a^2 to as many terms as there are coefficients.
int32_t alternating_series_q30(int32_t a2_q30, std::initializer_list<int32_t> coefficients_q30) {
    int32_t sum = 0;
    bool innermost = true;
    for (auto c = coefficients_q30.end(); c != coefficients_q30.begin();) {
        --c;
        sum = innermost ? *c : *c - linalg::mul_q30(a2_q30, sum);
        innermost = false;
    }
    return sum;
}

}  // namespace

// A gyro count so fine that kMaxTurnAxisQ26 is more than 2e9 units: the turn's unit
// limit is held at 2e9 (a float beyond int32_t would not convert), and any turn sum
// beyond it is taken as 2e9 units.
TEST(DcmExact, TheTurnsUnitLimitIsHeldAt2e9) {
    const dcm::DcmSettings& settings = dcm::kDefaultDcmSettings;
    // Q26 radians per unit for a limit of 2.1e9 units (within int32_t, beyond 2e9).
    const double q26_per_unit = (double)dcm::kMaxTurnAxisQ26 / 2.1e9;
    const float gyro_rad_s_per_count = (float)(q26_per_unit / 67108864.0 * dcm::kTurnScale / settings.step_s);
    dcm::DcmCoefficients k;
    k.from_settings(settings);
    k.set_scales(settings, gyro_rad_s_per_count, dcm::kFloatAccelScale);
    ASSERT_NE(k.theta_factor_q30, 0) << "the integer path";
    const double limit_units = (double)dcm::kMaxTurnAxisQ26 / ((double)k.turn_rad_per_unit() * 67108864.0);
    ASSERT_GT(limit_units, 2.05e9);
    ASSERT_LT(limit_units, 2.14e9);
    EXPECT_EQ(k.theta_units_limit, 2000000000L);
    EXPECT_EQ(k.theta_axis_q26(2100000000L), linalg::mul_q30(k.theta_factor_q30, 2000000000L));
    EXPECT_EQ(k.theta_axis_q26(-2100000000L), linalg::mul_q30(k.theta_factor_q30, -2000000000L));
}

// The integration's factors sin(a)/a and (1 - cos a)/a^2 come from their series to a^2
// below a^2 = 2^-10 (a = 1/32 rad) and to a^6 / a^4 from there on, to the bit. A turn
// about x from R = I shows both: row b becomes (0, 1 - a^2 (1 - cos a)/a^2, -a sin(a)/a).
TEST(DcmExact, TheShortSeriesRunsBelowASquaredOf2ToTheMinus10) {
    using linalg::q30_ratio;
    const dcm::DcmCoefficients k = float_form_coefficients();
    ASSERT_NE(k.theta_factor_q30, 0) << "the integer path";
    const int32_t threshold_a2 = q30_ratio(1, 1024);
    const int32_t middle_units = (int32_t)std::lround(1.0 / 32.0 / (double)k.turn_rad_per_unit());
    int told_apart_below = 0, told_apart_above = 0;
    for (int32_t units = middle_units - middle_units / 32; units < middle_units + middle_units / 32; units += 997) {
        dcm::Strapdown s;
        s.reset(linalg::q30_from_matrix(Matrix3f::identity()));
        ASSERT_EQ(s.r().b.y, linalg::kOneQ30);
        s.add_turn(Vector3l(units, 0, 0));
        for (int step = 0; step < dcm::kIntegrationSteps; ++step) s.end_step();
        s.integrate(k);
        const int32_t a_q30 = k.theta_q30(Vector3l(units, 0, 0)).x;
        const int32_t a2 = linalg::dot_q30(Vector3l(a_q30, 0, 0), Vector3l(a_q30, 0, 0));
        const bool small = a2 < threshold_a2;
        const int32_t sin_short = alternating_series_q30(a2, {linalg::kOneQ30, q30_ratio(1, 6)});
        const int32_t sin_long = alternating_series_q30(a2, {linalg::kOneQ30, q30_ratio(1, 6), q30_ratio(1, 120),
                                                            q30_ratio(1, 5040)});
        const int32_t versine_short = alternating_series_q30(a2, {q30_ratio(1, 2), q30_ratio(1, 24)});
        const int32_t versine_long = alternating_series_q30(a2, {q30_ratio(1, 2), q30_ratio(1, 24), q30_ratio(1, 720)});
        const int32_t b_y_short = linalg::kOneQ30 - linalg::mul_q30(a2, versine_short);
        const int32_t b_y_long = linalg::kOneQ30 - linalg::mul_q30(a2, versine_long);
        const int32_t b_z_short = -linalg::mul_q30(sin_short, a_q30), b_z_long = -linalg::mul_q30(sin_long, a_q30);
        EXPECT_EQ(s.r().b.x, 0) << units;
        EXPECT_EQ(s.r().b.y, small ? b_y_short : b_y_long) << units;
        EXPECT_EQ(s.r().b.z, small ? b_z_short : b_z_long) << units;
        if (b_y_short != b_y_long || b_z_short != b_z_long) ++(small ? told_apart_below : told_apart_above);
    }
    // Turns on both sides where the two series differ in R's bits: the test tells them.
    EXPECT_GT(told_apart_below, 0);
    EXPECT_GT(told_apart_above, 0);
}

// The output's carry of a turn within 2^-10 rad an axis (|theta| < 65534 Q26) is to
// Q25: from R = I, the angle it gives is the exact atan within 3/4 of a Q24 unit (a
// quarter for the turn's rounding, a half for the angle's), up to the limit on each
// side (the coarse Q17 form there would be a unit off).
TEST(DcmExact, AFineTurnIsCarriedToQ25UpToItsLimit) {
    const linalg::Matrix3q30 r = linalg::q30_from_matrix(Matrix3f::identity());
    for (int32_t t = 65000; t <= 65533; ++t) {
        for (int32_t sign : {1, -1}) {
            const int32_t theta_q26 = sign * t;
            const double exact_q24 = std::atan(theta_q26 / 67108864.0) * 16777216.0;
            EXPECT_LT(std::fabs(dcm::euler_carried_q24(r, theta_q26, 0, 0).roll_q24 - exact_q24), 0.76) << theta_q26;
            EXPECT_LT(std::fabs(dcm::euler_carried_q24(r, 0, theta_q26, 0).pitch_q24 - exact_q24), 0.76) << theta_q26;
            EXPECT_LT(std::fabs(dcm::euler_carried_q24(r, 0, 0, theta_q26).yaw_q24 - exact_q24), 0.76) << theta_q26;
        }
    }
}

// At the gimbal lock (pitch +-90 deg) the carried yaw comes from R12 and R22: a turn
// about the body's x axis, vertical there, is all heading, and the carry gives the yaw of
// R (I + [theta x]) to first order, as it does away from the lock.
TEST(DcmExact, ATurnIsCarriedAtTheGimbalLockToo) {
    for (const float pitch_deg : {90.0f, -90.0f}) {
        for (const float yaw_deg : {30.0f, -120.0f}) {
            const Matrix3f r = dcm::dcm_from_euler(0.0f, pitch_deg * linalg::kRadPerDeg, yaw_deg * linalg::kRadPerDeg);
            for (const float turn_rad : {0.01f, -0.02f}) {
                const int32_t theta_q26 = (int32_t)std::lround(turn_rad * 67108864.0f);
                const Matrix3f turned = r * dcm::dcm_from_euler(turn_rad, 0.0f, 0.0f);
                const float expected_yaw = dcm::euler_from_dcm(turned).yaw_rad;
                const dcm::EulerQ24 e = dcm::euler_carried_q24(r, theta_q26, 0, 0);
                const float yaw = (float)e.yaw_q24 / 16777216.0f;
                EXPECT_NEAR(wrap_deg((yaw - expected_yaw) * linalg::kDegPerRad), 0.0f, 0.01f)
                    << pitch_deg << " " << yaw_deg << " " << turn_rad;
            }
        }
    }
}

namespace {

// One gravity window of `n` samples (counts) through low_pass_window, the low-pass set to
// take the window's mean as it is (alpha = 1): the means it gives, its low-pass after.
struct OneWindow {
    dcm::DcmCoefficients k = float_form_coefficients();
    dcm::GravityCorrection gravity;
    Vector3l gyro_mean, accel_mean;
    bool whole = false;
    OneWindow() {
        k.accel_alpha_q30 = linalg::kOneQ30;
        gravity.reset(-4096 * 256);
    }
    void run(const linalg::Matrix3q30& r, const Vector3l& gyro_counts, const Vector3l& accel_counts, uint8_t n,
             const Vector3l& sensor_bias_units = Vector3l(), bool starting = false, float startup_left = 0.0f) {
        for (uint8_t i = 0; i < n; ++i) gravity.add(gyro_counts, accel_counts);
        const Vector3l offset = Vector3l();
        dcm::WindowMeans means;
        const dcm::GravityContext c = {dcm::kDefaultDcmSettings, k, r, 0, offset, sensor_bias_units, starting,
                                       startup_left, startup_left};
        ASSERT_TRUE(gravity.low_pass_window(c, means));
        gyro_mean = means.gyro;
        accel_mean = means.accel;
        whole = means.whole;
    }
};

}  // namespace

// In flight the turn's term comes off the window with the calibrated bias taken off the
// gyro's sums in whole counts, rounded (100.78 counts: 101): a board reading its bias
// alone, level at 18 m/s, keeps its window as it is.
TEST(DcmExact, TheTurnTermTakesTheCalibratedBiasOffInRoundedCounts) {
    // y's bias beyond a byte (300.5 counts: 18 deg/s), z's within.
    const Vector3l accel_counts(0, 0, -4096), gyro_counts(0, 301, 101);
    const Vector3l sensor_bias_units(0, 300 * 256 + 130, 100 * 256 + 200);
    // The usual four samples, and a late correction's five.
    for (const uint8_t n : {4, 5}) {
        dcm::TurnMean turn = dcm::TurnMean();
        turn.configure(2048, 4096);  // about 18 m/s
        OneWindow w;
        for (uint8_t i = 0; i < n; ++i) w.gravity.add(gyro_counts, accel_counts);
        const linalg::Matrix3q30 level = linalg::q30_from_matrix(Matrix3f::identity());
        const Vector3l offset = Vector3l();
        const dcm::GravityContext c = {dcm::kDefaultDcmSettings, w.k, level, 0, offset, sensor_bias_units, false,
                                       0.0f, 0.0f};
        w.gravity.subtract_turn(turn, c);  // level
        dcm::WindowMeans means;
        ASSERT_TRUE(w.gravity.low_pass_window(c, means));
        w.accel_mean = means.accel;
        EXPECT_EQ(w.accel_mean.x, 0) << (int)n;
        EXPECT_EQ(w.accel_mean.y, 0) << (int)n;
        EXPECT_NEAR(w.accel_mean.z, -4096 * 256, 1) << (int)n;
    }
}

// A reset (a start) leaves no correction from before it.
TEST(DcmExact, AResetClearsTheCorrection) {
    OneWindow w;
    // About 0.25 g and 0.12 g of tilt at the float form's scale (4096 counts per m/s^2).
    w.run(linalg::q30_from_matrix(Matrix3f::identity()), Vector3l(), Vector3l(10000, -5000, -38000), 4);
    dcm::GyroBias bias;
    const linalg::Matrix3q30 level = linalg::q30_from_matrix(Matrix3f::identity());
    const Vector3l zero = Vector3l();
    w.gravity.correct_tilt({dcm::kDefaultDcmSettings, w.k, level, 0, zero, zero, false, 0.0f, 0.0f}, true, bias);
    const Vector3l before = w.gravity.correction_units();
    ASSERT_TRUE(before.x != 0 && before.y != 0);
    w.gravity.reset(-4096 * 256);
    EXPECT_EQ(w.gravity.correction_units().x, 0);
    EXPECT_EQ(w.gravity.correction_units().y, 0);
    EXPECT_EQ(w.gravity.correction_units().z, 0);
}

// The window's means over its usual four samples are exact: the gyro's less the
// calibrated bias, and the earth-frame force's, whose sum is the matrix's 16-bit entries
// times the sums (mul_q14: a multiple of 4, as the accel units' sums are of 256).
TEST(DcmExact, AFourSampleWindowsMeansAreExact) {
    using linalg::q14_of;
    using linalg::hot::mul_q14;
    const linalg::Matrix3q30 r = linalg::q30_from_matrix(dcm::dcm_from_euler(0.3f, -0.2f, 0.1f));
    const Vector3l accel_counts(3, -5, -4093), sensor_bias_units(5 * 256, -3 * 256, 7 * 256);
    OneWindow w;
    w.run(r, Vector3l(), accel_counts, 4, sensor_bias_units);
    EXPECT_TRUE(w.whole);
    EXPECT_EQ(w.gyro_mean.x, -sensor_bias_units.x);
    EXPECT_EQ(w.gyro_mean.y, -sensor_bias_units.y);
    EXPECT_EQ(w.gyro_mean.z, -sensor_bias_units.z);
    // No turn: the body-axis sum is the samples', in accel units.
    const Vector3l sum(accel_counts.x * 4 * 256, accel_counts.y * 4 * 256, accel_counts.z * 4 * 256);
    const linalg::Vector3l* rows[3] = {&r.a, &r.b, &r.c};
    const int32_t lp[3] = {w.gravity.low_pass_ef().x, w.gravity.low_pass_ef().y, w.gravity.low_pass_ef().z};
    for (int i = 0; i < 3; ++i) {
        const linalg::Vector3l& row = *rows[i];
        const int32_t sum_ef = mul_q14(q14_of(row.x), sum.x) + mul_q14(q14_of(row.y), sum.y) + mul_q14(q14_of(row.z), sum.z);
        EXPECT_EQ(sum_ef % 4, 0) << i;
        EXPECT_EQ(lp[i], sum_ef / 4) << i;
    }
}

// A window's mean over 1 to 5 samples is its sum times 1/n in Q30 rounded to nearest
// (q30_ratio), to the unit: the sums here tell that factor from the float's 1/n (one
// unit apart); a longer window (never in the estimator's schedule, possible in the
// class) is its sum over n too.
TEST(DcmExact, AWindowsMeanIsItsSumTimesTheRoundedInverse) {
    struct Case {
        uint8_t n;
        int32_t gyro_counts;
    };
    for (const Case& c : {Case{3, 256}, Case{5, 820}, Case{1, 820}, Case{2, 821}}) {
        OneWindow w;
        w.run(linalg::q30_from_matrix(Matrix3f::identity()), Vector3l(c.gyro_counts, -c.gyro_counts, 0), Vector3l(0, 0, -4096),
              c.n);
        const int32_t sum_units = c.gyro_counts * c.n * 256;
        const int32_t expected = linalg::mul_q30(linalg::q30_ratio(1, c.n), sum_units);
        EXPECT_EQ(w.gyro_mean.x, expected) << (int)c.n;
        EXPECT_EQ(w.gyro_mean.y, -expected) << (int)c.n;
        if (c.n == 3 || c.n == 5) {
            EXPECT_NE(expected, linalg::mul_q30(linalg::fixed_from_float(1.0f / c.n, linalg::kQ30), sum_units)) << (int)c.n;
        }
    }
    for (uint8_t n = 6; n <= 9; ++n) {
        OneWindow w;
        w.run(linalg::q30_from_matrix(Matrix3f::identity()), Vector3l(10, -20, 30), Vector3l(100, -200, -4096), n);
        EXPECT_NEAR(w.gyro_mean.x, 10 * 256, 1) << (int)n;
        EXPECT_NEAR(w.gyro_mean.z, 30 * 256, 1) << (int)n;
        EXPECT_NEAR(w.accel_mean.y, -200 * 256, 1) << (int)n;
        EXPECT_TRUE(w.whole) << (int)n;
    }
}

// The low-pass's factor ramps over the start-up from the start's (startup_accel_alpha)
// to the steady one (accel_alpha): startup_left of the way back from the steady one.
TEST(DcmExact, TheLowPassFactorRampsOverTheStartUp) {
    for (float startup_left : {1.0f, 0.5f, 0.25f}) {
        OneWindow w;
        w.k = float_form_coefficients();
        const float steady = linalg::float_from_fixed(w.k.accel_alpha_q30, linalg::kQ30);
        const float expected = w.k.startup_accel_alpha + (steady - w.k.startup_accel_alpha) * (1.0f - startup_left);
        ASSERT_GT(w.k.startup_accel_alpha, 2.0f * steady);
        // Level, 1 000 counts along x: the low-pass (at gravity, x = 0) moves by alpha of it.
        w.run(linalg::q30_from_matrix(Matrix3f::identity()), Vector3l(), Vector3l(1000, 0, -4096), 4, Vector3l(), true,
              startup_left);
        EXPECT_NEAR(w.gravity.low_pass_ef().x / (1000.0f * 256.0f), expected, 1e-5f) << startup_left;
    }
}

// Each sample of the window meets the matrix of its own step: turned back by the rate
// times the steps from it to the matrix's time (R = I, nothing pending: n - j + 1 for
// sample j), sum_j a_j - (w dt x a_j)(n - j + 1). Against that sum in double, the
// window's earth-frame mean is within the turn's 16-bit rounding (2^-15 rad a step) on
// every axis, for a turn about all three.
TEST(DcmExact, TheWindowsSamplesAreTurnedToTheMatrixsTime) {
    OneWindow w;
    const double w_rad_s[3] = {1.5, -2.0, 2.5};
    const double dt = w.k.step_s;
    const Vector3l gyro_counts((int32_t)std::lround(w_rad_s[0] / dcm::kFloatGyroScale),
                               (int32_t)std::lround(w_rad_s[1] / dcm::kFloatGyroScale),
                               (int32_t)std::lround(w_rad_s[2] / dcm::kFloatGyroScale));
    const Vector3l accel_counts(2000, -1500, -3000);
    const uint8_t n = 4;
    w.run(linalg::q30_from_matrix(Matrix3f::identity()), gyro_counts, accel_counts, n);
    const double a[3] = {accel_counts.x * 256.0, accel_counts.y * 256.0, accel_counts.z * 256.0};
    const double phi[3] = {gyro_counts.x * dcm::kFloatGyroScale * dt, gyro_counts.y * dcm::kFloatGyroScale * dt,
                           gyro_counts.z * dcm::kFloatGyroScale * dt};
    const double phi_x_a[3] = {phi[1] * a[2] - phi[2] * a[1], phi[2] * a[0] - phi[0] * a[2], phi[0] * a[1] - phi[1] * a[0]};
    const double steps_summed = n * (n + 1) / 2.0;  // sum_j (n - j + 1)
    const double bound = 0.5 / 16384.0 * steps_summed * std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) / n + 8.0;
    const int32_t lp[3] = {w.gravity.low_pass_ef().x, w.gravity.low_pass_ef().y, w.gravity.low_pass_ef().z};
    for (int i = 0; i < 3; ++i) {
        const double expected = a[i] - steps_summed / n * phi_x_a[i];
        EXPECT_NEAR(lp[i], expected, bound) << i;
        EXPECT_GT(std::fabs(expected - a[i]), 10.0 * bound) << i << ": the turn term is seen";
    }
}

// Beyond 90 deg of heading error the correction is the one of 90 deg (the sine held at
// +-1, monotonic): two estimators alike but for a field 91 deg off (whose earth-frame
// north component is only -0.35 uT) and one 170 deg off turn R identically, bit for bit.
TEST(DcmExact, AHeadingErrorBeyond90DegIsCorrectedAsAt90) {
    dcm::DcmSettings settings = dcm::kDefaultDcmSettings;
    settings.kp_startup_1_s = settings.kp_yaw_1_s;  // the steady gain from the start: 0.2 deg a mean
    const Matrix3f level = Matrix3f::identity();
    dcm::Dcm a(settings), b(settings), unturned(settings);
    for (dcm::Dcm* f : {&a, &b, &unturned}) ASSERT_TRUE(f->init(accel_for(level), mag_for(level)));
    const Vector3f field_91 = dcm::dcm_from_euler(0, 0, 91.0f * linalg::kRadPerDeg).mul_transpose(earth_field_uT());
    const Vector3f field_170 = dcm::dcm_from_euler(0, 0, 170.0f * linalg::kRadPerDeg).mul_transpose(earth_field_uT());
    const float dt = settings.step_s;
    float next_mag_s = 0.0f;
    for (int i = 0; i < 40; ++i) {  // 0.2 s: five means, the error stays beyond 90 deg
        if (i * dt >= next_mag_s) {
            a.correct_heading(field_91);
            b.correct_heading(field_170);
            unturned.correct_heading(mag_for(level));
            next_mag_s += 1.0f / 75.0f;
        }
        for (dcm::Dcm* f : {&a, &b, &unturned}) f->update(Vector3f(), accel_for(level));
    }
    const Matrix3f ra = a.matrix(), rb = b.matrix();
    const float da[9] = {ra.a.x, ra.a.y, ra.a.z, ra.b.x, ra.b.y, ra.b.z, ra.c.x, ra.c.y, ra.c.z};
    const float db[9] = {rb.a.x, rb.a.y, rb.a.z, rb.b.x, rb.b.y, rb.b.z, rb.c.x, rb.c.y, rb.c.z};
    for (int i = 0; i < 9; ++i) EXPECT_EQ(da[i], db[i]) << i;
    // The heading did turn (towards the field) meanwhile.
    EXPECT_GT(std::fabs(a.euler().yaw_rad - unturned.euler().yaw_rad), 0.5f * linalg::kRadPerDeg);
    EXPECT_FALSE(a.status() & dcm::kStatusMagIgnored);
}

// A field sample is brought forward by the latency turn, rounded to Q16 radians to
// nearest (as every rounding on its way is): mirrored in y (a turn about z of -w for +w,
// the field's y negated), the heading taken at once from one strong sample is mirrored
// to the bit. A turn rounded down would be a unit larger one way than the other.
TEST(DcmExact, TheFieldsLatencyTurnIsRoundedAlikeBothWays) {
    const Vector3f field_uT(900.0f, 150.0f, 400.0f);  // strong: a unit of the turn moves y by ~0.4 of a Q5 count
    int mirrored = 0;
    for (int32_t counts = 128 * 30; counts <= 128 * 90; counts += 128 * 3) {  // 0.23 to 0.7 rad/s
        Matrix3f r[2];
        for (int side = 0; side < 2; ++side) {
            const float sign = side == 0 ? 1.0f : -1.0f;
            dcm::Dcm f;
            ASSERT_TRUE(f.init(accel_for(Matrix3f::identity()), earth_field_uT()));
            f.update(Vector3f(), accel_for(Matrix3f::identity()));
            // The second step's rate waits (not yet integrated: R stays I) and is the last.
            f.update(Vector3f(0.0f, 0.0f, sign * (float)counts * dcm::kFloatGyroScale), accel_for(Matrix3f::identity()));
            f.reset_mag_reference(true);
            f.correct_heading(Vector3f(field_uT.x, sign * field_uT.y, field_uT.z));
            r[side] = f.matrix();
        }
        EXPECT_EQ(r[0].a.x, r[1].a.x) << counts;
        EXPECT_EQ(r[0].a.y, -r[1].a.y) << counts;
        EXPECT_EQ(r[0].b.x, -r[1].b.x) << counts;
        EXPECT_EQ(r[0].b.y, r[1].b.y) << counts;
        EXPECT_GT(std::fabs(r[0].a.y), 0.1f) << counts << ": the heading taken from the sample";
        mirrored += r[0].a.y == -r[1].a.y;
    }
    EXPECT_EQ(mirrored, 21);
}

// The output's Q15 factors and the compass latency in Q12 are their values rounded:
// the lead in steps (up to 1.99 of them: 1.5 here), Q26 radians per unit, and the
// latency held at 5.9 steps (10 asked); the coarse turn is the 16-bit factor's product.
TEST(DcmExact, TheOutputAndLatencyFactorsAreTheirRoundedValues) {
    dcm::DcmSettings settings = dcm::kDefaultDcmSettings;
    settings.output_lead_s = 1.5f * settings.step_s;
    settings.mag_latency_s = 10.0f * settings.step_s;
    dcm::DcmCoefficients k;
    k.from_settings(settings);
    k.derive_from_scales(settings);
    EXPECT_EQ(k.lead_steps_q15, 49152);  // 1.5 * 2^15
    EXPECT_NEAR(k.theta_q26_per_unit_q15, (double)k.turn_rad_per_unit() * 67108864.0 * 32768.0, 0.51);
    EXPECT_NEAR(k.mag_latency_steps_q12, 5.9 * 4096.0, 0.51);
    const Vector3l units(123456, -654321, 7777777);
    const Vector3l coarse = k.theta_q26_coarse(units);
    EXPECT_EQ(coarse.x, dcm::scale_q15(units.x, k.theta_q26_per_unit_q15));
    EXPECT_EQ(coarse.y, dcm::scale_q15(units.y, k.theta_q26_per_unit_q15));
    EXPECT_EQ(coarse.z, dcm::scale_q15(units.z, k.theta_q26_per_unit_q15));
    EXPECT_NE(coarse.z, k.theta_q26(units).z) << "the 16-bit factor's product, not the Q30 one's";
}

// No tilt correction from a low-pass shorter than g/2: at |lp|^2 = min_lp2 exactly (the
// sum of the mul_q30 squares it is compared as) none; with the limit a unit lower, one.
TEST(DcmExact, NoTiltCorrectionFromALowPassAtTheLimit) {
    OneWindow w;
    const linalg::Matrix3q30 level = linalg::q30_from_matrix(Matrix3f::identity());
    w.run(level, Vector3l(), Vector3l(1000, 0, -4000), 4);
    const Vector3l lp = w.gravity.low_pass_ef();
    const uint32_t lp2 = (uint32_t)linalg::mul_q30(lp.x, lp.x) + (uint32_t)linalg::mul_q30(lp.y, lp.y) +
                         (uint32_t)linalg::mul_q30(lp.z, lp.z);
    for (uint32_t below : {0u, 1u}) {
        dcm::GravityCorrection gravity = w.gravity;
        dcm::DcmCoefficients k = w.k;
        k.min_lp2 = lp2 - below;
        dcm::GyroBias bias;
        const Vector3l zero = Vector3l();
        gravity.correct_tilt({dcm::kDefaultDcmSettings, k, level, 0, zero, zero, false, 0.0f, 0.0f}, true, bias);
        if (below)
            EXPECT_NE(gravity.correction_units().y, 0);
        else
            EXPECT_TRUE(gravity.correction_units().x == 0 && gravity.correction_units().y == 0 &&
                        gravity.correction_units().z == 0);
    }
}

// The output leads by output_lead_s on every axis: turning at a steady 100 deg/s in roll
// or in pitch, euler_now() is ahead of euler() by the rate times the lead.
TEST(DcmExact, TheOutputLeadsOnRollAndPitch) {
    for (int axis = 0; axis < 2; ++axis) {
        dcm::Dcm filter;
        ASSERT_TRUE(filter.init(accel_for(Matrix3f::identity()), Vector3f()));
        const float rate_rad_s = 100.0f * linalg::kRadPerDeg;
        const Vector3f rate = axis == 0 ? Vector3f(rate_rad_s, 0, 0) : Vector3f(0, rate_rad_s, 0);
        for (int i = 0; i < 40; ++i) {  // 0.2 s: 20 deg, the accelerometer turning with it
            const float angle = rate_rad_s * filter.settings().step_s * (float)i;
            filter.update(rate, accel_for(axis == 0 ? dcm::dcm_from_euler(angle, 0, 0) : dcm::dcm_from_euler(0, angle, 0)));
        }
        const dcm::EulerAngles now = filter.euler_now(), then = filter.euler();
        const float lead_rad = axis == 0 ? now.roll_rad - then.roll_rad : now.pitch_rad - then.pitch_rad;
        EXPECT_NEAR(lead_rad / linalg::kRadPerDeg, 100.0f * filter.settings().output_lead_s, 0.01f) << axis;
    }
}

// Near unit length (|r|^2 within 1 +- 0.002) a row is rescaled by the first-order factor
// (3 - r.r) / 2, to the bit (r.r as the sum of the mul_q30 squares); a row a little
// longer or shorter than that window by the exact factor instead.
TEST(DcmExact, ARowNearUnitLengthIsRescaledToFirstOrder) {
    for (double length2 : {1.0015, 0.9985, 1.0005}) {
        const double scale = std::sqrt(length2 / 3.0);
        const Vector3l row = linalg::fixed_from_vector(Vector3f((float)scale, (float)-scale, (float)scale), linalg::kQ30);
        const uint32_t r2 = (uint32_t)linalg::mul_q30(row.x, row.x) + (uint32_t)linalg::mul_q30(row.y, row.y) +
                            (uint32_t)linalg::mul_q30(row.z, row.z);
        const int32_t factor = linalg::kOneQ30 + linalg::kOneQ30 / 2 - (int32_t)(r2 / 2);
        Vector3l out;
        ASSERT_TRUE(dcm::Strapdown::rescale(row, out)) << length2;
        EXPECT_EQ(out.x, linalg::mul_q30(factor, row.x)) << length2;
        EXPECT_EQ(out.y, linalg::mul_q30(factor, row.y)) << length2;
        EXPECT_EQ(out.z, linalg::mul_q30(factor, row.z)) << length2;
    }
}

// A heading correction stands for the steps its mean covers, up to 20 (after an outage
// the first sample must not make a jump): a mean over 19 steps turns less than one over
// 20, and one over 25 exactly as much as one over 20.
TEST(DcmExact, AHeadingCorrectionStandsForAtMost20Steps) {
    float yaw_rad[3];
    constexpr int k = dcm::kHeadingSteps;
    const int quiet_steps[3] = {20 - k, 21 - k, 26 - k};  // the mean covers kHeadingSteps - 1 more: 19, 20, 25
    for (int i = 0; i < 3; ++i) {
        dcm::Dcm f;
        ASSERT_TRUE(f.init(accel_for(Matrix3f::identity()), earth_field_uT()));
        for (int s = 0; s < quiet_steps[i]; ++s) f.update(Vector3f(), accel_for(Matrix3f::identity()));
        f.reset_mag_reference(false);  // the next sample closes a mean alone, at the usual rate
        f.correct_heading(dcm::dcm_from_euler(0, 0, 0.5f).mul_transpose(earth_field_uT()));
        EXPECT_FALSE(f.status() & dcm::kStatusMagIgnored) << i;
        yaw_rad[i] = f.euler_now().yaw_rad;
    }
    EXPECT_GT(std::fabs(yaw_rad[0]), 0.01f);
    EXPECT_LT(std::fabs(yaw_rad[0]), std::fabs(yaw_rad[1]));
    EXPECT_EQ(yaw_rad[1], yaw_rad[2]);
}

// The low-pass starts at gravity (earth down), so the start-up's fast gain corrects from
// the first windows: a board tilted by 10 deg just after a level start is followed by
// more than a fifth of the way within 0.3 s (a third here; a low-pass started elsewhere would pass
// through a length below g/2, where no correction is made).
TEST(DcmExact, ATiltRightAfterTheStartIsCorrectedAtOnce) {
    dcm::Dcm f;
    ASSERT_TRUE(f.init(accel_for(Matrix3f::identity()), earth_field_uT()));
    const Matrix3f tilted = dcm::dcm_from_euler(10.0f * linalg::kRadPerDeg, 0.0f, 0.0f);
    for (int i = 0; i < 60; ++i) f.update(Vector3f(), accel_for(tilted));  // 0.3 s
    EXPECT_GT(f.euler().roll_rad, 2.0f * linalg::kRadPerDeg);
}

// A start from a mean (the calibration's, a never-still window's) has nothing for the
// fast gain to pull in: the same 10 deg that a start from one sample follows by a third
// within 0.3 s (above) is an acceleration after it (a gust), followed at the steady gain.
TEST(DcmExact, AStartFromAMeanFollowsNoAccelerationFast) {
    dcm::Dcm f;
    ASSERT_TRUE(f.init(accel_for(Matrix3f::identity()), earth_field_uT(), true));
    const Matrix3f tilted = dcm::dcm_from_euler(10.0f * linalg::kRadPerDeg, 0.0f, 0.0f);
    for (int i = 0; i < 60; ++i) f.update(Vector3f(), accel_for(tilted));  // 0.3 s
    EXPECT_LT(f.euler().roll_rad, 1.5f * linalg::kRadPerDeg);
}

// q14_ratio is a positive ratio in Q14 rounded to nearest (the coning term's 2/3: 10923,
// not the truncated 10922).
TEST(DcmExact, Q14RatioRoundsToNearest) {
    for (int32_t num : {2, 1, 5}) {
        for (int32_t den : {3, 7, 6}) {
            const double exact = num * 16384.0 / den;
            EXPECT_LE(std::fabs(linalg::q14_ratio(num, den) - exact), 0.5) << num << "/" << den;
        }
    }
    EXPECT_EQ(linalg::q14_ratio(2, 3), 10923);
}
