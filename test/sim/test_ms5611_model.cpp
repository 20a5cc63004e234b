// SPDX-License-Identifier: GPL-3.0-or-later
// The MS5611 model (sim/models/Ms5611Model.h) through its SPI commands: the codes it
// answers turned back into pressure and temperature by lib/MS5611's compensation (the
// firmware's), which test/MS5611 holds to the datasheet's worked example.
#include <gtest/gtest.h>

#include <cmath>

#include "Geodesy.h"
#include "Ms5611Math.h"
#include "Ms5611Model.h"
#include "sim_models_support.h"

namespace {

// --- the datasheet's arithmetic: lib/MS5611's, tested against the datasheet's worked example
// and cold cases in test/MS5611 (one implementation for the firmware and the model) ----------

unsigned an520_crc4(const uint16_t prom[8]) { return ms5611::crc4(prom); }

void datasheet_compensate(const uint16_t c[8], uint32_t d1, uint32_t d2, int32_t& p, int32_t& temp) {
    const ms5611::Terms t = ms5611::terms(c, d2);
    temp = t.temp_c100;
    p = ms5611::pressure_pa(t, d1);
}

// --- a driver's side of the bus ----------------------------------------------------------

struct Bus {
    sim::Ms5611Model chip;
    double t_s = 0.0;
    explicit Bus(const sim::Trajectory& t, const sim::Ms5611Options& o = sim::Ms5611Options()) : chip(t, o) {}

    void at(double t) {
        t_s = t;
        chip.advance_to(t);
    }
    // One transaction: chip select low, the bytes, chip select high; the bytes read back.
    std::vector<uint8_t> transaction(const std::vector<uint8_t>& out) {
        chip.advance_to(t_s);
        chip.set_chip_select(true);
        std::vector<uint8_t> in;
        for (uint8_t b : out) in.push_back(chip.transfer(b));
        chip.set_chip_select(false);
        return in;
    }
    uint16_t prom(int word) {
        const std::vector<uint8_t> r = transaction({(uint8_t)(0xA0 + 2 * word), 0, 0});
        return (uint16_t)(r[1] << 8 | r[2]);
    }
    uint32_t adc() {
        const std::vector<uint8_t> r = transaction({0x00, 0, 0, 0});
        return (uint32_t)r[1] << 16 | (uint32_t)r[2] << 8 | r[3];
    }
    // Converts (cmd), waits `wait_s`, reads.
    uint32_t convert(uint8_t cmd, double wait_s) {
        transaction({cmd});
        at(t_s + wait_s);
        return adc();
    }
};

sim::Trajectory still_at_depth(double d_m, double seconds = 30.0) {
    const double still[3] = {0, 0, 0};
    sim::Trajectory t = simtest::moving_trajectory(seconds, still, 10.0);
    for (sim::TrajectorySample& s : t.samples()) s.ned_m[2] = d_m;
    return t;
}

TEST(Ms5611Model, PromReadsTheDatasheetCoefficientsWithAValidCrc) {
    Bus bus(still_at_depth(0));
    bus.transaction({0x1E});
    bus.at(0.003);
    uint16_t prom[8];
    for (int w = 0; w < 8; ++w) prom[w] = bus.prom(w);
    const uint16_t example[6] = {40127, 36924, 23317, 23282, 33464, 28312};
    for (int i = 0; i < 6; ++i) EXPECT_EQ(prom[i + 1], example[i]) << "C" << i + 1;
    EXPECT_EQ(prom[7] & 0x000F, an520_crc4(prom));
    EXPECT_NE(prom[0], 0);  // a factory word that the CRC covers
    // A single flipped bit anywhere fails it.
    for (int w = 0; w < 8; ++w) {
        uint16_t bad[8];
        for (int i = 0; i < 8; ++i) bad[i] = prom[i];
        bad[w] ^= w == 7 ? 0x0100 : 0x0004;
        EXPECT_NE(bad[7] & 0x000F, an520_crc4(bad)) << w;
    }
    EXPECT_EQ(bus.chip.counters().prom_reads, 8u);
}

TEST(Ms5611Model, CodesGiveBackThePressureWithTheDatasheetsArithmetic) {
    // Noise-free conversions at several heights and chip temperatures (above 20, between
    // -15 and 20, below -15 degC: both second-order branches).
    for (double alt : {-300.0, 0.0, 1028.0, 2500.0, 5000.0}) {
        for (double temp_c : {40.0, 25.0, 20.0, 12.0, 0.0, -10.0, -20.0, -35.0}) {
            sim::Ms5611Options o;
            o.noise_pa = 0.0;
            o.fixed_temperature = true;
            o.temperature_c = temp_c;
            o.home.alt_m = alt;
            Bus bus(still_at_depth(0), o);
            bus.at(1.0);
            const uint32_t d1 = bus.convert(0x48, 0.0091);
            const uint32_t d2 = bus.convert(0x58, 0.0091);
            int32_t p = 0, temp = 0;
            datasheet_compensate(sim::Ms5611Model::kProm, d1, d2, p, temp);
            const double truth_pa = 101325.0 * std::pow(1.0 - 2.25577e-5 * alt, 5.25588);
            EXPECT_NEAR(p, truth_pa, 1.5) << alt << " m, " << temp_c << " degC";  // 0.015 hPa
            EXPECT_NEAR(temp * 0.01, temp_c, 0.011) << alt << " m, " << temp_c << " degC";
        }
    }
}

TEST(Ms5611Model, ThePressureFollowsTheHeightAndTheStandardAtmosphere) {
    // 1028 m at home, 100 m above it: 1128 m; the ISA temperature by default.
    sim::Ms5611Options o;
    o.noise_pa = 0.0;
    Bus bus(still_at_depth(-100.0), o);
    bus.at(0.5);
    const uint32_t d1 = bus.convert(0x48, 0.01), d2 = bus.convert(0x58, 0.01);
    int32_t p = 0, temp = 0;
    datasheet_compensate(sim::Ms5611Model::kProm, d1, d2, p, temp);
    EXPECT_NEAR(p, 88488.0, 2.0);         // ISA at 1128 m: 884.88 hPa
    EXPECT_NEAR(temp * 0.01, 7.67, 0.02);  // 15 - 6.5 x 1.128
    EXPECT_NEAR(sim::isa_altitude_m(p), 1128.0, 0.2);
}

TEST(Ms5611Model, AReadBeforeTheConversionEndsIsZero) {
    sim::Ms5611Options o;
    o.noise_pa = 0.0;
    Bus bus(still_at_depth(0), o);
    bus.at(1.0);
    // OSR 4096: 9.04 ms at most. At 8.5 ms: 0, and that conversion is spoiled.
    EXPECT_EQ(bus.convert(0x48, 0.0085), 0u);
    bus.at(1.1);
    EXPECT_EQ(bus.adc(), 0u);
    EXPECT_EQ(bus.chip.counters().reads_during_conversion, 1u);
    // Waited out: a value; read again: 0 (the result is read once).
    const uint32_t d1 = bus.convert(0x48, 0.00905);
    EXPECT_GT(d1, 1000000u);
    EXPECT_EQ(bus.adc(), 0u);
    // Each OSR's time: just before, 0; just after, a value.
    const double times[5] = {0.60e-3, 1.17e-3, 2.28e-3, 4.54e-3, 9.04e-3};
    for (int osr = 0; osr < 5; ++osr) {
        bus.at(bus.t_s + 0.02);
        EXPECT_EQ(bus.convert((uint8_t)(0x50 + 2 * osr), times[osr] - 20e-6), 0u) << osr;
        bus.at(bus.t_s + 0.02);
        EXPECT_GT(bus.convert((uint8_t)(0x50 + 2 * osr), times[osr] + 1e-6), 1000000u) << osr;
    }
    // No conversion at all: 0.
    bus.at(bus.t_s + 0.02);
    EXPECT_EQ(bus.adc(), 0u);
}

TEST(Ms5611Model, ResetMakesTheChipDeafForItsReload) {
    Bus bus(still_at_depth(0));
    bus.at(1.0);
    bus.transaction({0x1E});
    bus.at(1.001);
    EXPECT_EQ(bus.prom(1), 0);  // still reloading
    EXPECT_EQ(bus.chip.counters().commands_during_reset, 1u);
    bus.at(1.003);
    EXPECT_EQ(bus.prom(1), 40127);
}

TEST(Ms5611Model, NoiseIsAboutATenthOfAHectopascal) {
    Bus bus(still_at_depth(0, 200.0));
    bus.at(0.1);
    const uint32_t d2 = bus.convert(0x58, 0.01);
    double sum = 0, sum2 = 0;
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
        const uint32_t d1 = bus.convert(0x48, 0.0095);
        int32_t p = 0, temp = 0;
        datasheet_compensate(sim::Ms5611Model::kProm, d1, d2, p, temp);
        sum += p;
        sum2 += (double)p * p;
    }
    const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(sigma, 10.0, 1.0);
    EXPECT_NEAR(mean, sim::isa_pressure_pa(sim::kHomeAlt_m), 1.5);
}

