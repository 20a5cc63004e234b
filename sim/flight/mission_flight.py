#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A mission flown by the board in the closed loop (`make fly FLIGHT=mission`): the firmware
in apm25sim flies the JSBSim Rascal from a hand launch through a mission file, then draws the
flight and prints its figures.

    mission_flight.py [--mission sim/flight/missions/thesis.waypoints | FILE.plan] [--gust 0|1|2]
        [--seed N] [--seconds S] [--plot build/flight/mission.png] [--work DIR]
        [--sim build/apm25sim] [--elf build/firmware.elf] [--serial tcp:PORT] [--speed X]
        [--timeout S]

The flight: the aeroplane is held on the launch stand at LAUNCH's height and pitch while the
board boots, calibrates, is armed (closed_loop.py --arm), finds the simulator's u-blox and
sets home; the mode switch goes to AUTO (FLTMODE5, set on the console with the Rascal's cruise,
TRIM_THROTTLE 11 and TRIM_ARSPD_CM 1800) at AUTO_S; at LAUNCH_S it is thrown (the backend's
--launch). The mission's first item is to be NAV_TAKEOFF; the rest is flown as the board
flies it. Parameters at their defaults: WP_RADIUS 30 m, WP_LOITER_RAD 60 m, ALT_HOLD_RTL 100 m.

The mission is a QGC WPL 110 file (Mission Planner's .waypoints; apm25sim --mission loads it
into the EEPROM) or a QGroundControl .plan (JSON), converted here (plan_to_waypoints):
SimpleItems only, DO_JUMP's target the item's doJumpId turned into its seq as QGroundControl
does when it uploads.

Figures (printed): the hand launch (the lowest height after the throw, the bank in the climb),
each waypoint's closest distance on each lap, the cross-track RMS per leg and the height RMS
(on each leg from its capture: within 3 m of its line and 10 deg of its course, until
WP_RADIUS before its end; the height against the leg's straight slope between the two
waypoints' heights), the laps the DO_JUMP flew, the circle at home (radius and height from
25 s after RTL first comes within 80 m of home: CIRCLE_AFTER_S). The picture: the map (the true path over the
waypoints and their WP_RADIUS circles, home, the loiter circle) and the true height against
the route's over time.
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CLOSED_LOOP = os.path.join(HERE, "closed_loop.py")
DEFAULT_MISSION = os.path.join(HERE, "missions", "thesis.waypoints")

# The simulator's GPS origin (apm25sim --home's default, sim/models/Geodesy.h): the backend's
# north-east metres from its start are metres from this point.
SIM_HOME = (7.135045, -73.119421, 1028.0)
GPS_LATENCY_S = 0.2  # apm25sim --gps-latency's default

# The hand launch (the backend's --launch): held 1.8 m above the ground (a hand over the
# head), the nose 10 deg up, thrown at 11 m/s; the Rascal flies from 6.3 m/s at its stall.
LAUNCH = (11.0, 1.8, 10.0)
HOLD_S = 12.0       # on the stand until then: home is set by ~8 s
AUTO_S = 10.0       # the mode switch to AUTO (refused before home: said)
AUTO_SWITCH, STABILIZE_SWITCH = 1700, 2000  # channel 8: FLTMODE5, FLTMODE6
THROTTLE_US = 1106  # the stick's throttle (STABILIZE on the stand; AUTO takes TECS's)
CONSOLE = ["set FLTMODE5 10", "set TRIM_THROTTLE 11", "set TRIM_ARSPD_CM 1800", "set THR_MAX 45"]
WP_RADIUS_M, LOITER_RAD_M, RTL_ALT_M = 30.0, 60.0, 100.0  # the parameters' defaults
# The circle at home is measured from this long after RTL first comes within 80 m of home:
# the RTL test's 15 s, and 10 s for RTL's climb from the last waypoint (60 m at 113 m from home
# in the thesis' mission: TECS_CLMB_MAX 5 m/s and the transient after it).
CIRCLE_AFTER_S = 25.0

