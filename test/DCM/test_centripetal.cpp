// SPDX-License-Identifier: GPL-3.0-or-later
// The centripetal correction of the accelerometer from the airspeed: the gravity window's
// term (lib/DCM/Centripetal.h) and its gain from the airspeed (lib/Pipeline): gravity at
// the bank in a coordinated turn, the bounds and the turn's mean through turbulence, off
// below the minimum airspeed, held at the extremes; the pipeline flying a turn with and
// without it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Airspeed.h"
#include "Dcm.h"
#include "Params.h"
#include "Mpu6000.h"
#include "Pipeline.h"

namespace {

using linalg::Vector3f;
using linalg::Vector3i;

constexpr float kG = 9.80665f;
constexpr float kDeg = 3.14159265f / 180.0f;
// 1 g in the counts of the driver's accelerometer range.
const int16_t kGravityCounts = (int16_t)std::lround(kG / mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange));

mpu6000::Sample imu(const Vector3f& gyro, const Vector3f& accel) {
    return mpu6000::sample_from_si(gyro, accel, 25.0f, mpu6000::kGyroRange, mpu6000::kAccelRange);
}

// A level coordinated turn at this bank and airspeed: body rates and specific force.
struct Turn {
    Vector3f gyro_rad_s, accel_m_s2;
};
Turn coordinated_turn(float bank_deg, float airspeed_m_s) {
    const float phi = bank_deg * kDeg;
    const float turn_rad_s = kG * std::tan(phi) / airspeed_m_s;  // Omega V = g tan(phi)
    return {Vector3f(0.0f, turn_rad_s * std::sin(phi), turn_rad_s * std::cos(phi)),
            Vector3f(0.0f, 0.0f, -kG / std::cos(phi))};
}

int32_t down_y_q30_at(float bank_deg) { return (int32_t)std::lround(std::sin(bank_deg * kDeg) * 1073741824.0); }

// One gravity window of n equal samples through a TurnMean: the accel sums after
// subtract_from_window, per sample in m/s^2, and the running sums' sum per unit weight.
struct Window {
    Vector3f accel_m_s2, weighted_m_s2;
};
Window take_off(dcm::TurnMean& turn, const mpu6000::Sample& s, float bank_deg, uint8_t n = 4,
               bool start_tilt = false) {
    linalg::Vector3l sum(s.accel.x * n, s.accel.y * n, s.accel.z * n);
    const int32_t weight = n * (n + 1) / 2;  // sum over j of n - j + 1
    linalg::Vector3l sum_of_sums(s.accel.x * weight, s.accel.y * weight, s.accel.z * weight);
    // Earth down in body axes at the bank, pitch 0 (z is not read).
    turn.subtract_from_window(s.gyro.y * n, s.gyro.z * n, linalg::Vector3l(0, down_y_q30_at(bank_deg), 0), n, sum,
                              sum_of_sums, start_tilt);
    const float per_count = s.accel_m_s2_per_count;
    return {Vector3f((float)sum.x, (float)sum.y, (float)sum.z) * (per_count / (float)n),
            Vector3f((float)sum_of_sums.x, (float)sum_of_sums.y, (float)sum_of_sums.z) * (per_count / (float)weight)};
}
dcm::TurnMean turn_at(float airspeed_m_s) {
    dcm::TurnMean turn = dcm::TurnMean();
    turn.configure(pipeline::centripetal_gain_q8(airspeed_m_s), kGravityCounts);
    return turn;
}

// The usual window of 4 samples, and windows of 1 to 3 (a broken read left out of the
// gravity window) or 5 (a correction late by a step) alike.
TEST(Centripetal, CoordinatedTurnCorrectedToGravityAtTheBank) {
    for (uint8_t n = 1; n <= 5; ++n) {
        for (float bank : {-45.0f, -30.0f, 10.0f, 30.0f, 60.0f}) {
            for (float v : {12.0f, 18.0f, 30.0f}) {
                const Turn t = coordinated_turn(bank, v);
                const mpu6000::Sample s = imu(t.gyro_rad_s, t.accel_m_s2);
                // The estimate at the true bank: the bank provides the whole turn.
                dcm::TurnMean turn = turn_at(v);
                const Window w = take_off(turn, s, bank, n);
                // Gravity at the bank: -g (0, sin phi, cos phi), in the sums and in the
                // running sums' sum alike.
                for (const Vector3f& f : {w.accel_m_s2, w.weighted_m_s2}) {
                    EXPECT_NEAR(f.x, 0.0f, 0.01f);
                    EXPECT_NEAR(f.y, -kG * std::sin(bank * kDeg), 0.03f) << bank << " deg at " << v << " m/s, n " << (int)n;
                    EXPECT_NEAR(f.z, -kG * std::cos(bank * kDeg), 0.03f) << bank << " deg at " << v << " m/s, n " << (int)n;
                }
            }
        }
    }
}

