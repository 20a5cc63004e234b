// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MavLink/StreamRates: REQUEST_DATA_STREAM's groups, their periods, the link's budget.
#include <gtest/gtest.h>

#include "StreamRates.h"

namespace {

using mav::StreamRates;

TEST(StreamRates, DefaultsAreTheFixedRates) {
    StreamRates r;
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 5u);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 5u);
    EXPECT_EQ(r.period_ms(mav::kGroupRcChan), 200u);
    EXPECT_EQ(r.bytes_per_s(), 5u * (28u + 87u));
}

TEST(StreamRates, RequestSetsOneGroup) {
    StreamRates r;
    EXPECT_TRUE(r.request(mav::kDataStreamRcChannels, 2, 1, 0));
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 2u);
    EXPECT_EQ(r.period_ms(mav::kGroupRcChan), 500u);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 5u);
    EXPECT_TRUE(r.request(mav::kDataStreamRawSensors, 10, 1, 0));
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 10u);
    EXPECT_EQ(r.period_ms(mav::kGroupRawSens), 100u);
}

TEST(StreamRates, StopByRateOrStartStop) {
    StreamRates r;
    r.request(mav::kDataStreamRcChannels, 0, 1, 0);
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 0u);
    EXPECT_EQ(r.period_ms(mav::kGroupRcChan), 0u);
    r.request(mav::kDataStreamRawSensors, 4, 0, 0);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 0u);
    r.request(mav::kDataStreamRcChannels, 3, 1, 0);  // started again
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 3u);
}

TEST(StreamRates, AllSetsEveryGroup) {
    StreamRates r;
    EXPECT_TRUE(r.request(mav::kDataStreamAll, 2, 1, 0));
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 2u);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 2u);
    r.request(mav::kDataStreamAll, 2, 0, 0);
    EXPECT_EQ(r.bytes_per_s(), 0u);
}

TEST(StreamRates, OtherStreamsNotTaken) {
    StreamRates r;
    for (uint8_t id : {2, 4, 6, 10, 11, 12, 200}) EXPECT_FALSE(r.request(id, 1, 1, 0)) << (int)id;
    EXPECT_EQ(r.hz(mav::kGroupRcChan), 5u);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 5u);
}

TEST(StreamRates, CappedToArduPilotsRange) {
    StreamRates r;
    r.request(mav::kDataStreamRawSensors, 400, 1, 0);
    EXPECT_EQ(r.hz(mav::kGroupRawSens), 50u);  // 1400 B/s: fits; 50 Hz is SRn_'s top
}

TEST(StreamRates, CappedToTheLink) {
    StreamRates r;
    // Beside 50 Hz of ATTITUDE (2000 B/s) and SCALED_PRESSURE at 5 Hz (140 B/s), RC_CHAN's
    // 87 bytes fit (8640 - 2140) / 87 = 74 times: 50 Hz (SRn_'s top) fits.
    EXPECT_EQ(r.set(mav::kGroupRcChan, 50, 2000), 50u);
    // Beside 100 Hz of ATTITUDE and more (5000 B/s): (8640 - 5000 - 140) / 87 = 40 Hz.
    EXPECT_EQ(r.set(mav::kGroupRcChan, 50, 5000), 40u);
    EXPECT_LE(5000u + r.bytes_per_s(), mav::kLinkBudgetBytesPerS);
    EXPECT_GT(5000u + r.bytes_per_s() + 87u, mav::kLinkBudgetBytesPerS);  // one more would not fit
    // A link already full: off.
    EXPECT_EQ(r.set(mav::kGroupRawSens, 5, 9000), 0u);
    // A group's old rate does not count against its new one.
    StreamRates s;
    EXPECT_EQ(s.set(mav::kGroupRcChan, 40, 5000), 40u);
    EXPECT_EQ(s.set(mav::kGroupRcChan, 40, 5000), 40u);
}

TEST(StreamRates, BudgetLeavesAQuarter) {
    EXPECT_EQ(mav::kLinkBytesPerS, 11520u);
    EXPECT_EQ(mav::kLinkBudgetBytesPerS, 8640u);
}

}  // namespace
