# SPDX-License-Identifier: GPL-3.0-or-later
"""The modes in the closed loop with a ground station (issue 47): the JSBSim Rascal flown by
the firmware in apm25sim (sim/flight/closed_loop.py --serial tcp:0, in real time), a pymavlink
client as system 255 that sends its HEARTBEAT, arms (forced, as MAVProxy's `arm throttle
force`), sets the parameters and the modes, and reads HEARTBEAT, COMMAND_ACK, MISSION_ACK and
STATUSTEXT; the truth from the backend's --log. Its actions are stamped in the board's time
(the last time_boot_ms heard), never in wall time. Run by test_closed_loop.py's groups
modes_from_switch and modes_flown (their checks are in its docstring).
"""
import math
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
sys.path.insert(0, os.path.join(ROOT, "test", "support"))
from soft_assert import soft_assert  # noqa: E402

MODES = {"MANUAL": 0, "CIRCLE": 1, "STABILIZE": 2, "FBWA": 5, "FBWB": 6, "CRUISE": 7, "AUTO": 10, "RTL": 11,
         "LOITER": 12, "GUIDED": 15}
NAMES = {v: k for k, v in MODES.items()}
# A width in each of ArduPlane's six bands of the mode switch (<= 1230, 1231-1360, 1361-1490,
# 1491-1620, 1621-1749, >= 1750 us): FLTMODE1..6.
BAND_US = (1165, 1295, 1425, 1555, 1685, 1815)
THROTTLE_US = 1106
SET_MODE_ACK = 11  # COMMAND_ACK's command for SET_MODE: its message id (ArduPilot's)
WALL_GUARD_S = 2300  # only against a hang: a loaded machine runs far behind real time


def row(t, pos, pitch=1500, roll=1500):
    """A stick row: the mode switch at FLTMODE`pos` (1..6)."""
    return "%.3f,%d,%d,%d,1500,1500,1500,1500,%d\n" % (t, roll, pitch, THROTTLE_US, BAND_US[pos - 1])


