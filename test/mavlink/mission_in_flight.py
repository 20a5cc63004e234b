#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A ground station loads a mission into the flying board and sends it on its way (issue 47).

    build/venv/bin/python test/mavlink/mission_in_flight.py --tools build --work DIR

The board flies the JSBSim Rascal in closed loop (sim/flight/closed_loop.py: the backend and
`apm25sim --physics json`, lock-step) and serves its UART0 on TCP at the same time
(`--serial tcp:0`, real time as SITL); MAVProxy (`--default-modules wp,mode`, its telemetry
log mav.tlog in DIR; `--streamrate -1`: the board's SR0_ defaults kept, ATTITUDE at 50 Hz
stamps the log with the board's time, MISSION_CURRENT's stream at 1 Hz) connects to it as to
SITL's 5760 and is typed into as a user does:
  - launched in STABILIZE (the Rascal's cruise: TRIM_THROTTLE 11, TRIM_ARSPD_CM 1800 typed on
    the console before), `mode LOITER` typed until the board takes it (it refuses before its
    first fix); it circles;
  - `wp load` of a QGC WPL 110 file: a 500 m x 300 m rectangle at 25, 45, 35 and 15 m above
    home, DO_JUMP back to its first corner for ever ("Sent all 6 waypoints"); `wp list`
    downloads it back and `wp save` writes it: equal to the file, home aside (to 6e-7 deg:
    `wp save` writes 6 decimals);
  - `mode AUTO`: the board flies the rectangle: MISSION_CURRENT 1, 2, 3, 4, 1, 2 (each at once:
    within 0.1 s of board time of the MISSION_ITEM_REACHED before it), one MISSION_ITEM_REACHED
    for each corner, the true path within WP_RADIUS (30 m) of each;
  - on the second lap, heading for corner 2, `wp set 4` (MAVProxy's MAV_CMD_DO_SET_MISSION_CURRENT,
    ACCEPTED): MISSION_CURRENT 4 at once, the true course within 20 deg of the bearing to corner 4
    within 25 s, the corner reached within WP_RADIUS; then, with MAVProxy set to send the
    MISSION_SET_CURRENT message (`set wp_use_waypoint_set_current 1`), `wp set 3` the same way;
  - MISSION_CURRENT on its stream (SR0_EXT_STAT, 1 Hz) between the changes: no gap over 1.1 s;
    no sample missed ("loop overrun").
Times are the board's (time_boot_ms in MAVProxy's telemetry log) and the backend's truth log;
the wall clock only bounds the waits. The distance at each corner and the seconds from AUTO to
each MISSION_ITEM_REACHED are printed. Exit 1 with every failure listed.
"""
import math
import os
import queue
import re
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "test", "support"))
sys.path.insert(0, os.path.join(ROOT, "test", "flight"))
from mavproxy_session import Lines  # noqa: E402
from sim_run import tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402
import test_closed_loop as tcl  # noqa: E402

CLOSED_LOOP = os.path.join(ROOT, "sim", "flight", "closed_loop.py")
# North-east metres from the launch point (the backend's origin), heights above home.
CORNERS = [(400.0, 0.0, 25.0), (400.0, 300.0, 45.0), (-100.0, 300.0, 35.0), (-100.0, 0.0, 15.0)]
WP_RADIUS_M = 30.0
SECONDS = 600.0       # the flight's length at most; the test stops it when done
WAIT_S = 400.0        # wall seconds for one event (a leg is ~30 s of board time)
AT_ONCE_S = 0.1       # MISSION_CURRENT after MISSION_ITEM_REACHED, board time
TURN_S, TURN_DEG = 25.0, 20.0


def write_mission(path):
    """QGC WPL 110: home, the four corners (GLOBAL_RELATIVE_ALT), DO_JUMP to 1 for ever."""
    lines = ["QGC WPL 110", "0\t1\t0\t16\t0\t0\t0\t0\t%.7f\t%.7f\t%.2f\t1" % tcl.SIM_HOME]
    for i, (n, e, h) in enumerate(CORNERS):
        lat, lon = tcl.sim_latlon(n, e)
        lines.append("%d\t0\t3\t16\t0\t0\t0\t0\t%.7f\t%.7f\t%.2f\t1" % (i + 1, lat, lon, h))
    lines.append("%d\t0\t0\t177\t1\t-1\t0\t0\t0\t0\t0\t1" % (len(CORNERS) + 1))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def wpl_rows(path):
    """(command, frame as GLOBAL_RELATIVE_ALT or not, p1, p2, lat, lon, alt) after home."""
    rows = []
    for line in open(path).read().split("\n")[1:]:
        c = line.split()
        if len(c) == 12 and int(c[0]) > 0:
            rows.append((int(c[3]), int(c[2]) in (3, 6), float(c[4]), float(c[5]), float(c[8]), float(c[9]),
                         float(c[10])))
    return rows


class Flight:
    """closed_loop.py with --serial tcp:0: the port from apm25sim's line on its stderr."""

    def __init__(self, args):
        self.work = args.work
        rc = tcl.write_rc(os.path.join(args.work, "rc.csv"), [tcl.row(0.0)])
        console = os.path.join(args.work, "console.txt")
        with open(console, "w") as f:
            f.write("set TRIM_THROTTLE 11\nset TRIM_ARSPD_CM %d\n" % tcl.TRIM_ARSPD_CM)
        self.log_path = os.path.join(args.work, "truth.csv")
        self.stderr_log = open(os.path.join(args.work, "closed_loop.stderr"), "w")
        self.proc = subprocess.Popen(
            [sys.executable, CLOSED_LOOP, "--rc", rc, "--seconds", "%g" % SECONDS, "--gust", "0", "--arm",
             "--gps", "ublox", "--input", console, "--serial", "tcp:0", "--log", self.log_path,
             "--out", os.path.join(args.work, "serial.bin"), "--sim", os.path.join(args.tools, "apm25sim"),
             "--elf", os.path.join(args.tools, "firmware.elf"), "--timeout", "3000"],
            stderr=subprocess.PIPE, text=True)
        self.ports = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stderr:
            self.stderr_log.write(line)
            self.stderr_log.flush()
            m = re.search(r"serving UART0 on tcp:127\.0\.0\.1:(\d+)", line)
            if m:
                self.ports.put(m.group(1))

    def port(self):
        try:
            return self.ports.get(timeout=180)
        except queue.Empty:
            return None

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)  # closed_loop.py stops apm25sim and the backend
            try:
                self.proc.wait(120)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def truth_at(truth, t):
    """The last truth row at or before t."""
    best = truth[0]
    for r in truth:
        if r["t"] > t + 1e-9:
            break
        best = r
    return best


