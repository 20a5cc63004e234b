// SPDX-License-Identifier: GPL-3.0-or-later
// The airspeed sensor (lib/Pipeline/Airspeed.h): the MPXV7002DP's counts to airspeed, the
// start's choice of zero (ARSPD_OFFSET), the cruise speed of a board without one
// (TRIM_ARSPD_CM) and its growth in a banked turn.
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
    const uint16_t zero_counts = counts_at(0.0f);
    const uint16_t zero = airspeed::offset_of(8u * zero_counts, 8);  // ARSPD_OFFSET's unit
    EXPECT_EQ(zero, 4u * zero_counts);
    EXPECT_TRUE(airspeed::present(zero_counts));
    EXPECT_FALSE(airspeed::present(0));
    EXPECT_FALSE(airspeed::present(1023));
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * zero_counts, 8, zero), 0.0f);
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * (zero_counts - 3u), 8, zero), 0.0f);  // below the zero
    // A 10-bit reading resolves 4.9 Pa: 18 m/s (198 Pa) to within 0.3 m/s.
    EXPECT_NEAR(airspeed::airspeed_m_s(8u * counts_at(18.0f), 8, zero), 18.0f, 0.3f);
    EXPECT_NEAR(airspeed::airspeed_m_s(8u * counts_at(40.0f), 8, zero), 40.0f, 0.2f);
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(0u, 0, zero), 0.0f);
    // A zero no still sensor reads (ARSPD_OFFSET 0 after `defaults`, or set to 5 V): none.
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * counts_at(18.0f), 8, 0), 0.0f);
    EXPECT_FLOAT_EQ(airspeed::airspeed_m_s(8u * counts_at(18.0f), 8, 4000), 0.0f);
}

// ARSPD_OFFSET's unit: a quarter of a 10-bit count (ArduPilot's 12-bit counts of 5 V, 2048
// at 2.5 V); the mean of many readings keeps its quarters, rounded to the nearest.
TEST(AirspeedSensor, TheZeroInArduPilotsUnitKeepsQuarterCounts) {
    EXPECT_EQ(airspeed::offset_of(512u * 100u, 100), 2048u);
    EXPECT_EQ(airspeed::offset_of(512u * 99u + 513u, 100), 2048u);       // 512.01: 2048.04
    EXPECT_EQ(airspeed::offset_of(512u * 75u + 513u * 25u, 100), 2049u);  // 512.25
    EXPECT_EQ(airspeed::offset_of(512u * 50u + 513u * 50u, 100), 2050u);  // 512.5
    EXPECT_EQ(airspeed::offset_of(1023u * 4000u, 4000), 4092u);          // no overflow over a long calibration
    EXPECT_EQ(airspeed::offset_of(0u, 0), 0u);
    EXPECT_FALSE(airspeed::offset_present(0));
    EXPECT_TRUE(airspeed::offset_present(2048));
    EXPECT_FALSE(airspeed::offset_present(4u * 1023u));
    // A zero a quarter count off the reading's shifts 18 m/s by well under 0.1 m/s.
    EXPECT_NEAR(airspeed::airspeed_m_s(8u * counts_at(18.0f), 8, (uint16_t)(4u * counts_at(0.0f) + 1u)), 18.0f, 0.3f);
}