class GcsFlight:
    """One flight with the ground station attached. actions: (board seconds, fn(flight)),
    each run once when the board's time reaches it; mission: [(lat, lon, alt above home m)]
    uploaded when an action calls upload_mission()."""

    def __init__(self, work, tools, name, rows, seconds, actions, fix_after):
        self.name, self.seconds = name, seconds
        self.truth_path = os.path.join(work, name + "_truth.csv")
        rc = os.path.join(work, name + "_rc.csv")
        with open(rc, "w") as f:
            f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n" + "".join(rows))
        self.actions = sorted(actions, key=lambda a: a[0])
        self.msgs = []    # (board s, message)
        self.sent = []    # (board s, what)
        self.t = 0.0      # the board's time: the last time_boot_ms heard
        self.mission = []
        self.conn = None
        cmd = [sys.executable, os.path.join(ROOT, "sim", "flight", "closed_loop.py"), "--rc", rc,
               "--seconds", "%g" % seconds, "--sim", os.path.join(tools, "apm25sim"),
               "--elf", os.path.join(tools, "firmware.elf"), "--serial", "tcp:0", "--timeout", "%d" % WALL_GUARD_S,
               "--log", self.truth_path, "--gps", "ublox", "--gps-fix-after", "%g" % fix_after]
        self.launched = time.monotonic()
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self.stderr_lines, self.port = [], None
        self.port_found = threading.Event()
        threading.Thread(target=self._read_stderr, daemon=True).start()

    def _read_stderr(self):
        for line in self.proc.stderr:
            self.stderr_lines.append(line)
            m = re.search(r"serving UART0 on tcp:127\.0\.0\.1:(\d+)", line)
            if m and self.port is None:
                self.port = int(m.group(1))
                self.port_found.set()
        self.port_found.set()

    # --- what an action sends --------------------------------------------------------------
    def set_mode(self, name):
        self.conn.mav.set_mode_send(1, mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, MODES[name])
        self.sent.append((self.t, "SET_MODE " + name))

    def do_set_mode(self, name):
        self.conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_DO_SET_MODE, 0,
                                        mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, MODES[name], 0, 0, 0, 0, 0)
        self.sent.append((self.t, "DO_SET_MODE " + name))

    def param(self, name, value):
        self.conn.mav.param_set_send(1, 1, name.encode(), float(value), mavlink2.MAV_PARAM_TYPE_REAL32)

    def fly_to(self, lat, lon, alt_m):
        """MAVProxy's `guided LAT LON ALT` (its default frame: above home)."""
        self.conn.mav.mission_item_int_send(1, 1, 0, mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                                            mavlink2.MAV_CMD_NAV_WAYPOINT, 2, 0, 0, 0, 0, 0,
                                            int(round(lat * 1e7)), int(round(lon * 1e7)), alt_m)
        self.sent.append((self.t, "guided"))

    def upload_mission(self, items):
        """home (seq 0, ignored by the board) and waypoints [(lat, lon, alt above home m)]."""
        self.mission = [(0.0, 0.0, 0.0)] + list(items)
        self.conn.mav.mission_count_send(1, 1, len(self.mission), mavlink2.MAV_MISSION_TYPE_MISSION)

    def _answer_request(self, m):
        if not self.mission or m.seq >= len(self.mission) or getattr(m, "mission_type", 0) != 0:
            return
        lat, lon, alt = self.mission[m.seq]
        self.conn.mav.mission_item_int_send(1, 1, m.seq, mavlink2.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                                            mavlink2.MAV_CMD_NAV_WAYPOINT, 0, 1, 0, 0, 0, 0,
                                            int(round(lat * 1e7)), int(round(lon * 1e7)), alt)

    # --- the run -----------------------------------------------------------------------------
    def run(self):
        """Until the flight ends; the flight's exit status and stderr."""
        self.port_found.wait(WALL_GUARD_S)
        if self.port is None:
            soft_assert(False, "%s: the flight did not serve UART0:\n%s" % (self.name, "".join(self.stderr_lines)[-3000:]))
            return self._end()
        conn = mavutil.mavlink_connection("tcp:127.0.0.1:%d" % self.port, source_system=255, source_component=190,
                                          autoreconnect=False)
        closed = []
        conn.handle_eof = lambda: closed.append("eof")
        conn.handle_disconnect = lambda: closed.append("reset")
        self.conn = conn
        last_hb, armed_sent, pending = 0.0, False, list(self.actions)
        try:
            while time.monotonic() - self.launched < WALL_GUARD_S:
                now = time.monotonic()
                if now - last_hb > 1.0:
                    try:
                        conn.mav.heartbeat_send(mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0)
                    except OSError:
                        pass
                    last_hb = now
                m = conn.recv_match(blocking=True, timeout=0.2)
                if m is None or m.get_type() == "BAD_DATA":
                    if closed or self.proc.poll() is not None:
                        break
                    continue
                if m.get_srcSystem() != 1:
                    continue
                if hasattr(m, "time_boot_ms") and m.get_type() != "MISSION_ITEM_INT":
                    self.t = max(self.t, m.time_boot_ms / 1000.0)
                self.msgs.append((self.t, m))
                kind = m.get_type()
                if kind == "HEARTBEAT" and not armed_sent:
                    conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 2989, 0, 0, 0, 0, 0)
                    armed_sent = True
                elif kind in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
                    self._answer_request(m)
                while pending and armed_sent and pending[0][0] <= self.t:
                    pending.pop(0)[1](self)
        finally:
            conn.close()
        return self._end()

    def _end(self):
        try:
            status = self.proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            status = self.proc.wait()
        return status, "".join(self.stderr_lines)

    # --- reading back ------------------------------------------------------------------------
    def heartbeats(self, t0, t1):
        return [(t, m.custom_mode) for t, m in self.msgs if t0 <= t < t1 and m.get_type() == "HEARTBEAT"]

    def first(self, kind, after, pred=lambda m: True):
        return next(((t, m) for t, m in self.msgs if t >= after and m.get_type() == kind and pred(m)), None)

    def text(self, start, after):
        """The first STATUSTEXT from `after` that starts with `start`: (t, text) or None."""
        r = self.first("STATUSTEXT", after, lambda m: m.text.startswith(start))
        return (r[0], r[1].text) if r else None

    def truth(self):
        import csv
        with open(self.truth_path) as f:
            return [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]


