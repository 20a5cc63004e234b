// SPDX-License-Identifier: GPL-3.0-or-later
#include "Ppm.h"

namespace flight {

void PpmDecoder::reset() {
    have_capture_ = false;
    count_ = 0;
    last_count_ = 0;
}

bool PpmDecoder::feed(uint16_t capture_ticks) {
    const uint16_t last = last_capture_;
    last_capture_ = capture_ticks;
    if (!have_capture_) {
        // The first edge after an idle line (a receiver switched on, or captures lost)
        // is taken as a frame's first: if it was not, that frame has too few widths and
        // the count test rejects it and the next, as a frame after no sync gap would be.
        have_capture_ = true;
        count_ = 0;
        bad_ = false;
        return false;
    }
    // The timer counts 0..kPeriodTicks-1 and wraps: the width is the difference modulo
    // the period (a gap longer than the period aliases, but then it is the sync gap
    // before, or a garbled frame the count test rejects).
    const uint16_t ticks = capture_ticks >= last ? (uint16_t)(capture_ticks - last)
                                                 : (uint16_t)(capture_ticks + (kPeriodTicks - last));
    const uint16_t width_us = (uint16_t)((ticks + 1u) / kTicksPerUs);
    if (width_us > kSyncUs) {
        const bool accept = count_ == kChannels && last_count_ == kChannels && !bad_;
        last_count_ = count_;
        count_ = 0;
        bad_ = false;
        return accept;
    }
    if (width_us < kMinUs || width_us > kMaxUs) bad_ = true;
    if (count_ < kChannels) frame_us_[count_] = width_us;
    else bad_ = true;  // too many widths: a glitch split one
    if (count_ < 0xFE) ++count_;
    return false;
}

}  // namespace flight