TEST(Ms5611Model, OnlyAnswersWhileSelected) {
    Bus bus(still_at_depth(0));
    bus.at(0.1);
    EXPECT_EQ(bus.chip.transfer(0xA2), 0);  // chip select high: nothing driven, nothing counted
    EXPECT_EQ(bus.chip.transfer(0x00), 0);
    EXPECT_EQ(bus.chip.counters().bytes, 0u);
    EXPECT_EQ(bus.prom(1), 40127);
}

TEST(Ms5611Model, Faults) {
    sim::Ms5611Options o;
    o.noise_pa = 0.0;
    Bus bus(still_at_depth(0, 10.0), o);
    bus.chip.faults().absent.add(sim::TimeWindow::between(1.0, 2.0));
    bus.chip.faults().stuck.add(sim::TimeWindow::between(3.0, 4.0));
    bus.chip.faults().spike.add(sim::TimeWindow::between(5.0, 6.0));
    bus.at(0.5);
    const uint32_t d1 = bus.convert(0x48, 0.01);
    bus.at(1.5);
    EXPECT_EQ(bus.prom(1), 0);
    EXPECT_EQ(bus.convert(0x48, 0.01), 0u);
    EXPECT_GT(bus.chip.counters().bytes_while_absent, 0u);
    // All-zero PROM: its CRC-4 is 0 too, so a driver must reject it on its own.
    const uint16_t zeros[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    EXPECT_EQ(an520_crc4(zeros), 0u);
    // Stuck: the same D1 whatever the height does.
    bus.at(2.9);
    const uint32_t before = bus.convert(0x48, 0.01);
    bus.chip.trajectory().samples().back().ned_m[2] = -500.0;  // the board shoots up (held after the end)
    for (sim::TrajectorySample& s : bus.chip.trajectory().samples()) s.ned_m[2] = -500.0;
    bus.at(3.5);
    EXPECT_EQ(bus.convert(0x48, 0.01), before);
    bus.at(4.5);
    const uint32_t high = bus.convert(0x48, 0.01);
    EXPECT_LT(high, before);  // lower pressure up there
    // Spike: bit 19 flipped.
    bus.at(5.5);
    EXPECT_EQ(bus.convert(0x48, 0.01), high ^ (1u << 19));
    (void)d1;
}

}  // namespace
