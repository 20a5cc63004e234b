// SPDX-License-Identifier: GPL-3.0-or-later
// A FlightControl on the default settings with a receiver script, stepped at 50 Hz: the
// rig of the flight control's and the arming's tests.
#pragma once

#include "Flight.h"
#include "Settings.h"

namespace flight_test {

struct Rig {
    settings::Settings s = settings::defaults();
    flight::FlightControl fc{s.flight};
    uint16_t rc[8] = {1500, 1500, 1100, 1500, 1500, 1500, 1500, 1000};  // mode switch low: MANUAL
    uint32_t now_ms = 0;
    flight::Attitude att{0, 0, 0, 0, true};
    uint16_t out[8] = {};

    // Runs `seconds` of 50 Hz steps with frames every 22 ms while `signal`.
    void run(float seconds, bool signal = true) {
        const uint32_t end = now_ms + (uint32_t)(seconds * 1000.0f);
        uint32_t next_frame = now_ms;
        while (now_ms < end) {
            if (signal && now_ms >= next_frame) {
                fc.on_frame(rc, now_ms);
                next_frame += 22;
            }
            if (now_ms % 20u == 0u) fc.step(now_ms, att, out);
            ++now_ms;
        }
    }
};

}  // namespace flight_test
