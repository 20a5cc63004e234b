// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MavLink/StreamRates: ArduPlane's stream groups, REQUEST_DATA_STREAM onto the SR0_
// rates, SET/GET_MESSAGE_INTERVAL, the timers, the link's cap; the SR0_ parameter rows.
#include <gtest/gtest.h>

#include <string.h>

#include "MavLink.h"
#include "Params.h"
#include "Settings.h"
#include "StreamRates.h"

namespace {

using mav::StreamRates;

// The SR0_ defaults: the rates the board sent before they existed.
struct Sr0 {
    uint8_t hz[mav::kStreamGroups] = {5, 1, 5, 4, 50, 4, 1, 10};
};

uint16_t ms(const StreamRates& r, mav::StreamMsg m) { return r.interval_ms(m); }

TEST(StreamRates, GroupsAreArduPlanes) {
    EXPECT_EQ(mav::group_of_data_stream(1), mav::kGroupRawSens);
    EXPECT_EQ(mav::group_of_data_stream(2), mav::kGroupExtStat);
    EXPECT_EQ(mav::group_of_data_stream(3), mav::kGroupRcChan);
    EXPECT_EQ(mav::group_of_data_stream(6), mav::kGroupPosition);
    EXPECT_EQ(mav::group_of_data_stream(10), mav::kGroupExtra1);
    EXPECT_EQ(mav::group_of_data_stream(11), mav::kGroupExtra2);
    EXPECT_EQ(mav::group_of_data_stream(12), mav::kGroupExtra3);
    EXPECT_EQ(mav::group_of_data_stream(0), mav::kStreamGroups);   // ALL: not one group
    EXPECT_EQ(mav::group_of_data_stream(4), mav::kStreamGroups);   // RAW_CONTROLLER: nothing sent
    EXPECT_EQ(mav::group_of_data_stream(13), mav::kStreamGroups);
    for (uint8_t unknown : {5, 7, 8, 9, 255}) EXPECT_EQ(mav::group_of_data_stream(unknown), mav::kStreamGroups);
    // Each message the board sends on a timer, by its MAVLink id.
    EXPECT_EQ(mav::stream_msg_of(29), mav::kStreamScaledPressure);
    EXPECT_EQ(mav::stream_msg_of(1), mav::kStreamSysStatus);
    EXPECT_EQ(mav::stream_msg_of(24), mav::kStreamGpsRawInt);
    EXPECT_EQ(mav::stream_msg_of(65), mav::kStreamRcChannels);
    EXPECT_EQ(mav::stream_msg_of(36), mav::kStreamServoOutputRaw);
    EXPECT_EQ(mav::stream_msg_of(33), mav::kStreamGlobalPositionInt);
    EXPECT_EQ(mav::stream_msg_of(30), mav::kStreamAttitude);
    EXPECT_EQ(mav::stream_msg_of(74), mav::kStreamVfrHud);
    EXPECT_EQ(mav::stream_msg_of(2), mav::kStreamSystemTime);
    EXPECT_EQ(mav::stream_msg_of(147), mav::kStreamBatteryStatus);
    EXPECT_EQ(mav::stream_msg_of(42), mav::kStreamMissionCurrent);
    EXPECT_EQ(mav::stream_msg_of(0), mav::kStreamMsgs);    // HEARTBEAT: 1 Hz, not a stream
    EXPECT_EQ(mav::stream_msg_of(27), mav::kStreamMsgs);   // RAW_IMU: not sent by the board
    EXPECT_EQ(mav::stream_msg_of(65536u + 30u), mav::kStreamMsgs);
}

TEST(StreamRates, DefaultsPlanTheRatesTheBoardSent) {
    StreamRates r;
    Sr0 s;
    r.plan(s.hz, 50);
    EXPECT_EQ(ms(r, mav::kStreamScaledPressure), 200u);
    EXPECT_EQ(ms(r, mav::kStreamSysStatus), 1000u);
    EXPECT_EQ(ms(r, mav::kStreamGpsRawInt), 1000u);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), 200u);
    EXPECT_EQ(ms(r, mav::kStreamServoOutputRaw), 200u);
    EXPECT_EQ(ms(r, mav::kStreamGlobalPositionInt), 250u);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 20u);
    EXPECT_EQ(ms(r, mav::kStreamVfrHud), 250u);
    EXPECT_EQ(ms(r, mav::kStreamSystemTime), 1000u);
    EXPECT_EQ(ms(r, mav::kStreamBatteryStatus), 1000u);
    EXPECT_EQ(ms(r, mav::kStreamMissionCurrent), 1000u);  // SR0_EXT_STAT's, as ArduPlane's
    EXPECT_LT(r.bytes_per_s(), mav::kLinkBudgetBytesPerS);
}