NAV_WAYPOINT, NAV_RTL, NAV_TAKEOFF, DO_JUMP, DO_CHANGE_SPEED = 16, 20, 22, 177, 178


# ---- the mission file ---------------------------------------------------------------------

def plan_to_waypoints(plan):
    """A QGroundControl .plan (its parsed JSON) as QGC WPL 110 text: home from
    plannedHomePosition at seq 0, then each SimpleItem; DO_JUMP's param 1 (a doJumpId in a
    .plan) becomes the seq of the item that has it. ValueError for what it cannot take."""
    mission = plan.get("mission") if isinstance(plan, dict) else None
    if not isinstance(mission, dict) or not isinstance(mission.get("items"), list):
        raise ValueError("not a QGroundControl plan: no mission.items")
    home = mission.get("plannedHomePosition") or [SIM_HOME[0], SIM_HOME[1], 0.0]
    items = mission["items"]
    jump_ids = {}
    for seq, it in enumerate(items, start=1):
        if it.get("type") != "SimpleItem":
            raise ValueError("item %d: a %s (survey, corridor ...): only SimpleItems are flown here"
                             % (seq, it.get("complexItemType", it.get("type"))))
        if "doJumpId" in it:
            jump_ids[int(it["doJumpId"])] = seq
    lines = ["QGC WPL 110", "0\t1\t0\t16\t0\t0\t0\t0\t%.8f\t%.8f\t%.2f\t1" % (home[0], home[1], home[2])]
    for seq, it in enumerate(items, start=1):
        params = [0.0 if p is None else float(p) for p in it.get("params", [])]
        if len(params) != 7:
            raise ValueError("item %d: %d params, a SimpleItem has 7" % (seq, len(params)))
        command = int(it["command"])
        if command == DO_JUMP:
            target = int(params[0])
            if target not in jump_ids:
                raise ValueError("item %d: DO_JUMP to doJumpId %d, which no item has" % (seq, target))
            params[0] = jump_ids[target]
        lines.append("%d\t0\t%d\t%d\t%s\t%.8f\t%.8f\t%.2f\t%d" % (
            seq, int(it.get("frame", 3)), command, "\t".join("%g" % p for p in params[:4]),
            params[4], params[5], params[6], 1 if it.get("autoContinue", True) else 0))
    return "\n".join(lines) + "\n"


def read_waypoints(path):
    """The items of a QGC WPL 110 file: dicts of seq, frame, command, p (4), lat, lon, alt."""
    with open(path) as f:
        lines = [ln.split() for ln in f.read().splitlines() if ln.strip()]
    if not lines or lines[0][:2] != ["QGC", "WPL"]:
        raise ValueError("%s: not a QGC WPL file" % path)
    items = []
    for fields in lines[1:]:
        if len(fields) != 12:
            raise ValueError("%s: a line of %d fields (12 wanted)" % (path, len(fields)))
        v = [float(x) for x in fields]
        items.append({"seq": int(v[0]), "frame": int(v[2]), "command": int(v[3]), "p": v[4:8],
                      "lat": v[8], "lon": v[9], "alt": v[10]})
    return items


def sim_ned(lat_deg, lon_deg):
    """Degrees to the backend's north-east metres (apm25sim's flat map, sim/models/Geodesy.h)."""
    a, e2 = 6378137.0, 6.69437999014e-3
    s = math.sin(math.radians(SIM_HOME[0]))
    r_m = a * (1 - e2) / (1 - e2 * s * s) ** 1.5
    r_n = a / math.sqrt(1 - e2 * s * s)
    return (math.radians(lat_deg - SIM_HOME[0]) * (r_m + SIM_HOME[2]),
            math.radians(lon_deg - SIM_HOME[1]) * (r_n + SIM_HOME[2]) * math.cos(math.radians(SIM_HOME[0])))