def read_tlog(path):
    """[(board time s, message)] of MAVProxy's telemetry log, each message at the last
    time_boot_ms seen (ATTITUDE's at 50 Hz: within 0.02 s)."""
    from pymavlink import mavutil
    out = []
    t = 0.0
    log = mavutil.mavlink_connection(path, dialect="ardupilotmega")
    while True:
        m = log.recv_match()
        if m is None:
            break
        if m.get_type() == "BAD_DATA" or m.get_srcSystem() != 1:
            continue
        ms = getattr(m, "time_boot_ms", None)
        if ms is not None:
            t = ms / 1000.0
        out.append((t, m))
    return out


def main():
    args = tools_and_work()
    mission = os.path.join(args.work, "rectangle.waypoints")
    back = os.path.join(args.work, "downloaded.waypoints")
    for p in (back, os.path.join(args.work, "mav.tlog")):
        if os.path.exists(p):
            os.remove(p)
    write_mission(mission)
    flight = Flight(args)
    mp = None
    sets = []  # (what typed, seq)
    try:
        port = flight.port()
        if port is None:
            soft_assert(False, "apm25sim never served UART0 on TCP")
            return
        mp_log = open(os.path.join(args.work, "mavproxy.out"), "w")
        mp = subprocess.Popen([sys.executable, os.path.join(os.path.dirname(sys.executable), "mavproxy.py"),
                               "--master", "tcp:127.0.0.1:" + port, "--default-modules", "wp,mode",
                               "--streamrate", "-1", "--target-system", "1"],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              bufsize=1, cwd=args.work)
        out = Lines(mp.stdout, mp_log)

        def type_line(cmd):
            mp.stdin.write(cmd + "\n")
            mp.stdin.flush()

        def wait(pattern, what, timeout_s=WAIT_S):
            return out.wait(pattern, what, timeout_s)

        if not wait(r"Detected vehicle 1:1", "the vehicle"):
            return
        # Circling while the ground station works: LOITER once the board has its fix.
        end = time.time() + WAIT_S
        while time.time() < end and not any("LOITER>" in line for line in out.seen):
            type_line("mode LOITER")
            time.sleep(3)
        if not soft_assert(any("LOITER>" in line for line in out.seen), "LOITER never taken"):
            return
        type_line("wp load " + mission)
        soft_assert(wait(r"Sent all 6 waypoints", "the upload's end"), "`wp load` did not finish")
        time.sleep(2)
        type_line("wp list")
        soft_assert(wait(r"Requesting 6 waypoints", "`wp list`'s count"), "`wp list` did not get 6")
        type_line("wp save " + back)
        soft_assert(wait(r"Saved 6 waypoints", "`wp save`"), "`wp save` did not save 6")
        if os.path.exists(back):
            got, want = wpl_rows(back), wpl_rows(mission)
            soft_assert(len(got) == len(want), "downloaded %d items, uploaded %d" % (len(got), len(want)))
            for i, (g, w) in enumerate(zip(got, want)):
                soft_assert(g[:4] == w[:4] and all(abs(a - b) <= 6e-7 for a, b in zip(g[4:6], w[4:6]))
                            and abs(g[6] - w[6]) < 0.006, "item %d downloaded %r, uploaded %r" % (i + 1, g, w))
        type_line("mode AUTO")  # its prompt may come after "waypoint 1": HEARTBEAT's mode checked below
        for seq in (1, 2, 3, 4, 1, 2):
            if not wait(r"^waypoint %d\s*$" % seq, "waypoint %d (MISSION_CURRENT)" % seq):
                return
        type_line("wp set 4")
        sets.append(("wp set 4 (MAV_CMD_DO_SET_MISSION_CURRENT)", 4))
        if not wait(r"^waypoint 4\s*$", "waypoint 4 after `wp set 4`"):
            return
        if not wait(r"^waypoint 1\s*$", "waypoint 1 after corner 4"):
            return
        type_line("set wp_use_waypoint_set_current 1")
        type_line("wp set 3")
        sets.append(("wp set 3 (MISSION_SET_CURRENT)", 3))
        if not wait(r"^waypoint 3\s*$", "waypoint 3 after `wp set 3`"):
            return
        wait(r"^waypoint 4\s*$", "waypoint 4 after corner 3")
        time.sleep(3)
    finally:
        if mp is not None:
            mp.terminate()
            try:
                mp.wait(timeout=30)
            except subprocess.TimeoutExpired:
                mp.kill()
        flight.stop()
    check(args, flight, sets)