// A window's sum a sample: for the usual 4 rounded to the nearest count (a half up), and
// the inverse of times_n for any window.
TEST(Centripetal, APerSampleMeanIsRoundedAndUndoesTimesN) {
    for (int32_t sum = -41; sum <= 41; ++sum)
        EXPECT_EQ(dcm::per_sample(sum, 4), (int32_t)std::floor((double)sum / 4.0 + 0.5)) << sum;
    for (uint8_t n = 1; n <= 5; ++n)
        for (int32_t x : {-32767, -5, -1, 0, 1, 7, 32767}) EXPECT_EQ(dcm::per_sample(dcm::times_n(x, n), n), x) << (int)n;
}

// The bounds: 0 to a_y either side, widened by the margin, to the count.
TEST(Centripetal, TheBoundsAreZeroToAyWidenedByTheMargin) {
    EXPECT_EQ(dcm::lateral_bounds(0, 10).lo, -10);
    EXPECT_EQ(dcm::lateral_bounds(0, 10).hi, 10);
    EXPECT_EQ(dcm::lateral_bounds(300, 10).lo, -10);
    EXPECT_EQ(dcm::lateral_bounds(300, 10).hi, 310);
    EXPECT_EQ(dcm::lateral_bounds(-300, 10).lo, -310);
    EXPECT_EQ(dcm::lateral_bounds(-300, 10).hi, 10);
}

// A steady coordinated turn, window after window: what the clipping takes is nothing,
// what the mean gives back nothing; the term stays the one the first window took, to the
// count, for a minute.
TEST(Centripetal, ASteadyTurnsTermStaysTheSameToTheCount) {
    const Turn t = coordinated_turn(30.0f, 18.0f);
    const mpu6000::Sample s = imu(t.gyro_rad_s, t.accel_m_s2);
    dcm::TurnMean turn = turn_at(18.0f);
    const float first = take_off(turn, s, 30.0f).accel_m_s2.y;
    for (int window = 1; window < 50 * 60; ++window) {
        const float f_y = take_off(turn, s, 30.0f).accel_m_s2.y;
        ASSERT_EQ(f_y, first) << window;
    }
}

// The bound on the mean follows a_y's mean: after a long yaw with the wings level (the
// term held to the margin), a coordinated turn at its bank gets its whole term again once
// the means have moved on (a stale a_y mean would keep it at the margin).
TEST(Centripetal, TheMeansBoundFollowsTheBank) {
    dcm::TurnMean turn = turn_at(18.0f);
    const mpu6000::Sample yawing = imu(Vector3f(0.0f, 0.0f, 20.0f * kDeg), Vector3f(0.0f, 0.0f, -kG));
    for (int window = 0; window < 50 * 20; ++window) take_off(turn, yawing, 0.0f);
    const Turn t = coordinated_turn(30.0f, 18.0f);
    const mpu6000::Sample turning = imu(t.gyro_rad_s, t.accel_m_s2);
    Vector3f f;
    for (int window = 0; window < 50 * 20; ++window) f = take_off(turn, turning, 30.0f).accel_m_s2;
    EXPECT_NEAR(f.y, -kG * std::sin(30.0f * kDeg), 0.03f);
}

// Wings level, yawing at 20 deg/s (turbulence turning the aeroplane into the relative
// wind): no bank provides that turn, so at most the margin of it is taken off (unbounded
// it would be 6.3 m/s^2, 33 deg of false bank).
TEST(Centripetal, AYawRateWithoutTheBankIsHeldToTheMargin) {
    for (float sign : {1.0f, -1.0f}) {
        const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, sign * 20.0f * kDeg), Vector3f(0.0f, 0.0f, -kG));
        dcm::TurnMean turn = turn_at(18.0f);
        for (int window = 0; window < 200; ++window) {
            const Vector3f f = take_off(turn, s, 0.0f).accel_m_s2;
            EXPECT_NEAR(std::atan2(-f.y, -f.z) / kDeg, sign * dcm::kTurnBankMargin_deg, 0.05f) << window;
        }
    }
}

// Beyond 2^21 counts a window (500 g) omega V is no turn and is held there, keeping its
// sign: reached at the gyro's full scale with a gain above the pipeline's (3 414 at its
// 60 m/s limit: 1.75e6 counts), as an accelerometer of another range would give.
TEST(Centripetal, OmegaVBeyondAnyTurnIsHeldWithItsSign) {
    for (float sign : {1.0f, -1.0f}) {
        const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, sign * 1990.0f * kDeg), Vector3f(0.0f, 0.0f, -kG));
        dcm::TurnMean turn = dcm::TurnMean();
        turn.configure(16000, kGravityCounts);  // 8.2e6 counts a window unheld
        for (int window = 0; window < 200; ++window) {
            const Vector3f f = take_off(turn, s, 0.0f).accel_m_s2;
            EXPECT_NEAR(std::atan2(-f.y, -f.z) / kDeg, sign * dcm::kTurnBankMargin_deg, 0.05f) << window;
        }
    }
}

