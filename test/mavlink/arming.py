#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Arming, modes and RC overrides from a ground station, pymavlink over TCP.

    build/venv/bin/python test/mavlink/arming.py --tools build --work DIR

Runs build/firmware.elf in `apm25sim --serial tcp:0 --speed 1` at rest with a scripted
receiver (--rc), the outputs measured on the pins (--servo-log), the compass and the
barometer taken away for a while (--fault), and talks to it as a ground station:
  - MAV_CMD_COMPONENT_ARM_DISARM refused (FAILED) with each provoked reason said as
    STATUSTEXT "PreArm: ...": with no receiver (RC not found), the throttle stick up (Throttle too high), the
    compass and the barometer gone (Compass not healthy, Barometer not healthy), the
    receiver lost (Radio failsafe on), during `cal gyro` (Gyros not calibrated; tried at
    start-up too), `cal mag` (Compass calibration running) and, the calibration cancelled,
    with COMPASS_LEARN 0 (Compass not calibrated);
  - armed by the rudder (full right, throttle at zero, 3 s: "Throttle armed" 3 s after the
    gesture began), disarmed by the command, armed by the command, disarmed by the rudder
    (full left 3 s with ARMING_RUDDER 2 set by PARAM_SET); HEARTBEAT's SAFETY_ARMED follows;
  - the throttle pin (OUT3) at 1000 us from the first pulse whenever disarmed, the stick's
    width while armed;
  - SET_MODE (ACK command 11), DO_SET_MODE in COMMAND_LONG and COMMAND_INT for MANUAL,
    STABILIZE and FBWA, each ACCEPTED and in HEARTBEAT's custom_mode; 8 (AUTOTUNE) and 4 (ACRO)
    refused with FAILED and "no mode", 10 (AUTO, no mission) with FAILED and its reason; the
    mode switch moving takes over; PARAM_SET FLTMODE1 4 refused;
  - RC_CHANNELS_OVERRIDE of channel 1 on the pin (OUT1) and RC_CHANNELS, back to the
    receiver's RC_OVERRIDE_TIME (set to 1.5 s by PARAM_SET: in force at once) after the last
    message.
