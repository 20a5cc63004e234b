// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Battery/BatteryMonitor.h: counts to volts and amps, the charge integrated, the
// remaining percentage, ArduPlane's low-battery failsafe rule; and the whole chain from the
// simulator's pack and power module (sim/models/BatteryModel.h) through the ADC's counts.
#include <gtest/gtest.h>

#include <cmath>

#include "BatteryModel.h"
#include "BatteryMonitor.h"

namespace {

battery::Settings power_module(uint8_t monitor = battery::kMonitorVoltageAndCurrent) {
    battery::Settings s{};
    s.monitor = monitor;
    s.volt_pin = 13;
    s.curr_pin = 12;
    s.volt_mult = 10.1f;
    s.amp_per_volt = 17.0f;
    s.amp_offset_v = 0.0f;
    s.capacity_mah = 3300;
    s.fs_voltage_v = 0.0f;
    s.fs_mah = 0;
    return s;
}

// The ATmega2560's conversion of a pin's millivolts at a 5 V reference (datasheet 26.7:
// ADC = Vin x 1024 / Vref, truncated, at most 1023).
uint16_t adc_counts(double mV) {
    const double c = std::floor(mV * 1024.0 / 5000.0);
    return (uint16_t)std::min(std::max(c, 0.0), 1023.0);
}

TEST(BatteryMonitor, PinVoltsAreTheMeanCountTimesFiveOver1024) {
    EXPECT_FLOAT_EQ(battery::pin_volts(0, 0), 0.0f);
    EXPECT_FLOAT_EQ(battery::pin_volts(1023, 1), 1023.0f * 5.0f / 1024.0f);
    EXPECT_FLOAT_EQ(battery::pin_volts(255u * 10u + 5u, 10), 255.5f * 5.0f / 1024.0f);
    // 63 conversions of 1023 (a 5 V pin for a 10 Hz update at 630 Hz) do not overflow.
    EXPECT_NEAR(battery::pin_volts(1023u * 630u, 630), 4.995f, 0.001f);
}

TEST(BatteryMonitor, VoltsAndAmpsThroughTheMultipliersAndOffset) {
    battery::Settings s = power_module();
    s.amp_offset_v = 0.1f;
    battery::Monitor m;
    m.update(s, 1.2f, 0.6f, 0.0f, 0);
    EXPECT_NEAR(m.voltage_v(), 12.12f, 1e-4f);
    EXPECT_NEAR(m.current_a(), 8.5f, 1e-4f);  // (0.6 - 0.1) x 17
    // Voltage only: no current, no remaining capacity.
    s.monitor = battery::kMonitorVoltage;
    m.update(s, 1.2f, 0.6f, 0.1f, 100);
    EXPECT_NEAR(m.voltage_v(), 12.12f, 1e-4f);
    EXPECT_EQ(m.current_a(), 0.0f);
    EXPECT_EQ(m.remaining_pct(s), -1);
    // Off (and 1, 2: ArduPilot monitors nothing for them): nothing.
    for (uint8_t off : {0, 1, 2}) {
        s.monitor = off;
        m.update(s, 1.2f, 0.6f, 0.1f, 200);
        EXPECT_EQ(m.voltage_v(), 0.0f) << (int)off;
        EXPECT_FALSE(battery::Monitor::enabled(s));
    }
}

TEST(BatteryMonitor, TheChargeIsTheCurrentIntegrated) {
    const battery::Settings s = power_module();
    battery::Monitor m;
    const float pin = 10.0f / 17.0f;  // 10 A
    m.update(s, 1.2f, pin, 0.0f, 0);  // the first: no interval yet
    EXPECT_EQ(m.consumed_mah(), 0.0f);
    for (uint32_t i = 1; i <= 3600; ++i) m.update(s, 1.2f, pin, 0.1f, i * 100u);  // 6 min at 10 A
    EXPECT_NEAR(m.consumed_mah(), 1000.0f, 0.5f);
    // A gap of 2 s or more (a stalled loop) is not integrated, as AP_BattMonitor.
    m.update(s, 1.2f, pin, 2.0f, 400000u);
    EXPECT_NEAR(m.consumed_mah(), 1000.0f, 0.5f);
    m.update(s, 1.2f, pin, 1.9f, 402000u);
    EXPECT_NEAR(m.consumed_mah(), 1000.0f + 10.0f * 1.9f / 3.6f, 0.5f);
}

TEST(BatteryMonitor, RemainingIsWhatIsLeftOfTheCapacity) {
    battery::Settings s = power_module();
    s.capacity_mah = 2000;
    battery::Monitor m;
    EXPECT_EQ(m.remaining_pct(s), 100);
    const float pin = 36.0f / 17.0f;  // 36 A: 1 mAh a 0.1 s step
    for (int i = 0; i < 500; ++i) m.update(s, 1.2f, pin, 0.1f, 0);
    EXPECT_NEAR(m.consumed_mah(), 500.0f, 0.05f);
    // 75 %, truncated as ArduPilot's uint8_t cast (float's sum may land either side of 500).
    EXPECT_EQ(m.remaining_pct(s), (int8_t)(100.0f * (2000.0f - m.consumed_mah()) / 2000.0f));
    EXPECT_NEAR(m.remaining_pct(s), 75, 1);
    for (int i = 0; i < 2000; ++i) m.update(s, 1.2f, pin, 0.1f, 0);
    EXPECT_EQ(m.remaining_pct(s), 0);  // used more than the capacity: 0, never negative
    s.capacity_mah = 0;
    EXPECT_EQ(m.remaining_pct(s), -1);
}

TEST(BatteryMonitor, LowVoltageFailsafeAfterTenSecondsNotOnASag) {
    battery::Settings s = power_module();
    s.fs_voltage_v = 10.5f;
    battery::Monitor m;
    const float ok = 11.1f / 10.1f, low = 10.4f / 10.1f;
    uint32_t t = 0;
    auto run = [&](float pin, uint32_t ms) {
        bool entered = false;
        for (uint32_t end = t + ms; t < end;) {
            t += 100u;
            entered |= m.update(s, pin, 0.0f, 0.1f, t);
        }
        return entered;
    };
    EXPECT_FALSE(run(ok, 5000));
    EXPECT_FALSE(run(low, 9000));  // a 9 s sag under load
    EXPECT_TRUE(m.voltage_low());
    EXPECT_FALSE(run(ok, 200));
    EXPECT_FALSE(m.voltage_low());
    EXPECT_FALSE(run(low, 9000));  // another: the timer started again
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kNone);
    // The first low reading starts the timer; the failsafe is the first reading more than
    // 10 s after it: 10.0 s is not yet, 10.1 s is.
    EXPECT_FALSE(run(low, 1100));
    EXPECT_TRUE(run(low, 100));
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kVoltage);
    // Entered once; it stays when the voltage recovers (ArduPlane's failsafe.low_battery).
    EXPECT_FALSE(run(low, 1000));
    EXPECT_FALSE(run(ok, 1000));
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kVoltage);
    m.reset();
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kNone);
}

