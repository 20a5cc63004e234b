#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The battery monitor as a ground station sees it: the firmware in
`apm25sim --battery ... --serial tcp:0`, a pymavlink ground station on it.

    build/venv/bin/python test/mavlink/battery_monitor.py --tools build --work DIR

Run 1, a 3S 2200 mAh pack (40 mOhm) whose current follows the throttle the firmware sends the
ESC on OUT3 (apm25sim's battery model, its truth in --battery-log), the receiver scripted in
MANUAL: the throttle low, 70 % from 8 s, full from 20 s for 3 s (a sag of the voltage under
load), 50 % from 23 s. The ground station sets ARMING_REQUIRE 0 (the throttle follows the
stick), BATT_MONITOR 4, BATT_CAPACITY 2200, FS_BATT_VOLTAGE 11.5 V; at 28 s FS_BATT_VOLTAGE
12.8 V, above the pack. Checks:
  - SYS_STATUS and BATTERY_STATUS voltage and current within 1 % of the pack's at steady
    throttle (1.5 s after a change), or one ADC count where that is more (the 0.5 A idle:
    a count is 83 mA); at least 8 readings of each at 10 A and more; BATTERY_STATUS about once
    a second;
  - the charge used (BATTERY_STATUS current_consumed) within 1 % + 1 mAh of the pack's since
    BATT_MONITOR 4 was set; battery_remaining what is left of BATT_CAPACITY (within 1 %);
  - SYS_STATUS's battery bit present, enabled and healthy before the failsafe;
  - the 3 s sag below 11.5 V enters no failsafe;
  - "Low battery ...V used ... mAh" (STATUSTEXT, WARNING) 10 to 11.5 s after FS_BATT_VOLTAGE
    went above the pack, once; then the bit unhealthy and BATTERY_STATUS charge_state LOW,
    and "failsafe: low battery: RTL" (or its reason for none) once; the readings compared
    until the failsafe (RTL then flies TECS's throttle, not the stick's).
Run 2, a fixed 20 A: with the default BATT_MONITOR 0 SYS_STATUS says "not measured"
(voltage UINT16_MAX, current and remaining -1, no battery bit) and no BATTERY_STATUS comes;
then BATT_MONITOR 4, BATT_CAPACITY 1000, FS_BATT_MAH 995: the failsafe once more than 5 mAh
are used (0.9 s at 20 A), said with "Low battery". No sample missed in either run.
Timing is on simulated time (the time_boot_ms of the ATTITUDE frames). Exit 1 with every
failure listed.
"""
import bisect
import csv
import os
import sys

from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "support"))
sys.path.insert(0, HERE)
from gcs_link import Board  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

BATTERY_BIT = mavlink2.MAV_SYS_STATUS_SENSOR_BATTERY
THROTTLE = [(0.5, 1000), (8.0, 1700), (20.0, 2000), (23.0, 1500)]  # (t, OUT3 us) in MANUAL
SAG = (20.0, 23.0)
FS_RAISE_AT_S = 28.0
STEADY_AFTER_S = 1.5
# One ADC count (5 V / 1024) on each pin: what the board can resolve, in the pack's units.
COUNT_V = 5.0 / 1024 * 10.1   # 0.049 V
COUNT_A = 5.0 / 1024 * 17.0   # 0.083 A


def close(measured, truth, count):
    """Within 1 % of the truth, or one ADC count where 1 % is less than that (the idle current)."""
    return abs(measured - truth) <= max(0.01 * abs(truth), count)


def write_rc(path):
    with open(path, "w") as f:
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n")
        for t, thr in THROTTLE:
            f.write("%.3f,1500,1500,%d,1500,1500,1500,1500,1100\n" % (t, thr))


class Truth:
    """The pack's truth (apm25sim --battery-log), interpolated at a time."""

    def __init__(self, path):
        with open(path) as f:
            rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
        self.t = [r["t"] for r in rows]
        self.rows = rows

    def at(self, t, key):
        i = bisect.bisect_left(self.t, t)
        if i <= 0:
            return self.rows[0][key]
        if i >= len(self.t):
            return self.rows[-1][key]
        a, b = self.rows[i - 1], self.rows[i]
        w = (t - a["t"]) / (b["t"] - a["t"])
        return a[key] + w * (b[key] - a[key])


def set_param(board, name, value):
    board.conn.mav.param_set_send(1, 1, name.encode(), float(value), mavlink2.MAV_PARAM_TYPE_REAL32)
    m = board.param(name, "PARAM_VALUE %s" % name)
    soft_assert(m is not None and abs(m.param_value - value) < 1e-3, "%s set to %s: %r" % (name, value, m))
    return board.t_s


def steady(t):
    """True when the throttle has not changed for STEADY_AFTER_S before t."""
    last = max(c for c, _ in THROTTLE if c <= t) if t >= THROTTLE[0][0] else 0.0
    return t - last >= STEADY_AFTER_S


def low_battery_texts(msgs):
    return [(t, m) for t, m in msgs if m.get_type() == "STATUSTEXT" and "Low battery" in m.text]


def no_overrun(msgs, run):
    over = [m.text for _, m in msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not over, "%s: samples missed: %s" % (run, over))


def first_run(args, trajectory):
    rc_path = os.path.join(args.work, "throttle.csv")
    write_rc(rc_path)
    log = os.path.join(args.work, "run1_battery.csv")
    b = Board(args.tools, args.work, "run1", ["--trajectory", trajectory, "--speed", "0", "--seconds", "60",
                                              "--rc", rc_path, "--battery", "cells=3,mah=2200,r_ohm=0.04",
                                              "--battery-log", log])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
        b.stop()
        return
    set_param(b, "ARMING_REQUIRE", 0)
    set_param(b, "BATT_CAPACITY", 2200)
    set_param(b, "FS_BATT_VOLTAGE", 11.5)
    t_on = set_param(b, "BATT_MONITOR", 4)
    soft_assert(t_on < SAG[0] - 2.0, "BATT_MONITOR set at %.1f s, too late for the checks" % t_on)
    b.pump(lambda m: b.t_s >= FS_RAISE_AT_S, "simulated time %.0f s" % FS_RAISE_AT_S)
    t_raise = set_param(b, "FS_BATT_VOLTAGE", 12.8)
    fs = b.pump(lambda m: m.get_type() == "STATUSTEXT" and "Low battery" in m.text, "the Low battery STATUSTEXT",
                timeout_s=900)
    t_fs = b.t_s
    b.pump(lambda m: b.t_s >= t_fs + 3.0, "3 s after the failsafe")
    b.stop()
    truth = Truth(log)
    msgs = b.msgs

    # Voltage and current at steady throttle, both messages.
    n_sys = n_bat = 0
    for t, m in msgs:
        # Until the failsafe: its RTL flies TECS's throttle, not the stick's (with the
        # simulated GPS's fix and home at rest).
        if t < t_on + 1.5 or not steady(t) or t >= t_fs - 0.5:
            continue
        volts, amps = truth.at(t, "volts"), truth.at(t, "amps")
        if m.get_type() == "SYS_STATUS":
            n_sys += 1
            soft_assert(close(m.voltage_battery / 1000.0, volts, COUNT_V),
                        "SYS_STATUS at %.1f s: %.3f V, the pack %.3f V" % (t, m.voltage_battery / 1000.0, volts))
            soft_assert(close(m.current_battery / 100.0, amps, COUNT_A),
                        "SYS_STATUS at %.1f s: %.2f A, the pack %.2f A" % (t, m.current_battery / 100.0, amps))
        elif m.get_type() == "BATTERY_STATUS":
            n_bat += 1
            v = m.voltages[0] / 1000.0
            soft_assert(close(v, volts, COUNT_V), "BATTERY_STATUS at %.1f s: %.3f V, the pack %.3f V" % (t, v, volts))
            soft_assert(close(m.current_battery / 100.0, amps, COUNT_A),
                        "BATTERY_STATUS at %.1f s: %.2f A, the pack %.2f A" % (t, m.current_battery / 100.0, amps))
            used = truth.at(t, "mah") - truth.at(t_on, "mah")
            soft_assert(abs(m.current_consumed - used) <= 0.01 * used + 1.0,
                        "BATTERY_STATUS at %.1f s: %d mAh used, the pack %.1f mAh" % (t, m.current_consumed, used))
            left = 100.0 * (2200.0 - m.current_consumed) / 2200.0
            soft_assert(abs(m.battery_remaining - left) <= 1.0,
                        "BATTERY_STATUS at %.1f s: %d %% left, expected %.1f" % (t, m.battery_remaining, left))
    soft_assert(n_sys >= 15 and n_bat >= 15, "too few readings at steady throttle: %d SYS_STATUS, %d BATTERY_STATUS"
                % (n_sys, n_bat))
    loaded = [m for t, m in msgs if m.get_type() in ("SYS_STATUS", "BATTERY_STATUS") and t > t_on + 1.5 and steady(t)
              and truth.at(t, "amps") >= 10.0]
    soft_assert(len(loaded) >= 16, "%d readings at 10 A or more (the 1 %% figure)" % len(loaded))
    bat_times = [t for t, m in msgs if m.get_type() == "BATTERY_STATUS" and t > t_on + 2.0]
    gaps = [b2 - b1 for b1, b2 in zip(bat_times, bat_times[1:])]
    soft_assert(gaps and max(gaps) <= 1.6 and min(gaps) >= 0.9, "BATTERY_STATUS not about 1 Hz: gaps %s"
                % sorted(set(round(g, 2) for g in gaps)))
    # The sag: below FS_BATT_VOLTAGE 11.5 for its 3 s, no failsafe.
    sag_low = [t for t in truth.t if SAG[0] + 0.5 <= t <= SAG[1] and truth.at(t, "volts") < 11.5]
    soft_assert(len(sag_low) >= 20, "the sag did not take the pack below 11.5 V (%d readings)" % len(sag_low))
    texts = low_battery_texts(msgs)
    soft_assert(len(texts) == 1, "Low battery said %d times: %s" % (len(texts), [m.text for _, m in texts]))
    if texts:
        t_text, m = texts[0]
        soft_assert(t_text > t_raise, "Low battery at %.1f s, before FS_BATT_VOLTAGE was raised (%.1f s): the sag"
                    % (t_text, t_raise))
        soft_assert(10.0 <= t_text - t_raise <= 11.5, "Low battery %.2f s after FS_BATT_VOLTAGE went above the pack "
                    "(10 to 11.5 s)" % (t_text - t_raise))
        soft_assert(m.severity == mavlink2.MAV_SEVERITY_WARNING, "Low battery's severity %d" % m.severity)
        print("run 1: %r %.2f s after FS_BATT_VOLTAGE 12.8" % (m.text, t_text - t_raise))
    # The battery bit: present, enabled, healthy before; unhealthy after.
    for t, m in msgs:
        if m.get_type() != "SYS_STATUS" or t < t_on + 1.5:
            continue
        soft_assert(m.onboard_control_sensors_present & BATTERY_BIT and m.onboard_control_sensors_enabled & BATTERY_BIT,
                    "SYS_STATUS at %.1f s: battery bit not present or enabled" % t)
        healthy = bool(m.onboard_control_sensors_health & BATTERY_BIT)
        if t < t_fs - 1.5:
            soft_assert(healthy, "SYS_STATUS at %.1f s: battery unhealthy before the failsafe" % t)
        elif t > t_fs + 1.5:
            soft_assert(not healthy, "SYS_STATUS at %.1f s: battery healthy in the failsafe" % t)
    after = [m for t, m in msgs if m.get_type() == "BATTERY_STATUS" and t > t_fs + 1.5]
    soft_assert(after and all(m.charge_state == mavlink2.MAV_BATTERY_CHARGE_STATE_LOW for m in after),
                "BATTERY_STATUS charge_state after the failsafe: %s" % [m.charge_state for m in after])
    # ArduPlane's action: RTL (the board at rest has a fix and home), or the reason it cannot.
    rtl = [m.text for t, m in msgs if m.get_type() == "STATUSTEXT" and m.text.startswith("failsafe: low battery: ")]
    print("run 1: the failsafe's action: %r" % rtl)
    soft_assert(len(rtl) == 1 and (rtl[0].endswith(": RTL") or "no RTL (" in rtl[0]),
                "the battery failsafe's RTL not said once: %r" % rtl)
    no_overrun(msgs, "run 1")
    print("run 1: %d SYS_STATUS and %d BATTERY_STATUS at steady throttle compared" % (n_sys, n_bat))


def second_run(args, trajectory):
    b = Board(args.tools, args.work, "run2", ["--trajectory", trajectory, "--speed", "0", "--seconds", "40",
                                              "--battery", "amps=20"])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
        b.stop()
        return
    # The board's time from an ATTITUDE: the HEARTBEAT and SYS_STATUS carry none, and the
    # first ones can come before any frame that does (t_s still 0: a 3 s wait from there
    # ended at the first ATTITUDE, ~9 s, with one SYS_STATUS seen on a loaded machine).
    b.pump(lambda m: m.get_type() == "ATTITUDE", "ATTITUDE")
    t_first = b.t_s
    b.pump(lambda m: b.t_s >= t_first + 3.5, "3.5 s of SYS_STATUS")
    off = [(t, m) for t, m in b.msgs if m.get_type() == "SYS_STATUS"]
    in_window = [t for t, _ in off if t_first <= t <= t_first + 3.5]
    soft_assert(len(in_window) >= 3, "%d SYS_STATUS in 3.5 s (1 Hz)" % len(in_window))
    for t, m in off:
        soft_assert(m.voltage_battery == 65535 and m.current_battery == -1 and m.battery_remaining == -1,
                    "BATT_MONITOR 0: SYS_STATUS at %.1f s says %d mV, %d cA, %d %%" % (
                        t, m.voltage_battery, m.current_battery, m.battery_remaining))
        soft_assert(not (m.onboard_control_sensors_present & BATTERY_BIT), "BATT_MONITOR 0: a battery bit")
    soft_assert(not any(m.get_type() == "BATTERY_STATUS" for _, m in b.msgs), "BATT_MONITOR 0: BATTERY_STATUS sent")
    set_param(b, "BATT_CAPACITY", 1000)
    set_param(b, "FS_BATT_MAH", 995)
    t_on = set_param(b, "BATT_MONITOR", 4)
    b.pump(lambda m: m.get_type() == "STATUSTEXT" and "Low battery" in m.text, "the Low battery STATUSTEXT (FS_BATT_MAH)")
    t_fs = b.t_s
    b.pump(lambda m: b.t_s >= t_fs + 2.5, "2.5 s after the failsafe")
    b.stop()
    # More than 5 mAh used: 0.9 s at 20 A, and the 10 Hz update.
    soft_assert(0.8 <= t_fs - t_on <= 1.6, "FS_BATT_MAH's failsafe %.2f s after BATT_MONITOR 4 (0.9 s expected)"
                % (t_fs - t_on))
    texts = low_battery_texts(b.msgs)
    soft_assert(len(texts) == 1, "Low battery said %d times" % len(texts))
    if texts:
        print("run 2: %r %.2f s after BATT_MONITOR 4" % (texts[0][1].text, t_fs - t_on))
    on = [m for t, m in b.msgs if m.get_type() == "SYS_STATUS" and t > t_on + 0.5]
    soft_assert(on and all(abs(m.current_battery - 2000) <= 20 for m in on),
                "SYS_STATUS current with BATT_MONITOR 4: %s cA" % [m.current_battery for m in on])
    no_overrun(b.msgs, "run 2")


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "rest")
    first_run(args, trajectory)
    second_run(args, trajectory)


if __name__ == "__main__":
    main()
    sys.exit(finish("battery monitor", "the battery monitor over TCP: all checks passed"))
