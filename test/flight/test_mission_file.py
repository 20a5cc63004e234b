#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The mission files of sim/flight/mission_flight.py (`make fly FLIGHT=mission`), without a
flight: a QGroundControl .plan becomes the QGC WPL 110 text apm25sim --mission loads (the
thesis' .plan gives the thesis' .waypoints; DO_JUMP's doJumpId becomes the target's seq;
what cannot be flown is refused with its reason), the route is walked as the executor walks
it (DO_JUMP's count), and the hand launch starts where it says (the backend's --launch: held
at its height and pitch, then flying at its speed).

    build/venv/bin/python test/flight/test_mission_file.py
"""
import copy
import json
import math
import os
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "test", "support"))
sys.path.insert(0, os.path.join(ROOT, "sim", "flight"))
from soft_assert import finish, soft_assert  # noqa: E402

import mission_flight as mf  # noqa: E402

MISSIONS = os.path.join(ROOT, "sim", "flight", "missions")


def items_of_text(text):
    with tempfile.NamedTemporaryFile("w", suffix=".waypoints", delete=False) as f:
        f.write(text)
    try:
        return mf.read_waypoints(f.name)
    finally:
        os.unlink(f.name)


def refused(plan, words):
    try:
        mf.plan_to_waypoints(plan)
    except ValueError as e:
        soft_assert(words in str(e), "refused, but not for %r: %s" % (words, e))
        return
    soft_assert(False, "not refused: a plan that should be (%s)" % words)


def check_plan():
    with open(os.path.join(MISSIONS, "thesis.plan")) as f:
        plan = json.load(f)
    got = items_of_text(mf.plan_to_waypoints(plan))
    want = mf.read_waypoints(os.path.join(MISSIONS, "thesis.waypoints"))
    soft_assert(len(got) == len(want), "thesis.plan: %d items, thesis.waypoints %d" % (len(got), len(want)))
    for a, b in zip(got, want):
        same = (a["seq"], a["frame"], a["command"]) == (b["seq"], b["frame"], b["command"]) and all(
            abs(x - y) < 1e-6 for x, y in zip(a["p"] + [a["lat"], a["lon"], a["alt"]],
                                             b["p"] + [b["lat"], b["lon"], b["alt"]]))
        soft_assert(same, "thesis.plan's item %d differs from thesis.waypoints': %r vs %r" % (a["seq"], a, b))
    # doJumpIds need not be the seqs: the DO_JUMP's target is the item that has the id.
    shifted = copy.deepcopy(plan)
    for it in shifted["mission"]["items"]:
        it["doJumpId"] += 10
        if it["command"] == mf.DO_JUMP:
            it["params"][0] += 10
    jump = [it for it in items_of_text(mf.plan_to_waypoints(shifted)) if it["command"] == mf.DO_JUMP]
    soft_assert(len(jump) == 1 and jump[0]["p"][0] == 2.0 and jump[0]["p"][1] == 1.0,
                "DO_JUMP to doJumpId 12 (seq 2) once: %r" % jump)
    bad = copy.deepcopy(plan)
    bad["mission"]["items"][3] = {"type": "ComplexItem", "complexItemType": "survey"}
    refused(bad, "survey")
    bad = copy.deepcopy(plan)
    bad["mission"]["items"][6]["params"][0] = 42
    refused(bad, "doJumpId 42")
    refused({"fileType": "Plan"}, "no mission.items")


def check_route():
    route = mf.Route(mf.read_waypoints(os.path.join(MISSIONS, "thesis.waypoints")))
    seqs = [seq for seq, _, _ in route.visits]
    soft_assert(seqs == [2, 3, 4, 5, 6] * 2 and route.jumps == 1 and route.rtl,
                "thesis: the route walked %r, %d jumps, RTL %s (want 2-6 twice, 1 jump, RTL)"
                % (seqs, route.jumps, route.rtl))
    soft_assert(route.takeoff_m == 40.0 and route.takeoff_pitch_deg == 15.0,
                "thesis: NAV_TAKEOFF to %g m at %g deg" % (route.takeoff_m, route.takeoff_pitch_deg))
    heights = sorted(set(h for _, _, h in route.visits))
    soft_assert(heights == [60.0, 90.0], "thesis: heights %r (60 and 90 m)" % heights)
    items = mf.read_waypoints(os.path.join(MISSIONS, "thesis.waypoints"))
    speed = dict(items[3], command=mf.DO_CHANGE_SPEED, p=[0.0, 20.0, -1.0, 0.0])
    with_speed = mf.Route(items[:3] + [speed] + items[3:])
    soft_assert(len(with_speed.visits) == 10, "DO_CHANGE_SPEED changed the route: %d passes" % len(with_speed.visits))
    try:
        mf.Route(items[:3] + [dict(items[3], command=18)] + items[4:])
        soft_assert(False, "a LOITER_TURNS in the route not refused (the figures would not know it)")
    except ValueError as e:
        soft_assert("command 18" in str(e), "LOITER_TURNS refused for another reason: %s" % e)
    north, east = route.places[2][0]
    soft_assert(abs(north - 320.0) < 0.05 and abs(east) < 0.05, "waypoint 2 at %.2f N %.2f E (320, 0)" % (north, east))


def check_launch():
    import flightmodel
    speed, height, pitch = mf.LAUNCH
    m = flightmodel.FlightModel(hold_s=1.0, launch=mf.LAUNCH)
    s = m.state()
    soft_assert(abs(-s["position"][2] - height) < 0.01 and abs(math.degrees(s["euler"][1]) - pitch) < 0.01
                and s["airspeed"] == 0.0, "on the stand: %.2f m, pitch %.2f deg, %.1f m/s"
                % (-s["position"][2], math.degrees(s["euler"][1]), s["airspeed"]))
    m.step(1.0)
    m.step(0.01)
    s = m.state()
    alpha = math.degrees(m.launch_alpha())
    soft_assert(abs(s["airspeed"] - speed) < 0.3 and abs(-s["position"][2] - height) < 0.1 and 6.0 < alpha < 10.0,
                "thrown: %.2f m/s at %.2f m, alpha %.1f deg (want %g m/s from %g m, lift for the weight)"
                % (s["airspeed"], -s["position"][2], alpha, speed, height))
    print("mission_file: the launch: %.2f m/s at %.2f m, alpha %.2f deg" % (s["airspeed"], -s["position"][2], alpha))


def main():
    check_plan()
    check_route()
    check_launch()
    return finish("mission files", "mission files: all checks passed")


if __name__ == "__main__":
    sys.exit(main())
