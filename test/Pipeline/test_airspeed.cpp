// SPDX-License-Identifier: GPL-3.0-or-later
// The airspeed sensor (lib/Pipeline/Airspeed.h): the MPXV7002DP's counts to airspeed, the
// cruise speed of a board without one (TRIM_ARSPD_CM) and its growth in a banked turn.
#include <gtest/gtest.h>

#include <cmath>

#include "Airspeed.h"
#include "Params.h"
#include "Settings.h"

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

// The cruise speed of a board without a sensor (TRIM_ARSPD_CM): on by default (a default
// of 0 spirals in sustained turns), in cm/s within ArduPlane's 0..5000, kept by the record.
TEST(AirspeedSensor, TrimAirspeedParameterDefaultsOnAndRoundTrips) {
    settings::Settings s = settings::defaults();
    const int16_t p = params::find("TRIM_ARSPD_CM");
    ASSERT_GE(p, 0);
    EXPECT_EQ(s.flight.trim_arspd_cm, 1500u);
    EXPECT_FALSE(params::set(s, (uint16_t)p, 5001.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)p, -1.0f));
    EXPECT_TRUE(params::set(s, (uint16_t)p, 1800.0f));
    uint8_t bytes[settings::kFlightBytes];
    params::encode_flight(s, bytes);
    settings::Settings back = settings::defaults();
    params::decode_flight(bytes, settings::kFlightBytes, back);
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
