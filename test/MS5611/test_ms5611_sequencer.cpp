// SPDX-License-Identifier: GPL-3.0-or-later
// lib/MS5611/Ms5611.h's sequencer driving the simulator's MS5611 register model
// (sim/models/Ms5611Model.h) through the bus seam, in host time: start-up, the
// conversions' rhythm and timing, and each fault of the model; and a fake bus for a
// PROM with a wrong CRC.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../sim/sim_models_support.h"
#include "Geodesy.h"
#include "Ms5611.h"
#include "Ms5611Model.h"

namespace {

using ms5611::Event;

sim::Trajectory still_at_depth(double d_m, double seconds = 60.0) {
    const double still[3] = {0, 0, 0};
    sim::Trajectory t = simtest::moving_trajectory(seconds, still, 10.0);
    for (sim::TrajectorySample& s : t.samples()) s.ned_m[2] = d_m;
    return t;
}

struct ModelBus {
    sim::Ms5611Model chip;
    std::vector<uint8_t> commands;
    explicit ModelBus(const sim::Trajectory& t, const sim::Ms5611Options& o = sim::Ms5611Options()) : chip(t, o) {}
    static void transaction(void* ctx, uint8_t cmd, uint8_t* in, uint8_t len) {
        ModelBus& b = *static_cast<ModelBus*>(ctx);
        b.commands.push_back(cmd);
        b.chip.set_chip_select(true);
        b.chip.transfer(cmd);
        for (uint8_t i = 0; i < len; ++i) in[i] = b.chip.transfer(0x00);
        b.chip.set_chip_select(false);
    }
    ms5611::SpiDevice device() { return ms5611::SpiDevice{this, transaction}; }
};

// Runs the sequencer as a loop task would: polled every `poll_us`, serviced when due.
struct SeqRun {
    ModelBus bus;
    ms5611::Sequencer seq;
    uint32_t now_us = 0;
    std::vector<Event> events;
    explicit SeqRun(const sim::Trajectory& t, const sim::Ms5611Options& o = sim::Ms5611Options())
        : bus(t, o), seq(bus.device()) {}
    void until(double t_s, uint32_t poll_us = 250) {
        while (now_us < (uint32_t)(t_s * 1e6)) {
            now_us += poll_us;
            bus.chip.advance_to(now_us * 1e-6);
            if (!seq.due(now_us)) continue;
            const Event e = seq.service(now_us);
            if (e != Event::None && e != Event::Pressure) events.push_back(e);
        }
    }
    int count(Event e) const {
        int n = 0;
        for (Event x : events) n += x == e;
        return n;
    }
};

TEST(Ms5611Sequencer, StartsConvertsAndNeverReadsEarly) {
    SeqRun r(still_at_depth(0.0));
    r.until(1.0);
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0], Event::Found);
    EXPECT_TRUE(r.seq.converting());
    // Reset, the 8 PROM words, then conversions: D2 and four D1 in turn, each read.
    ASSERT_GE(r.bus.commands.size(), 20u);
    EXPECT_EQ(r.bus.commands[0], 0x1E);
    for (int w = 0; w < 8; ++w) EXPECT_EQ(r.bus.commands[1 + w], 0xA0 + 2 * w);
    std::vector<uint8_t> conversions;
    for (size_t i = 9; i < r.bus.commands.size(); ++i)
        if (r.bus.commands[i] != 0x00) conversions.push_back(r.bus.commands[i]);
    for (size_t i = 0; i < conversions.size(); ++i)
        EXPECT_EQ(conversions[i], i % 5 == 0 ? 0x58 : 0x48) << i;
    // A conversion every 9.1 ms, seen at the next 250 us poll (9.25 ms): ~107 in the
    // second after the reset's 3 ms; none read before its end, none missed.
    EXPECT_NEAR((double)r.seq.conversions(), 107.0, 1.0);
    EXPECT_EQ(r.bus.chip.counters().reads_during_conversion, 0u);
    EXPECT_EQ(r.bus.chip.counters().commands_during_conversion, 0u);
    EXPECT_EQ(r.bus.chip.counters().commands_during_reset, 0u);
    EXPECT_EQ(r.seq.missed(), 0u);
    EXPECT_EQ(r.seq.rejected(), 0u);
    // The pressure and temperature of the standard atmosphere at the field.
    float mean = 0.0f;
    ASSERT_TRUE(r.seq.take_average(mean));
    EXPECT_NEAR(mean, sim::isa_pressure_pa(sim::kHomeAlt_m), 5.0);  // ~80 readings of 10 Pa noise
    EXPECT_NEAR(r.seq.temperature_c100() * 0.01, sim::isa_temperature_c(sim::kHomeAlt_m), 0.02);
    EXPECT_FALSE(r.seq.take_average(mean));  // taken: nothing new yet
}

TEST(Ms5611Sequencer, NobodyThereIsSaidOnceAndTriedEverySecond) {
    sim::Trajectory t = still_at_depth(0.0);
    SeqRun r(t);
    r.bus.chip.faults().absent.add(sim::TimeWindow::between(0.0, 3.5));
    r.until(3.0);
    ASSERT_EQ(r.events.size(), 1u);
    EXPECT_EQ(r.events[0], Event::Blank);
    EXPECT_EQ(r.bus.chip.counters().resets, 0u);  // deaf: commands ignored
    const size_t resets_tried = (size_t)std::count(r.bus.commands.begin(), r.bus.commands.end(), 0x1E);
    EXPECT_EQ(resets_tried, 3u);  // at 0, 1 and 2 s
    r.until(5.0);
    ASSERT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.events[1], Event::Back);
    EXPECT_TRUE(r.seq.converting());
}

