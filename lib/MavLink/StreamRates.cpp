// SPDX-License-Identifier: GPL-3.0-or-later
#include "StreamRates.h"

namespace mav {

uint16_t StreamRates::bytes_per_s() const {
    uint16_t sum = 0;
    for (uint8_t g = 0; g < kStreamGroups; ++g) sum = (uint16_t)(sum + (uint16_t)hz_[g] * kGroupBytes[g]);
    return sum;
}

uint8_t StreamRates::set(StreamGroup g, uint16_t rate_hz, uint16_t fixed_bytes_per_s) {
    uint8_t hz = rate_hz > kStreamRateMaxHz ? kStreamRateMaxHz : (uint8_t)rate_hz;
    hz_[g] = 0;
    const uint16_t used = (uint16_t)(fixed_bytes_per_s + bytes_per_s());
    const uint16_t left = used >= kLinkBudgetBytesPerS ? 0u : (uint16_t)(kLinkBudgetBytesPerS - used);
    const uint16_t fits = left / kGroupBytes[g];
    if (hz > fits) hz = (uint8_t)fits;
    hz_[g] = hz;
    return hz;
}

bool StreamRates::request(uint8_t stream_id, uint16_t rate_hz, uint8_t start_stop, uint16_t fixed_bytes_per_s) {
    const uint16_t hz = start_stop == 0u ? 0u : rate_hz;
    if (stream_id == kDataStreamAll) {
        // Every group at the rate: the budget shared, the first ones first (stopped first,
        // so that the old rates do not count against the new).
        for (uint8_t g = 0; g < kStreamGroups; ++g) hz_[g] = 0;
        for (uint8_t g = 0; g < kStreamGroups; ++g) set((StreamGroup)g, hz, fixed_bytes_per_s);
        return true;
    }
    if (stream_id == kDataStreamRawSensors) return set(kGroupRawSens, hz, fixed_bytes_per_s), true;
    if (stream_id == kDataStreamRcChannels) return set(kGroupRcChan, hz, fixed_bytes_per_s), true;
    return false;
}

}  // namespace mav