Exit 1 with every failure listed. Timing assertions are on simulated time only.
"""
import csv
import os
import sys

from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from gcs_link import Board, command  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

MANUAL, HIGH = 1000, 1900  # channel 8: MANUAL low, STABILIZE high (FLTMODE6)
END_S = 49.0
# (t, ch1..ch8) or (t, None): no receiver.
RC = [
    (0.0, None),                                                # no receiver: RC not found
    (3.0, [1500, 1500, 1500, 1500, 1500, 1500, 1500, MANUAL]),  # throttle up: too high
    (6.0, [1500, 1500, 1000, 2000, 1500, 1500, 1500, MANUAL]),  # throttle 0, full right rudder: armed ~9.0
    (9.6, [1500, 1500, 1300, 1500, 1500, 1500, 1500, MANUAL]),  # armed: throttle 30 %
    (13.0, [1500, 1500, 1000, 1500, 1500, 1500, 1500, MANUAL]),  # throttle 0 (the command arms at ~13.5)
    (15.0, [1500, 1500, 1000, 1000, 1500, 1500, 1500, MANUAL]),  # full left: disarmed ~18 (ARMING_RUDDER 2)
    (18.6, [1500, 1500, 1000, 1500, 1500, 1500, 1500, MANUAL]),
    (35.0, [1500, 1500, 1000, 1500, 1500, 1500, 1500, HIGH]),    # the switch moves: STABILIZE
    (37.0, None),                                                # lost: Radio failsafe on
    (40.0, [1500, 1500, 1000, 1500, 1500, 1500, 1500, HIGH]),
]
FAULTS = ["mag:absent@19-21", "baro:absent@19-21"]


def write_rc(path):
    with open(path, "w") as f:
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n")
        for t, ch in RC:
            f.write("%.3f,%s\n" % (t, ",".join(str(c) for c in ch) if ch else ",,,,,,,"))


def wait_until(b, t_s):
    b.pump(lambda m: b.t_s >= t_s, "simulated time %.1f s" % t_s)


def prearm(b, reason, until_s, what, must=True):
    """Arms (COMMAND_LONG) until the reason is said or until_s: True when refused with it.
    A command the board did not answer (still in its text mode: it switches to MAVLink on
    the ground station's HEARTBEAT) is sent again after a wall second."""
    start = len(b.msgs)
    while b.t_s < until_s:
        b.conn.mav.heartbeat_send(mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0)
        command(b, mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        ack = b.pump(lambda m: m.get_type() == "COMMAND_ACK" and m.command == mavlink2.MAV_CMD_COMPONENT_ARM_DISARM,
                     "COMMAND_ACK to arm (%s)" % what, timeout_s=1.0, quiet=True)
        if ack is None:
            if b.proc.poll() is not None:
                break
            continue
        soft_assert(ack.result == mavlink2.MAV_RESULT_FAILED, "%s: arming answered %d, not FAILED" % (what, ack.result))
        t = b.t_s
        b.pump(lambda m, t=t: b.t_s > t + 0.3, "the reasons")
        said = [m.text for _, m in b.msgs[start:] if m.get_type() == "STATUSTEXT"]
        if "PreArm: " + reason in said:
            print("# %s: arming refused at %.2f s, 'PreArm: %s'" % (what, t, reason))
            return True
    soft_assert(not must, "%s: never refused with 'PreArm: %s' before %.1f s" % (what, reason, until_s))
    return False


def text_at(msgs, text, after=0.0):
    return next((t for t, m in msgs if t >= after and m.get_type() == "STATUSTEXT" and m.text == text), None)


def set_mode_checks(b):
    """Every mode by each message, a refusal, the HEARTBEAT following."""
    for how, number, name in (("SET_MODE", 2, "STABILIZE"), ("COMMAND_LONG", 5, "FBWA"), ("COMMAND_INT", 0, "MANUAL"),
                              ("COMMAND_LONG", 2, "STABILIZE"), ("SET_MODE", 5, "FBWA")):
        if how == "SET_MODE":
            b.conn.mav.set_mode_send(1, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, number)
            ack = b.ack(11, "COMMAND_ACK (11) to SET_MODE %d" % number)
        elif how == "COMMAND_LONG":
            command(b, mavlink2.MAV_CMD_DO_SET_MODE, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, number)
            ack = b.ack(mavlink2.MAV_CMD_DO_SET_MODE, "COMMAND_ACK to DO_SET_MODE %d" % number)
        else:
            b.conn.mav.command_int_send(1, 1, 0, mavlink2.MAV_CMD_DO_SET_MODE, 0, 0,
                                        mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, number, 0, 0, 0, 0, 0)
            ack = b.ack(mavlink2.MAV_CMD_DO_SET_MODE, "COMMAND_ACK to COMMAND_INT DO_SET_MODE %d" % number)
        soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "%s %s: %r" % (how, name, ack))
        t = b.t_s
        hb = b.pump(lambda m, t=t: m.get_type() == "HEARTBEAT" and b.t_s > t + 0.05, "HEARTBEAT after " + name)
        soft_assert(hb is not None and hb.custom_mode == number, "%s %s: HEARTBEAT custom_mode %r"
                    % (how, name, hb and hb.custom_mode))
    print("# modes: SET_MODE, DO_SET_MODE (COMMAND_LONG, COMMAND_INT) for MANUAL, STABILIZE, FBWA accepted and flown")
    # Refused: a mode the board does not have, in both messages, with its reason; AUTO
    # (a mode it has) for want of a fix, home or a mission, with that reason.
    command(b, mavlink2.MAV_CMD_DO_SET_MODE, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 8)
    ack = b.ack(mavlink2.MAV_CMD_DO_SET_MODE, "COMMAND_ACK to DO_SET_MODE 8")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_FAILED, "DO_SET_MODE 8 (AUTOTUNE): %r" % ack)
    b.conn.mav.set_mode_send(1, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 4)
    ack = b.ack(11, "COMMAND_ACK to SET_MODE 4")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_FAILED, "SET_MODE 4 (ACRO): %r" % ack)
    command(b, mavlink2.MAV_CMD_DO_SET_MODE, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 10)
    ack = b.ack(mavlink2.MAV_CMD_DO_SET_MODE, "COMMAND_ACK to DO_SET_MODE 10")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_FAILED, "DO_SET_MODE 10 (AUTO, no mission): %r"
                % ack)
    t = b.t_s
    b.pump(lambda m, t=t: b.t_s > t + 0.3, "the reasons")
    for n in (8, 4):
        soft_assert(text_at(b.msgs, "Mode change refused: no mode %d on this board" % n, t - 1.0) is not None,
                    "no reason said for mode %d" % n)
    auto = [m.text for tm, m in b.msgs if tm >= t - 1.0 and m.get_type() == "STATUSTEXT"
            and m.text.startswith("Mode change refused: AUTO: ")]
    print("# AUTO refused: %r" % auto)
    soft_assert(auto and auto[0].split(": ")[-1] in ("no 3D GPS fix", "no home", "no mission"),
                "no reason said for AUTO: %r" % auto)
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the refusals")
    soft_assert(hb is not None and hb.custom_mode == 5, "a refused mode changed the mode: %r" % (hb and hb.custom_mode))
    # FLTMODE1 4 (ACRO) refused: the old value back.
    b.conn.mav.param_set_send(1, 1, b"FLTMODE1", 4, mavlink2.MAV_PARAM_TYPE_INT8)
    pv = b.param("FLTMODE1", "PARAM_VALUE for FLTMODE1 4")
    soft_assert(pv is not None and pv.param_value == 0, "FLTMODE1 4 (not a mode here) -> %r" % pv)


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "rest")
    rc_path = os.path.join(args.work, "rc.csv")
    write_rc(rc_path)
    servo_log = os.path.join(args.work, "servo.csv")
    extra = ["--trajectory", trajectory, "--rc", rc_path, "--servo-log", servo_log, "--seconds", "%g" % (END_S + 5)]
    for f in FAULTS:
        extra += ["--fault", f]
    b = Board(args.tools, args.work, "arming", extra)
    # 1. During the start-up gyro calibration (~0.1 to 1.4 s: a ground station rarely
    # connects that early, so it is tried, and `cal gyro` provokes it below).
    prearm(b, "Gyros not calibrated", 1.4, "start-up gyro calibration", must=False)
    # 2. No receiver yet.
    wait_until(b, 1.6)
    prearm(b, "RC not found", 2.9, "no receiver")
    # 3. The throttle up.
    wait_until(b, 3.2)
    prearm(b, "Throttle too high", 5.8, "throttle high")
    # 4. Armed by the rudder (6.0 to ~9.0 s).
    armed_at = b.pump(lambda m: m.get_type() == "STATUSTEXT" and m.text == "Throttle armed", "'Throttle armed'")
    t_armed = b.t_s if armed_at else None
    soft_assert(t_armed is not None and 9.0 <= t_armed <= 9.3, "armed by the rudder at %s s (the gesture from 6.0 s)"
                % t_armed)
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT armed")
    soft_assert(hb is not None and hb.base_mode & mavlink2.MAV_MODE_FLAG_SAFETY_ARMED, "HEARTBEAT not armed: %r" % hb)
    # 5. Disarmed by the command (throttle stick at 30 %), armed by it (throttle at zero).
    wait_until(b, 11.0)
    command(b, mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 0)
    ack = b.ack(mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, "COMMAND_ACK to disarm")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "disarm: %r" % ack)
    t_disarmed = b.t_s
    hb = b.pump(lambda m, t=b.t_s: m.get_type() == "HEARTBEAT" and b.t_s > t, "HEARTBEAT disarmed")
    soft_assert(hb is not None and not hb.base_mode & mavlink2.MAV_MODE_FLAG_SAFETY_ARMED, "HEARTBEAT armed: %r" % hb)
    wait_until(b, 13.5)
    command(b, mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 1)
    ack = b.ack(mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, "COMMAND_ACK to arm")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "arm by the command: %r" % ack)
    t_armed2 = b.t_s
    # 6. Disarmed by the rudder (ARMING_RUDDER 2): full left from 15.0 s.
    b.conn.mav.param_set_send(1, 1, b"ARMING_RUDDER", 2, mavlink2.MAV_PARAM_TYPE_INT8)
    pv = b.param("ARMING_RUDDER", "PARAM_VALUE ARMING_RUDDER 2")
    soft_assert(pv is not None and pv.param_value == 2, "ARMING_RUDDER 2: %r" % pv)
    dis = b.pump(lambda m: m.get_type() == "STATUSTEXT" and m.text.startswith("Throttle disarmed (rudder)"),
                 "'Throttle disarmed (rudder)'")
    t_disarmed2 = b.t_s if dis else None
    soft_assert(t_disarmed2 is not None and 18.0 <= t_disarmed2 <= 18.3, "disarmed by the rudder at %s s (from 15.0)"
                % t_disarmed2)
    # RC_OVERRIDE_TIME 1.5 s for step 8 (before the sensors go: their recovery at 21 s and a
    # PARAM_SET's long pass, ~6 ms, are kept apart).
    b.conn.mav.param_set_send(1, 1, b"RC_OVERRIDE_TIME", 1.5, mavlink2.MAV_PARAM_TYPE_REAL32)
    pv = b.param("RC_OVERRIDE_TIME", "PARAM_VALUE RC_OVERRIDE_TIME 1.5")
    soft_assert(pv is not None and abs(pv.param_value - 1.5) < 1e-6, "RC_OVERRIDE_TIME 1.5: %r" % pv)
    # 7. The compass and the barometer gone (19 to 21 s).
    wait_until(b, 19.3)
    prearm(b, "Compass not healthy", 20.8, "compass gone")
    soft_assert(text_at(b.msgs, "PreArm: Barometer not healthy", 19.0) is not None, "no 'Barometer not healthy'")
    # 8. RC override of channel 1 (the receiver's 1500), in MANUAL: on the pin, then
    # RC_OVERRIDE_TIME (1.5 s) after the last message the receiver's again.
    wait_until(b, 21.8)
    t_override = b.t_s
    for _ in range(5):
        b.conn.mav.rc_channels_override_send(1, 1, 1800, 65535, 65535, 65535, 65535, 65535, 65535, 65535)
        b.pump(lambda m, t=b.t_s: b.t_s > t + 0.1, "time")
    t_last_override = b.t_s
    # 9. Modes (the switch low, MANUAL, until 35 s).
    wait_until(b, 25.5)
    set_mode_checks(b)
    soft_assert(b.t_s < 35.0, "the mode checks ran past the switch's move (%.1f s)" % b.t_s)
    # 10. The switch moves at 35 s: STABILIZE over the ground station's FBWA.
    wait_until(b, 36.2)
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the switch")
    soft_assert(hb is not None and hb.custom_mode == 2, "the switch did not take over: mode %r" % (hb and hb.custom_mode))
    # 11. The receiver lost (37 s, failsafe at 37.5).
    wait_until(b, 37.8)
    prearm(b, "Radio failsafe on", 39.8, "receiver lost")
    # 12. `cal gyro` running (a still second).
    wait_until(b, 40.5)
    command(b, mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, 1)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, "COMMAND_ACK to the gyro calibration")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "cal gyro: %r" % ack)
    prearm(b, "Gyros not calibrated", 41.4, "gyro calibration")
    # 13. `cal mag` running.
    wait_until(b, 42.5)
    command(b, mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, 0, 1)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, "COMMAND_ACK to the compass calibration")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "cal mag: %r" % ack)
    prearm(b, "Compass calibration running", 45.0, "compass calibration")
    # 14. The compass calibration cancelled, learning off (COMPASS_LEARN 0) on a board never
    # calibrated: "Compass not calibrated" (with COMPASS_LEARN 1 the offset is learned in motion).
    wait_until(b, 45.2)
    command(b, 42426)  # MAV_CMD_DO_CANCEL_MAG_CAL
    ack = b.ack(42426, "COMMAND_ACK to the cancel")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "cancel mag cal: %r" % ack)
    b.conn.mav.param_set_send(1, 1, b"COMPASS_LEARN", 0, mavlink2.MAV_PARAM_TYPE_UINT8)
    pv = b.param("COMPASS_LEARN", "PARAM_VALUE COMPASS_LEARN 0")
    soft_assert(pv is not None and pv.param_value == 0, "COMPASS_LEARN 0: %r" % pv)
    prearm(b, "Compass not calibrated", 48.5, "compass never calibrated, not learning")
    wait_until(b, END_S)
    b.stop()

    # The pins: OUT3 at 1000 us from the first pulse while disarmed, the stick's 1300 armed.
    pulses = {o: [] for o in range(1, 9)}
    with open(servo_log) as f:
        for row in csv.DictReader(f):
            pulses[int(row["out"])].append((float(row["t"]), float(row["width_us"])))
    thr = pulses[3]
    soft_assert(thr and thr[0][0] < 0.05, "OUT3's first pulse at %s s" % (thr[0][0] if thr else None))
    spans = [(0.0, t_armed or 0.0), (t_disarmed + 0.05, t_armed2), ((t_disarmed2 or END_S) + 0.05, END_S)]
    held = [w for t, w in thr for a, z in spans if a <= t < z]
    soft_assert(len(held) > 800 and all(abs(w - 1000.0) <= 0.3 for w in held),
                "OUT3 disarmed: %d pulses, widths %r" % (len(held), sorted(set(round(w, 1) for w in held))[-3:]))
    live = [w for t, w in thr if 9.8 <= t < (t_disarmed or 11.0)]
    soft_assert(live and all(abs(w - 1300.0) <= 1.3 for w in live), "OUT3 armed, stick 1300: %r" % sorted(set(live))[:3])
    print("# throttle pin: %d pulses at 1000 us while disarmed (from the first, at %.3f s), %d at the stick's "
          "1300 us armed" % (len(held), thr[0][0], len(live)))
    out1 = pulses[1]
    on = [w for t, w in out1 if t_override + 0.1 <= t < t_last_override + 1.4]
    back = [w for t, w in out1 if t_last_override + 1.6 <= t < 25.5]
    soft_assert(on and all(abs(w - 1800.0) <= 1.3 for w in on), "OUT1 overridden: %r" % sorted(set(on))[:3])
    soft_assert(back and all(abs(w - 1500.0) <= 1.3 for w in back), "OUT1 after the override's time: %r"
                % sorted(set(back))[:3])
    rc = [m.chan1_raw for t, m in b.msgs if m.get_type() == "RC_CHANNELS" and t_override + 0.2 <= t < t_last_override]
    soft_assert(rc and all(c == 1800 for c in rc), "RC_CHANNELS chan1 under the override: %r" % rc)
    print("# RC override: OUT1 at 1800 us for %d pulses, back to the receiver's 1.5 s (RC_OVERRIDE_TIME, set by "
          "PARAM_SET) after the last message"
          % len(on))
    overruns = ["%.2f s: %s" % (t, m.text) for t, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    if overruns:  # what the board said around them
        t0 = float(overruns[0].split(" s:")[0])
        print("# around the first overrun: %r" % [(round(t, 2), m.text) for t, m in b.msgs
                                                  if m.get_type() == "STATUSTEXT" and t0 - 1.0 <= t <= t0 + 0.2])
    soft_assert(not overruns, "samples missed: %r" % overruns)


if __name__ == "__main__":
    main()
    sys.exit(finish("arming", "arming, modes and RC overrides from a ground station: all checks passed"))