def captured_on_leg(samples, a, b, end_margin_m):
    """The samples of the passes along the leg a -> b (north, east m) after capture, as the
    host route test takes them: on a pass (within 45 deg of the leg's course and 50 m of its
    line, before end_margin_m of its end; a gap over 1 s ends one), from the first sample
    within 3 m of the line and 10 deg of its course. Yields (sample, along m, cross-track m,
    whether it is a pass's first)."""
    dn, de = b[0] - a[0], b[1] - a[1]
    length = math.hypot(dn, de)
    un, ue = dn / length, de / length
    course_leg = math.degrees(math.atan2(ue, un))
    captured, last_t = False, None
    for r in samples:
        pn, pe = r["north_m"] - a[0], r["east_m"] - a[1]
        along, cross = pn * un + pe * ue, pe * un - pn * ue
        off = abs(angle_diff(math.degrees(math.atan2(r["ve_m_s"], r["vn_m_s"])), course_leg))
        if not (0.0 <= along <= length - end_margin_m and off < 45.0 and abs(cross) < 50.0):
            captured = False
            continue
        if last_t is None or r["t"] - last_t > 1.0:
            captured = False
        last_t = r["t"]
        first = False
        if not captured and abs(cross) < 3.0 and off < 10.0:
            captured = first = True
        if captured:
            yield r, along, cross, first


class Route:
    """What the mission asks, walked as lib/Mission's executor walks it: the takeoff's
    height, then the waypoints in the order flown (DO_JUMPs taken while their count lasts),
    then whether it ends in RTL. Heights above home (relative frames only)."""

    def __init__(self, items):
        body = [it for it in items if it["seq"] > 0]
        if not body or body[0]["command"] != NAV_TAKEOFF:
            raise ValueError("the mission's first item is to be NAV_TAKEOFF (22): a hand launch")
        self.takeoff_m, self.takeoff_pitch_deg = body[0]["alt"], body[0]["p"][0]
        self.visits = []  # (seq, (north, east), height)
        self.jumps = 0
        self.rtl = False
        runs = {}
        i = 1
        while i < len(body) and len(self.visits) < 400:
            it = body[i]
            if it["command"] == NAV_WAYPOINT:
                self.visits.append((it["seq"], sim_ned(it["lat"], it["lon"]), it["alt"]))
            elif it["command"] == DO_JUMP:
                target, repeat = int(it["p"][0]), int(it["p"][1])
                if repeat < 0:
                    raise ValueError("DO_JUMP for ever (repeat -1): the flight would never end; give a count")
                if runs.get(i, 0) < repeat and 1 <= target <= len(body):
                    runs[i] = runs.get(i, 0) + 1
                    self.jumps += 1
                    i = target - 1
                    continue
            elif it["command"] == NAV_RTL:
                self.rtl = True
                break
            elif it["command"] not in (NAV_TAKEOFF, DO_CHANGE_SPEED):
                raise ValueError("item %d: command %d: this script measures NAV_WAYPOINT, DO_JUMP, DO_CHANGE_SPEED "
                                 "and RETURN_TO_LAUNCH after the takeoff (the board flies more)"
                                 % (it["seq"], it["command"]))
            i += 1
        if not self.visits:
            raise ValueError("no NAV_WAYPOINT after the takeoff")
        self.places = {}
        for seq, ne, h in self.visits:
            self.places[seq] = (ne, h)

    def length_m(self):
        pts = [(0.0, 0.0)] + [ne for _, ne, _ in self.visits] + [(0.0, 0.0)]
        return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(pts, pts[1:]))

    def legs(self):
        """The distinct legs (seq from, seq to) in the order first flown."""
        out = []
        for (s0, _, _), (s1, _, _) in zip(self.visits, self.visits[1:]):
            if (s0, s1) not in out:
                out.append((s0, s1))
        return out


# ---- the flight ---------------------------------------------------------------------------

def write_rc(path):
    rows = [(0.0, STABILIZE_SWITCH), (AUTO_S, AUTO_SWITCH)]
    with open(path, "w") as f:
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n")
        for t, mode in rows:
            f.write("%.3f,1500,1500,%d,1500,1500,1500,1500,%d\n" % (t, THROTTLE_US, mode))
    return path