// An estimate 10 deg short of a 30 deg coordinated turn's bank: the corrected gravity says
// the estimate's bank plus the margin, so the estimate is pulled on toward the truth.
TEST(Centripetal, AnEstimateShortOfTheBankIsPulledOnByTheMargin) {
    const Turn t = coordinated_turn(30.0f, 18.0f);
    const mpu6000::Sample s = imu(t.gyro_rad_s, t.accel_m_s2);
    dcm::TurnMean turn = turn_at(18.0f);
    const Vector3f f = take_off(turn, s, 20.0f).accel_m_s2;
    // The lateral term is g sin(20 deg) + the margin: g sin(0.5 deg) and the gyro's scale
    // error over the bank, 3 % of g sin(20 deg); the normal one is whole.
    EXPECT_NEAR(f.y,
                -kG * (std::sin(20.0f * kDeg) * (1.0f + dcm::kTurnBankScaleError) +
                       std::sin(dcm::kTurnBankMargin_deg * kDeg)),
                0.02f);
    EXPECT_NEAR(f.z, -kG * std::cos(30.0f * kDeg), 0.03f);
    // An estimate banked the other way: the margin alone (which grows with the bank).
    dcm::TurnMean other = turn_at(18.0f);
    const Vector3f g = take_off(other, s, -20.0f).accel_m_s2;
    EXPECT_NEAR(g.y, -kG * (std::sin(dcm::kTurnBankMargin_deg * kDeg) + dcm::kTurnBankScaleError * std::sin(20.0f * kDeg)),
                0.02f);
}

// Wings level, the aeroplane weathervaning at the rate of a 3 deg bank's turn, and an
// estimate that started 3 deg banked (a start's error in gusts): the estimate's a_y lets
// the yaw in as a turn's, the corrected gravity says the estimate's bank and holds it
// there; while the start's tilt is unproven (the start-up), the bound is the
// accelerometer's a_y alone and the margin is all that is taken off.
TEST(Centripetal, TheStartsTiltIsNoWitnessOfBank) {
    const float v = 18.0f, error_deg = 3.0f;
    const float yaw_rad_s = kG * std::tan(error_deg * kDeg) / v;
    const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, yaw_rad_s), Vector3f(0.0f, 0.0f, -kG));
    for (const bool start_tilt : {false, true}) {
        dcm::TurnMean turn = turn_at(v);
        Vector3f f;
        for (int window = 0; window < 100; ++window) f = take_off(turn, s, error_deg, 4, start_tilt).accel_m_s2;
        const float bank_deg = std::atan2(-f.y, -f.z) / kDeg;
        if (start_tilt)
            EXPECT_NEAR(bank_deg, dcm::kTurnBankMargin_deg, 0.05f);
        else
            EXPECT_NEAR(bank_deg, error_deg, 0.1f);
    }
}

// The same through the estimator: started in the air 3 deg banked (the start window's
// mean, off by a gust), then level and weathervaning at a 3 deg bank's rate, with the
// turn's term on. The start-up leaves the start's tilt out of the bound, so the gravity
// correction takes the error out (0.5 deg left at 3 s; the term held 3.0 without the rule).
TEST(Centripetal, AStartInTheAirIsNotHeldAtItsTiltError) {
    const float v = 18.0f, error_deg = 3.0f;
    const mpu6000::Sample s =
        imu(Vector3f(0.0f, 0.0f, kG * std::tan(error_deg * kDeg) / v), Vector3f(0.0f, 0.0f, -kG));
    dcm::TurnMean turn = turn_at(v);
    dcm::Dcm filter;
    filter.set_sample_scales(s.gyro_rad_s_per_count, s.accel_m_s2_per_count);
    ASSERT_TRUE(filter.init(Vector3f(0.0f, -kG * std::sin(error_deg * kDeg), -kG * std::cos(error_deg * kDeg)),
                            Vector3f(), true));
    filter.set_turn(&turn);
    for (int i = 0; i < 200 * 3; ++i) filter.update(s.gyro, s.accel, true, true);
    EXPECT_LT(std::fabs(filter.euler().roll_rad) / kDeg, 0.5f * error_deg);
}