TEST(StreamRates, AttitudeNoMoreOftenThanTheConsolesRate) {
    StreamRates r;
    Sr0 s;
    r.plan(s.hz, 10);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 100u);
    // Every line, whatever the board's clock says (the lines keep the MPU6000's).
    for (uint32_t t = 5000; t < 5100; t += 10) EXPECT_TRUE(r.take(mav::kStreamAttitude, t)) << t;
    s.hz[mav::kGroupExtra1] = 4;
    r.plan(s.hz, 10);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 250u);
    EXPECT_TRUE(r.take(mav::kStreamAttitude, 6000));
    EXPECT_FALSE(r.take(mav::kStreamAttitude, 6100));
    EXPECT_TRUE(r.take(mav::kStreamAttitude, 6250));
    s.hz[mav::kGroupExtra1] = 0;
    r.plan(s.hz, 10);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 0u);
}

TEST(StreamRates, RequestSetsOneGroupOrAllButParams) {
    Sr0 s;
    uint8_t set = 0;
    EXPECT_TRUE(mav::apply_data_stream_request(s.hz, 3, 2, 1, &set));
    EXPECT_EQ(set, 1u << mav::kGroupRcChan);
    EXPECT_EQ(s.hz[mav::kGroupRcChan], 2u);
    EXPECT_EQ(s.hz[mav::kGroupRawSens], 5u);
    // The same again: nothing changed, nothing to save (set_and_save_ifchanged).
    EXPECT_FALSE(mav::apply_data_stream_request(s.hz, 3, 2, 1, &set));
    EXPECT_EQ(set, 1u << mav::kGroupRcChan);
    // start_stop 0 stops, whatever the rate.
    EXPECT_TRUE(mav::apply_data_stream_request(s.hz, 12, 7, 0, &set));
    EXPECT_EQ(s.hz[mav::kGroupExtra3], 0u);
    // ALL: every group but PARAMS, 50 Hz at most.
    EXPECT_TRUE(mav::apply_data_stream_request(s.hz, 0, 300, 1, &set));
    EXPECT_EQ(set, 0x7Fu);
    for (uint8_t g = 0; g < mav::kGroupParams; ++g) EXPECT_EQ(s.hz[g], 50u) << (int)g;
    EXPECT_EQ(s.hz[mav::kGroupParams], 10u);
    // Unknown streams and start_stop values: nothing.
    Sr0 before;
    memcpy(before.hz, s.hz, sizeof s.hz);
    EXPECT_FALSE(mav::apply_data_stream_request(s.hz, 4, 3, 1, &set));
    EXPECT_EQ(set, 0u);
    EXPECT_FALSE(mav::apply_data_stream_request(s.hz, 1, 3, 2, &set));
    EXPECT_EQ(set, 0u);
    EXPECT_EQ(memcmp(before.hz, s.hz, sizeof s.hz), 0);
}

TEST(StreamRates, TheLinksCapStretchesEveryIntervalAlike) {
    StreamRates r;
    Sr0 s;
    for (uint8_t g = 0; g < mav::kGroupParams; ++g) s.hz[g] = 50;
    r.plan(s.hz, 100);
    // Asked: ~20 kB/s; given: within the budget, each message's share alike.
    EXPECT_LE(r.bytes_per_s(), mav::kLinkBudgetBytesPerS - mav::kHeartbeatFrame);
    EXPECT_GT(r.bytes_per_s(), mav::kLinkBudgetBytesPerS * 9u / 10u);
    EXPECT_GT(ms(r, mav::kStreamAttitude), 20u);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), ms(r, mav::kStreamAttitude));
    EXPECT_EQ(ms(r, mav::kStreamSystemTime), ms(r, mav::kStreamAttitude));
    // One group at 50 Hz beside the defaults fits: no stretch.
    Sr0 d;
    d.hz[mav::kGroupRcChan] = 50;
    r.plan(d.hz, 50);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), 20u);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 20u);
    // ... and beside ATTITUDE at 100 Hz (SET_MESSAGE_INTERVAL and `rate 100`), with the
    // others at 50: stretched.
    for (uint8_t g = 0; g < mav::kGroupParams; ++g) d.hz[g] = 50;
    EXPECT_EQ(r.set_interval(30, 10000.0f), mav::Result::Accepted);
    r.plan(d.hz, 100);
    EXPECT_LE(r.bytes_per_s(), mav::kLinkBudgetBytesPerS - mav::kHeartbeatFrame);
    EXPECT_GT(ms(r, mav::kStreamAttitude), 10u);
    EXPECT_GT(ms(r, mav::kStreamRcChannels), 20u);
}

