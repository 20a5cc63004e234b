// SPDX-License-Identifier: GPL-3.0-or-later
// A LiPo pack behind a 3DR power module, as the APM 2.5's analog inputs see it: the
// simulator drives A13 (voltage) and A12 (current) with it (apm25sim --battery), and the
// host tests check the firmware's battery monitor (lib/Battery) against it.
//
// The pack: `cells` LiPo cells in series, each at the open-circuit voltage of its state of
// charge (a typical LiPo discharge curve at low rate: 4.20 V full, a plateau near 3.8 V,
// 3.3 V empty; kOcvTable), less the current x the pack's internal resistance r_ohm. The
// charge falls by current x dt (coulomb counting); an empty pack holds at 0 %.
// The current: a fixed one (`amps`), or an electric motor's from the throttle the firmware
// sends the ESC on OUT3: idle_a + (max_a - idle_a) x throttle^1.5, throttle = (width -
// 1000 us) / 1000 us within 0..1 (an ESC calibrated to 1000-2000 us; a propeller's power
// rises with about the cube of its speed and the speed with the throttle, the current a
// little less steeply as the voltage sags: 1.5 is a plain middle), idle_a without a pulse.
// The power module (3DR PM, ArduPilot's APM2 defaults): voltage pin = pack volts / 10.1,
// current pin = amps / 17 A/V + 0 V, each held within the ADC's 0..5 V.
#pragma once

#include <stdint.h>

#include <string>

namespace sim {

struct BatteryOptions {
    int cells = 3;
    double capacity_mah = 2200.0;
    double charge = 1.0;          // state of charge at the start, 0..1
    double r_ohm = 0.04;          // the pack's internal resistance
    double fixed_a = -1.0;        // >= 0: this current always; < 0: from the throttle
    double max_a = 30.0;          // at full throttle
    double idle_a = 0.5;          // the board, the receiver, the servos
    double volt_mult = 10.1;      // the power module's divider (BATT_VOLT_MULT)
    double amp_per_volt = 17.0;   // its current sensor (BATT_AMP_PERVOLT)
    double amp_offset_v = 0.0;    // its output at 0 A (BATT_AMP_OFFSET)
};

// "cells=3,mah=2200,charge=1,r_ohm=0.04,amps=10,max_a=30,idle_a=0.5,volt_mult=10.1,
// amp_per_volt=17,amp_offset=0": any of the keys, in any order; "" the defaults. False
// with `error` on an unknown key or a value out of its range.
bool parse_battery_spec(const std::string& spec, BatteryOptions& out, std::string& error);

class BatteryModel {
public:
    explicit BatteryModel(const BatteryOptions& options) : o_(options), charge_(options.charge) {}

    // The current the pack gives with this OUT3 pulse width (0: no pulse).
    double current_a(uint16_t throttle_width_us) const;
    // dt_s at `amps`: the charge used, and the terminal voltage at that current.
    void step(double dt_s, double amps);

    double open_circuit_v() const;
    double voltage_v() const { return voltage_v_; }    // at the last step's current
    double current_a() const { return current_a_; }    // the last step's
    double consumed_mah() const { return consumed_mah_; }
    double charge() const { return charge_; }
    // The power module's outputs, mV at the board's pins.
    double volt_pin_mV() const;
    double curr_pin_mV() const;
    const BatteryOptions& options() const { return o_; }

    // A cell's open-circuit voltage at a state of charge 0..1.
    static double cell_ocv_v(double charge);

private:
    BatteryOptions o_;
    double charge_;
    double current_a_ = 0.0;
    double consumed_mah_ = 0.0;
    double voltage_v_ = 0.0;
    bool stepped_ = false;
};

}  // namespace sim