def check_mode_held(f, label, t0, t1, want):
    """Every HEARTBEAT from t0 + 0.6 s (the mode change and a HEARTBEAT in flight) to t1 says
    `want`; at least one."""
    hbs = f.heartbeats(t0 + 0.6, t1)
    ok = bool(hbs) and all(mode == MODES[want] for _, mode in hbs)
    soft_assert(ok, "%s: HEARTBEAT custom_mode %s from %.1f to %.1f s, want %s (%d)"
                % (label, [m for _, m in hbs], t0, t1, want, MODES[want]))
    return ok


def check_ack(f, label, command, t, want):
    ack = f.first("COMMAND_ACK", t, lambda m: m.command == command)
    soft_assert(ack is not None and ack[1].result == want and ack[0] < t + 2.0,
                "%s: COMMAND_ACK %r (want result %d)" % (label, ack and ack[1], want))


def check_said(f, label, start, after, within=2.0):
    said = f.text(start, after)
    soft_assert(said is not None and said[0] < after + within, "%s: no STATUSTEXT %r after %.1f s: %r"
                % (label, start, after, said))
    return said


# ---------------------------------------------------------------------------------------
# modes_from_switch

SWITCH_FIX_S = 32.0  # the first fix: the GPS modes refused before it
# FLTMODE1..6 before the fix, and after it (positions 3 and 6 unchanged: STABILIZE, AUTO).
SWITCH_MODES_1 = ("MANUAL", "CIRCLE", "STABILIZE", "FBWA", "FBWB", "AUTO")
SWITCH_MODES_2 = ("CRUISE", "RTL", "STABILIZE", "LOITER", "GUIDED", "AUTO")
# (board s, switch position): the script; every mode held 3 s.
SWITCH_SCRIPT = [(0.0, 3), (5.0, 1), (8.0, 2), (11.0, 4), (14.0, 5), (17.0, 3), (20.0, 6), (23.0, 3),
                 (37.0, 6), (40.0, 3), (48.0, 6), (51.0, 1), (54.0, 2), (57.0, 4), (60.0, 5), (63.0, 3),
                 (121.0, 1)]
GCS_FROM_S, GCS_STEP_S = 66.0, 2.5
GCS_ORDER = ("MANUAL", "CIRCLE", "STABILIZE", "FBWA", "FBWB", "CRUISE", "AUTO", "RTL", "GUIDED", "LOITER")
SWITCH_SECONDS = 125.0


def sim_latlon(north_m, east_m):
    """apm25sim's flat map about its --home (test_closed_loop.py's)."""
    lat0, lon0, alt0 = 7.135045, -73.119421, 1028.0
    a, e2 = 6378137.0, 6.69437999014e-3
    s = math.sin(math.radians(lat0))
    r_m = a * (1 - e2) / (1 - e2 * s * s) ** 1.5
    r_n = a / math.sqrt(1 - e2 * s * s)
    return (lat0 + math.degrees(north_m / (r_m + alt0)),
            lon0 + math.degrees(east_m / ((r_n + alt0) * math.cos(math.radians(lat0)))))


def sim_ne(lat, lon):
    lat0, lon0, alt0 = 7.135045, -73.119421, 1028.0
    a, e2 = 6378137.0, 6.69437999014e-3
    s = math.sin(math.radians(lat0))
    r_m = a * (1 - e2) / (1 - e2 * s * s) ** 1.5
    r_n = a / math.sqrt(1 - e2 * s * s)
    return (math.radians(lat - lat0) * (r_m + alt0),
            math.radians(lon - lon0) * (r_n + alt0) * math.cos(math.radians(lat0)))


