// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5's receiver input: a PPM sum from the board's ATmega32U2 encoder, read by
// Timer5's input capture (ICP5, rising edges, 0.5 us ticks, TOP = 39999 as ArduPilot's
// APM2 HAL: a 20 ms period). The firmware's capture interrupt only stores timestamps;
// this decoder turns them into frames.
//
// A frame is the widths between consecutive rising edges, one per channel, closed by a
// gap over kSyncUs (the encoder's frame is 22.5 ms, 8 widths of 0.8..2.2 ms each with
// its 400 us pulse, and at least ~4.5 ms of sync). A frame is accepted only when every
// width is plausible (kMinUs..kMaxUs) and it has kChannels widths, as the frame before
// it: a glitch that splits or swallows a pulse costs that frame and the next, never a
// wrong width. The first edge after an idle line opens a frame, so a receiver switched on
// is accepted from its second frame (45 ms). Pure C++: no clock, no registers.
#pragma once

#include <stdint.h>

#include "FlightSettings.h"

namespace flight {

class PpmDecoder {
public:
    static constexpr uint16_t kTicksPerUs = 2;            // Timer5 at 16 MHz / 8
    static constexpr uint16_t kPeriodTicks = 40000;       // Timer5's TOP + 1: captures wrap here
    static constexpr uint16_t kSyncUs = 3000;             // a longer gap closes the frame
    static constexpr uint16_t kMinUs = 800;
    static constexpr uint16_t kMaxUs = 2200;

    // One rising edge's capture (Timer5 ticks, 0..kPeriodTicks-1). True when it closed an
    // accepted frame: frame_us() holds its widths until the next call.
    bool feed(uint16_t capture_ticks);
    // Captures were lost (the interrupt's buffer overflowed): the frame in progress is
    // dropped and the next edge starts afresh.
    void reset();
    const uint16_t* frame_us() const { return frame_us_; }

private:
    uint16_t frame_us_[kChannels] = {};
    uint16_t last_capture_ = 0;
    uint8_t count_ = 0;         // widths in the frame in progress
    uint8_t last_count_ = 0;    // widths in the last closed frame
    bool have_capture_ = false;
    bool bad_ = false;          // the frame in progress had an implausible width
};

}  // namespace flight
