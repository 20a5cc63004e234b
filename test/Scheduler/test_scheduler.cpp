// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Scheduler: a small task table run on a fake clock, as firmware/Tasks.cpp runs its own.
#include <gtest/gtest.h>

#include <string>

#include "Scheduler.h"

namespace {

struct FakeClock {
    static constexpr uint8_t kUsPerTick = 4;
    static uint16_t now_ticks;
    static uint32_t since_sample_us;
    static uint16_t ticks() { return now_ticks; }
    static uint32_t us_since_sample() { return since_sample_us; }
    static void advance_us(uint32_t us) { now_ticks = (uint16_t)(now_ticks + us / kUsPerTick); }
};
uint16_t FakeClock::now_ticks = 0;
uint32_t FakeClock::since_sample_us = 0;

using Clock = FakeClock;
using Timing = sched::Timing<Clock>;

// What each task did, in order, and how long each "takes".
std::string ran;
uint32_t cost_us[8] = {};
bool gate_open = true;

void task_a() { ran += 'a'; Clock::advance_us(cost_us[0]); }
void task_b() { ran += 'b'; Clock::advance_us(cost_us[1]); }
void task_c() { ran += 'c'; Clock::advance_us(cost_us[2]); }
void task_d() { ran += 'd'; Clock::advance_us(cost_us[3]); }
void task_e() { ran += 'e'; Clock::advance_us(cost_us[4]); }
bool gate() { return gate_open; }

//     name  due      run     period budget_us section
#define TEST_SAMPLE_TASKS(X)          \
    X(a, nullptr, task_a, 1, 100, 0)  \
    X(b, gate, task_b, 1, 100, 0)     \
    X(c, nullptr, task_c, 3, 200, 0)
//     name  due      run     budget_us section flags
#define TEST_LOOP_TASKS(X)                   \
    X(d, nullptr, task_d, 2000, 0, 0)        \
    X(e, nullptr, task_e, 9000, 0, sched::kAlways)

#define ID(name, ...) kTask_##name,
enum TaskId : uint8_t { TEST_SAMPLE_TASKS(ID) TEST_LOOP_TASKS(ID) kTasks };
#define PHASE(name, ...) uint8_t name;
struct Phases { TEST_SAMPLE_TASKS(PHASE) };

struct Table {
    Phases phase{};
    sched::TaskStats stats[kTasks] = {};
    void run_sample_tasks() {
        uint16_t start = Clock::ticks();
        TEST_SAMPLE_TASKS(SCHED_SAMPLE_TASK)
        (void)start;
    }
    void run_loop_tasks(uint16_t deadline_us) {
        const uint32_t since_sample_us = Clock::us_since_sample();
        const uint16_t pass_start = Clock::ticks();
        TEST_LOOP_TASKS(SCHED_LOOP_TASK)
    }
};

class Scheduler : public ::testing::Test {
protected:
    void SetUp() override {
        ran.clear();
        for (uint32_t& c : cost_us) c = 0;
        gate_open = true;
        Clock::now_ticks = 0;
        Clock::since_sample_us = 0;
    }
};

TEST_F(Scheduler, SampleTasksRunInTableOrderEachByItsPeriod) {
    Table t;
    for (int i = 0; i < 6; ++i) t.run_sample_tasks();
    // c every third sample: the third and the sixth.
    EXPECT_EQ(ran, "abababcabababc");
}

TEST_F(Scheduler, ADueTestHoldsItsTask) {
    Table t;
    gate_open = false;
    t.run_sample_tasks();
    EXPECT_EQ(ran, "a");
}

TEST_F(Scheduler, ARunLongerThanItsBudgetIsAnOverrunWithItsLength) {
    Table t;
    cost_us[0] = 96;   // within 100
    cost_us[1] = 400;  // over 100
    t.run_sample_tasks();
    EXPECT_EQ(t.stats[kTask_a].overruns, 0u);
    EXPECT_EQ(t.stats[kTask_a].max_ticks, 96u / Clock::kUsPerTick);
    EXPECT_EQ(t.stats[kTask_b].overruns, 1u);
    EXPECT_EQ(t.stats[kTask_b].max_ticks, 400u / Clock::kUsPerTick);
    cost_us[1] = 200;
    t.run_sample_tasks();
    EXPECT_EQ(t.stats[kTask_b].overruns, 2u);
    EXPECT_EQ(t.stats[kTask_b].max_ticks, 400u / Clock::kUsPerTick);  // the longest kept
}

TEST_F(Scheduler, EachTaskIsTimedFromThePreviousOnesEnd) {
    Table t;
    cost_us[0] = 500;
    cost_us[1] = 40;
    t.run_sample_tasks();
    EXPECT_EQ(t.stats[kTask_b].overruns, 0u);  // a's 500 us are a's, not b's
    EXPECT_EQ(t.stats[kTask_b].max_ticks, 40u / Clock::kUsPerTick);
}

TEST_F(Scheduler, ALoopTaskStartsOnlyWhenItsBudgetEndsBeforeTheDeadline) {
    Table t;
    Clock::since_sample_us = 5000;  // d's 2000 us end at 7000: in time for 7300
    t.run_loop_tasks(7300);
    EXPECT_EQ(ran, "de");
    ran.clear();
    Clock::since_sample_us = 5400;  // 7400: late
    t.run_loop_tasks(7300);
    EXPECT_EQ(ran, "e");  // kAlways runs whatever the time
}

TEST_F(Scheduler, ALoopTasksTimeCountsAgainstTheOnesAfterIt) {
    Table t;
    Clock::since_sample_us = 4000;
    cost_us[3] = 1400;  // d ends at 5400: e (kAlways) still runs; its time is its own
    cost_us[4] = 100;
    t.run_loop_tasks(7300);
    EXPECT_EQ(ran, "de");
    EXPECT_EQ(t.stats[kTask_e].max_ticks, 100u / Clock::kUsPerTick);
}

TEST_F(Scheduler, TheOverrunCountSaturates) {
    Table t;
    t.stats[kTask_a].overruns = sched::kMaxOverruns;
    cost_us[0] = 1000;
    t.run_sample_tasks();
    EXPECT_EQ(t.stats[kTask_a].overruns, sched::kMaxOverruns);
}

TEST_F(Scheduler, BudgetsRoundUpToWholeTicks) {
    EXPECT_EQ(Timing::ticks_of(100), 25u);
    EXPECT_EQ(Timing::ticks_of(101), 26u);
    EXPECT_EQ(Timing::ticks_of(1000000), 0xFFFFu);
    EXPECT_TRUE(Timing::fits(5000, 0, 2300, 7300));
    EXPECT_FALSE(Timing::fits(5000, 1, 2300, 7300));  // one tick into the pass: 4 us late
}

}  // namespace
