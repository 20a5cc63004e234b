// SPDX-License-Identifier: GPL-3.0-or-later
// The centripetal correction of the accelerometer from the airspeed (lib/Pipeline,
// issue 24 item 3): gravity at the bank in a coordinated turn, off below the minimum
// airspeed, clamped at the extremes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Airspeed.h"
#include "Params.h"
#include "Pipeline.h"

namespace {

using linalg::Vector3f;
using linalg::Vector3i;

constexpr float kG = 9.80665f;
constexpr float kDeg = 3.14159265f / 180.0f;

mpu6000::Sample imu(const Vector3f& gyro, const Vector3f& accel) { return mpu6000::sample_from_si(gyro, accel, 25.0f); }

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

TEST(Centripetal, CoordinatedTurnCorrectedToGravityAtTheBank) {
    for (float bank : {-45.0f, -30.0f, 10.0f, 30.0f, 60.0f}) {
        for (float v : {12.0f, 18.0f, 30.0f}) {
            const Turn t = coordinated_turn(bank, v);
            const mpu6000::Sample s = imu(t.gyro_rad_s, t.accel_m_s2);
            // The estimate at the true bank: the bank provides the whole turn.
            const int32_t down_y_q30 = (int32_t)std::lround(std::sin(bank * kDeg) * 1073741824.0);
            const Vector3i c = pipeline::centripetal_corrected(s.accel, s.gyro.y, s.gyro.z,
                                                               pipeline::centripetal_gain_q8(v),
                                                               pipeline::turn_lateral_bounds(s.accel.y, down_y_q30));
            const Vector3f f = linalg::scaled(c, s.accel_m_s2_per_count);
            // Gravity at the bank: -g (0, sin phi, cos phi).
            EXPECT_NEAR(f.x, 0.0f, 0.01f);
            EXPECT_NEAR(f.y, -kG * std::sin(bank * kDeg), 0.03f) << bank << " deg at " << v << " m/s";
            EXPECT_NEAR(f.z, -kG * std::cos(bank * kDeg), 0.03f) << bank << " deg at " << v << " m/s";
            EXPECT_NEAR(std::atan2(-f.y, -f.z) / kDeg, bank, 0.2f);
        }
    }
}

int32_t down_y_q30_at(float bank_deg) { return (int32_t)std::lround(std::sin(bank_deg * kDeg) * 1073741824.0); }

// Wings level, yawing at 20 deg/s (turbulence turning the aeroplane into the relative
// wind): no bank provides that turn, so at most kTurnBankMargin_deg of it is taken off
// (unbounded it would be 6.3 m/s^2, 33 deg of false bank).
TEST(Centripetal, AYawRateWithoutTheBankIsHeldToTheMargin) {
    const float v = 18.0f;
    for (float sign : {1.0f, -1.0f}) {
        const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, sign * 20.0f * kDeg), Vector3f(0.0f, 0.0f, -kG));
        const Vector3i c = pipeline::centripetal_corrected(s.accel, s.gyro.y, s.gyro.z, pipeline::centripetal_gain_q8(v),
                                                           pipeline::turn_lateral_bounds(s.accel.y, 0));
        const Vector3f f = linalg::scaled(c, s.accel_m_s2_per_count);
        const float false_bank_deg = std::atan2(-f.y, -f.z) / kDeg;
        EXPECT_NEAR(false_bank_deg, sign * pipeline::kTurnBankMargin_deg, 0.05f) << sign;
    }
}

// An estimate 10 deg short of a 30 deg coordinated turn's bank: the corrected gravity says
// the estimate's bank plus the margin, so the estimate is pulled on toward the truth.
TEST(Centripetal, AnEstimateShortOfTheBankIsPulledOnByTheMargin) {
    const float v = 18.0f;
    const Turn t = coordinated_turn(30.0f, v);
    const mpu6000::Sample s = imu(t.gyro_rad_s, t.accel_m_s2);
    const Vector3i c = pipeline::centripetal_corrected(s.accel, s.gyro.y, s.gyro.z, pipeline::centripetal_gain_q8(v),
                                                       pipeline::turn_lateral_bounds(s.accel.y, down_y_q30_at(20.0f)));
    const Vector3f f = linalg::scaled(c, s.accel_m_s2_per_count);
    // The lateral term is g sin(20 deg) + g sin(margin); the normal one is whole.
    EXPECT_NEAR(f.y, -kG * (std::sin(20.0f * kDeg) + std::sin(pipeline::kTurnBankMargin_deg * kDeg)), 0.02f);
    EXPECT_GT(std::atan2(-f.y, -f.z) / kDeg, 20.0f);
    // A bank on the other side from the turn gives no room but the margin.
    const pipeline::LateralBounds other = pipeline::turn_lateral_bounds(0, down_y_q30_at(-20.0f));
    const pipeline::LateralBounds level = pipeline::turn_lateral_bounds(0, 0);
    EXPECT_EQ(other.hi, level.hi);
    EXPECT_LT(other.lo, level.lo);
}

