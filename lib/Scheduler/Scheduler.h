// SPDX-License-Identifier: GPL-3.0-or-later
// The loop's task table, as ArduPlane's scheduler_tasks[] (AP_Scheduler): every periodic
// job of the firmware is a row that says what runs, how often, how long it may take and
// which profiling section measures it. The firmware's table is firmware/Tasks.cpp; this
// is how a row runs.
//
// Two kinds of rows:
// - Sample tasks run on each MPU6000 sample (200 Hz), in table order, each when it is
//   due: every `period` samples, and, when the row has one, when its own test says so.
//   They always run when due (they are the fast path); one that takes longer than its
//   budget is counted as an overrun.
// - Loop tasks run between samples, on every pass of the loop (each interrupt wakes
//   one), when due. One starts only when it can end, within its budget, before the
//   next sample would be late (the deadline, counted from the last sample): long work
//   waits for a pass with room, so no sample is ever missed for it. A row marked
//   kAlways runs whenever due: work that must not wait (bytes moved on before a ring
//   overflows) or that only runs while no sample flows (a sensor's bring-up).
//
// The table is a list of rows that the firmware expands into straight code (an X-macro):
// each row's test and job are direct calls the compiler can inline, so that a row costs
// the fast path a clock read and a compare, not a table walk and two indirect calls.
// Each run is timed on a cheap clock (Clock::ticks(), a few cycles on the AVR) and
// bracketed by its profiling section (profile::begin/end: one OUT instruction each),
// which the simulator's profiler counts exactly (`make bench`: each task's cycles,
// average and maximum, against its budget).
//
// Clock, a policy type (the firmware's reads timer0; the host tests' is a fake):
//   static constexpr uint8_t kUsPerTick;   // the tick's length
//   static uint16_t ticks();               // now, in ticks (wraps)
//   static uint32_t us_since_sample();     // since the last sample was read (0: none due)
#pragma once

#include <stddef.h>
#include <stdint.h>

#include "Profile.h"

namespace sched {

constexpr uint8_t kAlways = 1;  // a loop task not held back for the next sample

// A task's record since start-up.
// overruns is a byte: the only reader is `status`'s tasks line (firmware/Tasks.cpp;
// `make bench` times the tasks from the simulator's profile, not from these), where 255
// says "often" as well as 65535 would; 37 rows x 1 B of the 8 KB RAM saved.
struct TaskStats {
    uint8_t overruns;    // runs longer than the budget (saturates at 255)
    uint16_t max_ticks;  // the longest run
};
constexpr uint8_t kMaxOverruns = 0xFFu;  // TaskStats::overruns saturates here

// A row's test: none (due by its period alone), or the row's function.
inline bool is_due(decltype(nullptr)) { return true; }
inline bool is_due(bool (*due)()) { return due(); }

// A periodic sample task's turn: every period-th call is true.
template <uint8_t kPeriod>
inline bool every(uint8_t& phase) {
    if (kPeriod <= 1u) return true;
    if (++phase < kPeriod) return false;
    phase = 0;
    return true;
}

template <class Clock>
struct Timing {
    // A budget in the clock's ticks, rounded up (at compile time in a row).
    static constexpr uint16_t ticks_of(uint32_t us) {
        return us / Clock::kUsPerTick >= 0xFFFFu ? (uint16_t)0xFFFFu
                                                 : (uint16_t)((us + Clock::kUsPerTick - 1u) / Clock::kUsPerTick);
    }
    // A loop task may start now: its budget ends before the deadline (us after the last
    // sample), `elapsed` ticks into a pass that started since_sample_us after it.
    static bool fits(uint32_t since_sample_us, uint16_t elapsed, uint32_t budget_us, uint16_t deadline_us) {
        return since_sample_us + (uint32_t)elapsed * Clock::kUsPerTick + budget_us <= deadline_us;
    }
    // A run from `start` to now: an overrun when longer than budget_ticks; returns now.
    __attribute__((always_inline)) static uint16_t record(TaskStats& s, uint16_t start, uint16_t budget_ticks) {
        const uint16_t end = Clock::ticks();
        const uint16_t took = (uint16_t)(end - start);
        if (took > budget_ticks && s.overruns != kMaxOverruns) ++s.overruns;
        if (took > s.max_ticks) s.max_ticks = took;
        return end;
    }
    // The same out of line, for the loop tasks (not the fast path: flash over cycles).
    __attribute__((noinline)) static uint16_t now() { return Clock::ticks(); }
    __attribute__((noinline)) static void record_loop(TaskStats& s, uint16_t start, uint16_t budget_ticks) {
        record(s, start, budget_ticks);
    }
};

}  // namespace sched

// One row of each kind, expanded where the firmware runs its table (Tasks.cpp):
// `start` is the time the row's work starts from (the previous row's end), `stats` the
// table's TaskStats by task id, `phase` the periodic rows' counters.
#define SCHED_SAMPLE_TASK(name, due, run, period, budget_us, section)                              \
    if (::sched::every<period>(phase.name) && ::sched::is_due(due)) {                              \
        ::profile::begin(section);                                                                 \
        run();                                                                                     \
        ::profile::end(section);                                                                   \
        start = Timing::record(stats[kTask_##name], start, Timing::ticks_of(budget_us));           \
    }

#define SCHED_LOOP_TASK(name, due, run, budget_us, section, flags)                                 \
    if (::sched::is_due(due) &&                                                                    \
        (((flags) & ::sched::kAlways) ||                                                           \
         Timing::fits(since_sample_us, (uint16_t)(Timing::now() - pass_start), budget_us, deadline_us))) { \
        const uint16_t task_start = Timing::now();                                                 \
        ::profile::begin(section);                                                                 \
        run();                                                                                     \
        ::profile::end(section);                                                                   \
        Timing::record_loop(stats[kTask_##name], task_start, Timing::ticks_of(budget_us));         \
    }