def check_modes_from_switch(work, tools):
    """Every mode from the switch and from the ground station; the refusals with their reasons."""
    rows = [row(t, pos) for t, pos in SWITCH_SCRIPT]
    actions = [(0.0, lambda f: [f.param("FLTMODE%d" % (i + 1), MODES[n]) for i, n in enumerate(SWITCH_MODES_1)]),
               (0.1, lambda f: (f.param("TRIM_THROTTLE", 11), f.param("TRIM_ARSPD_CM", 1800))),
               # Before the fix: the GPS modes refused, from both messages and a "fly to here".
               (25.0, lambda f: f.do_set_mode("LOITER")), (26.0, lambda f: f.set_mode("GUIDED")),
               (27.0, lambda f: f.fly_to(*sim_latlon(300.0, 0.0), alt_m=30.0)),
               (28.0, lambda f: f.set_mode("CRUISE")), (29.0, lambda f: f.do_set_mode("RTL")),
               (30.0, lambda f: f.set_mode("AUTO")),
               # The fix, home, no mission: AUTO refused for it.
               (36.0, lambda f: f.do_set_mode("AUTO")),
               (41.0, lambda f: f.upload_mission([sim_latlon(600.0, 0.0) + (20.0,), sim_latlon(600.0, 400.0) + (20.0,)])),
               (46.0, lambda f: [f.param("FLTMODE%d" % (i + 1), MODES[n]) for i, n in enumerate(SWITCH_MODES_2)])]
    gcs = []
    for i, name in enumerate(GCS_ORDER):  # SET_MODE in this order, then DO_SET_MODE backwards
        gcs.append((GCS_FROM_S + i * GCS_STEP_S, "SET_MODE", name))
    for i, name in enumerate(reversed(GCS_ORDER[:-1])):
        gcs.append((GCS_FROM_S + (len(GCS_ORDER) + i) * GCS_STEP_S, "DO_SET_MODE", name))
    gcs.append((GCS_FROM_S + (2 * len(GCS_ORDER) - 1) * GCS_STEP_S, "DO_SET_MODE", "LOITER"))
    for t, how, name in gcs:
        actions.append((t, (lambda n: lambda f: f.set_mode(n))(name) if how == "SET_MODE"
                        else (lambda n: lambda f: f.do_set_mode(n))(name)))
    f = GcsFlight(work, tools, "modes_from_switch", rows, SWITCH_SECONDS, actions, SWITCH_FIX_S)
    status, err = f.run()
    soft_assert(status == 0, "modes_from_switch: the flight exited %s:\n%s" % (status, err[-3000:]))
    soft_assert(f.t > SWITCH_SECONDS - 2.0, "modes_from_switch: the board's time reached only %.1f s" % f.t)

    # The switch: each position's mode, in HEARTBEAT, until the next move.
    entered = []
    for i, (t, pos) in enumerate(SWITCH_SCRIPT[1:], 1):
        t_next = SWITCH_SCRIPT[i + 1][0] if i + 1 < len(SWITCH_SCRIPT) else SWITCH_SECONDS
        if t_next > GCS_FROM_S and t < GCS_FROM_S:
            t_next = GCS_FROM_S
        names = SWITCH_MODES_1 if t < 46.0 else SWITCH_MODES_2
        want = names[pos - 1]
        if (t, pos) in ((20.0, 6), (37.0, 6)):
            want = "STABILIZE"  # refused: the mode before flies on
        if check_mode_held(f, "switch to FLTMODE%d at %.0f s" % (pos, t), t, t_next, want):
            entered.append(want)
    reason = check_said(f, "the switch's AUTO before the fix", "Mode change refused (switch): AUTO: ", 20.0)
    soft_assert(reason and reason[1].endswith("no 3D GPS fix"), "switch AUTO before the fix: %r" % (reason,))
    reason2 = check_said(f, "the switch's AUTO without a mission", "Mode change refused (switch): AUTO: ", 37.0)
    soft_assert(reason2 and reason2[1].endswith("no mission"), "switch AUTO, no mission: %r" % (reason2,))
    print("modes_from_switch: the switch entered %s; refused %r, %r"
          % (", ".join(sorted(set(entered), key=lambda n: MODES[n])), reason and reason[1], reason2 and reason2[1]))
    soft_assert(set(entered) == set(MODES), "modes_from_switch: the switch did not enter %s"
                % sorted(set(MODES) - set(entered)))

    # The ground station's refusals: FAILED (MISSION_ACK ERROR for "fly to here"), the
    # reason said, STABILIZE (the switch's) flying on.
    refusals = []
    for t, how, name, why in ((25.0, "DO_SET_MODE", "LOITER", "no 3D GPS fix"),
                              (26.0, "SET_MODE", "GUIDED", "no 3D GPS fix"),
                              (27.0, "guided", "GUIDED", "no 3D GPS fix"),
                              (28.0, "SET_MODE", "CRUISE", "no 3D GPS fix"),
                              (29.0, "DO_SET_MODE", "RTL", "no 3D GPS fix"),
                              (30.0, "SET_MODE", "AUTO", "no 3D GPS fix"),
                              (36.0, "DO_SET_MODE", "AUTO", "no mission")):
        label = "%s %s at %.0f s" % (how, name, t)
        if how == "guided":
            ack = f.first("MISSION_ACK", t)
            soft_assert(ack is not None and ack[1].type == mavlink2.MAV_MISSION_ERROR and ack[0] < t + 2.0,
                        "%s: MISSION_ACK %r (want ERROR)" % (label, ack and ack[1]))
        else:
            check_ack(f, label, SET_MODE_ACK if how == "SET_MODE" else mavlink2.MAV_CMD_DO_SET_MODE, t,
                      mavlink2.MAV_RESULT_FAILED)
        said = check_said(f, label, "Mode change refused: %s: " % name, t)
        soft_assert(said is None or said[1].endswith(why), "%s: said %r, want %r" % (label, said, why))
        refusals.append(said and said[1])
    check_mode_held(f, "after the ground station's refusals", 25.0, 37.0, "STABILIZE")
    print("modes_from_switch: the ground station's refusals said %s" % refusals)
    upload = f.first("MISSION_ACK", 41.0)
    soft_assert(upload is not None and upload[1].type == mavlink2.MAV_MISSION_ACCEPTED,
                "the mission's upload: %r" % (upload and upload[1]))

    # Every mode from the ground station: ACCEPTED, then HEARTBEAT's custom_mode until the next.
    accepted = {"SET_MODE": [], "DO_SET_MODE": []}
    for i, (t, how, name) in enumerate(gcs):
        t_next = gcs[i + 1][0] if i + 1 < len(gcs) else 121.0
        label = "%s %s at %.1f s" % (how, name, t)
        check_ack(f, label, SET_MODE_ACK if how == "SET_MODE" else mavlink2.MAV_CMD_DO_SET_MODE, t,
                  mavlink2.MAV_RESULT_ACCEPTED)
        if check_mode_held(f, label, t, t_next, name):
            accepted[how].append(name)
    for how, names in accepted.items():
        print("modes_from_switch: %s entered %s" % (how, ", ".join(names)))
    soft_assert(set(accepted["SET_MODE"]) == set(MODES) and set(accepted["DO_SET_MODE"]) == set(MODES),
                "modes_from_switch: not every mode from the ground station: %r" % accepted)
    # The ground station's LOITER holds while the switch stays; the switch moved takes over.
    last = gcs[-1][0]
    held = f.heartbeats(last + 0.6, 121.0)
    after = f.heartbeats(121.6, SWITCH_SECONDS)
    print("modes_from_switch: the ground station's LOITER held %d HEARTBEATs to 121 s, then the switch's %s"
          % (len(held), [NAMES.get(m, m) for _, m in after]))
    soft_assert(len(held) >= 3 and all(m == MODES["LOITER"] for _, m in held), "LOITER held: %r" % held)
    soft_assert(after and all(m == MODES["CRUISE"] for _, m in after), "the switch moved to CRUISE: %r" % after)


