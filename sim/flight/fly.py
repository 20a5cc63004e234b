#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Flights without the board: a Python stand-in for the autopilot flies the JSBSim backend over
the same UDP JSON protocol as apm25sim would, and the backend writes the flight as a
trajectory (../shared/SIM.md) and a true-state log.

    build/venv/bin/python sim/flight/fly.py --flight turn --out build/flights/turn.csv [--log L.csv]
        [--gust 0|1|2] [--seed N] [--seconds S] [--rc FILE] [--mode stabilize|manual]
    build/venv/bin/python sim/flight/fly.py --list
    build/venv/bin/python sim/flight/fly.py --all DIR      every flight: DIR/NAME.csv.gz, DIR/NAME_log.csv
    build/venv/bin/python sim/flight/fly.py --write-pilots DIR     the flights' stick scripts

The stand-in does what the firmware's STABILIZE does (issue 21): the sticks from the
backend's rc channels command a bank (full stick 45 deg) and a pitch (full stick 25 deg, about
the trim pitch), PI-D loops on the attitude from the reply's quaternion and the gyro, turn
coordination on the elevator, the rudder against side acceleration, throttle passed
through; outputs update at 50 Hz as servo pulses do. MANUAL passes the sticks through
about the servo trims.
"""
import argparse
import math
import os
import socket
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import flightio  # noqa: E402
import flightmodel  # noqa: E402
import jsonlink  # noqa: E402

FRAME_RATE_HZ = 400
OUTPUT_RATE_HZ = 50
BANK_FULL_STICK_DEG = 45.0
PITCH_FULL_STICK_DEG = 25.0


def stick_for_bank(bank_deg):
    return 1500.0 + 500.0 * bank_deg / BANK_FULL_STICK_DEG


def stick_for_pitch(pitch_deg):
    return 1500.0 + 500.0 * pitch_deg / PITCH_FULL_STICK_DEG


def turn_seconds(bank_deg, airspeed_m_s, degrees=360.0):
    """Time for a level coordinated turn of so many degrees: rate = g tan(bank) / V."""
    return math.radians(degrees) / (flightmodel.G0 * math.tan(math.radians(bank_deg)) / airspeed_m_s)


def flights(cruise_throttle_us, airspeed_m_s=18.0):
    """name -> (description, seconds, gust level, rc rows, extra backend arguments)."""
    thr = round(cruise_throttle_us)
    turn_thr = thr + 40  # a 30 deg bank needs 1/cos(30) = 1.15 g of lift, so more power

    def row(t, roll_us=1500, pitch_us=1500, throttle_us=thr, yaw_us=1500):
        return (float(t), (round(roll_us), round(pitch_us), round(throttle_us), round(yaw_us), 1500, 1500, 1500, 1500))

    circle = turn_seconds(30.0, airspeed_m_s + 1.5)  # the turn's power setting flies it faster
    out = {}
    out["cruise"] = ("60 s of level cruise, hands off", 60.0, 0, [row(0)], [])
    out["gusty"] = ("60 s of cruise in moderate Dryden turbulence, hands off", 60.0, 2, [row(0)], [])
    out["upset"] = ("cruise, hands off; at 5 s a 20 N m roll moment for 0.5 s (48 deg of bank if nothing resists)", 30.0, 0,
                    [row(0)], ["--upset", "5,0.5,20"])
    out["turn"] = ("5 s level, 60 s in a 30 deg bank to the right, 10 s level", 75.0, 0,
                   [row(0), row(5, stick_for_bank(30), throttle_us=turn_thr), row(65)], [])
    t = 5.0
    eight = [row(0)]
    for _ in range(2):
        eight.append(row(t, stick_for_bank(30), throttle_us=turn_thr))
        t += circle
        eight.append(row(t, stick_for_bank(-30), throttle_us=turn_thr))
        t += circle
    eight.append(row(t))
    out["figure8"] = ("two figure-eights of 30 deg bank circles, right then left", t + 5.0, 0, eight, [])
    out["climb"] = ("5 s level, 20 s climbing at 10 deg, 15 s level, 15 s descending at -5 deg, 10 s level",
                    65.0, 0, [row(0), row(5, pitch_us=stick_for_pitch(10), throttle_us=1400), row(25),
                              row(40, pitch_us=stick_for_pitch(-5), throttle_us=1000), row(55)], [])
    return out


class StandIn:
    """The autopilot stand-in: STABILIZE or MANUAL, outputs OUT1..OUT4 in us."""

    def __init__(self, trim, mode):
        self.trim_us = trim.widths_us()
        self.trim_pitch = trim.alpha_rad  # level flight: pitch = alpha
        self.mode = mode
        self.roll_integral = 0.0
        self.pitch_integral = 0.0
        self.yaw_integral = 0.0
        self.outputs = [round(w) for w in self.trim_us]

    def update(self, reply, dt_s):
        rc = reply.get("rc")
        if not rc:  # no receiver: wings level, trim throttle (a failsafe of sorts)
            sticks = (1500.0, 1500.0, self.trim_us[2], 1500.0)
        else:
            sticks = (rc["rc_1"], rc["rc_2"], rc["rc_3"], rc["rc_4"])
        if self.mode == "manual":  # pass-through about the servo trims, throttle as is
            self.outputs = [round(self.trim_us[i] + sticks[i] - 1500.0) if i != 2 else round(sticks[2])
                            for i in range(4)]
            return self.outputs
        qw, qx, qy, qz = reply["quaternion"]
        roll = math.atan2(2 * (qw * qx + qy * qz), 1 - 2 * (qx * qx + qy * qy))
        pitch = math.asin(max(-1.0, min(1.0, 2 * (qw * qy - qz * qx))))
        p, q, _ = reply["imu"]["gyro"]
        ay = reply["imu"]["accel_body"][1]
        roll_cmd = math.radians(BANK_FULL_STICK_DEG) * (sticks[0] - 1500.0) / 500.0
        pitch_cmd = self.trim_pitch + math.radians(PITCH_FULL_STICK_DEG) * (sticks[1] - 1500.0) / 500.0
        roll_err, pitch_err = roll_cmd - roll, pitch_cmd - pitch
        self.roll_integral = max(-0.2, min(0.2, self.roll_integral + 0.2 * roll_err * dt_s))
        self.pitch_integral = max(-0.3, min(0.3, self.pitch_integral + 0.5 * pitch_err * dt_s))
        aileron = 1.5 * roll_err - 0.15 * p + self.roll_integral
        coordination = 0.5 * (1.0 / max(math.cos(roll), 0.5) - 1.0)
        elevator_up = 2.0 * pitch_err - 0.2 * q + self.pitch_integral + coordination
        self.yaw_integral = max(-0.3, min(0.3, self.yaw_integral - 0.3 * ay * dt_s))
        rudder = -0.1 * ay + self.yaw_integral + (sticks[3] - 1500.0) / 500.0
        a_us = self.trim_us[0] + 500.0 * aileron
        e_us = self.trim_us[1] + 500.0 * elevator_up
        r_us = self.trim_us[3] + 500.0 * rudder
        self.outputs = [round(max(1000.0, min(2000.0, w))) for w in (a_us, e_us, sticks[2], r_us)]
        return self.outputs


def start_backend(args, rc_path, seconds, gust, work, extra):
    port_file = os.path.join(work, "port")
    cmd = [sys.executable, os.path.join(HERE, "jsbsim_backend.py"), "--port", "0", "--port-file", port_file,
           "--rc", rc_path, "--gust", str(gust), "--seed", str(args.seed), "--seconds", repr(seconds),
           "--idle-timeout", "20", "--linger", "0.1", "--airspeed", repr(args.airspeed), "--altitude", repr(args.altitude)]
    if args.out:
        cmd += ["--trajectory", args.out]
    if args.log:
        cmd += ["--log", args.log]
    if args.quiet:
        cmd.append("--quiet")
    cmd += list(extra) + [a for u in args.upset for a in ("--upset", u)]
    if args.vibration:
        cmd += ["--vibration", repr(args.vibration)]
    if args.hold:
        cmd += ["--hold", repr(args.hold)]
    proc = subprocess.Popen(cmd)
    deadline = time.monotonic() + 60.0
    while not (os.path.exists(port_file) and open(port_file).read().endswith("\n")):
        if proc.poll() is not None or time.monotonic() > deadline:
            raise RuntimeError("the backend did not start (exit %s)" % proc.poll())
        time.sleep(0.02)
    return proc, int(open(port_file).read())


def fly(args, trim, rc_path, seconds, gust, work, extra=()):
    proc, port = start_backend(args, rc_path, seconds, gust, work, extra)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.settimeout(5.0)
    pilot = StandIn(trim, args.mode)
    frames = int(round(seconds * FRAME_RATE_HZ))
    per_output = FRAME_RATE_HZ // OUTPUT_RATE_HZ
    outputs = pilot.outputs
    try:
        for frame in range(frames):
            packet = jsonlink.pack_servo_packet(FRAME_RATE_HZ, frame, outputs)
            for attempt in range(4):
                sock.sendto(packet, ("127.0.0.1", port))
                try:
                    data, _ = sock.recvfrom(4096)
                    break
                except socket.timeout:
                    continue  # the same frame count again: the backend answers without stepping
            else:
                raise RuntimeError("no answer from the backend at frame %d" % frame)
            reply = jsonlink.parse_reply(data)
            if (frame + 1) % per_output == 0:
                outputs = pilot.update(reply, 1.0 / OUTPUT_RATE_HZ)
    finally:
        sock.close()
    if proc.wait(timeout=60) != 0:
        raise RuntimeError("the backend failed (exit %d)" % proc.returncode)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--flight", help="a named flight (--list)")
    p.add_argument("--rc", help="fly this stick script instead (CSV t,ch1..ch8)")
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the flight's)")
    p.add_argument("--gust", type=int, choices=sorted(flightmodel.GUST_LEVELS), help="override the flight's")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--airspeed", type=float, default=18.0)
    p.add_argument("--altitude", type=float, default=100.0)
    p.add_argument("--mode", choices=("stabilize", "manual"), default="stabilize")
    p.add_argument("--vibration", type=float, default=0.0, metavar="M_S2", help="passed to the backend")
    p.add_argument("--upset", action="append", default=[], metavar="T,SECONDS,NM", help="passed to the backend")
    p.add_argument("--hold", type=float, default=0.0, metavar="S", help="passed to the backend (a launch stand)")
    p.add_argument("--out", help="trajectory file (.csv or .csv.gz)")
    p.add_argument("--log", help="true-state log")
    p.add_argument("--list", action="store_true")
    p.add_argument("--write-pilots", metavar="DIR")
    p.add_argument("--all", metavar="DIR", help="fly every flight into DIR")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args()

    trim = flightmodel.FlightModel(args.airspeed, args.altitude).trim
    table = flights(trim.widths_us()[2], args.airspeed)
    if args.list:
        for name, (text, seconds, gust, _, _) in table.items():
            print("%-8s %5.1f s  gust %s  %s" % (name, seconds, flightmodel.GUST_NAMES[gust], text))
        return 0
    if args.write_pilots:
        os.makedirs(args.write_pilots, exist_ok=True)
        for name, (_, _, _, rows, _) in table.items():
            flightio.RcScript(rows).save(os.path.join(args.write_pilots, name + ".csv"))
        return 0
    if args.all:
        os.makedirs(args.all, exist_ok=True)
        for name, (_, seconds, gust, rows, extra) in table.items():
            args.out = os.path.join(args.all, name + ".csv.gz")
            args.log = os.path.join(args.all, name + "_log.csv")
            with tempfile.TemporaryDirectory(prefix="fly-") as work:
                rc_path = os.path.join(work, name + ".csv")
                flightio.RcScript(rows).save(rc_path)
                try:
                    fly(args, trim, rc_path, args.seconds or seconds, gust if args.gust is None else args.gust, work,
                        extra)
                except (OSError, RuntimeError, ValueError) as e:
                    print("fly.py: %s: %s" % (name, e), file=sys.stderr)
                    return 1
            print("%s: %s" % (name, args.out))
        return 0
    if bool(args.flight) == bool(args.rc):
        p.error("give --flight NAME or --rc FILE")
    if args.flight and args.flight not in table:
        p.error("unknown flight %r (--list)" % args.flight)
    with tempfile.TemporaryDirectory(prefix="fly-") as work:
        extra = []
        if args.flight:
            _, seconds, gust, rows, extra = table[args.flight]
            rc_path = os.path.join(work, args.flight + ".csv")
            flightio.RcScript(rows).save(rc_path)
        else:
            seconds, gust, rc_path = 60.0, 0, args.rc
        seconds = args.seconds or seconds
        gust = gust if args.gust is None else args.gust
        try:
            fly(args, trim, rc_path, seconds, gust, work, extra)
        except (OSError, RuntimeError, ValueError) as e:
            print("fly.py: %s" % e, file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
