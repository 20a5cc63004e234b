// SPDX-License-Identifier: GPL-3.0-or-later
#include "StreamRates.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define STREAM_TABLE PROGMEM
#define TABLE_BYTE(p) ((uint8_t)pgm_read_byte(&(p)))
#else
#define STREAM_TABLE
#define TABLE_BYTE(p) ((uint8_t)(p))
#endif

namespace mav {

namespace {

// A message on a timer: its MAVLink id, its group, its frame at its longest (bytes).
struct Entry {
    uint8_t msgid;
    uint8_t group;
    uint8_t frame_bytes;
};
// In StreamMsg's order; ArduPlane's groups (GCS_Mavlink.cpp's STREAM_*_msgs).
const Entry kTable[kStreamMsgs] STREAM_TABLE = {
    {29, kGroupRawSens, kScaledPressureFrame},          // SCALED_PRESSURE
    {1, kGroupExtStat, kMaxFrame},                      // SYS_STATUS (~55 with the battery's fields)
    {24, kGroupExtStat, kFrameOverhead + 52},           // GPS_RAW_INT
    {65, kGroupRcChan, kRcChannelsFrame},               // RC_CHANNELS
    {36, kGroupRcChan, kFrameOverhead + 21},            // SERVO_OUTPUT_RAW (channels 1-8)
    {33, kGroupPosition, kFrameOverhead + 28},          // GLOBAL_POSITION_INT
    {30, kGroupExtra1, kAttitudeFrame},                 // ATTITUDE
    {74, kGroupExtra2, kFrameOverhead + 20},            // VFR_HUD
    {2, kGroupExtra3, kFrameOverhead + 12},             // SYSTEM_TIME
    {147, kGroupExtra3, kBatteryStatusFrame},           // BATTERY_STATUS
    {62, kGroupExtStat, kFrameOverhead + 26},           // NAV_CONTROLLER_OUTPUT (while a navigation mode flies)
    {42, kGroupExtStat, kFrameOverhead + 6},            // MISSION_CURRENT (seq, total)
};

uint8_t group_of(uint8_t m) { return TABLE_BYTE(kTable[m].group); }
uint8_t frame_bytes_of(uint8_t m) { return TABLE_BYTE(kTable[m].frame_bytes); }

// HEARTBEAT, 1 Hz whatever is asked: the budget's first bytes.
constexpr uint16_t kStreamBudgetBytesPerS = kLinkBudgetBytesPerS - kHeartbeatFrame;
constexpr uint16_t kMaxIntervalMs = 60000;  // ArduPilot's longest

}  // namespace

// MAV_DATA_STREAM id -> group, in flash: the switch it was became a lookup table the
// compiler put in the AVR's RAM (12 bytes of .data).
const uint8_t kGroupOfDataStream[] STREAM_TABLE = {
    kStreamGroups,   // 0 ALL: not a group
    kGroupRawSens,   // 1 MAV_DATA_STREAM_RAW_SENSORS
    kGroupExtStat,   // 2 _EXTENDED_STATUS
    kGroupRcChan,    // 3 _RC_CHANNELS
    kStreamGroups,   // 4 _RAW_CONTROLLER: nothing sent
    kStreamGroups,   // 5 unknown
    kGroupPosition,  // 6 _POSITION
    kStreamGroups, kStreamGroups, kStreamGroups,  // 7..9 unknown
    kGroupExtra1,    // 10
    kGroupExtra2,    // 11
    kGroupExtra3,    // 12
};

StreamGroup group_of_data_stream(uint8_t stream_id) {
    if (stream_id >= sizeof kGroupOfDataStream) return kStreamGroups;  // unknown
    return (StreamGroup)TABLE_BYTE(kGroupOfDataStream[stream_id]);
}

StreamMsg stream_msg_of(uint32_t msgid) {
    for (uint8_t m = 0; m < kStreamMsgs; ++m)
        if (TABLE_BYTE(kTable[m].msgid) == msgid) return (StreamMsg)m;
    return kStreamMsgs;
}

bool apply_data_stream_request(uint8_t sr0_hz[kStreamGroups], uint8_t stream_id, uint16_t rate_hz,
                               uint8_t start_stop, uint8_t* groups_set) {
    *groups_set = 0;
    if (start_stop > 1u) return false;
    const uint8_t hz = start_stop == 0u ? 0u : rate_hz > kStreamRateMaxHz ? kStreamRateMaxHz : (uint8_t)rate_hz;
    uint8_t mask;
    if (stream_id == kDataStreamAll) {
        mask = (uint8_t)((1u << kGroupParams) - 1u);  // not PARAMS: ArduPilot's "internal" rate
    } else {
        const StreamGroup g = group_of_data_stream(stream_id);
        if (g == kStreamGroups) return false;
        mask = (uint8_t)(1u << g);
    }
    bool changed = false;
    for (uint8_t g = 0; g < kStreamGroups; ++g) {
        if ((mask & (1u << g)) == 0u) continue;
        changed = changed || sr0_hz[g] != hz;
        sr0_hz[g] = hz;
    }
    *groups_set = mask;
    return changed;
}

void StreamRates::plan(const uint8_t sr0_hz[kStreamGroups], uint8_t output_rate_hz) {
    uint16_t asked[kStreamMsgs];
    uint32_t load = 0;  // bytes a second at the intervals asked
    bool every_line = false;
    for (uint8_t m = 0; m < kStreamMsgs; ++m) {
        uint16_t ms = own_ms_[m];
        if (ms == kFollowGroup) {
            uint8_t hz = sr0_hz[group_of(m)];
            if (hz > kStreamRateMaxHz) hz = kStreamRateMaxHz;
            ms = hz == 0u ? (uint16_t)0u : (uint16_t)(1000u / hz);
        } else if (ms == kStopped) {
            ms = 0;
        }
        // ATTITUDE goes with an output line: never more often than the console's `rate`.
        if (m == kStreamAttitude && ms != 0u && output_rate_hz != 0u && ms <= 1000u / output_rate_hz) {
            every_line = true;
            ms = (uint16_t)(1000u / output_rate_hz);
        }
        asked[m] = ms;
        if (ms != 0u) load += (uint32_t)frame_bytes_of(m) * 1000u / ms;
    }
    // Over the budget: every interval stretched by load / budget (Q8, rounded up).
    uint32_t stretch_q8 = 256;
    if (load > kStreamBudgetBytesPerS) stretch_q8 = (load * 256u + kStreamBudgetBytesPerS - 1u) / kStreamBudgetBytesPerS;
    every_line_ = every_line && stretch_q8 == 256u;
    for (uint8_t m = 0; m < kStreamMsgs; ++m) {
        uint32_t ms = ((uint32_t)asked[m] * stretch_q8 + 255u) >> 8;
        if (ms > kMaxIntervalMs) ms = kMaxIntervalMs;
        // Due an interval after it was last due: a shorter interval does not wait out the old one.
        if (interval_ms_[m] != 0u) next_ms_[m] = next_ms_[m] - interval_ms_[m] + ms;
        interval_ms_[m] = (uint16_t)ms;
    }
}

void StreamRates::sent(StreamMsg m, uint32_t now_ms) {
    next_ms_[m] += interval_ms_[m];
    if ((int32_t)(now_ms - next_ms_[m]) >= 0) next_ms_[m] = now_ms + interval_ms_[m];
}

Result StreamRates::set_interval(uint32_t msgid, float interval_us) {
    const StreamMsg m = stream_msg_of(msgid);
    // NaN, below -1 and beyond int32 refused; a fraction of a us is the whole us below it.
    if (m == kStreamMsgs || !(interval_us >= -1.0f && interval_us < 2147483647.0f)) return Result::Denied;
    const int32_t us = (int32_t)interval_us;
    uint16_t ms;
    if (us == 0) {
        ms = kFollowGroup;
    } else if (us < 0) {
        ms = kStopped;  // -1
    } else if (us < 1000) {
        ms = 1;  // as fast as it may (the cap and the output's room decide)
    } else if (us > (int32_t)kMaxIntervalMs * 1000) {
        ms = kMaxIntervalMs;
    } else {
        ms = (uint16_t)(us / 1000);
    }
    own_ms_[m] = ms;
    return Result::Accepted;
}

int32_t StreamRates::interval_us(uint32_t msgid) const {
    if (msgid == 0u) return 1000000;  // HEARTBEAT
    const StreamMsg m = stream_msg_of(msgid);
    if (m == kStreamMsgs || interval_ms_[m] == 0u) return -1;
    return (int32_t)interval_ms_[m] * 1000;
}

void StreamRates::follow_groups(uint8_t mask) {
    for (uint8_t m = 0; m < kStreamMsgs; ++m)
        if ((mask & (1u << group_of(m))) != 0u) own_ms_[m] = kFollowGroup;
}

uint16_t StreamRates::bytes_per_s() const {
    uint32_t sum = 0;
    for (uint8_t m = 0; m < kStreamMsgs; ++m)
        if (interval_ms_[m] != 0u) sum += (uint32_t)frame_bytes_of(m) * 1000u / interval_ms_[m];
    return (uint16_t)(sum > 0xFFFFu ? 0xFFFFu : sum);
}

}  // namespace mav