// A flat skidding turn (wings level, the rudder's sideforce turning the path): the
// accelerometer reads the whole omega_z V sideways, so all of it is taken off: level.
TEST(Centripetal, AFlatSkidTurnIsTakenOffWhole) {
    const float v = 18.0f, rate_rad_s = 10.0f * kDeg;
    const mpu6000::Sample s = imu(Vector3f(0.0f, 0.0f, rate_rad_s), Vector3f(0.0f, rate_rad_s * v, -kG));
    const Vector3i c = pipeline::centripetal_corrected(s.accel, s.gyro.y, s.gyro.z, pipeline::centripetal_gain_q8(v),
                                                       pipeline::turn_lateral_bounds(s.accel.y, 0));
    const Vector3f f = linalg::scaled(c, s.accel_m_s2_per_count);
    EXPECT_NEAR(std::atan2(-f.y, -f.z) / kDeg, 0.0f, 0.1f);
}

TEST(Centripetal, OffBelowTheMinimumAirspeedAndWithoutOne) {
    EXPECT_EQ(pipeline::centripetal_gain_q8(0.0f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(pipeline::kCentripetalMinAirspeed_m_s - 0.01f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(-20.0f), 0);
    EXPECT_EQ(pipeline::centripetal_gain_q8(NAN), 0);
    EXPECT_GT(pipeline::centripetal_gain_q8(pipeline::kCentripetalMinAirspeed_m_s), 0);
    const Vector3i a(100, -2000, -4000);
    const Vector3i c = pipeline::centripetal_corrected(a, 3000, -3000, 0);
    EXPECT_EQ(c.x, a.x);
    EXPECT_EQ(c.y, a.y);
    EXPECT_EQ(c.z, a.z);
}

TEST(Centripetal, ExtremesClampedWithoutOverflow) {
    const int16_t top = pipeline::centripetal_gain_q8(pipeline::kCentripetalMaxAirspeed_m_s);
    EXPECT_EQ(pipeline::centripetal_gain_q8(1000.0f), top);
    EXPECT_EQ(pipeline::centripetal_gain_q8(INFINITY), top);
    // Full-scale rates at the top airspeed, the correction against the sample: each axis
    // saturates at the far side, none wraps. y loses omega_z V, z gains omega_y V.
    Vector3i c = pipeline::centripetal_corrected(Vector3i(0, 32767, -32767), -32767, 32767, top);
    EXPECT_EQ(c.y, -32767);
    EXPECT_EQ(c.z, -32767);
    c = pipeline::centripetal_corrected(Vector3i(0, -32767, -32767), 32767, -32767, top);
    EXPECT_EQ(c.y, 32767);
    EXPECT_EQ(c.z, 32767);
    // The same rates with the sample on their side: still saturated, not wrapped.
    c = pipeline::centripetal_corrected(Vector3i(0, -32767, 32767), 32767, 32767, top);
    EXPECT_EQ(c.y, -32767);
    EXPECT_EQ(c.z, 32767);
}

// The pipeline holds the bank of a long coordinated turn with the airspeed; without it
// the estimate levels (the turn's lift taken for gravity).
float bank_after_turn(float airspeed_given_m_s) {
    const float bank = 30.0f, v = 18.0f;
    pipeline::AttitudePipeline pipe;
    const Turn t = coordinated_turn(bank, v);
    const Vector3f still(0.0f, -kG * std::sin(bank * kDeg), -kG * std::cos(bank * kDeg));
    for (int i = 0; i < 400; ++i) pipe.on_imu_sample(imu(Vector3f(), still));
    EXPECT_EQ(pipe.phase(), pipeline::Phase::Running);
    pipe.set_airspeed_m_s(airspeed_given_m_s);
    for (int i = 0; i < 200 * 60; ++i) pipe.on_imu_sample(imu(t.gyro_rad_s, t.accel_m_s2));
    return pipe.angles().roll_deg;
}

// Wings level in turbulence: the gusts yaw the aeroplane +-15 deg/s (0.2 Hz) while the
// path and the accelerometer stay level. Each half cycle's 2.5 s of yaw moves the
// estimate at most the margin beyond where it is at a time: it stays within a few
// degrees (the whole omega_z V, unbounded, rolls it 18 deg).
TEST(Centripetal, PipelineKeepsTheWingsLevelWhenGustsYawTheAeroplane) {
    pipeline::AttitudePipeline pipe;
    const Vector3f level(0.0f, 0.0f, -kG);
    for (int i = 0; i < 400; ++i) pipe.on_imu_sample(imu(Vector3f(), level));
    ASSERT_EQ(pipe.phase(), pipeline::Phase::Running);
    pipe.set_airspeed_m_s(18.0f);
    float worst_roll_deg = 0.0f;
    for (int i = 0; i < 200 * 30; ++i) {
        const float yaw_rate_rad_s = 15.0f * kDeg * std::sin(2.0f * 3.14159265f * 0.2f * i / 200.0f);
        pipe.on_imu_sample(imu(Vector3f(0.0f, 0.0f, yaw_rate_rad_s), level));
        worst_roll_deg = std::max(worst_roll_deg, std::fabs(pipe.angles().roll_deg));
    }
    EXPECT_LT(worst_roll_deg, 2.0f * pipeline::kTurnBankMargin_deg);
}

TEST(Centripetal, PipelineHoldsTheBankOfATurnWithTheAirspeed) {
    EXPECT_NEAR(bank_after_turn(18.0f), 30.0f, 1.0f);
    EXPECT_LT(bank_after_turn(0.0f), 25.0f);  // the baseline: levelled without it
    EXPECT_LT(bank_after_turn(8.0f), 25.0f);  // below the minimum: no correction
}

}  // namespace

namespace {

// The MPXV7002DP's counts for an airspeed (the simulator's model: 2.5 V + 1 V/kPa).
uint16_t counts_at(float v_m_s) {
    const float mV = 2500.0f + 0.5f * 1.225f * v_m_s * v_m_s;
    return (uint16_t)(mV / 5000.0f * 1024.0f + 0.5f);
}

TEST(AirspeedSensor, CountsToAirspeedWithTheMeasuredZero) {
    const uint16_t zero = counts_at(0.0f);
    EXPECT_TRUE(airspeed::present(zero));
    EXPECT_FALSE(airspeed::present(0));
    EXPECT_FALSE(airspeed::present(1023));
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * zero, 8, zero), 0.0f);
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * (zero - 3u), 8, zero), 0.0f);  // below the zero
    // A 10-bit reading resolves 4.9 Pa: 18 m/s (198 Pa) to within 0.3 m/s.
    EXPECT_NEAR(airspeed::airspeed_m_s(8u * counts_at(18.0f), 8, zero), 18.0f, 0.3f);
    EXPECT_NEAR(airspeed::airspeed_m_s(8u * counts_at(40.0f), 8, zero), 40.0f, 0.2f);
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(0u, 0, zero), 0.0f);
}

}  // namespace