TEST(StreamRates, TimersKeepTheRateAndNeverBurst) {
    StreamRates r;
    Sr0 s;
    r.plan(s.hz, 50);
    // RC_CHANNELS at 200 ms, checked every 3 ms for 10 s: 50 sends, none closer than 197 ms.
    uint32_t last = 0;
    int sends = 0;
    for (uint32_t t = 1000; t < 11000; t += 3) {
        if (r.take(mav::kStreamRcChannels, t)) {
            if (sends > 0) EXPECT_GE(t - last, 197u) << t;
            last = t;
            ++sends;
        }
    }
    EXPECT_EQ(sends, 50);
    // Not served for 5 s (the text console): one send, then the rate again.
    EXPECT_TRUE(r.take(mav::kStreamRcChannels, 16000));
    EXPECT_FALSE(r.take(mav::kStreamRcChannels, 16001));
    EXPECT_FALSE(r.take(mav::kStreamRcChannels, 16199));
    EXPECT_TRUE(r.take(mav::kStreamRcChannels, 16200));
    // A shorter interval does not wait out the old one.
    s.hz[mav::kGroupExtra3] = 0;
    r.plan(s.hz, 50);
    EXPECT_FALSE(r.due(mav::kStreamSystemTime, 16300));
    EXPECT_EQ(r.set_interval(2, 100000.0f), mav::Result::Accepted);
    r.plan(s.hz, 50);
    EXPECT_TRUE(r.take(mav::kStreamSystemTime, 16300));
    EXPECT_FALSE(r.due(mav::kStreamSystemTime, 16399));
    EXPECT_TRUE(r.due(mav::kStreamSystemTime, 16400));
}

TEST(StreamRates, SetMessageIntervalAsArduPilot) {
    StreamRates r;
    Sr0 s;
    EXPECT_EQ(r.set_interval(65, 100000.0f), mav::Result::Accepted);  // RC_CHANNELS at 10 Hz
    r.plan(s.hz, 50);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), 100u);
    EXPECT_EQ(ms(r, mav::kStreamServoOutputRaw), 200u);  // its group's other message keeps the group's
    EXPECT_EQ(r.interval_us(65), 100000);
    EXPECT_EQ(r.set_interval(65, -1.0f), mav::Result::Accepted);  // stop
    r.plan(s.hz, 50);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), 0u);
    EXPECT_EQ(r.interval_us(65), -1);
    EXPECT_EQ(r.set_interval(65, 0.0f), mav::Result::Accepted);  // the default: the group's
    r.plan(s.hz, 50);
    EXPECT_EQ(r.interval_us(65), 200000);
    EXPECT_EQ(r.set_interval(29, 10.0f), mav::Result::Accepted);  // below 1 ms: 1 ms, then the cap
    EXPECT_EQ(r.set_interval(2, 1e9f), mav::Result::Accepted);    // above 60 s: 60 s
    r.plan(s.hz, 50);
    EXPECT_GT(ms(r, mav::kStreamScaledPressure), 1u);
    EXPECT_LE(r.bytes_per_s(), mav::kLinkBudgetBytesPerS - mav::kHeartbeatFrame);
    EXPECT_EQ(ms(r, mav::kStreamSystemTime) > 60000u, false);
    // Refused: not a message the board sends on a timer (ArduPilot's DENIED), HEARTBEAT
    // (1 Hz always), NaN, a negative interval other than -1.
    EXPECT_EQ(r.set_interval(27, 100000.0f), mav::Result::Denied);
    EXPECT_EQ(r.set_interval(0, 100000.0f), mav::Result::Denied);
    EXPECT_EQ(r.set_interval(0xFFFFFFFFu, 100000.0f), mav::Result::Denied);
    EXPECT_EQ(r.set_interval(65, NAN), mav::Result::Denied);
    EXPECT_EQ(r.set_interval(65, -5.0f), mav::Result::Denied);
    EXPECT_EQ(r.set_interval(65, 3e9f), mav::Result::Denied);
    // GET: HEARTBEAT 1 s, a message not sent -1.
    EXPECT_EQ(r.interval_us(0), 1000000);
    EXPECT_EQ(r.interval_us(27), -1);
    // REQUEST_DATA_STREAM for the group: its messages follow it again.
    EXPECT_EQ(r.set_interval(29, 0.0f), mav::Result::Accepted);
    EXPECT_EQ(r.set_interval(2, 0.0f), mav::Result::Accepted);
    EXPECT_EQ(r.set_interval(65, 50000.0f), mav::Result::Accepted);
    EXPECT_EQ(r.set_interval(30, 50000.0f), mav::Result::Accepted);
    r.follow_groups(1u << mav::kGroupRcChan);
    r.plan(s.hz, 50);
    EXPECT_EQ(ms(r, mav::kStreamRcChannels), 200u);
    EXPECT_EQ(ms(r, mav::kStreamAttitude), 50u);  // another group's: kept
}

