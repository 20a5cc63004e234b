// SPDX-License-Identifier: GPL-3.0-or-later
// sim/models/BatteryModel.h: the pack's voltage by charge and load, the current from the
// throttle, the power module's pins, the --battery option's grammar.
#include <gtest/gtest.h>

#include "BatteryModel.h"

namespace {

TEST(BatteryModel, OpenCircuitVoltageFollowsTheCharge) {
    EXPECT_DOUBLE_EQ(sim::BatteryModel::cell_ocv_v(1.0), 4.20);
    EXPECT_DOUBLE_EQ(sim::BatteryModel::cell_ocv_v(0.0), 3.27);
    EXPECT_DOUBLE_EQ(sim::BatteryModel::cell_ocv_v(-0.5), 3.27);
    double last = 0.0;
    for (int i = 0; i <= 100; ++i) {
        const double v = sim::BatteryModel::cell_ocv_v(i / 100.0);
        EXPECT_GT(v, last) << i;  // strictly rising: a charge has one voltage
        last = v;
    }
    sim::BatteryOptions o;
    o.cells = 4;
    EXPECT_DOUBLE_EQ(sim::BatteryModel(o).open_circuit_v(), 16.8);
}

TEST(BatteryModel, TheLoadSagsTheVoltageAndDrainsTheCharge) {
    sim::BatteryOptions o;  // 3S, 2200 mAh, 40 mOhm
    sim::BatteryModel b(o);
    b.step(0.0, 25.0);
    EXPECT_NEAR(b.voltage_v(), 12.6 - 25.0 * 0.04, 1e-9);
    for (int i = 0; i < 3600; ++i) b.step(0.1, 11.0);  // 6 min at 11 A: 1100 mAh
    EXPECT_NEAR(b.consumed_mah(), 1100.0, 1e-6);
    EXPECT_NEAR(b.charge(), 0.5, 1e-9);
    EXPECT_NEAR(b.voltage_v(), 3.0 * sim::BatteryModel::cell_ocv_v(0.5) - 11.0 * 0.04, 1e-9);
    for (int i = 0; i < 7200; ++i) b.step(0.1, 11.0);  // past empty: the charge holds at 0
    EXPECT_EQ(b.charge(), 0.0);
}

TEST(BatteryModel, CurrentFromTheThrottle) {
    sim::BatteryOptions o;  // 0.5 A idle, 30 A full
    sim::BatteryModel b(o);
    EXPECT_DOUBLE_EQ(b.current_a(0), 0.5);     // no pulse
    EXPECT_DOUBLE_EQ(b.current_a(900), 0.5);
    EXPECT_DOUBLE_EQ(b.current_a(1000), 0.5);
    EXPECT_NEAR(b.current_a(1500), 0.5 + 29.5 * 0.353553, 1e-4);
    EXPECT_DOUBLE_EQ(b.current_a(2000), 30.0);
    EXPECT_DOUBLE_EQ(b.current_a(2100), 30.0);
    o.fixed_a = 7.0;
    EXPECT_DOUBLE_EQ(sim::BatteryModel(o).current_a(2000), 7.0);
}

TEST(BatteryModel, PowerModulePins) {
    sim::BatteryOptions o;
    sim::BatteryModel b(o);
    EXPECT_NEAR(b.volt_pin_mV(), 12600.0 / 10.1, 1e-9);  // before any step: open circuit
    b.step(0.01, 17.0);
    EXPECT_NEAR(b.curr_pin_mV(), 1000.0, 1e-9);
    EXPECT_NEAR(b.volt_pin_mV(), (12.6 - 17.0 * 0.04) / 10.1 * 1000.0, 0.05);  // 47 mAs used: 0.008 mV less
    b.step(0.0, 200.0);  // 200 A: 11.8 V on the current pin, held at 5 V
    EXPECT_DOUBLE_EQ(b.curr_pin_mV(), 5000.0);
}

TEST(BatteryModel, SpecGrammar) {
    sim::BatteryOptions o;
    std::string err;
    ASSERT_TRUE(sim::parse_battery_spec("", o, err)) << err;
    EXPECT_EQ(o.cells, 3);
    EXPECT_LT(o.fixed_a, 0.0);
    ASSERT_TRUE(sim::parse_battery_spec("cells=4,mah=5000,charge=0.5,r_ohm=0.02,amps=12,amp_offset=0.1", o, err))
        << err;
    EXPECT_EQ(o.cells, 4);
    EXPECT_DOUBLE_EQ(o.capacity_mah, 5000.0);
    EXPECT_DOUBLE_EQ(o.charge, 0.5);
    EXPECT_DOUBLE_EQ(o.r_ohm, 0.02);
    EXPECT_DOUBLE_EQ(o.fixed_a, 12.0);
    EXPECT_DOUBLE_EQ(o.amp_offset_v, 0.1);
    for (const char* bad : {"cells=0", "cells=2.5", "charge=1.5", "volts=12", "mah", "amps=x", "mah=-1"}) {
        sim::BatteryOptions keep;
        keep.cells = 6;
        EXPECT_FALSE(sim::parse_battery_spec(bad, keep, err)) << bad;
        EXPECT_FALSE(err.empty()) << bad;
        EXPECT_EQ(keep.cells, 6) << bad;  // nothing changed
    }
}

}  // namespace