def default_seconds(route):
    # The launch and climb, the route at ~17 m/s over the ground, 80 s about home.
    return round(HOLD_S + 20.0 + route.length_m() / 17.0 + 80.0)


def fly(mission, work, seconds=None, gust=1, seed=1, sim=None, elf=None, serial=None, speed=None, timeout=2300.0,
        quiet=False):
    """Flies the mission file (.waypoints or .plan); returns a Flight."""
    os.makedirs(work, exist_ok=True)
    if mission.endswith(".plan"):
        with open(mission) as f:
            text = plan_to_waypoints(json.load(f))
        mission = os.path.join(work, "mission.waypoints")
        with open(mission, "w") as f:
            f.write(text)
    route = Route(read_waypoints(mission))
    seconds = seconds or default_seconds(route)
    base = os.path.join(work, "mission")
    console = base + "_console.txt"
    with open(console, "w") as f:
        f.write("".join(line + "\n" for line in CONSOLE))
    cmd = [sys.executable, CLOSED_LOOP, "--rc", write_rc(base + "_rc.csv"), "--seconds", "%g" % seconds,
           "--gust", str(gust), "--seed", str(seed), "--stamp", "--out", base + "_serial.txt",
           "--log", base + "_log.csv", "--hold", "%g" % HOLD_S, "--launch", "%g,%g,%g" % LAUNCH,
           "--gps", "ublox", "--mission", mission, "--input", console, "--arm", "--timeout", "%g" % timeout]
    if sim:
        cmd += ["--sim", sim]
    if elf:
        cmd += ["--elf", elf]
    if serial:
        cmd += ["--serial", serial]
    if speed is not None:
        cmd += ["--speed", "%g" % speed]
    if not quiet:
        print("# mission: %s, %d waypoint passes, %d jump(s), %s; %g s simulated, %s gusts, seed %d"
              % (os.path.basename(mission), len(route.visits), route.jumps, "then RTL" if route.rtl else "no RTL",
                 seconds, ("no", "light", "moderate")[gust], seed), flush=True)
    status = subprocess.call(cmd, stderr=subprocess.DEVNULL if quiet else None)
    return Flight(route, base, status, seconds)


LOG_EVERY = 10  # the backend logs every 1 ms frame: 100 Hz is plenty here