TEST(StreamRates, MessageIntervalOnTheWire) {
    mav::Packer p;
    uint8_t f[mav::kMaxFrame];
    const uint8_t n = p.message_interval(f, 0x0141, 200000);  // 321: no byte trimmed
    ASSERT_EQ(n, mav::kMessageIntervalFrame);
    EXPECT_EQ(f[0], 0xFDu);
    EXPECT_EQ(f[7] | f[8] << 8 | f[9] << 16, 244);
    // interval_us (int32) then message_id (uint16), little-endian.
    EXPECT_EQ((uint32_t)(f[10] | f[11] << 8 | f[12] << 16 | (uint32_t)f[13] << 24), 200000u);
    EXPECT_EQ(f[14] | f[15] << 8, 321);
    EXPECT_EQ(p.message_interval(f, 65, -1), mav::kMessageIntervalFrame - 1u);  // MAVLink 2 trims the 0
    EXPECT_EQ(f[10] & f[11] & f[12] & f[13], 0xFF);
    EXPECT_EQ(f[14], 65u);
}

TEST(StreamRates, Sr0ParametersAreArduPilotsSavedInTheSecondRecord) {
    const char* names[mav::kStreamGroups] = {"SR0_RAW_SENS", "SR0_EXT_STAT", "SR0_RC_CHAN", "SR0_POSITION",
                                            "SR0_EXTRA1",   "SR0_EXTRA2",   "SR0_EXTRA3",  "SR0_PARAMS"};
    settings::Settings s{};
    params::apply_defaults(s);
    Sr0 want;
    for (uint8_t g = 0; g < mav::kStreamGroups; ++g) {
        const int16_t i = params::find(names[g]);
        ASSERT_GE(i, 0) << names[g];
        params::Info info;
        ASSERT_TRUE(params::info((uint16_t)i, info));
        EXPECT_EQ(info.type, params::Type::UInt8);
        EXPECT_EQ(info.min, 0.0f);
        EXPECT_EQ(info.max, 50.0f);
        EXPECT_EQ(s.vehicle.sr0_hz[g], want.hz[g]) << names[g];
        EXPECT_TRUE(params::set(s, (uint16_t)i, 7.0f));
        EXPECT_EQ(s.vehicle.sr0_hz[g], 7u);
        EXPECT_FALSE(params::set(s, (uint16_t)i, 51.0f));
        EXPECT_FALSE(params::set(s, (uint16_t)i, 2.5f));
    }
    // In the second record: a value changed changes its bytes.
    const uint16_t n = params::vehicle_bytes();
    uint8_t a[256], b[256];
    params::vehicle_part(s, 0, (uint8_t)n, a);
    s.vehicle.sr0_hz[mav::kGroupExtra2] = 9;
    params::vehicle_part(s, 0, (uint8_t)n, b);
    EXPECT_NE(memcmp(a, b, n), 0);
}

}  // namespace
