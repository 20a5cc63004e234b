// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/Wind: the ground velocity less the air's velocity along the fuselage, low-passed.
#include <gtest/gtest.h>

#include <cmath>

#include "Wind.h"

namespace {

constexpr float kDegToRad = (float)(M_PI / 180.0);

TEST(Wind, AWindFromTheWestOnEveryHeading) {
    // 5 m/s from 270 deg (blowing east), 18 m/s of air, the plane circling.
    nav::WindEstimator w;
    for (int i = 0; i < 400; ++i) {
        const float heading = (float)(i * 3 % 360) * kDegToRad;
        const nav::NorthEast ground = {18.0f * cosf(heading), 18.0f * sinf(heading) + 5.0f};
        w.update(ground, 18.0f, heading, 0.0f, 0.2f);
    }
    ASSERT_TRUE(w.valid());
    EXPECT_NEAR(w.wind_m_s().north_m, 0.0f, 0.01f);
    EXPECT_NEAR(w.wind_m_s().east_m, 5.0f, 0.01f);
    EXPECT_NEAR(w.speed_m_s(), 5.0f, 0.01f);
    EXPECT_NEAR(w.from_deg(), 270.0f, 0.2f);
}

TEST(Wind, PitchShortensTheAirVector) {
    nav::WindEstimator w;
    // Climbing at 20 deg into still air, heading north: ground speed 18 cos 20.
    w.update({18.0f * cosf(20.0f * kDegToRad), 0.0f}, 18.0f, 0.0f, 20.0f * kDegToRad, 0.2f);
    EXPECT_NEAR(w.speed_m_s(), 0.0f, 1e-4f);
}

TEST(Wind, LowPassWithItsTimeConstant) {
    nav::WindEstimator w;
    w.update({10.0f, 0.0f}, 10.0f, 0.0f, 0.0f, 0.2f);  // still air first
    ASSERT_NEAR(w.speed_m_s(), 0.0f, 1e-5f);
    // A 4 m/s wind from the south appears: after one time constant, 63 % of it.
    float t = 0.0f;
    while (t < nav::WindEstimator::kTimeConstant_s - 1e-3f) {
        w.update({14.0f, 0.0f}, 10.0f, 0.0f, 0.0f, 0.2f);
        t += 0.2f;
    }
    EXPECT_NEAR(w.wind_m_s().north_m, 4.0f * (1.0f - expf(-1.0f)), 0.03f);
    EXPECT_NEAR(w.from_deg(), 180.0f, 0.01f);
}

TEST(Wind, NothingLearntSlowOrOnBadInput) {
    nav::WindEstimator w;
    w.update({3.0f, 0.0f}, 4.0f, 0.0f, 0.0f, 0.2f);  // below kMinAirspeed_m_s
    EXPECT_FALSE(w.valid());
    w.update({3.0f, 0.0f}, NAN, 0.0f, 0.0f, 0.2f);
    w.update({NAN, 0.0f}, 12.0f, 0.0f, 0.0f, 0.2f);
    w.update({3.0f, 0.0f}, 12.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_FALSE(w.valid());
    EXPECT_EQ(w.speed_m_s(), 0.0f);
}

TEST(Wind, TrueAirspeedAtTheField) {
    // ISA at 1028 m: 89 870 Pa, 8.3 degC: rho 1.113 kg/m^3, TAS/EAS 1.049.
    EXPECT_NEAR(nav::eas_to_tas(89870.0f, 8.32f), 1.049f, 0.002f);
    EXPECT_NEAR(nav::eas_to_tas(101325.0f, 15.0f), 1.0f, 0.001f);
    EXPECT_EQ(nav::eas_to_tas(0.0f, 15.0f), 1.0f);  // no barometer: EAS taken as TAS
    EXPECT_EQ(nav::eas_to_tas(NAN, 15.0f), 1.0f);
}

}  // namespace
