#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The board flies the JSBSim aeroplane: the JSBSim backend and `apm25sim --physics json`
with the firmware's ELF, in lock-step, the board's serial output on stdout.

    closed_loop.py --flight turn [--gust 0|1|2] [--seed N] [--seconds S]
    closed_loop.py --rc STICKS.csv [--upset T,SECONDS,NM ...] [--seconds S]
        [--sim build/apm25sim] [--elf build/firmware.elf] [--stamp] [--input FILE]
        [--servo-log FILE] [--log TRUTH.csv] [--trajectory FLIGHT.csv.gz] [--timeout S]
        [--no-airspeed] [--airframe plain|elevons|vtail] [--serial tcp:PORT] [--speed X]
        [--gps ublox|nmea|none] [--gps-fix-after S] [--arm] [--launch V,H,PITCH] [--fault SPEC ...]
        [--eeprom FILE]

--flight NAME takes the named flight of fly.py (its stick script in sim/flight/pilots/, its
length, gusts and upsets); --rc FILE any stick script in the simulator's --rc format
(the backend sends it in its replies' rc; apm25sim turns it into the receiver's PPM).
The backend listens on a free UDP port, apm25sim flies it; --log is the backend's true
state, --servo-log apm25sim's measured pulses. Both processes always end: when apm25sim
ends the backend is stopped, when the backend dies apm25sim is stopped, and after
--timeout s of wall time (default 900) both are. --no-airspeed flies an aeroplane without
a pitot (the backend sends no airspeed: the board's A0 reads 0 V, no sensor); --airframe
elevons or vtail flies the outputs as an elevon or V-tail aeroplane's (the backend's
--airframe: the board is to be set to mix for it, ELEVON_OUTPUT or VTAIL_OUTPUT 1). --serial
tcp:PORT attaches a ground station: apm25sim also serves the board's UART0 on TCP
127.0.0.1:PORT (MAVProxy, QGroundControl, Mission Planner connect as to SITL's 5760) and
flies in real time (--speed X for X times real time; 0 as fast as the host goes). --gps
KIND is apm25sim's module on the GPS port (default: apm25sim's, a u-blox; none: no GPS);
--gps-fix-after S its first 3D fix at S simulated seconds (apm25sim's; default 3).
--arm arms the board on the launch stand as a pilot would (ARMING_REQUIRE 1 holds the
throttle at its minimum until armed): the stick script's throttle at zero until ARM_S
(2 s) and `arm` typed into the board (apm25sim --input: at its first angle line, ~1.4 s,
after any --input lines). --launch V,H,PITCH is the backend's hand launch: held --hold s at H m,
PITCH deg nose up, then thrown at V m/s.
--fault SPEC goes to apm25sim as it is (its --help lists the
faults: gps:no-fix@45-75 loses the fix for 30 s).
--eeprom FILE is apm25sim's: the board's EEPROM from FILE and back
into it at the end (what an earlier run saved, as across a power cycle).
Exit status: apm25sim's, or 4 when the backend failed, 5 on the timeout.
"""
import argparse
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)

import fly  # noqa: E402

PILOTS = os.path.join(HERE, "pilots")
# The cruise throttle of the default trim, only to build the named flights' list (their
# stick scripts come from sim/flight/pilots/, written by fly.py --write-pilots).
NOMINAL_THROTTLE_US = 1106


# --arm: the throttle stick at zero until then, `arm` typed before it.
ARM_S = 2.0


def armed_script(rc, input_path, work):
    """The stick script with its throttle (channel 3) at zero (1000 us) before ARM_S, the
    rows in force from ARM_S on unchanged; and an input file ending in `arm`. Their paths."""
    with open(rc) as f:
        header, rows = f.readline(), [line.rstrip("\n").split(",") for line in f if line.strip()]
    out_rows = []
    for i, r in enumerate(rows):
        t = float(r[0])
        nxt = float(rows[i + 1][0]) if i + 1 < len(rows) else float("inf")
        if t < ARM_S and r[3] != "":
            out_rows.append([r[0]] + r[1:3] + ["1000"] + r[4:])
            if nxt > ARM_S:
                out_rows.append(["%.3f" % ARM_S] + r[1:])
        else:
            out_rows.append(r)
    rc_out = os.path.join(work, "armed_rc.csv")
    with open(rc_out, "w") as f:
        f.write(header + "".join(",".join(r) + "\n" for r in out_rows))
    text = open(input_path).read() if input_path else ""
    if text and not text.endswith("\n"):
        text += "\n"
    input_out = os.path.join(work, "armed_input.txt")
    with open(input_out, "w") as f:
        f.write(text + "arm\n")
    return rc_out, input_out


def named_flights():
    return fly.flights(NOMINAL_THROTTLE_US)


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--flight", help="a named flight (fly.py --list)")
    src.add_argument("--rc", help="a stick script, CSV t,ch1..ch8 (us)")
    p.add_argument("--gust", type=int, help="turbulence 0 none, 1 light, 2 moderate (default: the flight's, or 0)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--upset", action="append", default=[], metavar="T,SECONDS,NM")
    p.add_argument("--hold", type=float, default=3.0, metavar="S",
                   help="the aeroplane held still for S s first, released at trim (default 3: the board "
                        "powers up and calibrates at rest, as on the ground before a launch)")
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the flight's length, or 30)")
    p.add_argument("--sim", default=os.path.join(ROOT, "build", "apm25sim"))
    p.add_argument("--elf", default=os.path.join(ROOT, "build", "firmware.elf"))
    p.add_argument("--python", default=sys.executable, help="the Python that runs the backend")
    p.add_argument("--stamp", action="store_true", help="apm25sim --stamp: each line after its simulated time")
    p.add_argument("--input", help="apm25sim --input: console commands typed into the board")
    p.add_argument("--servo-log", help="apm25sim --servo-log: every output pulse")
    p.add_argument("--log", help="the backend's true state, one row a frame")
    p.add_argument("--no-airspeed", action="store_true",
                   help="the backend sends no airspeed: no pitot, the board's A0 at 0 V")
    p.add_argument("--airframe", default="plain", choices=("plain", "elevons", "vtail"),
                   help="the backend reads the outputs as this airframe's surfaces (default plain)")
    p.add_argument("--trajectory", help="the backend's trajectory file (ideal sensors, truth)")
    p.add_argument("--gps", choices=("ublox", "nmea", "none"), help="apm25sim --gps (default: apm25sim's)")
    p.add_argument("--gps-fix-after", type=float, metavar="S", help="apm25sim --gps-fix-after: the first 3D fix")
    p.add_argument("--out", help="the serial output into this file instead of stdout")
    p.add_argument("--wind", help="the backend's --wind N,E: a steady wind, m/s")
    p.add_argument("--launch", metavar="V,H,PITCH",
                   help="the backend's hand launch: held at H m, PITCH deg nose up, thrown at V m/s after --hold")
    p.add_argument("--mission", help="apm25sim --mission: a QGC WPL 110 file into the EEPROM before the run")
    p.add_argument("--eeprom", help="apm25sim --eeprom: the EEPROM from this file, written back at the end")
    p.add_argument("--profile", help="apm25sim --profile: the sections' cycle counts")
    p.add_argument("--fault", action="append", default=[], metavar="SPEC", help="apm25sim --fault SPEC (repeatable)")
    p.add_argument("--physics-rate", type=int, default=1000, help="frames per simulated second (default 1000)")
    p.add_argument("--timeout", type=float, default=900.0, help="wall seconds before both are stopped")
    p.add_argument("--serial", metavar="tcp:PORT",
                   help="apm25sim --serial: the board's UART0 on TCP for a ground station, in real time")
    p.add_argument("--arm", action="store_true",
                   help="arm on the launch stand: the throttle at zero until 2 s and `arm` typed")
    p.add_argument("--speed", type=float, metavar="X",
                   help="apm25sim --speed: X simulated seconds a wall second (default 1 with --serial, else 0)")
    return p.parse_args(argv)


def resolve(args):
    """(rc path, seconds, gust, extra backend arguments) of the flight asked for."""
    if args.flight:
        table = named_flights()
        if args.flight not in table:
            raise ValueError("no flight '%s'; the flights: %s" % (args.flight, ", ".join(sorted(table))))
        _, seconds, gust, _, extra = table[args.flight]
        rc = os.path.join(PILOTS, args.flight + ".csv")
    else:
        rc, seconds, gust, extra = args.rc, 30.0, 0, []
    if not os.path.isfile(rc):
        raise ValueError("no stick script %s" % rc)
    for spec in args.upset:
        extra = list(extra) + ["--upset", spec]
    return (rc, args.seconds if args.seconds else seconds, gust if args.gust is None else args.gust, list(extra))


def stop(proc, grace_s=5.0, sig=signal.SIGTERM):
    """sig, then SIGKILL after grace_s; returns the exit status."""
    if proc.poll() is None:
        proc.send_signal(sig)
        try:
            proc.wait(grace_s)
        except subprocess.TimeoutExpired:
            proc.kill()
    return proc.wait()


def run(args):
    for path, what in ((args.sim, "apm25sim"), (args.elf, "the firmware")):
        if not os.path.isfile(path):
            print("closed_loop: %s missing: %s (make all)" % (what, path), file=sys.stderr)
            return 2
    try:
        rc, seconds, gust, extra = resolve(args)
    except ValueError as e:
        print("closed_loop: %s" % e, file=sys.stderr)
        return 2
    work = tempfile.mkdtemp(prefix="closed_loop_")
    port_file = os.path.join(work, "port")
    console_input = args.input
    if args.arm:
        rc, console_input = armed_script(rc, args.input, work)
    backend_cmd = [args.python, os.path.join(HERE, "jsbsim_backend.py"), "--port", "0", "--port-file", port_file,
                   "--rc", rc, "--gust", str(gust), "--seed", str(args.seed), "--seconds", "%g" % seconds,
                   "--idle-timeout", "60", "--hold", "%g" % args.hold] + extra
    if args.log:
        backend_cmd += ["--log", args.log]
    if args.trajectory:
        backend_cmd += ["--trajectory", args.trajectory]
    if args.no_airspeed:
        backend_cmd.append("--no-airspeed")
    if args.wind:
        backend_cmd += ["--wind", args.wind]
    if args.launch:
        backend_cmd += ["--launch", args.launch]
    if args.airframe != "plain":
        backend_cmd += ["--airframe", args.airframe]
    deadline = time.monotonic() + args.timeout
    backend = subprocess.Popen(backend_cmd)
    sim = None
    out = open(args.out, "wb") if args.out else sys.stdout.buffer
    timed_out = False
    ended_itself = False
    listen_deadline = time.monotonic() + 120.0
    try:
        while not os.path.exists(port_file) or not open(port_file).read().strip():
            if backend.poll() is not None:
                print("closed_loop: the backend ended before it listened (status %d)" % backend.returncode,
                      file=sys.stderr)
                return 4
            if time.monotonic() > listen_deadline:
                print("closed_loop: the backend did not listen within 120 s", file=sys.stderr)
                return 4
            time.sleep(0.05)
        port = int(open(port_file).read())
        sim_cmd = [args.sim, "--elf", args.elf, "--physics", "json:127.0.0.1:%d" % port, "--seconds", "%g" % seconds,
                   "--physics-rate", str(args.physics_rate), "--physics-timeout", "60"]
        if args.stamp:
            sim_cmd.append("--stamp")
        if console_input:
            sim_cmd += ["--input", console_input]
        if args.servo_log:
            sim_cmd += ["--servo-log", args.servo_log]
        if args.serial:
            sim_cmd += ["--serial", args.serial]
        if args.speed is not None:
            sim_cmd += ["--speed", "%g" % args.speed]
        if args.gps:
            sim_cmd += ["--gps", args.gps]
        if args.gps_fix_after is not None:
            sim_cmd += ["--gps-fix-after", "%g" % args.gps_fix_after]
        if args.mission:
            sim_cmd += ["--mission", args.mission]
        if args.eeprom:
            sim_cmd += ["--eeprom", args.eeprom]
        if args.profile:
            sim_cmd += ["--profile", args.profile]
        for spec in args.fault:
            sim_cmd += ["--fault", spec]
        sim = subprocess.Popen(sim_cmd, stdout=subprocess.PIPE)

        def watchdog():
            # The backend dying or the wall clock running out stops the simulator (whose
            # stdout the main thread is reading).
            nonlocal timed_out
            while sim.poll() is None:
                if backend.poll() is not None or time.monotonic() > deadline:
                    timed_out = time.monotonic() > deadline
                    stop(sim)
                    return
                time.sleep(0.1)

        threading.Thread(target=watchdog, daemon=True).start()
        while True:
            chunk = sim.stdout.read1(4096)
            if not chunk:
                break
            out.write(chunk)
            out.flush()
        status = sim.wait()
        ended_itself = status == 0 and not timed_out
    except KeyboardInterrupt:
        status = 130
    except BrokenPipeError:
        status = 0  # the reader (a pager, the view) went away
    finally:
        if sim is not None:
            stop(sim)
        # A backend that saw the flight to its end stops by itself (after --linger s of
        # silence); one that did not is interrupted (SIGINT: it closes its files).
        try:
            backend.wait(30.0 if ended_itself else 0.1)
        except subprocess.TimeoutExpired:
            pass
        backend_status = stop(backend, 5.0, signal.SIGINT)
        if args.out:
            out.close()
        shutil.rmtree(work, ignore_errors=True)
    if timed_out:
        print("closed_loop: stopped after %.0f s of wall time (--timeout)" % args.timeout, file=sys.stderr)
        return 5
    if status == 0 and backend_status != 0:
        return 4
    return status


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
