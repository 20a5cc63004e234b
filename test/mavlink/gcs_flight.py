#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A ground station watching the simulated board fly (issues 45 and 46), with pymavlink.

    build/venv/bin/python test/mavlink/gcs_flight.py --tools build --work DIR

Flies the first 20 s of the `turn` flight (3 s held on the stand, 2 s level, then a 30 deg
bank to the right in STABILIZE) with sim/flight/closed_loop.py --serial tcp:0, as `make fly
SERIAL=tcp:5760` does: the JSBSim backend and apm25sim --physics json in lock-step, the
board's UART0 also on TCP, paced at real time by default. A pymavlink client connects as
a ground station does (a HEARTBEAT from system 255 once a wall second: the board starts
in its text mode and switches to MAVLink on the first one) and reads what the board sends
while it flies. Checks:
  - HEARTBEAT: FIXED_WING, ARDUPILOTMEGA, STABILIZE (custom_mode 2; MANUAL before the switch is
    read), about one a second;
  - arming from the ground station: the flight's throttle stick is up, so the client arms
    with MAV_CMD_COMPONENT_ARM_DISARM forced (param2 2989, MAVProxy's `arm throttle force`)
    on the board's first HEARTBEAT: ACCEPTED, and every HEARTBEAT after it says armed;
  - ATTITUDE: several a simulated second, roll and pitch against the backend's true
    attitude (its --log) at the message's time_boot_ms, from 4.5 s (the board calibrated
    on the stand): worst error under 3 deg, RMS under 1.5 deg; the turn's bank seen (over
    20 deg);
  - real time: no message's simulated time ahead of the wall time since the flight was
    launched (pacing never runs ahead; a loaded host only runs behind);
  - the flight ran to its end (time_boot_ms past 19 s), the flight's exit status 0 and
    apm25sim's link summary on stderr.
Then 6 s of cruise with `mode mavlink` typed into the board as it starts (closed_loop.py
--input, as `make fly MODE=mavlink`): a client that sends nothing, pymavlink's plain
wait_heartbeat(), hears the board's HEARTBEAT and ATTITUDE. (Without a HEARTBEAT from the
ground station or `mode mavlink`, the port stays in its text mode: the first phase's
client must send one.)
Exit 1 with every failure listed. The wall clock bounds only the pacing's invariant and
the guard against a hang.
"""
import bisect
import csv
import os
import re
import subprocess
import sys
import threading
import time

from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from sim_run import tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

SECONDS = 20.0
FROM_S = 4.5           # released from the stand at 3 s; the gyro calibrated before
WALL_GUARD_S = 900     # a loaded machine runs far behind real time: only a hang guard
PACING_SLACK_S = 0.5   # TCP and this reader's delays, and the pacer's 1 ms steps


def truth_table(path):
    """(t list, roll list, pitch list) of the backend's true-state log."""
    ts, rolls, pitches = [], [], []
    with open(path) as f:
        for row in csv.DictReader(f):
            ts.append(float(row["t"]))
            rolls.append(float(row["roll_deg"]))
            pitches.append(float(row["pitch_deg"]))
    return ts, rolls, pitches


def interpolate(ts, values, t):
    i = bisect.bisect_left(ts, t)
    if i <= 0:
        return values[0]
    if i >= len(ts):
        return values[-1]
    w = (t - ts[i - 1]) / (ts[i] - ts[i - 1])
    return values[i - 1] + w * (values[i] - values[i - 1])