# ---------------------------------------------------------------------------------------
# modes_flown

FLOWN_FIX_S = 40.0
FLOWN_MODES = ("CIRCLE", "FBWB", "STABILIZE", "CRUISE", "LOITER", "FBWA")  # FLTMODE1..6
T_CIRCLE, T_FBWB, T_CLIMB, T_LEVEL, T_CRUISE, T_LOITER, T_GUIDED, FLOWN_SECONDS = \
    5.0, 42.0, 72.0, 87.0, 97.0, 137.0, 197.0, 262.0
CLIMB_RATE = 2.0           # FBWB_CLIMB_RATE's default, m/s at full stick
LOITER_RAD = 60.0          # WP_LOITER_RAD's default
GUIDED_OFFSET = (250.0, 150.0)  # the "fly to here": north, east of LOITER's entry (m)
GUIDED_ALT = 40.0          # above home


def circle_fit(points):
    """The least-squares circle through (x, y) points (Kasa): (cx, cy, radius)."""
    import numpy as np
    a = np.array([[x, y, 1.0] for x, y in points])
    b = np.array([-(x * x + y * y) for x, y in points])
    d, e, f = np.linalg.lstsq(a, b, rcond=None)[0]
    cx, cy = -d / 2.0, -e / 2.0
    return cx, cy, math.sqrt(max(cx * cx + cy * cy - f, 0.0))