TEST(BatteryMonitor, NoVoltageFailsafeWithoutABatteryOrWhenOff) {
    battery::Settings s = power_module(battery::kMonitorVoltage);
    s.fs_voltage_v = 10.5f;
    battery::Monitor m;
    for (uint32_t t = 100; t <= 30000; t += 100) EXPECT_FALSE(m.update(s, 0.0f, 0.0f, 0.1f, t));  // 0 V: none
    s.fs_voltage_v = 0.0f;
    for (uint32_t t = 30100; t <= 60000; t += 100) EXPECT_FALSE(m.update(s, 0.5f, 0.0f, 0.1f, t));  // 5 V: off
    s.fs_voltage_v = 10.5f;
    s.monitor = battery::kMonitorDisabled;
    for (uint32_t t = 60100; t <= 90000; t += 100) EXPECT_FALSE(m.update(s, 0.5f, 0.0f, 0.1f, t));
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kNone);
}

TEST(BatteryMonitor, CapacityFailsafeWhenLessThanFsBattMahIsLeft) {
    battery::Settings s = power_module();
    s.capacity_mah = 1000;
    s.fs_mah = 200;
    battery::Monitor m;
    const float pin = 36.0f / 17.0f;  // 1 mAh a step
    int entered_at = -1;
    for (int i = 1; i <= 900; ++i)
        if (m.update(s, 1.2f, pin, 0.1f, (uint32_t)i * 100u)) entered_at = i;
    // Entered at the first step with more than 800 mAh used (once; float's sum within a step).
    EXPECT_GE(entered_at, 800);
    EXPECT_LE(entered_at, 802);
    EXPECT_EQ(m.failsafe(), battery::Failsafe::kCapacity);
    // Voltage only: the charge is not measured, so no capacity rule.
    battery::Settings v = s;
    v.monitor = battery::kMonitorVoltage;
    battery::Monitor m2;
    for (int i = 1; i <= 900; ++i) EXPECT_FALSE(m2.update(v, 1.2f, pin, 0.1f, (uint32_t)i * 100u));
}

// The pack and power module the simulator drives the pins with, through the ADC's
// truncating conversion and the 10 Hz mean of 5 conversions of each pin (the firmware's
// rhythm): 60 s at 20 A then 60 s at 5 A on a 3S 2200 mAh pack.
TEST(BatteryMonitor, ReadsTheSimulatorsPackWithinOnePercent) {
    sim::BatteryOptions o;
    o.fixed_a = 20.0;
    sim::BatteryModel pack(o);
    const battery::Settings s = power_module();
    battery::Monitor m;
    uint32_t sum_v = 0, sum_i = 0;
    uint16_t n = 0;
    bool first = true;
    for (int step = 1; step <= 12000; ++step) {  // 10 ms steps: 120 s
        const double amps = step <= 6000 ? 20.0 : 5.0;
        pack.step(0.01, amps);
        if (step % 2 == 0) {  // a conversion of each pin every 20 ms
            sum_v += adc_counts(pack.volt_pin_mV());
            sum_i += adc_counts(pack.curr_pin_mV());
            ++n;
        }
        if (step % 10 == 0) {
            m.update(s, battery::pin_volts(sum_v, n), battery::pin_volts(sum_i, n), first ? 0.0f : 0.1f,
                     (uint32_t)step * 10u);
            first = false;
            sum_v = sum_i = 0;
            n = 0;
            EXPECT_NEAR(m.voltage_v(), pack.voltage_v(), 0.01 * pack.voltage_v()) << step;
            EXPECT_NEAR(m.current_a(), amps, 0.01 * amps) << step;
        }
    }
    // 20 A for 60 s and 5 A for 60 s: 416.7 mAh (the first 0.1 s not integrated).
    EXPECT_NEAR(pack.consumed_mah(), 416.67, 0.01);
    EXPECT_NEAR(m.consumed_mah(), pack.consumed_mah(), 0.01 * pack.consumed_mah());
    EXPECT_EQ(m.remaining_pct(s), (int)(100.0 * (3300.0 - m.consumed_mah()) / 3300.0));
}

}  // namespace