class Flight:
    """closed_loop.py with --serial tcp:0, its stderr read on a thread (the port it serves)."""

    def __init__(self, tools, work, flight, seconds, extra):
        self.work = work
        cmd = [sys.executable, os.path.join(ROOT, "sim", "flight", "closed_loop.py"), "--flight", flight,
               "--seconds", "%g" % seconds, "--sim", os.path.join(tools, "apm25sim"),
               "--elf", os.path.join(tools, "firmware.elf"), "--serial", "tcp:0",
               "--timeout", "%d" % WALL_GUARD_S] + extra
        self.launched = time.monotonic()
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.stderr_lines = []
        self.port = None
        self.port_found = threading.Event()
        self.reader = threading.Thread(target=self.read_stderr, daemon=True)
        self.reader.start()

    def read_stderr(self):
        for line in self.proc.stderr:
            self.stderr_lines.append(line)
            m = re.search(r"serving UART0 on tcp:127\.0\.0\.1:(\d+)", line)
            if m and self.port is None:
                self.port = int(m.group(1))
                self.port_found.set()
        self.port_found.set()  # the flight ended without serving

    def connect(self):
        """A pymavlink connection to the board as system 255, or None (a failure printed)."""
        self.port_found.wait(WALL_GUARD_S)
        if self.port is None:
            print("FAIL: the flight did not serve UART0 on TCP:\n" + "".join(self.stderr_lines)[-3000:])
            return None
        conn = mavutil.mavlink_connection("tcp:127.0.0.1:%d" % self.port, source_system=255, source_component=190,
                                          autoreconnect=False)
        conn.closed = []  # the board's end closes the connection: no more to read
        conn.handle_eof = lambda: conn.closed.append("eof")
        conn.handle_disconnect = lambda: conn.closed.append("reset")
        return conn

    def end(self):
        """The flight's exit status and stderr (killed after the guard)."""
        try:
            status = self.proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            status = self.proc.wait()
        self.reader.join(timeout=10)
        return status, "".join(self.stderr_lines)

    def kill(self):
        """SIGTERM (closed_loop.py then stops the backend and apm25sim), SIGKILL after 30 s."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def listen_only(tools, work):
    """The board told `mode mavlink` as it starts: a client that sends nothing hears it."""
    input_path = os.path.join(work, "mode_mavlink.txt")
    with open(input_path, "w") as f:
        f.write("mode mavlink\n")
    flight = Flight(tools, work, "cruise", 6.0, ["--input", input_path])
    try:
        conn = flight.connect()
        if conn is None:
            soft_assert(False, "listen-only: the flight did not serve")
            return
        # Until the flight ends (the guard only against a hang).
        def live():
            return not conn.closed and flight.proc.poll() is None and \
                time.monotonic() - flight.launched < WALL_GUARD_S
        hb = att = None
        while hb is None and live():
            hb = conn.wait_heartbeat(timeout=1.0)
        soft_assert(hb is not None and hb.get_srcSystem() == 1 and hb.type == mavlink2.MAV_TYPE_FIXED_WING,
                    "listen-only: wait_heartbeat() heard %r in the flight" % hb)
        while att is None and live():
            att = conn.recv_match(type="ATTITUDE", blocking=True, timeout=1.0)
        soft_assert(att is not None, "listen-only: no ATTITUDE in the flight")
        if hb is not None and att is not None:
            print("# listen-only client: HEARTBEAT and ATTITUDE at %.2f s without sending a byte"
                  % (att.time_boot_ms / 1000.0))
        conn.close()
        status, err = flight.end()  # the 6 s flight ends by itself
        soft_assert(status == 0, "listen-only: the flight exited %s:\n%s" % (status, err[-3000:]))
    finally:
        flight.kill()


def main():
    args = tools_and_work()
    for need in ("apm25sim", "firmware.elf"):
        if not os.path.exists(os.path.join(args.tools, need)):
            print("FAIL: %s missing in %s (make firmware tools)" % (need, args.tools))
            return 1
    truth_path = os.path.join(args.work, "truth.csv")
    serial_path = os.path.join(args.work, "serial.bin")
    flight = Flight(args.tools, args.work, "turn", SECONDS, ["--log", truth_path, "--out", serial_path])
    launched = flight.launched
    proc = flight.proc
    msgs = []  # (wall s since launch, message)
    try:
        conn = flight.connect()
        if conn is None:
            return 1
        closed = conn.closed
        last_hb = 0.0
        arm_sent = False
        while time.monotonic() - launched < WALL_GUARD_S:
            now = time.monotonic()
            if now - last_hb > 1.0:
                try:
                    conn.mav.heartbeat_send(mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0)
                except OSError:
                    pass  # the board went away: the loop ends below
                last_hb = now
            m = conn.recv_match(blocking=True, timeout=0.5)
            if m is None or m.get_type() == "BAD_DATA":
                if closed or proc.poll() is not None:
                    break
                continue
            if m.get_srcSystem() == 1:
                msgs.append((time.monotonic() - launched, m))
                if m.get_type() == "HEARTBEAT" and not arm_sent:
                    conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 2989, 0, 0, 0, 0, 0)
                    arm_sent = True
        conn.close()
        status, err = flight.end()
    finally:
        flight.kill()
    soft_assert(status == 0, "the flight exited %s:\n%s" % (status, err[-3000:]))
    summary = re.search(r"physics backend at \S+: (\d+) frames, (\d+) sent again, (\d+) late or duplicate", err)
    soft_assert(summary is not None, "no link summary from apm25sim:\n" + err[-3000:])
    if summary:
        print("# apm25sim: %s frames, %s sent again, %s late or duplicate replies dropped" % summary.groups())

    heartbeats = [m for _, m in msgs if m.get_type() == "HEARTBEAT"]
    attitudes = [(w, m) for w, m in msgs if m.get_type() == "ATTITUDE"]
    soft_assert(heartbeats, "no HEARTBEAT from the board: did it switch to MAVLink?")
    soft_assert(attitudes, "no ATTITUDE from the board")
    if not heartbeats or not attitudes:
        return finish("gcs_flight", "")
    # The mode: MANUAL (0) until the receiver's first frames have set the switch's mode, then
    # STABILIZE (2) throughout: a HEARTBEAT may come before the switch is read.
    modes = [hb.custom_mode for hb in heartbeats]
    settled = modes.index(2) if 2 in modes else len(modes)
    soft_assert(settled < len(modes), "no HEARTBEAT says STABILIZE: %r" % modes)
    soft_assert(all(m == 0 for m in modes[:settled]) and all(m == 2 for m in modes[settled:]),
                "the HEARTBEATs' modes %r: MANUAL until the switch is read, then STABILIZE" % modes)
    for hb in heartbeats:
        soft_assert(hb.type == mavlink2.MAV_TYPE_FIXED_WING and hb.autopilot == mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA,
                    "HEARTBEAT %r" % hb)
    acks = [m for _, m in msgs if m.get_type() == "COMMAND_ACK" and m.command == mavlink2.MAV_CMD_COMPONENT_ARM_DISARM]
    soft_assert(acks and acks[0].result == mavlink2.MAV_RESULT_ACCEPTED, "the forced arm: %r" % acks)
    armed = [bool(hb.base_mode & mavlink2.MAV_MODE_FLAG_SAFETY_ARMED) for hb in heartbeats]
    first_armed = armed.index(True) if True in armed else len(armed)
    soft_assert(first_armed <= 2 and all(armed[first_armed:]), "HEARTBEATs armed: %r" % armed)
    first_s = attitudes[0][1].time_boot_ms / 1000.0
    last_s = attitudes[-1][1].time_boot_ms / 1000.0
    span_s = last_s - first_s
    soft_assert(last_s > SECONDS - 1.0, "the last ATTITUDE at %.2f s of a %.0f s flight" % (last_s, SECONDS))
    soft_assert(len(heartbeats) >= span_s - 2.0, "%d HEARTBEATs in %.1f s" % (len(heartbeats), span_s))
    soft_assert(len(attitudes) >= 5.0 * span_s, "%d ATTITUDEs in %.1f s" % (len(attitudes), span_s))

    # The pacing's invariant: simulated time since the board's reset never ahead of the
    # wall time since the flight was launched (the board started after that).
    ahead = max(m.time_boot_ms / 1000.0 - w for w, m in msgs if hasattr(m, "time_boot_ms"))
    soft_assert(ahead < PACING_SLACK_S, "a message %.2f s of simulated time ahead of the wall clock: not real time"
                % ahead)

    ts, rolls, pitches = truth_table(truth_path)
    # The board's time is the backend's less its first reply's (frame 0: one step in).
    t0 = ts[1] if len(ts) > 1 else 0.0
    errors = []
    bank_seen = 0.0
    for _, m in attitudes:
        t = m.time_boot_ms / 1000.0
        if t < FROM_S:
            continue
        roll, pitch = m.roll * 57.29578, m.pitch * 57.29578
        er = roll - interpolate(ts, rolls, t + t0)
        ep = pitch - interpolate(ts, pitches, t + t0)
        errors.append((t, er, ep))
        bank_seen = max(bank_seen, roll)
    soft_assert(len(errors) > 50, "%d ATTITUDEs after %.1f s" % (len(errors), FROM_S))
    if errors:
        worst = max(errors, key=lambda e: max(abs(e[1]), abs(e[2])))
        rms_roll = (sum(e[1] ** 2 for e in errors) / len(errors)) ** 0.5
        rms_pitch = (sum(e[2] ** 2 for e in errors) / len(errors)) ** 0.5
        print("# %d HEARTBEAT, %d ATTITUDE over %.1f s of flight; against the truth from %.1f s: roll RMS %.2f, "
              "pitch RMS %.2f deg, worst %.2f / %.2f deg at %.2f s; bank seen %.1f deg; %.2f s ahead at most"
              % (len(heartbeats), len(attitudes), span_s, FROM_S, rms_roll, rms_pitch, worst[1], worst[2], worst[0],
                 bank_seen, ahead))
        soft_assert(max(abs(worst[1]), abs(worst[2])) < 3.0, "ATTITUDE %.2f / %.2f deg off the truth at %.2f s"
                    % (worst[1], worst[2], worst[0]))
        soft_assert(rms_roll < 1.5 and rms_pitch < 1.5, "RMS roll %.2f pitch %.2f deg" % (rms_roll, rms_pitch))
        soft_assert(bank_seen > 20.0, "the ground station saw at most %.1f deg of bank in the turn" % bank_seen)
    listen_only(args.tools, args.work)
    return finish("gcs_flight", "gcs_flight: a ground station watched the board fly in real time")


if __name__ == "__main__":
    sys.exit(main())
