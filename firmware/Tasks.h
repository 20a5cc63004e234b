// SPDX-License-Identifier: GPL-3.0-or-later
// The firmware's task table (Tasks.cpp) and the scheduler that runs it (lib/Scheduler).
#pragma once

#include <stdint.h>

#include "Text.h"

// On a loop task's job (the table's `run`) that a single row calls, the inliner would fold
// it into run_loop_tasks: its locals (a MAVLink frame ...) would join that function's frame,
// beyond the 63 bytes ldd/std reach, and every access to the others would take a subi,
// sbci pair before and after (644 B over GcsLink's take_request, run_pending_command and
// save). Loop tasks run between samples: a call is free. (position::run and
// battery_input::update out of line too saved 520 B more, but moved the loop's timing so
// that e2e.Beyond128K's padded image flew 5 us apart from the image itself.)
#define TASK_OWN_FRAME __attribute__((noinline))

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
