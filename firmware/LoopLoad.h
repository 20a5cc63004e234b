// SPDX-License-Identifier: GPL-3.0-or-later
// The loop's load: the share of each second spent on samples (their tasks, from the
// data-ready seen to the work done), measured on the board's clock; `status` and
// SYS_STATUS show it.
#pragma once

#include <stdint.h>

namespace loop_load {

// Just before the first loop(): the first window starts.
void start(uint32_t now_us);
// After each sample's work that started at start_us.
void add_sample_work(uint32_t start_us, uint32_t end_us);
// A second has passed since the window started.
bool second_due();
// The window closes: the load over it; a new window starts.
void new_second();
uint8_t percent();

}  // namespace loop_load
