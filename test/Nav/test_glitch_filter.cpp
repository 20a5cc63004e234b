// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Nav/GlitchFilter: AP_GPS_Glitch's rule, kRadius_m + 1/2 a t^2 from the prediction.
#include <gtest/gtest.h>

#include <math.h>

#include "GlitchFilter.h"

namespace {

const nav::Location kField = [] {
    nav::Location l;
    l.lat_e7 = 71350450;
    l.lon_e7 = -731194210;
    l.alt_cm = 102800;
    return l;
}();

class GlitchFilterTest : public ::testing::Test {
protected:
    // A fix at (north, east) metres from the field at t_ms, flying at vel.
    bool fix(float north_m, float east_m, uint32_t t_ms, nav::NorthEast vel = {20.0f, 0.0f}) {
        return filter.check(map.moved(kField, north_m, east_m), vel, t_ms, map);
    }
    nav::LocalMap map{kField};
    nav::GlitchFilter filter;
};

TEST_F(GlitchFilterTest, StraightFlightAt5HzIsGood) {
    for (uint32_t i = 0; i < 50; ++i) EXPECT_TRUE(fix(4.0f * (float)i, 0.0f, 1000u + 200u * i)) << i;
    EXPECT_FALSE(filter.glitching());
    EXPECT_EQ(filter.rejected(), 0u);
}

TEST_F(GlitchFilterTest, ATurnAtOneGIsGood) {
    // 20 m/s in a 45 deg bank: 9.8 m/s^2 towards the centre, radius 40.8 m.
    const float r = 400.0f / 9.81f, w = 20.0f / r;
    for (uint32_t i = 0; i < 60; ++i) {
        const float a = w * 0.2f * (float)i;
        EXPECT_TRUE(fix(r * sinf(a), r - r * cosf(a), 200u * i, {20.0f * cosf(a), 20.0f * sinf(a)})) << i;
    }
}

TEST_F(GlitchFilterTest, AJumpIsRejectedUntilItsTimeOrAGoodFix) {
    ASSERT_TRUE(fix(0.0f, 0.0f, 0u, {0.0f, 0.0f}));
    // 2.5 m after 0.2 s: more than 2 m + 0.2 m.
    EXPECT_FALSE(fix(2.5f, 0.0f, 200u, {0.0f, 0.0f}));
    EXPECT_TRUE(filter.glitching());
    EXPECT_NEAR(filter.distance_m(), 2.5f, 0.01f);
    // Back where it was: good again.
    EXPECT_TRUE(fix(0.1f, 0.0f, 400u, {0.0f, 0.0f}));
    EXPECT_FALSE(filter.glitching());
    // A 50 m jump: rejected while 2 + 5 t^2 < 50 (t < 3.10 s after the good fix at 400 ms),
    // taken after.
    for (uint32_t t = 600; t <= 3400; t += 200) EXPECT_FALSE(fix(50.0f, 0.0f, t, {0.0f, 0.0f})) << t;
    EXPECT_TRUE(fix(50.0f, 0.0f, 3600u, {0.0f, 0.0f}));
    EXPECT_EQ(filter.rejected(), 1u + 15u);
}

TEST_F(GlitchFilterTest, PredictsWithTheLastGoodVelocity) {
    ASSERT_TRUE(fix(0.0f, 0.0f, 0u, {0.0f, 20.0f}));
    // 1 s later, 20 m east is where it should be; 20 m north is not (28 m off > 7 m).
    EXPECT_TRUE(fix(0.0f, 21.0f, 1000u, {0.0f, 20.0f}));
    EXPECT_FALSE(fix(20.0f, 21.0f, 2000u, {0.0f, 20.0f}));
}

TEST_F(GlitchFilterTest, AnyFixAfterTheTimeOut) {
    ASSERT_TRUE(fix(0.0f, 0.0f, 0u, {0.0f, 0.0f}));
    EXPECT_FALSE(fix(2000.0f, 0.0f, 9800u, {0.0f, 0.0f}));  // 2 km: 2 + 5 * 9.8^2 = 482 m
    EXPECT_TRUE(fix(2000.0f, 0.0f, 10000u, {0.0f, 0.0f}));
    // reset(): the next is taken as it is.
    filter.reset();
    EXPECT_TRUE(fix(-3000.0f, 0.0f, 10200u, {0.0f, 0.0f}));
}

}  // namespace