def read_log(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return [{k: float(v) for k, v in r.items()} for i, r in enumerate(csv.DictReader(f)) if i % LOG_EVERY == 0]


def read_serial(path):
    lines = []
    if os.path.exists(path):
        with open(path, "rb") as f:
            for raw in f.read().split(b"\n")[:-1]:
                stamp, _, rest = raw.decode("ascii", "replace").rstrip("\r").partition(" ")
                try:
                    lines.append((float(stamp), rest))
                except ValueError:
                    pass
    return lines


def angle_diff(a, b):
    return (a - b + 180.0) % 360.0 - 180.0


def rms(v):
    return math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")


class Flight:
    """One mission flight read back, and its figures (measure())."""

    def __init__(self, route, base, status, seconds):
        self.route, self.status, self.seconds = route, status, seconds
        self.truth = read_log(base + "_log.csv")
        self.lines = read_serial(base + "_serial.txt")
        self.home = None
        h = self.said("# home: set at ")
        if h is not None and self.truth:
            lat, lon = (float(x) for x in h[1].split("set at ")[1].split(",")[0].split())
            at = self.truth_at(h[0] - GPS_LATENCY_S)
            self.home = sim_ned(lat, lon) + (-at["down_m"],)

    def said(self, prefix, after=0.0):
        for t, text in self.lines:
            if t >= after and text.startswith(prefix):
                return t, text
        return None

    def truth_at(self, t):
        best = self.truth[0] if self.truth else None
        for r in self.truth:
            if r["t"] > t + 1e-9:
                break
            best = r
        return best

    def height(self, r):
        return -r["down_m"] - self.home[2]

    def measure(self):
        """The figures as a dict (None where the flight gives none)."""
        m = {"status": self.status, "home": self.home, "auto": self.said("# flight AUTO"),
             "refused": self.said("# Mode change refused (switch): AUTO")}
        flown = [r for r in self.truth if r["t"] >= HOLD_S]
        if self.home is None or len(flown) < 100:
            return m
        route = self.route
        # The hand launch: from the throw until the takeoff's height (above home).
        climb_end = next((r["t"] for r in flown if self.height(r) >= route.takeoff_m), None)
        climb = [r for r in flown if climb_end is None or r["t"] <= climb_end]
        m["launch_min_m"] = min(-r["down_m"] for r in flown)
        m["launch_dip_m"] = LAUNCH[1] - min(-r["down_m"] for r in climb)
        m["climb_s"] = None if climb_end is None else climb_end - HOLD_S
        m["climb_bank_deg"] = max(abs(r["roll_deg"]) for r in climb)
        # The pitch from 0.5 s after the throw (the throw's own nose-down first).
        m["climb_pitch_deg"] = (min(r["pitch_deg"] for r in (climb[50:] or climb)), max(r["pitch_deg"] for r in climb))
        # The waypoints in the order flown: each pass is the closest point of the first
        # stretch within 100 m of the waypoint after the pass before.
        passes, i = [], 0
        for seq, (n, e), _ in route.visits:
            best = None
            while i < len(flown):
                d = math.hypot(flown[i]["north_m"] - n, flown[i]["east_m"] - e)
                if d < 100.0:
                    if best is None or d < best[0]:
                        best = (d, flown[i]["t"])
                elif best is not None:
                    break
                i += 1
            passes.append((seq, best))
        m["passes"] = passes
        # The laps: stretches within WP_RADIUS of the route's first waypoint, over the flight.
        first = route.places[route.visits[0][0]][0]
        laps, inside = 0, False
        for r in flown:
            near = math.hypot(r["north_m"] - first[0], r["east_m"] - first[1]) <= WP_RADIUS_M
            laps += near and not inside
            inside = near
        m["laps"] = laps
        # Legs: cross-track per leg, the height against the leg's slope.
        t_route = climb_end if climb_end is not None else HOLD_S
        on_route = [r for r in flown if r["t"] >= t_route and (not passes[-1][1] or r["t"] <= passes[-1][1][1] + 1.0)]
        m["legs"], heights = [], []
        for s0, s1 in route.legs():
            (a, h0), (b, h1) = route.places[s0], route.places[s1]
            xt, dh = self.leg_errors(on_route, a, b, h0, h1)
            m["legs"].append((s0, s1, rms(xt), max((abs(x) for x in xt), default=float("nan")), len(xt)))
            heights += dh
        m["height_rms_m"], m["height_mean_m"] = rms(heights), sum(heights) / max(len(heights), 1)
        # The circle at home after the route.
        t_last = passes[-1][1][1] if passes[-1][1] else HOLD_S

        def dist_home(r):
            return math.hypot(r["north_m"] - self.home[0], r["east_m"] - self.home[1])
        near = next((r["t"] for r in flown if r["t"] > t_last and dist_home(r) < 80.0), None)
        m["rtl_near_s"] = near
        if near is not None:
            circle = [r for r in flown if r["t"] >= near + CIRCLE_AFTER_S]
            if circle:
                radii = [dist_home(r) for r in circle]
                hs = [self.height(r) - RTL_ALT_M for r in circle]
                turned = sum(abs(angle_diff(b["yaw_deg"], a["yaw_deg"])) for a, b in zip(circle, circle[1:]))
                # Each whole turn's mean radius and height (a turn by the heading: ~21 s).
                turns, acc, start = [], 0.0, 0
                for k in range(1, len(circle)):
                    acc += abs(angle_diff(circle[k]["yaw_deg"], circle[k - 1]["yaw_deg"]))
                    if acc >= 360.0:
                        turns.append((sum(radii[start:k]) / (k - start), sum(hs[start:k]) / (k - start)))
                        acc, start = acc - 360.0, k
                m["circle"] = {"from_s": near + CIRCLE_AFTER_S, "s": circle[-1]["t"] - near - CIRCLE_AFTER_S,
                               "turned_deg": turned,
                               "radius": (min(radii), max(radii), sum(radii) / len(radii)),
                               "height": (min(hs), max(hs), sum(hs) / len(hs)), "turns": turns}
        return m

    def leg_errors(self, samples, a, b, h0, h1):
        """Cross-track and height errors on passes along a -> b after capture."""
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        xt, dh = [], []
        for r, along, cross, _ in captured_on_leg(samples, a, b, WP_RADIUS_M):
            xt.append(cross)
            dh.append(self.height(r) - (h0 + (h1 - h0) * along / length))
        return xt, dh

    def route_height(self, passes):
        """(t, height) of the route's height as flown: the takeoff's, then each waypoint's at
        its pass (the legs' slopes between), then RTL's."""
        out = [(HOLD_S, self.route.takeoff_m)]
        for (_, p), (_, _, h) in zip(passes, self.route.visits):
            if p is None:
                break
            out.append((p[1], h))
        if self.route.rtl and len(out) > 1:
            out += [(out[-1][0] + 10.0, RTL_ALT_M), (self.seconds, RTL_ALT_M)]
        return out


def report(m, route):
    """The figures as text lines."""
    out = []
    if "passes" not in m:
        return ["mission: no figures (no home said, or no flight after the launch)"]
    out.append("hand launch at %g m/s from %g m, %g deg: lowest %.2f m above the ground (%.2f m below the "
               "hand), %s to the takeoff's %g m; |bank| <= %.1f deg, pitch %.1f to %.1f deg in the climb"
               % (LAUNCH[0], LAUNCH[1], LAUNCH[2], m["launch_min_m"], m["launch_dip_m"],
                  "never" if m["climb_s"] is None else "%.1f s" % m["climb_s"], route.takeoff_m,
                  m["climb_bank_deg"], m["climb_pitch_deg"][0], m["climb_pitch_deg"][1]))
    per_lap = {}
    for seq, p in m["passes"]:
        per_lap.setdefault(seq, []).append("missed" if p is None else "%.1f m (%.0f s)" % p)
    for seq, text in per_lap.items():
        out.append("waypoint %d (%.0f m): closest %s" % (seq, route.places[seq][1], ", ".join(text)))
    out.append("laps (passes within WP_RADIUS of waypoint %d): %d, DO_JUMP taken %d time(s)"
               % (route.visits[0][0], m["laps"], route.jumps))
    for s0, s1, x, worst, n in m["legs"]:
        out.append("leg %d -> %d: cross-track RMS %.2f m (worst %.1f) over %.0f s after capture"
                   % (s0, s1, x, worst, n * LOG_EVERY / 1000.0))
    out.append("height RMS %.2f m (mean %+.2f) against the legs' slopes" % (m["height_rms_m"], m["height_mean_m"]))
    c = m.get("circle")
    if c:
        out.append("home circled from %.0f s for %.0f s (%.0f deg): radius %.1f-%.1f m (mean %.1f, WP_LOITER_RAD %g), "
                   "height %+.1f to %+.1f m of home + %g m (mean %+.2f); each whole turn's mean radius, height: %s"
                   % (c["from_s"], c["s"], c["turned_deg"], c["radius"][0], c["radius"][1], c["radius"][2],
                      LOITER_RAD_M, c["height"][0], c["height"][1], RTL_ALT_M, c["height"][2],
                      ", ".join("%.1f m %+.1f m" % t for t in c["turns"]) or "none"))
    else:
        out.append("home never circled")
    return out


def plot(flight, m, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    route, home = flight.route, flight.home
    flown = [r for r in flight.truth if r["t"] >= HOLD_S - 1.0]
    fig, (map_ax, h_ax) = plt.subplots(1, 2, figsize=(11, 4.6), gridspec_kw={"width_ratios": [1, 1.5]})
    map_ax.plot([r["east_m"] for r in flown], [r["north_m"] for r in flown], color="black", lw=0.8, label="flown")
    for seq, ((n, e), h) in route.places.items():
        map_ax.add_patch(plt.Circle((e, n), WP_RADIUS_M, fill=False, color="tab:blue", lw=0.8))
        map_ax.annotate("%d: %.0f m" % (seq, h), (e, n), textcoords="offset points", xytext=(6, 6), fontsize=8,
                        color="tab:blue")
    pts = [ne for _, ne, _ in route.visits]
    map_ax.plot([p[1] for p in pts], [p[0] for p in pts], "o--", color="tab:blue", lw=0.6, ms=3, label="route")
    if home:
        map_ax.add_patch(plt.Circle((home[1], home[0]), LOITER_RAD_M, fill=False, color="tab:red", ls="--", lw=0.8))
        map_ax.plot(home[1], home[0], "rH", ms=8, label="home, loiter circle")
    map_ax.set_aspect("equal", adjustable="datalim")
    map_ax.set_xlabel("east (m)")
    map_ax.set_ylabel("north (m)")
    map_ax.legend(loc="center", fontsize=7)
    map_ax.set_title("from above (WP_RADIUS circles)")
    if home:
        every = flown[::10]
        h_ax.plot([r["t"] for r in every], [flight.height(r) for r in every], color="black", lw=0.9, label="true height")
        if "passes" in m:
            steps = flight.route_height(m["passes"])
            h_ax.plot([s[0] for s in steps], [s[1] for s in steps], color="tab:blue", ls="--", lw=0.9,
                      label="the route's height")
            for seq, p in m["passes"]:
                if p:
                    h_ax.axvline(p[1], color="tab:blue", lw=0.3)
    h_ax.set_xlabel("time (s)")
    h_ax.set_ylabel("height above home (m)")
    h_ax.grid(True, alpha=0.3)
    h_ax.legend(loc="lower right", fontsize=8)
    h_ax.set_title("hand launch, %d laps, RTL (waypoints: vertical lines)" % m.get("laps", 0))
    fig.tight_layout()
    fig.savefig(path, dpi=72)
    plt.close(fig)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--mission", default=DEFAULT_MISSION, help="a .waypoints (QGC WPL 110) or .plan file")
    p.add_argument("--gust", type=int, default=1, choices=(0, 1, 2), help="turbulence (default 1, light)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--seconds", type=float, help="simulated seconds (default: the route's length at 17 m/s + 112)")
    p.add_argument("--plot", default=os.path.join(ROOT, "build", "flight", "mission.png"))
    p.add_argument("--work", help="keep the flight's files here (default: a temporary directory)")
    p.add_argument("--sim")
    p.add_argument("--elf")
    p.add_argument("--serial", metavar="tcp:PORT", help="a ground station on the board's UART0 (real time)")
    p.add_argument("--speed", type=float)
    p.add_argument("--timeout", type=float, default=2300.0)
    args = p.parse_args()
    try:
        with tempfile.TemporaryDirectory(prefix="mission_") as tmp:
            work = args.work or tmp
            f = fly(args.mission, work, args.seconds, args.gust, args.seed, args.sim, args.elf, args.serial,
                    args.speed, args.timeout)
            m = f.measure()
            for t, text in f.lines:  # what the board said about its modes, home and faults
                if text.startswith(("# flight ", "# home:", "# Mode change", "# failsafe", "# warn", "# error")):
                    print("%9.3f %s" % (t, text))
            for line in report(m, f.route):
                print("# " + line)
            if "passes" in m:
                os.makedirs(os.path.dirname(os.path.abspath(args.plot)), exist_ok=True)
                plot(f, m, args.plot)
                print("# the picture: %s" % args.plot)
    except (OSError, ValueError) as e:
        print("mission_flight: %s" % e, file=sys.stderr)
        return 2
    return 0 if f.status == 0 and "passes" in m else 1


if __name__ == "__main__":
    sys.exit(main())