def turned_deg(samples):
    return sum(abs((b["yaw_deg"] - a["yaw_deg"] + 180.0) % 360.0 - 180.0) for a, b in zip(samples, samples[1:]))


def check_modes_flown(work, tools):
    """CIRCLE without a fix, FBWB, CRUISE, LOITER from the switch and GUIDED's "fly to here",
    each flown for 30-60 s, against the flight model's truth."""
    script = [(0.0, 3, 1500), (T_CIRCLE, 1, 1500), (T_FBWB, 2, 1500), (T_CLIMB, 2, 2000), (T_LEVEL, 2, 1500),
              (T_CRUISE, 4, 1500), (T_LOITER, 5, 1500)]
    rows = [row(t, pos, pitch) for t, pos, pitch in script]
    marks = {}

    def mark_loiter(f):
        pos = [m for _, m in f.msgs if m.get_type() == "GLOBAL_POSITION_INT"]
        marks["loiter"] = (pos[-1].lat * 1e-7, pos[-1].lon * 1e-7) if pos else None

    def guide(f):
        if marks.get("loiter") is None:
            return
        n, e = sim_ne(*marks["loiter"])
        marks["target"] = sim_latlon(n + GUIDED_OFFSET[0], e + GUIDED_OFFSET[1])
        f.fly_to(marks["target"][0], marks["target"][1], GUIDED_ALT)

    actions = [(0.0, lambda f: [f.param("FLTMODE%d" % (i + 1), MODES[n]) for i, n in enumerate(FLOWN_MODES)]),
               (0.1, lambda f: (f.param("TRIM_THROTTLE", 11), f.param("TRIM_ARSPD_CM", 1800))),
               (T_LOITER + 0.3, mark_loiter), (T_GUIDED, guide)]
    f = GcsFlight(work, tools, "modes_flown", rows, FLOWN_SECONDS, actions, FLOWN_FIX_S)
    status, err = f.run()
    soft_assert(status == 0, "modes_flown: the flight exited %s:\n%s" % (status, err[-3000:]))
    truth = f.truth()
    soft_assert(truth and truth[-1]["t"] > FLOWN_SECONDS - 1.0, "modes_flown: the truth ends early")
    if not truth or truth[-1]["t"] < FLOWN_SECONDS - 1.0:
        return

    def between(t0, t1):
        return [r for r in truth if t0 <= r["t"] < t1]

    def at(t):
        return min(truth, key=lambda r: abs(r["t"] - t))

    def height(r):
        return -r["down_m"]

    for t, pos in ((T_CIRCLE, 1), (T_FBWB, 2), (T_CRUISE, 4), (T_LOITER, 5)):
        check_mode_held(f, "modes_flown: the switch to FLTMODE%d" % pos, t, t + 2.0, FLOWN_MODES[pos - 1])
    lowest = min(height(r) for r in between(HOLD_FREE_S, FLOWN_SECONDS))
    soft_assert(lowest > 40.0, "modes_flown: down to %.1f m above the ground" % lowest)

    # CIRCLE before the first fix: a third of LIM_ROLL_CD (15 deg), the height kept.
    home = f.text("home: set at ", 0.0)
    soft_assert(home is not None and home[0] >= FLOWN_FIX_S, "modes_flown: home said %r (the fix at %g s)"
                % (home, FLOWN_FIX_S))
    circle = between(T_CIRCLE + 10.0, FLOWN_FIX_S)
    h0 = height(at(T_CIRCLE))
    banks = [r["roll_deg"] for r in circle]
    dh = [height(r) - h0 for r in circle]
    print("modes_flown: CIRCLE without a fix, %.0f-%.0f s: bank %.1f to %.1f deg (mean %.1f), %.0f deg turned, "
          "height %+.1f to %+.1f m of its entry (%.0f m)" % (T_CIRCLE + 10.0, FLOWN_FIX_S, min(banks), max(banks),
                                                           sum(banks) / len(banks), turned_deg(circle), min(dh),
                                                           max(dh), h0))
    soft_assert(abs(sum(banks) / len(banks) - 15.0) <= 5.0, "CIRCLE: mean bank %.1f deg, not 15 +- 5"
                % (sum(banks) / len(banks)))
    soft_assert(turned_deg(circle) > 180.0, "CIRCLE: only %.0f deg turned" % turned_deg(circle))
    soft_assert(max(abs(x) for x in dh) <= 3.0, "CIRCLE: the height left its entry's +- 3 m")

    # FBWB: the height held with the sticks centred, FBWB_CLIMB_RATE with the stick up.
    h1 = height(at(T_FBWB))
    hold = [height(r) - h1 for r in between(T_FBWB + 5.0, T_CLIMB)]
    rate = (height(at(T_LEVEL)) - height(at(T_CLIMB + 5.0))) / (T_LEVEL - T_CLIMB - 5.0)
    top = height(at(T_LEVEL))
    after = [height(r) - top for r in between(T_LEVEL + 3.0, T_CRUISE)]
    print("modes_flown: FBWB, sticks centred %.0f-%.0f s: height %+.1f to %+.1f m of its entry; stick up: %.2f m/s "
          "(FBWB_CLIMB_RATE %g), then %+.1f to %+.1f m of the top" % (T_FBWB + 5.0, T_CLIMB, min(hold), max(hold),
                                                                      rate, CLIMB_RATE, min(after), max(after)))
    soft_assert(max(abs(x) for x in hold) <= 3.0, "FBWB: the height left +- 3 m of its entry")
    soft_assert(abs(rate - CLIMB_RATE) <= 0.5, "FBWB: climbed %.2f m/s, not %g +- 0.5" % (rate, CLIMB_RATE))
    soft_assert(max(abs(x) for x in after) <= 5.0, "FBWB: after the climb the height left +- 5 m")

    # CRUISE: the ground track locked, the height held.
    cruise = between(T_CRUISE + 5.0, T_LOITER)
    a, b = cruise[0], cruise[-1]
    ln, le = b["north_m"] - a["north_m"], b["east_m"] - a["east_m"]
    length = math.hypot(ln, le)
    cross = [((r["east_m"] - a["east_m"]) * ln - (r["north_m"] - a["north_m"]) * le) / length for r in cruise]
    course0 = math.degrees(math.atan2(at(T_CRUISE)["ve_m_s"], at(T_CRUISE)["vn_m_s"]))
    course = math.degrees(math.atan2(le, ln))
    h2 = height(at(T_CRUISE))
    dh2 = [height(r) - h2 for r in cruise]
    print("modes_flown: CRUISE %.0f-%.0f s: %.0f m along a course of %.1f deg (%.1f at its entry), off the line "
          "%.1f m at most, height %+.1f to %+.1f m of its entry" % (T_CRUISE + 5.0, T_LOITER, length, course % 360.0,
                                                                   course0 % 360.0, max(abs(x) for x in cross),
                                                                   min(dh2), max(dh2)))
    soft_assert(abs((course - course0 + 180.0) % 360.0 - 180.0) <= 5.0, "CRUISE: the track turned from its entry's")
    soft_assert(max(abs(x) for x in cross) <= 5.0, "CRUISE: %.1f m off a straight track" % max(abs(x) for x in cross))
    soft_assert(max(abs(x) for x in dh2) <= 3.0, "CRUISE: the height left +- 3 m of its entry")

    # LOITER: WP_LOITER_RAD about where it was entered, at that height.
    entry = at(T_LOITER)
    loiter = between(T_LOITER + 25.0, T_GUIDED)
    cn, ce, radius = circle_fit([(r["north_m"], r["east_m"]) for r in loiter])
    radii = [math.hypot(r["north_m"] - cn, r["east_m"] - ce) for r in loiter]
    moved = math.hypot(cn - entry["north_m"], ce - entry["east_m"])
    dh3 = [height(r) - height(entry) for r in loiter]
    print("modes_flown: LOITER %.0f-%.0f s: radius %.1f-%.1f m (fit %.1f, WP_LOITER_RAD %g) about a centre %.1f m "
          "from its entry, %.0f deg turned, height %+.1f to %+.1f m of its entry"
          % (T_LOITER + 25.0, T_GUIDED, min(radii), max(radii), radius, LOITER_RAD, moved, turned_deg(loiter),
             min(dh3), max(dh3)))
    soft_assert(max(abs(x - LOITER_RAD) for x in radii) <= 5.0, "LOITER: the radius left %g +- 5 m" % LOITER_RAD)
    soft_assert(moved <= 15.0, "LOITER: the circle %.1f m from its entry" % moved)
    soft_assert(turned_deg(loiter) > 360.0, "LOITER: %.0f deg turned" % turned_deg(loiter))
    soft_assert(max(abs(x) for x in dh3) <= 5.0, "LOITER: the height left +- 5 m of its entry")

    # GUIDED: "fly to here", WP_LOITER_RAD about the place given at home + GUIDED_ALT.
    ack = f.first("MISSION_ACK", T_GUIDED)
    soft_assert(ack is not None and ack[1].type == mavlink2.MAV_MISSION_ACCEPTED and ack[0] < T_GUIDED + 2.0,
                "GUIDED: MISSION_ACK %r" % (ack and ack[1]))
    check_mode_held(f, "GUIDED's fly to here", T_GUIDED, FLOWN_SECONDS, "GUIDED")
    if "target" not in marks or home is None:
        soft_assert(False, "GUIDED: no place given (%r) or no home" % marks)
        return
    tn, te = sim_ne(*marks["target"])
    home_h = height(at(home[0] - 0.2))  # the board's heights: the barometer's since the home fix
    guided = between(T_GUIDED + 35.0, FLOWN_SECONDS)
    cn, ce, radius = circle_fit([(r["north_m"], r["east_m"]) for r in guided])
    radii = [math.hypot(r["north_m"] - tn, r["east_m"] - te) for r in guided]
    dh4 = [height(r) - home_h - GUIDED_ALT for r in guided]
    print("modes_flown: GUIDED to %.0f m away, %.0f-%.0f s: %.1f-%.1f m from the place given (fit %.1f m about a "
          "centre %.1f m from it), height %+.1f to %+.1f m of home + %g"
          % (math.hypot(tn - at(T_GUIDED)["north_m"], te - at(T_GUIDED)["east_m"]), T_GUIDED + 35.0, FLOWN_SECONDS,
             min(radii), max(radii), radius, math.hypot(cn - tn, ce - te), min(dh4), max(dh4), GUIDED_ALT))
    soft_assert(max(abs(x - LOITER_RAD) for x in radii) <= 8.0, "GUIDED: %.1f-%.1f m from the place given, not %g "
                "+- 8" % (min(radii), max(radii), LOITER_RAD))
    soft_assert(max(abs(x) for x in dh4) <= 5.0, "GUIDED: the height left home + %g +- 5 m" % GUIDED_ALT)


HOLD_FREE_S = 4.0  # released from the stand at 3 s