// A flat skidding turn (wings level, the rudder's sideforce turning the path): the
// accelerometer reads the whole omega_z V sideways, so all of it is taken off: level.
TEST(Centripetal, AFlatSkidTurnIsTakenOffWhole) {
    const float v = 18.0f, rate_rad_s = 10.0f * kDeg;
    const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, rate_rad_s), Vector3f(0.0f, rate_rad_s * v, -kG));
    dcm::TurnMean turn = turn_at(v);
    const Vector3f f = take_off(turn, s, 0.0f).accel_m_s2;
    EXPECT_NEAR(std::atan2(-f.y, -f.z) / kDeg, 0.0f, 0.1f);
}

// A 30 deg turn at 18 m/s through turbulence, the yaw rate swinging +-10 deg/s (0.5 Hz)
// about the turn's, flown for 60 s through `turn`: how far the term's mean falls short of
// the turn's omega_z V from 10 s on, and how far the windows clipped alone at the bank's
// bound would (m/s^2), beside the turn's term.
struct Shortfall {
    double clipped, term, turn;
};
float yaw_swing_rad_s(int window) {
    return 10.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.5f * (float)window / 50.0f);
}
Shortfall turn_through_swings(dcm::TurnMean& turn) {
    const float bank = 30.0f, v = 18.0f;
    const Turn t = coordinated_turn(bank, v);
    double sum_lateral = 0.0, sum_clipped = 0.0;
    int n = 0;
    for (int window = 0; window < 50 * 60; ++window) {
        const float swing_rad_s = yaw_swing_rad_s(window);
        const mpu6000::Sample s = imu(t.gyro_rad_s + Vector3f(0.0f, 0.0f, swing_rad_s), t.accel_m_s2);
        const float lateral = -take_off(turn, s, bank).accel_m_s2.y;
        // The clipped term alone: the bound at the bank, sample by sample.
        const float raw = (t.gyro_rad_s.z + swing_rad_s) * v;
        const float bound = kG * std::sin(bank * kDeg) * (1.0f + dcm::kTurnBankScaleError) +
                            kG * std::sin(dcm::kTurnBankMargin_deg * kDeg);
        if (window >= 50 * 10) {
            sum_lateral += lateral;
            sum_clipped += std::min(raw, bound);
            ++n;
        }
    }
    const double turn_m_s2 = kG * std::sin(bank * kDeg);
    return {turn_m_s2 - sum_clipped / n, turn_m_s2 - sum_lateral / n, turn_m_s2};
}

// In the turn through turbulence each window clipped alone keeps the lower swings and
// loses the upper ones, a term short of the turn's on the mean; the mean's share given
// back makes up most of it.
TEST(Centripetal, TheTermsMeanIsTheTurnsThroughTheSwings) {
    dcm::TurnMean turn = turn_at(18.0f);
    const Shortfall s = turn_through_swings(turn);
    // Clipped alone the term is 18 % short; with the mean's share 3 %: a 0.5 Hz swing
    // still moves the 1.3 s mean beyond the bound at its peaks.
    EXPECT_GT(s.clipped, 0.1 * s.turn);
    EXPECT_LT(s.term, 0.2 * s.clipped);
    EXPECT_GT(s.term, -0.01 * s.turn);
}

// Straight flight in turbulence, wings rocked +-3 deg about level and the nose yawed
// +-10 deg/s about the path (the estimate level): no turn, so nothing clipped is given
// back, and the term stays within the bound of the windows it was worked out on, 0 ..
// their mean a_y widened by the margin. (Given back, the swings' chance agreement over the
// 1.3 s mean took it up to two margins beyond, roll the estimate held for seconds.)
TEST(Centripetal, StraightFlightInGustsGetsNothingGivenBack) {
    dcm::TurnMean turn = turn_at(18.0f);
    const float margin = kG * std::sin(dcm::kTurnBankMargin_deg * kDeg);
    float worst_beyond = -1.0f;
    float f_y_since_update = 0.0f;
    for (int window = 0; window < 50 * 60; ++window) {
        const float t = (float)window / 50.0f;
        const float bank = 3.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.31f * t);
        const float yaw_rate = 10.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.47f * t + 1.0f);
        const Vector3f f(0.0f, -kG * std::sin(bank), -kG * std::cos(bank));
        const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, yaw_rate), f);
        const float f_y = (float)s.accel.y * s.accel_m_s2_per_count;
        f_y_since_update += f_y;
        const float term = f_y - take_off(turn, s, 0.0f).accel_m_s2.y;
        // The bound: a_y = f_y + g down_y (the estimate level: f_y), its mean over the
        // windows since the last update (the first alone), widened by the margin.
        const float a_y = window == 0 ? f_y : f_y_since_update / dcm::TurnMean::kUpdateEvery;
        if (window % dcm::TurnMean::kUpdateEvery == 0) f_y_since_update = 0.0f;
        const float beyond = std::max(term - (std::max(a_y, 0.0f) + margin), (std::min(a_y, 0.0f) - margin) - term);
        // (The term is worked out every kUpdateEvery-th window and kept between.)
        if (window >= 50 * 5 && window % dcm::TurnMean::kUpdateEvery == 0) worst_beyond = std::max(worst_beyond, beyond);
    }
    EXPECT_LT(worst_beyond, 0.01f);  // a count of rounding
}