namespace {

// The cruise speed of a board without a sensor (TRIM_ARSPD_CM): off by default, in cm/s
// within ArduPlane's 0..5000, kept by the settings record.
TEST(AirspeedSensor, TrimAirspeedParameterDefaultsOffAndRoundTrips) {
    settings::Settings s = settings::defaults();
    const int16_t p = params::find("TRIM_ARSPD_CM");
    ASSERT_GE(p, 0);
    EXPECT_EQ(s.flight.trim_arspd_cm, 0u);
    EXPECT_FALSE(params::set(s, (uint16_t)p, 5001.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)p, -1.0f));
    EXPECT_TRUE(params::set(s, (uint16_t)p, 1800.0f));
    uint8_t bytes[settings::kFlightBytes];
    params::encode_flight(s, bytes);
    settings::Settings back = settings::defaults();
    params::decode_flight(bytes, back);
    EXPECT_EQ(back.flight.trim_arspd_cm, 1800u);
}

}  // namespace

namespace {

// A configured cruise speed in a banked turn: level it is the trim; at 30 deg of bank
// the lift needs sqrt(1 / cos 30) of it (7.5 % more); beyond 60 deg it stays at sqrt(2);
// an upside-down estimate (down_z < 0) is held there too.
TEST(AirspeedSensor, ACruiseSpeedGrowsWithTheTurnsLoadFactor) {
    EXPECT_FLOAT_EQ(airspeed::cruise_in_turn_m_s(18.0f, 1.0f), 18.0f);
    EXPECT_FLOAT_EQ(airspeed::cruise_in_turn_m_s(18.0f, 1.0001f), 18.0f);
    EXPECT_NEAR(airspeed::cruise_in_turn_m_s(18.0f, std::cos(30.0f * linalg::kRadPerDeg)), 18.0f * 1.0746f, 0.01f);
    EXPECT_NEAR(airspeed::cruise_in_turn_m_s(18.0f, 0.2f), 18.0f * std::sqrt(2.0f), 1e-4f);
    EXPECT_NEAR(airspeed::cruise_in_turn_m_s(18.0f, -1.0f), 18.0f * std::sqrt(2.0f), 1e-4f);
}

}  // namespace