// The start's choice of zero (docs/flight.md "Airspeed"): a still start measures it and saves
// it only when it moved beyond the noise; a start in motion takes the saved one when a still
// sensor could have read it and the reading is not below it, else the cruise speed.
TEST(AirspeedSensor, AStartInMotionUsesTheSavedZeroAndAStillOneSavesOnlyAMovedOne) {
    using airspeed::StartZero;
    const uint16_t zero = (uint16_t)(4u * counts_at(0.0f));
    const uint16_t cruise = (uint16_t)(4u * counts_at(18.0f));  // 41 counts above the zero
    const uint16_t noise = airspeed::kOffsetNoise;
    EXPECT_EQ(noise, 8u);  // 2 counts
    // Still: none saved, or one beyond the noise either way, is saved; within it, kept.
    EXPECT_EQ(airspeed::start_zero(zero, true, 0), StartZero::kSave);
    EXPECT_EQ(airspeed::start_zero(zero, true, zero), StartZero::kKeep);
    EXPECT_EQ(airspeed::start_zero(zero, true, (uint16_t)(zero + noise)), StartZero::kKeep);
    EXPECT_EQ(airspeed::start_zero(zero, true, (uint16_t)(zero - noise)), StartZero::kKeep);
    EXPECT_EQ(airspeed::start_zero(zero, true, (uint16_t)(zero + noise + 1u)), StartZero::kSave);
    EXPECT_EQ(airspeed::start_zero(zero, true, (uint16_t)(zero - noise - 1u)), StartZero::kSave);
    // ... and a saved one no still sensor reads (set by hand) is replaced.
    EXPECT_EQ(airspeed::start_zero(zero, true, 4000), StartZero::kSave);
    // Still and outside 2.0-3.0 V: no sensor, whatever was saved.
    EXPECT_EQ(airspeed::start_zero(0, true, zero), StartZero::kNone);
    EXPECT_EQ(airspeed::start_zero(4u * 1023u, true, zero), StartZero::kNone);
    EXPECT_EQ(airspeed::start_zero(4u * 409u - 4u, true, 0), StartZero::kNone);
    // In motion at cruise: the saved zero; none saved, the cruise speed (today's words).
    EXPECT_EQ(airspeed::start_zero(cruise, false, zero), StartZero::kSaved);
    EXPECT_EQ(airspeed::start_zero(cruise, false, 0), StartZero::kCruise);
    // In motion but slow or still in fact (a reading within the noise of the saved zero): saved.
    EXPECT_EQ(airspeed::start_zero((uint16_t)(zero - noise), false, zero), StartZero::kSaved);
    // Fast, past 3.0 V (~31 m/s) but within the sensor's 4.5 V: the saved zero still.
    EXPECT_EQ(airspeed::start_zero((uint16_t)(4u * counts_at(35.0f)), false, zero), StartZero::kSaved);
    // A saved zero refused: one no still MPXV7002DP reads (out of 2.0-3.0 V) ...
    EXPECT_EQ(airspeed::start_zero(cruise, false, 4u * 300u), StartZero::kCruise);
    EXPECT_EQ(airspeed::start_zero(cruise, false, 4u * 700u), StartZero::kCruise);
    // ... or above the reading (a pitot reads no suction: another sensor's zero) ...
    EXPECT_EQ(airspeed::start_zero((uint16_t)(zero - noise - 1u), false, zero), StartZero::kCruise);
    // ... or a reading no sensor gives (an open input at 0 V, a rail at 5 V): no sensor.
    EXPECT_EQ(airspeed::start_zero(0, false, zero), StartZero::kNone);
    EXPECT_EQ(airspeed::start_zero(4u * 1023u, false, zero), StartZero::kNone);
    EXPECT_EQ(airspeed::start_zero(0, false, 0), StartZero::kNone);
}

// ARSPD_OFFSET: a parameter of the second record, 0 (none measured) by default, within a
// 12-bit count; a second record saved before it (2 bytes shorter) loads with it at 0.
TEST(AirspeedSensor, ArspdOffsetIsASavedParameterAbsentFromOlderRecords) {
    settings::Settings s = settings::defaults();
    const int16_t p = params::find("ARSPD_OFFSET");
    ASSERT_GE(p, 0);
    EXPECT_EQ(s.vehicle.arspd_offset, 0u);
    EXPECT_FALSE(params::set(s, (uint16_t)p, 4096.0f));
    EXPECT_FALSE(params::set(s, (uint16_t)p, 2048.5f));
    EXPECT_TRUE(params::set(s, (uint16_t)p, 2049.0f));
    EXPECT_EQ(s.vehicle.arspd_offset, 2049u);
    const uint8_t n = (uint8_t)params::vehicle_bytes();
    uint8_t bytes[244];
    params::vehicle_part(s, 0, n, bytes);
    settings::Settings back = settings::defaults();
    params::decode_vehicle(bytes, n, back);
    EXPECT_EQ(back.vehicle.arspd_offset, 2049u);
    // Where its two bytes lie (the first byte that differs from the defaults' record): a
    // record that ends before them is an earlier firmware's.
    uint8_t def[244];
    params::vehicle_part(settings::defaults(), 0, n, def);
    uint8_t at = 0;
    while (at < n && bytes[at] == def[at]) ++at;
    ASSERT_LE(at + 2u, (unsigned)n);
    EXPECT_EQ(bytes[at] | bytes[at + 1u] << 8, 2049);
    settings::Settings older = settings::defaults();
    params::decode_vehicle(bytes, at, older);
    EXPECT_EQ(older.vehicle.arspd_offset, 0u);
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