// Level and straight, the airframe yawing at 12.5 or 25 Hz (3 deg/s: a propeller's
// vibration it answers, folded by the sampling) and the accelerometer shaken sideways at
// 25 Hz (2 m/s^2): no turn, and the terms' mean over 10 s stays at nothing. Worked out from
// the last window alone every fourth window (80 ms), the same phase of both came round
// each time: a steady 0.36-0.88 m/s^2 sideways at 12.5 Hz, 2-5 deg of roll.
TEST(Centripetal, AnOscillationAtTheUpdateRateMakesNoSteadyTerm) {
    for (float hz : {12.5f, 25.0f}) {
        for (float phase : {0.4f, 1.2f, 2.0f}) {
            dcm::TurnMean turn = turn_at(18.0f);
            double sum_term = 0.0;
            int windows = 0;
            for (int window = 0; window < 50 * 12; ++window) {
                const float t = (float)window / 50.0f;
                const float yaw_rate = 3.0f * kDeg * std::sin(2.0f * 3.14159265f * hz * t + phase);
                const float shake = (window % 2 == 0) ? 2.0f : -2.0f;
                const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, yaw_rate), Vector3f(0.0f, shake, -kG));
                const float f_y = (float)s.accel.y * s.accel_m_s2_per_count;
                const float term = f_y - take_off(turn, s, 0.0f).accel_m_s2.y;
                if (window >= 50 * 2) {
                    sum_term += term;
                    ++windows;
                }
            }
            EXPECT_LT(std::fabs(sum_term / windows), 0.02) << hz << " Hz, phase " << phase;
        }
    }
}

// The give-back follows the bank's mean: after a stretch wings level (nothing given
// back), a 30 deg turn in turbulence gets its term's mean back once a_y's mean has moved
// on to the bank (a mean held at level would keep the turn straight: 18 % short).
TEST(Centripetal, ATurnAfterStraightFlightGetsItsMeanBack) {
    dcm::TurnMean turn = turn_at(18.0f);
    for (int window = 0; window < 50 * 20; ++window)
        take_off(turn, imu(Vector3f(0.0f, 0.0f, yaw_swing_rad_s(window)), Vector3f(0.0f, 0.0f, -kG)), 0.0f);
    const Shortfall s = turn_through_swings(turn);
    EXPECT_GT(s.clipped, 0.1 * s.turn);
    EXPECT_LT(s.term, 0.2 * s.clipped);
}

