#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The GPS-aided attitude on flights of fresh seeds: ours with the GPS against
ours without it and against VQF, per flight.

    build/venv/bin/python bench/gps_flights.py --seeds 52001-52005
        [--flights turn:1,turn:2,figure8:1,...,cruise:1,gusty] [--out DIR] [--jobs N]

Each flight (NAME or NAME:GUST, `fly.py --list`) is flown on each seed by sim/flight/fly.py
(cached as bench/flights.py caches them). Ours runs through build/replay in the three
airspeed modes make bench uses (none, the cruise speed, the airspeed sensor), each without
and with the GPS (`replay --gps-log`: the simulator's u-blox model on the flight's logged
path, its noise seeded by the flight's seed), scored by build/score (total RMSE, deg); VQF
on the same IMU samples from the firmware's first sample (flights.vqf_from_loop_start).
Printed per flight, then per kind the means and how many flights with the GPS are ahead of
VQF and of the same mode without the GPS; and the 60 s 30-deg turns' worst roll error
without an airspeed sensor. This is replay on the flights' IMU (open loop: the flight's
own pilot flew it), not the firmware flying them.
"""
import argparse
import os
import sys
from concurrent.futures import ProcessPoolExecutor

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

import bench  # noqa: E402
import flights  # noqa: E402
from fresh_flights import flight_list, seed_list, vqf_totals  # noqa: E402

DEFAULT_FLIGHTS = "turn:1,turn:2,figure8:1,figure8:2,climb:1,climb:2,upset:1,upset:2,cruise:1,gusty"


def seed_of(stem):
    return int(stem.rsplit("_s", 1)[1].split("+")[0])


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seeds", required=True, type=seed_list)
    p.add_argument("--flights", default=DEFAULT_FLIGHTS, type=flight_list)
    p.add_argument("--out", default=os.path.join(REPO, "build", "gps_flights"))
    p.add_argument("--build", default=os.path.join(REPO, "build"))
    p.add_argument("--jobs", type=int, default=2)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    log = lambda m: print("[gps] " + m, file=sys.stderr, flush=True)
    files = flights.make_turbulent_flights(a.out, log, a.flights, a.seeds)
    if not files:
        log("no flights")
        return 1
    replay, score = os.path.join(a.build, "replay"), os.path.join(a.build, "score")
    tasks, runs = [], []
    for stem, (kind, traj, state) in sorted(files.items()):
        for suffix, _, extra in flights.airspeed_variants(state):
            for gps in (False, True):
                more = tuple(extra) + (("--gps-log", state, "--gps-seed", str(seed_of(stem))) if gps else ())
                est = os.path.join(a.out, "%s_estimate%s%s.csv" % (stem, suffix, "_gps" if gps else ""))
                tasks.append((stem, suffix, gps))
                runs.append(("%s %s" % (stem, suffix), traj, est, replay, score, (), more))
    with ProcessPoolExecutor(a.jobs) as pool:
        cache, key = vqf_totals(files, a.out, pool)
        results = {}
        for t, r in zip(tasks, pool.map(bench.task_replay, runs)):
            if r[3]:
                log("%s: %s" % (t[0], r[3]))
                return 1
            results[t] = r[2]["total"]
    modes = [s for s, _, _ in flights.airspeed_variants("")]
    names = {"": "none", "_cruise": "cruise", "_sensor": "sensor"}
    print("%-26s %s %7s" % ("flight (total RMSE, deg)", " ".join("%15s" % ("%s -> +gps" % names[m]) for m in modes),
                            "VQF"))
    kinds, worse = {}, []
    for stem, (kind, traj, _) in sorted(files.items()):
        vqf = cache[key(traj)]
        cells = ["%6.3f -> %6.3f" % (results[(stem, m, False)], results[(stem, m, True)]) for m in modes]
        print("%-26s %s %7.3f" % (stem, " ".join(cells), vqf))
        kinds.setdefault(kind, []).append((stem, vqf))
        for m in modes:
            g = results[(stem, m, True)]
            if not (g < vqf and g < results[(stem, m, False)]):
                worse.append("%s %s: %.3f with the GPS, %.3f without, VQF %.3f" % (
                    stem, names[m], g, results[(stem, m, False)], vqf))
    print()
    for kind, rows in sorted(kinds.items()):
        n = len(rows)
        parts = []
        for m in modes:
            mean0 = sum(results[(s, m, False)] for s, _ in rows) / n
            mean1 = sum(results[(s, m, True)] for s, _ in rows) / n
            ahead_vqf = sum(results[(s, m, True)] < v for s, v in rows)
            ahead_self = sum(results[(s, m, True)] < results[(s, m, False)] for s, _ in rows)
            parts.append("%s %.3f -> %.3f (ahead of VQF %d, of no-GPS %d)" % (names[m], mean0, mean1, ahead_vqf,
                                                                               ahead_self))
        print("%s (%d): %s; VQF %.3f" % (kind, n, "; ".join(parts), sum(v for _, v in rows) / n))
    total = len(files) * len(modes)
    print("\nwith the GPS, ahead of both VQF and the same mode without it: %d of %d runs (%d flights x %d modes)" % (
        total - len(worse), total, len(files), len(modes)))
    for w in worse:
        print("  not ahead: " + w)
    # The 60 s, 30-deg turns without an airspeed sensor: the worst roll error.
    print()
    for stem, (kind, traj, _) in sorted(files.items()):
        if not kind.startswith("turn"):
            continue
        for suffix in ("", "_cruise"):
            for gps in (False, True):
                est = os.path.join(a.out, "%s_estimate%s%s.csv" % (stem, suffix, "_gps" if gps else ""))
                w = flights.worst_roll_error_replay(traj, est)
                print("%s %s%s: worst roll error %+.2f deg at %.1f s" % (
                    stem, names[suffix], " +gps" if gps else "", w[0], w[1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