TEST(Ms5611Sequencer, AChipThatStopsAnsweringIsLostThenBack) {
    SeqRun r(still_at_depth(0.0));
    r.bus.chip.faults().absent.add(sim::TimeWindow::between(2.0, 4.0));
    r.until(6.0);
    ASSERT_EQ(r.events.size(), 3u);
    EXPECT_EQ(r.events[0], Event::Found);
    EXPECT_EQ(r.events[1], Event::Lost);
    EXPECT_EQ(r.events[2], Event::Back);
    EXPECT_EQ(r.seq.missed(), ms5611::kLostAfter);
    EXPECT_TRUE(r.seq.converting());
}

TEST(Ms5611Sequencer, AStuckChipIsNoticedAndItsReturn) {
    SeqRun r(still_at_depth(0.0));
    r.bus.chip.faults().stuck.add(sim::TimeWindow::between(2.0, 4.0));
    r.until(3.0);
    ASSERT_EQ(r.events.size(), 2u);
    EXPECT_EQ(r.events[1], Event::Stuck);
    EXPECT_TRUE(r.seq.stuck());
    r.until(5.0);
    ASSERT_EQ(r.events.size(), 3u);
    EXPECT_EQ(r.events[2], Event::Unstuck);
    EXPECT_FALSE(r.seq.stuck());
}

TEST(Ms5611Sequencer, SpikesAreRejectedAndCounted) {
    SeqRun r(still_at_depth(0.0));
    r.bus.chip.faults().spike.add(sim::TimeWindow::between(2.0, 2.2));
    r.until(2.0);
    float mean = 0.0f;
    r.seq.take_average(mean);
    r.until(4.0);
    // ~16 D1 in 0.2 s, each ~100 hPa off: all rejected, said once.
    EXPECT_GE(r.seq.rejected(), 12u);
    EXPECT_LE(r.seq.rejected(), 20u);
    EXPECT_EQ(r.count(Event::Rejected), 1);
    ASSERT_TRUE(r.seq.take_average(mean));
    EXPECT_NEAR(mean, sim::isa_pressure_pa(sim::kHomeAlt_m), 5.0);  // none of them in the mean
}

TEST(Ms5611Sequencer, ALastingStepIsBelievedAfterARun) {
    // The board at 0 m, then 200 m up at once (a trajectory jump): ~2300 Pa, past
    // kSpikePa; after kSpikeRun readings the new level is taken.
    const double still[3] = {0, 0, 0};
    sim::Trajectory t = simtest::moving_trajectory(5.0, still, 1000.0);
    for (sim::TrajectorySample& s : t.samples())
        if (s.t_s >= 2.0) s.ned_m[2] = -200.0;
    SeqRun r(t);
    r.until(4.0);
    float mean = 0.0f;
    ASSERT_TRUE(r.seq.take_average(mean));
    EXPECT_NEAR(r.seq.last_pressure_pa(), sim::isa_pressure_pa(sim::kHomeAlt_m + 200.0), 50.0);
    EXPECT_EQ(r.seq.rejected(), ms5611::kSpikeRun);
}

TEST(Ms5611Sequencer, ABadCrcIsNoBarometer) {
    struct Fake {
        static void transaction(void*, uint8_t cmd, uint8_t* in, uint8_t len) {
            // The simulator's PROM with word 3 changed: the CRC no longer fits.
            uint16_t word = 0;
            if (cmd >= 0xA0 && cmd <= 0xAE) {
                word = sim::Ms5611Model::kProm[(cmd - 0xA0) / 2];
                if (cmd == 0xA6) word ^= 0x0010;
            }
            if (len == 2) {
                in[0] = (uint8_t)(word >> 8);
                in[1] = (uint8_t)word;
            }
        }
    };
    ms5611::Sequencer seq(ms5611::SpiDevice{nullptr, Fake::transaction});
    std::vector<Event> events;
    for (uint32_t t = 0; t < 5000000u; t += 500)
        if (seq.due(t)) events.push_back(seq.service(t));
    EXPECT_EQ(std::count(events.begin(), events.end(), Event::BadCrc), 1);
    EXPECT_EQ(std::count(events.begin(), events.end(), Event::Found), 0);
    EXPECT_FALSE(seq.converting());
}

TEST(Ms5611Sequencer, AbsurdTemperaturesAreRejected) {
    // 90 degC is past the chip's 85: the D2 refused, no pressure without a temperature.
    sim::Ms5611Options o;
    o.fixed_temperature = true;
    o.temperature_c = 84.0;
    SeqRun ok(still_at_depth(0.0), o);
    ok.until(0.5);
    EXPECT_TRUE(ok.seq.have_temperature());
    EXPECT_EQ(ok.seq.rejected(), 0u);
    // The limits are the datasheet's range: a TEMP of 85.01 degC is refused.
    EXPECT_EQ(ms5611::kMaxTempC100, 8500);
    EXPECT_EQ(ms5611::kMinTempC100, -4000);
}

}  // namespace
