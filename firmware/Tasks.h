// SPDX-License-Identifier: GPL-3.0-or-later
// The firmware's task table (Tasks.cpp) and the scheduler that runs it (lib/Scheduler).
#pragma once

#include <stdint.h>

#include "Text.h"

namespace tasks {

// In setup(), the last thing before the loop starts.
void loop_starts();
// One pass of loop(): the loop tasks that are due and fit before the next sample, then,
// when a sample is ready, its read and the sample tasks; else the core idles until the
// next interrupt.
void loop_pass();
// `status`'s tasks line: the runs over budget, per task.
void print_status_line(const text::Sink* out);

}  // namespace tasks
