// SPDX-License-Identifier: GPL-3.0-or-later
// ArduPilot's stream groups as a ground station sets them with REQUEST_DATA_STREAM
// (GCS_MAVLink's SRn_* rates, Hz): the groups whose messages this board sends on their own
// timer, their rates in RAM (as ArduPilot: a REQUEST_DATA_STREAM is not saved), and the
// link's capacity: a rate that would take the port beyond kLinkBudgetBytesPerS is lowered to
// the highest that fits (REQUEST_DATA_STREAM has no answer; the stream's rate says it).
//
//   SR0_RAW_SENS  (MAV_DATA_STREAM_RAW_SENSORS 1):  SCALED_PRESSURE            5 Hz, 28 bytes
//   SR0_RC_CHAN   (MAV_DATA_STREAM_RC_CHANNELS 3):  RC_CHANNELS, SERVO_OUTPUT_RAW  5 Hz, 54 + 33 bytes
//
// MAV_DATA_STREAM_ALL (0) sets both. The others (EXTENDED_STATUS, POSITION, EXTRA1, EXTRA2)
// are not taken yet: their messages keep their fixed rates (SYS_STATUS 1 Hz, the position
// round, ATTITUDE at the console's `rate`). Plain C++, host-tested.
#pragma once

#include <stdint.h>

namespace mav {

// The port: 115200 baud, 10 bits a byte; three quarters for the streams, the rest left to
// parameter and command traffic.
constexpr uint16_t kLinkBytesPerS = 11520;
constexpr uint16_t kLinkBudgetBytesPerS = kLinkBytesPerS / 4u * 3u;  // 8640
constexpr uint8_t kStreamRateMaxHz = 50;  // ArduPilot's SRn_ range: 0..50

// MAV_DATA_STREAM.
constexpr uint8_t kDataStreamAll = 0;
constexpr uint8_t kDataStreamRawSensors = 1;
constexpr uint8_t kDataStreamRcChannels = 3;

enum StreamGroup : uint8_t { kGroupRawSens, kGroupRcChan, kStreamGroups };
// One second of a group at 1 Hz, bytes (its frames at their longest).
constexpr uint16_t kGroupBytes[kStreamGroups] = {28u, 54u + 33u};
constexpr uint8_t kGroupDefaultHz = 5;

class StreamRates {
public:
    uint8_t hz(StreamGroup g) const { return hz_[g]; }
    // The period of a group's timer, ms (0: off).
    uint16_t period_ms(StreamGroup g) const { return hz_[g] == 0u ? 0u : (uint16_t)(1000u / hz_[g]); }
    // Bytes a second the groups take at their rates.
    uint16_t bytes_per_s() const;
    // REQUEST_DATA_STREAM: req_stream_id, req_message_rate (Hz), start_stop (0 stop).
    // fixed_bytes_per_s: what the port carries besides the groups (HEARTBEAT, ATTITUDE ...).
    // False for a stream id the board does not take (nothing changes).
    bool request(uint8_t stream_id, uint16_t rate_hz, uint8_t start_stop, uint16_t fixed_bytes_per_s);
    // A group's rate set, capped to kStreamRateMaxHz and to what the link carries beside
    // fixed_bytes_per_s and the other groups; the rate in force returned.
    uint8_t set(StreamGroup g, uint16_t rate_hz, uint16_t fixed_bytes_per_s);

private:
    uint8_t hz_[kStreamGroups] = {kGroupDefaultHz, kGroupDefaultHz};
};

}  // namespace mav