def check(args, flight, sets):
    tlog = os.path.join(args.work, "mav.tlog")
    if not soft_assert(os.path.exists(tlog), "MAVProxy wrote no mav.tlog"):
        return
    msgs = read_tlog(tlog)
    truth = tcl.read_log(flight.log_path)
    if not soft_assert(msgs and truth, "no telemetry (%d) or no truth (%d)" % (len(msgs), len(truth))):
        return
    auto = next((t for t, m in msgs if m.get_type() == "HEARTBEAT" and m.custom_mode == 10), None)
    if not soft_assert(auto is not None, "HEARTBEAT never said AUTO"):
        return
    home_msg = next((m for t, m in msgs if m.get_type() == "HOME_POSITION"), None)
    home_t = next((t for t, m in msgs if m.get_type() == "HOME_POSITION"), None)
    if not soft_assert(home_msg is not None, "no HOME_POSITION"):
        return
    home = tcl.sim_ned(home_msg.latitude * 1e-7, home_msg.longitude * 1e-7)
    # The board's heights are the barometer's change since the home fix: the truth's then.
    home_h = -truth_at(truth, home_t - tcl.GPS_LATENCY_S)["down_m"]
    print("# AUTO at %.1f s (board time); home %.1f m N %.1f m E of the launch, %.1f m up" % (auto, home[0], home[1],
                                                                                          home_h))
    # MISSION_CURRENT changes and MISSION_ITEM_REACHED, from AUTO on.
    changes, reached, currents = [], [], []
    last = None
    for t, m in msgs:
        if t < auto - 0.5:
            continue
        if m.get_type() == "MISSION_CURRENT":
            currents.append(t)
            if m.seq != last:
                changes.append((t, m.seq))
                last = m.seq
        elif m.get_type() == "MISSION_ITEM_REACHED":
            reached.append((t, m.seq))
    print("# MISSION_CURRENT: %s" % ", ".join("%d at %.2f s" % (s, t - auto) for t, s in changes))
    print("# MISSION_ITEM_REACHED: %s" % ", ".join("%d at %.2f s" % (s, t - auto) for t, s in reached))
    want_changes = [1, 2, 3, 4, 1, 2, 4, 1, 3, 4]
    got_changes = [s for _, s in changes]
    while got_changes and got_changes[0] == 0:  # before AUTO: no command yet
        got_changes.pop(0)
    soft_assert(got_changes[:len(want_changes)] == want_changes,
                "MISSION_CURRENT went %r, expected %r" % (got_changes, want_changes))
    want_reached = [1, 2, 3, 4, 1, 4, 3]
    got_reached = [s for _, s in reached]
    soft_assert(got_reached[:len(want_reached)] == want_reached,
                "MISSION_ITEM_REACHED %r, expected %r (once each)" % (got_reached, want_reached))
    # At once: the new current within AT_ONCE_S of the MISSION_ITEM_REACHED before it.
    for t, s in reached:
        nxt = next((tc for tc, sc in changes if tc >= t - 0.05), None)
        soft_assert(nxt is not None and nxt - t <= AT_ONCE_S,
                    "MISSION_CURRENT after MISSION_ITEM_REACHED %d at %.2f s: at %s" % (s, t - auto, nxt))
    # On its stream: 1 Hz (SR0_EXT_STAT's default), news between.
    gaps = [b - a for a, b in zip(currents, currents[1:])]
    soft_assert(gaps and max(gaps) <= 1.1, "MISSION_CURRENT's longest gap %.2f s" % max(gaps, default=0.0))
    print("# MISSION_CURRENT: %d frames from AUTO on, the longest gap %.2f s" % (len(currents), max(gaps, default=0)))
    # Each corner reached: the true path's closest approach while it was current.
    starts = {}
    for t, s in changes:
        starts.setdefault(s, []).append(t)
    print("# corner: seconds from AUTO to MISSION_ITEM_REACHED, closest approach, height there (want)")
    for t, s in reached:
        start = max((ts for ts in starts.get(s, []) if ts <= t), default=None)
        if start is None:
            soft_assert(False, "MISSION_ITEM_REACHED %d before it was current" % s)
            continue
        n, e, h = CORNERS[s - 1]
        flown = [r for r in truth if start <= r["t"] <= t + 3.0]
        if not flown:
            soft_assert(False, "no truth from %.1f to %.1f s" % (start, t))
            continue
        d, i = min((math.hypot(r["north_m"] - n, r["east_m"] - e), i) for i, r in enumerate(flown))
        r = flown[i]
        print("#   %d: %6.1f s, %5.1f m, %5.1f m (%g)" % (s, t - auto, d, -r["down_m"] - home_h, h))
        soft_assert(d <= WP_RADIUS_M, "corner %d passed %.1f m away (WP_RADIUS %g)" % (s, d, WP_RADIUS_M))
    # The jumps: ACKed, answered at once, the plane turned to the corner.
    acks = [(t, m.result) for t, m in msgs if m.get_type() == "COMMAND_ACK" and m.command == 224]
    print("# DO_SET_MISSION_CURRENT ACKs: %r" % acks)
    soft_assert(acks and acks[0][1] == 0, "MAV_CMD_DO_SET_MISSION_CURRENT not ACCEPTED: %r" % acks)
    jumps = [(t, s) for (t, s), prev in zip(changes[1:], changes) if (prev[1] % 4) + 1 != s]
    soft_assert(len(jumps) >= len(sets), "%d jumps seen for %d `wp set`: %r" % (len(jumps), len(sets), changes))
    for (what, seq), (t, s) in zip(sets, jumps):
        soft_assert(s == seq, "%s: MISSION_CURRENT went to %d" % (what, s))
        n, e, _ = CORNERS[seq - 1]
        turned = None
        before = truth_at(truth, t)
        for r in truth:
            if t <= r["t"] <= t + TURN_S:
                course = math.degrees(math.atan2(r["ve_m_s"], r["vn_m_s"]))
                bearing = math.degrees(math.atan2(e - r["east_m"], n - r["north_m"]))
                if abs(tcl.angle_diff(course, bearing)) <= TURN_DEG:
                    turned = r["t"] - t
                    break
        c0 = math.degrees(math.atan2(before["ve_m_s"], before["vn_m_s"]))
        b0 = math.degrees(math.atan2(e - before["east_m"], n - before["north_m"]))
        print("# %s at %.1f s: the course %.0f deg off the bearing to corner %d, within %g deg %s" %
              (what, t - auto, abs(tcl.angle_diff(c0, b0)), seq, TURN_DEG,
               "%.1f s later" % turned if turned is not None else "never"))
        soft_assert(turned is not None, "%s: not turned to corner %d within %g s" % (what, seq, TURN_S))
    overruns = [m.text for _, m in msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "samples missed: %r" % overruns)


if __name__ == "__main__":
    main()
    sys.exit(finish("mission in flight", "MAVProxy loaded the mission in flight, AUTO flew it, wp set jumped"))
