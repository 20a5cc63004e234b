// SPDX-License-Identifier: GPL-3.0-or-later
// The host's monotonic clock, for what the harness does in wall-clock time (pacing a live
// board, a silent physics backend's timeouts); simulated time is avr->cycle.
#pragma once

#include <time.h>

namespace sim {

inline double wall_clock_s() {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

}  // namespace sim