TEST(Centripetal, OffBelowTheMinimumAirspeedAndWithoutOne) {
    EXPECT_EQ(pipeline::centripetal_gain_q8(0.0f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(pipeline::kCentripetalMinAirspeed_m_s - 0.01f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(-20.0f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(NAN), 0);
    EXPECT_GT(pipeline::centripetal_gain_q8(pipeline::kCentripetalMinAirspeed_m_s), 0);
    dcm::TurnMean off = turn_at(0.0f);
    EXPECT_FALSE(off.active());
    EXPECT_TRUE(turn_at(pipeline::kCentripetalMinAirspeed_m_s).active());
}

TEST(Centripetal, ExtremesHeldWithoutOverflow) {
    const int16_t top = pipeline::centripetal_gain_q8(pipeline::kCentripetalMaxAirspeed_m_s);
    EXPECT_EQ(pipeline::centripetal_gain_q8(1000.0f), top);
    EXPECT_EQ(pipeline::centripetal_gain_q8(INFINITY), top);
    // Five full-scale samples at the top airspeed against the sums: y loses omega_z V,
    // z gains omega_y V, each at most the accelerometer's full scale a sample.
    for (const int32_t sign : {1, -1}) {
        dcm::TurnMean turn = dcm::TurnMean();
        turn.configure(top, kGravityCounts);
        const int32_t full = 5L * 32767L;
        linalg::Vector3l sum(0, sign * full, -full), sum_of_sums(0, sign * 3 * full, -3 * full);
        turn.subtract_from_window(-sign * full, sign * full, linalg::Vector3l(), 5, sum, sum_of_sums, false);
        EXPECT_EQ(sum.y, 0) << sign;  // held at a_y (+ the margin): then at full scale
        EXPECT_EQ(sum.z, -full - sign * full) << sign;
        EXPECT_EQ(sum_of_sums.y, 0) << sign;
        EXPECT_EQ(sum_of_sums.z, -3 * full - 3 * sign * full) << sign;
    }
}

// A pipeline started still at this bank (its gyro calibration and start), then given the
// airspeed.
void start_banked(pipeline::AttitudePipeline& pipe, float bank_deg, float airspeed_m_s) {
    const Vector3f still(0.0f, -kG * std::sin(bank_deg * kDeg), -kG * std::cos(bank_deg * kDeg));
    for (int i = 0; i < 400; ++i) pipe.on_imu_sample(imu(Vector3f(), still));
    ASSERT_EQ(pipe.phase(), pipeline::Phase::Running);
    pipe.set_airspeed_m_s(airspeed_m_s);
}

// The pipeline holds the bank of a long coordinated turn with the airspeed; without it
// the estimate levels (the turn's lift taken for gravity).
float bank_after_turn(float airspeed_given_m_s) {
    const float bank = 30.0f, v = 18.0f;
    pipeline::AttitudePipeline pipe;
    const Turn t = coordinated_turn(bank, v);
    start_banked(pipe, bank, airspeed_given_m_s);
    for (int i = 0; i < 200 * 60; ++i) pipe.on_imu_sample(imu(t.gyro_rad_s, t.accel_m_s2));
    return pipe.angles().roll_deg;
}

// Wings level in turbulence: the gusts yaw the aeroplane +-15 deg/s (0.2 Hz) while the
// path and the accelerometer stay level. Each half cycle's 2.5 s of yaw moves the
// estimate at most the margin beyond where it is at a time, and the term's mean over
// 1.3 s (TurnMean) a part of that mean: it stays within 2 deg (the whole omega_z V,
// unbounded, rolls it 18 deg).
TEST(Centripetal, PipelineKeepsTheWingsLevelWhenGustsYawTheAeroplane) {
    pipeline::AttitudePipeline pipe;
    const Vector3f level(0.0f, 0.0f, -kG);
    ASSERT_NO_FATAL_FAILURE(start_banked(pipe, 0.0f, 18.0f));
    float worst_roll_deg = 0.0f;
    for (int i = 0; i < 200 * 30; ++i) {
        const float yaw_rate_rad_s = 15.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.2f * i / 200.0f);
        pipe.on_imu_sample(imu(Vector3f(0.0f, 0.0f, yaw_rate_rad_s), level));
        worst_roll_deg = std::max(worst_roll_deg, std::fabs(pipe.angles().roll_deg));
    }
    EXPECT_LT(worst_roll_deg, 2.0f);
}

// A 30 deg coordinated turn through turbulence: the gusts swing the yaw rate +-10 deg/s
// (0.5 Hz) about the turn's. Each sample's term clipped at the bound alone loses the upper
// swings, the estimate levels and the bound follows it down (23.9 deg in the last 10 s of
// the minute, and falling); the turn's mean (TurnMean) keeps the term's mean whole: 28.0,
// as with the whole omega_z V taken off unbounded (28.2: the swings themselves cost that).
TEST(Centripetal, PipelineHoldsTheBankOfATurnThroughTurbulence) {
    const float bank = 30.0f, v = 18.0f;
    pipeline::AttitudePipeline pipe;
    const Turn t = coordinated_turn(bank, v);
    ASSERT_NO_FATAL_FAILURE(start_banked(pipe, bank, v));
    float bank_sum_deg = 0.0f;
    int n = 0;
    for (int i = 0; i < 200 * 60; ++i) {
        const float swing_rad_s = 10.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.5f * (float)i / 200.0f);
        // About earth's vertical (body (0, sin, cos) at the bank): the bank stays.
        const Vector3f swing(0.0f, swing_rad_s * std::sin(bank * kDeg), swing_rad_s * std::cos(bank * kDeg));
        pipe.on_imu_sample(imu(t.gyro_rad_s + swing, t.accel_m_s2));
        if (i >= 200 * 50) {
            bank_sum_deg += pipe.angles().roll_deg;
            ++n;
        }
    }
    EXPECT_NEAR(bank_sum_deg / (float)n, bank, 3.0f);
}

// The speed's change (Pipeline.h, longitudinal_counts): dV/dt in accel counts between two
// flying speeds read close in time, nothing else.
TEST(Centripetal, TheAirspeedsChangeIsTheLongitudinalAcceleration) {
    const float count_m_s2 = mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
    // 18 -> 18.2 m/s over 8 steps (40 ms): 5 m/s^2.
    EXPECT_NEAR(pipeline::longitudinal_counts(18.0f, 18.2f, 8) * count_m_s2, 5.0f, 0.01f);
    EXPECT_NEAR(pipeline::longitudinal_counts(18.2f, 18.0f, 8) * count_m_s2, -5.0f, 0.01f);
    EXPECT_NEAR(pipeline::longitudinal_counts(18.0f, 18.2f, 16) * count_m_s2, 2.5f, 0.01f);
    EXPECT_EQ(pipeline::longitudinal_counts(18.0f, 18.0f, 8), 0);
    // Held at 2 g along the path.
    EXPECT_NEAR(pipeline::longitudinal_counts(18.0f, 28.0f, 8) * count_m_s2, pipeline::kMaxLongitudinal_m_s2, 0.01f);
    EXPECT_NEAR(pipeline::longitudinal_counts(28.0f, 18.0f, 8) * count_m_s2, -pipeline::kMaxLongitudinal_m_s2, 0.01f);
    // Not from a speed below the correction's minimum (a launch), nor to one, nor from
    // readings at once or far apart.
    const float slow = pipeline::kCentripetalMinAirspeed_m_s - 0.1f, fast = pipeline::kCentripetalMinAirspeed_m_s + 0.1f;
    EXPECT_EQ(pipeline::longitudinal_counts(slow, fast, 8), 0);
    EXPECT_EQ(pipeline::longitudinal_counts(fast, slow, 8), 0);
    EXPECT_NE(pipeline::longitudinal_counts(fast, fast + 0.2f, 8), 0);
    EXPECT_EQ(pipeline::longitudinal_counts(18.0f, 18.2f, 0), 0);
    EXPECT_EQ(pipeline::longitudinal_counts(18.0f, 18.2f, pipeline::kMaxAirspeedGapSteps + 1), 0);
    EXPECT_NE(pipeline::longitudinal_counts(18.0f, 18.2f, pipeline::kMaxAirspeedGapSteps), 0);
}

// Level, speeding up at 1 m/s^2: the accelerometer reads it along x (6 deg of pitch) and
// the term, held by a_x = f_x + g down_x, takes it off whole; a gust's change of airspeed
// that the accelerometer does not feel (the path keeps its speed) is held to the margin.
TEST(Centripetal, TheLongitudinalTermIsWhatTheAccelerometerFeels) {
    const float count_m_s2 = mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
    const int16_t one_m_s2 = (int16_t)std::lround(1.0f / count_m_s2);
    for (const bool felt : {true, false}) {
        dcm::TurnMean turn = dcm::TurnMean();
        turn.configure(pipeline::centripetal_gain_q8(18.0f), (int16_t)std::lround(kG / count_m_s2), one_m_s2);
        const mpu6000::Sample s = imu(Vector3f(), Vector3f(felt ? 1.0f : 0.0f, 0.0f, -kG));
        Window w{};
        for (int i = 0; i < 40; ++i) w = take_off(turn, s, 0.0f);
        // A late window's five samples take off five samples' worth.
        const Window late = take_off(turn, s, 0.0f, 5);
        EXPECT_NEAR(late.accel_m_s2.x, w.accel_m_s2.x, 0.002f) << felt;
        EXPECT_NEAR(late.weighted_m_s2.x, w.weighted_m_s2.x, 0.002f) << felt;
        // What remains is gravity, level: f_x less the term.
        if (felt) {
            EXPECT_NEAR(w.accel_m_s2.x, 0.0f, 0.01f);
            EXPECT_NEAR(w.weighted_m_s2.x, 0.0f, 0.01f);
        } else {
            // 0.5 deg of pitch at most (the margin: g sin 0.5 deg = 0.086 m/s^2).
            EXPECT_LT(std::fabs(w.accel_m_s2.x), 0.09f);
            EXPECT_GT(std::fabs(w.accel_m_s2.x), 0.05f);
        }
    }
}

// dV/dt is worked out every eighth window (6.25 Hz, the pace of a climb's change of
// speed) and held between: a new airspeed's derivative is taken off from the next eighth
// window, not before (and not at twice the rate: its work is every eighth window's).
TEST(Centripetal, TheLongitudinalTermIsWorkedOutEveryEighthWindow) {
    const float count_m_s2 = mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
    const int16_t one_m_s2 = (int16_t)std::lround(1.0f / count_m_s2);
    const int16_t gain = pipeline::centripetal_gain_q8(18.0f);
    dcm::TurnMean turn = dcm::TurnMean();
    turn.configure(gain, kGravityCounts, one_m_s2);
    const mpu6000::Sample s = imu(Vector3f(), Vector3f(1.0f, 0.0f, -kG));  // the accelerometer feels it
    EXPECT_NEAR(take_off(turn, s, 0.0f).accel_m_s2.x, 0.0f, 0.01f);  // window 0 works it out
    turn.configure(gain, kGravityCounts, 0);                         // the speed stops changing
    for (int window = 1; window < 8; ++window)
        EXPECT_NEAR(take_off(turn, s, 0.0f).accel_m_s2.x, 0.0f, 0.01f) << window;  // held
    EXPECT_NEAR(take_off(turn, s, 0.0f).accel_m_s2.x, 1.0f, 0.01f);  // window 8: no change to take off
}

// A climb's entry: 5 s of level cruise, then speeding up at 1 m/s^2 for 10 s, the airspeed
// read as the firmware reads it (every 8 steps). Without the speed's change the estimate
// pitches up toward the 5.8 deg the accelerometer says; with it the pitch stays level.
float pitch_after_speeding_up(bool measured) {
    pipeline::AttitudePipeline pipe;
    start_banked(pipe, 0.0f, 15.0f);
    float worst_deg = 0.0f;
    for (int i = -200 * 5; i < 200 * 10; ++i) {
        const float dv_dt = i < 0 ? 0.0f : 1.0f;
        if (i % 8 == 0) {
            const float v = 15.0f + dv_dt * (float)i / 200.0f;
            if (measured) pipe.set_airspeed_m_s(v); else pipe.set_cruise_airspeed_m_s(v);
        }
        pipe.on_imu_sample(imu(Vector3f(), Vector3f(dv_dt, 0.0f, -kG)));
        worst_deg = std::max(worst_deg, std::fabs(pipe.angles().pitch_deg));
    }
    return worst_deg;
}

TEST(Centripetal, PipelineKeepsThePitchWhileTheAeroplaneSpeedsUp) {
    EXPECT_LT(pitch_after_speeding_up(true), 0.6f);
    EXPECT_GT(pitch_after_speeding_up(false), 3.0f);  // a configured speed tells no change
}

TEST(Centripetal, PipelineHoldsTheBankOfATurnWithTheAirspeed) {
    EXPECT_NEAR(bank_after_turn(18.0f), 30.0f, 1.0f);
    EXPECT_LT(bank_after_turn(0.0f), 25.0f);  // the baseline: levelled without it
    EXPECT_LT(bank_after_turn(8.0f), 25.0f);  // below the minimum: no correction
}

// Without an airspeed the turn's lift is taken for gravity: the estimate levels, and the
// gravity integrator would take the tilt error that stays for a gyro bias. A turn beyond
// integrator_hold_rate (30 deg of bank at 18 m/s: 18 deg/s) teaches none (2.5 deg/s at
// ArduPilot's 20 deg/s); a wider one (30 deg at 36 m/s: 9 deg/s) is not held, and
// calibrated still at the start a bias is only the gyro's drift since (GyroBias.h): the
// estimate stays within a quarter of bias_limit_rad_s on every axis (3.8 deg/s with the
// whole limit, rolling the estimate 31.8 deg off against 30.6).
struct TurnWithoutAirspeed {
    float worst_bias_rad_s = 0.0f, worst_roll_error_deg = 0.0f;
};
TurnWithoutAirspeed fly_turn_without_airspeed(float bank_deg, float v_m_s) {
    pipeline::AttitudePipeline pipe;
    const Turn t = coordinated_turn(bank_deg, v_m_s);
    TurnWithoutAirspeed out;
    start_banked(pipe, bank_deg, 0.0f);
    EXPECT_TRUE(pipe.estimator().gyro_bias_measured());
    for (int i = 0; i < 200 * 60; ++i) {
        pipe.on_imu_sample(imu(t.gyro_rad_s, t.accel_m_s2));
        const Vector3f b = pipe.estimator().gyro_bias_rad_s();
        out.worst_bias_rad_s = std::max({out.worst_bias_rad_s, std::fabs(b.x), std::fabs(b.y), std::fabs(b.z)});
        out.worst_roll_error_deg = std::max(out.worst_roll_error_deg, std::fabs(pipe.angles().roll_deg - bank_deg));
    }
    return out;
}

TEST(Centripetal, ATurnWithoutAnAirspeedTeachesNoBiasBeyondTheDrift) {
    const float drift_limit_rad_s = 0.25f * dcm::kDefaultDcmSettings.bias_limit_rad_s;
    const TurnWithoutAirspeed tight = fly_turn_without_airspeed(30.0f, 18.0f);
    EXPECT_LT(tight.worst_bias_rad_s, 0.1f * linalg::kRadPerDeg);
    EXPECT_LT(tight.worst_roll_error_deg, 31.0f);  // levelled, not beyond
    const TurnWithoutAirspeed wide = fly_turn_without_airspeed(30.0f, 36.0f);
    EXPECT_LE(wide.worst_bias_rad_s, drift_limit_rad_s + 1e-4f);
    EXPECT_GT(wide.worst_bias_rad_s, 0.9f * drift_limit_rad_s);  // the integrator did learn: to the bound
    EXPECT_LT(wide.worst_roll_error_deg, 31.0f);  // levelled, no further
}

}  // namespace
