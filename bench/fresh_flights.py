#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Flights on seeds of your choosing, ours against VQF (issue 24: decide on fresh seeds).

    build/venv/bin/python bench/fresh_flights.py --seeds 7700-7719 [--flights gusty,turn:1,figure8:1]
        [--imu] [--out DIR] [--build DIR [--build DIR2]] [--set NAME=VALUE ...] [--jobs N]

Each flight of --flights (NAME or NAME:GUST, `fly.py --list`) is flown on each seed by
sim/flight/fly.py (cached in --out, default build/fresh_flights, while newer than
sim/flight's sources, as make bench's flights are), and with --imu also as an
uncalibrated board's IMU measures it (bench/flights.py IMU_ERRORS). Ours runs through each
--build's replay (default build/; a second --build is a variant: before -> after; one
--build with --set: without -> with the settings) in the
three airspeed modes make bench uses (none, the cruise speed, the airspeed sensor), scored
by build/score; VQF from the firmware's first sample (flights.vqf_from_loop_start), the
peer the flights are compared with. Printed: per file, then per kind the means and how
many files each mode is ahead of VQF on. Seeds used here are spent: say so in the README
when a choice is made on them.
"""
import argparse
import json
import os
import sys
from concurrent.futures import ProcessPoolExecutor

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

import bench  # noqa: E402
import flights  # noqa: E402


def seed_list(text):
    """'7700-7703,7710' -> [7700, 7701, 7702, 7703, 7710]."""
    seeds = []
    for part in text.split(","):
        lo, _, hi = part.partition("-")
        seeds += list(range(int(lo), int(hi or lo) + 1))
    return seeds


def flight_list(text):
    """'gusty,turn:1' -> [('gusty', None), ('turn', 1)]."""
    out = []
    for part in text.split(","):
        name, _, gust = part.partition(":")
        out.append((name, int(gust) if gust else None))
    return out


def vqf_late(traj):
    import peers
    return flights.vqf_from_loop_start(peers.load_trajectory(traj))["total"]


def vqf_totals(files, out_dir, pool):
    """VQF's total RMSE on each flight of files ({stem: (kind, trajectory, log)}), cached in
    out_dir while the trajectory is unchanged: (cache, its key function)."""
    cache_path = os.path.join(out_dir, "vqf_from_loop_start.json")
    cache = json.load(open(cache_path)) if os.path.exists(cache_path) else {}
    key = lambda traj: "%s@%d" % (os.path.basename(traj), os.path.getmtime(traj))
    need = [traj for _, traj, _ in files.values() if key(traj) not in cache]
    for traj, total in zip(need, pool.map(vqf_late, need)):
        cache[key(traj)] = total
    json.dump(cache, open(cache_path, "w"))
    return cache, key


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seeds", required=True, type=seed_list)
    p.add_argument("--flights", default="gusty,turn:1,figure8:1", type=flight_list)
    p.add_argument("--imu", action="store_true", help="also with the uncalibrated board's IMU errors")
    p.add_argument("--out", default=os.path.join(REPO, "build", "fresh_flights"))
    p.add_argument("--build", action="append", help="a build directory with replay and score (twice: before, after)")
    p.add_argument("--set", action="append", default=[], help="replay --set NAME=VALUE for the last --build")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    a = p.parse_args()
    builds = a.build or [os.path.join(REPO, "build")]
    if len(builds) > 2:
        p.error("at most two --build (before, after)")
    if len(builds) == 1 and a.set:
        builds = builds * 2  # the build as it is -> with the settings
    os.makedirs(a.out, exist_ok=True)
    log = lambda m: print("[fresh] " + m, file=sys.stderr, flush=True)

    files = flights.make_turbulent_flights(a.out, log, a.flights, a.seeds)
    if a.imu:
        # The scenario tool of the project's own build (a variant's may hold only replay and score).
        files.update(flights.make_imu_flights(os.path.join(REPO, "build"), dict(files), a.out, log))
    if not files:
        log("no flights")
        return 1

    tasks, runs = [], []
    for stem, (kind, traj, state) in sorted(files.items()):
        for b, build in enumerate(builds):
            sets = a.set if b == len(builds) - 1 else []
            for suffix, _, extra in flights.airspeed_variants(state):
                est = os.path.join(a.out, "%s_estimate%s_%d.csv" % (stem, suffix, b))
                tasks.append((stem, b, suffix))
                runs.append(("%s %s" % (stem, suffix), traj, est, os.path.join(build, "replay"),
                             os.path.join(build, "score"), sets, extra))
    with ProcessPoolExecutor(a.jobs) as pool:
        cache, key = vqf_totals(files, a.out, pool)
        results = {}
        for (stem, b, suffix), r in zip(tasks, pool.map(bench.task_replay, runs)):
            if r[3]:
                log("%s: %s" % (stem, r[3]))
                return 1
            results[(stem, b, suffix)] = r[2]["total"]

    modes = [s for s, _, _ in flights.airspeed_variants("")]
    names = {"": "none", "_cruise": "cruise", "_sensor": "sensor"}
    head = " ".join("%15s" % names[m] for m in modes)
    print("%-28s %s %8s" % ("file (total RMSE, deg)", head, "VQF"))
    kinds = {}
    for stem, (kind, traj, _) in sorted(files.items()):
        vqf = cache[key(traj)]
        cells = []
        for m in modes:
            vals = [results[(stem, b, m)] for b in range(len(builds))]
            cells.append("%15s" % " -> ".join("%.3f" % v for v in vals))
        print("%-28s %s %8.3f" % (stem, " ".join(cells), vqf))
        kinds.setdefault(kind + ("+imu" if stem.endswith("+imu") else ""), []).append((stem, vqf))
    print()
    for kind, rows in kinds.items():
        n = len(rows)
        means, ahead = [], []
        for m in modes:
            means.append(" -> ".join("%.3f" % (sum(results[(s, b, m)] for s, _ in rows) / n)
                                     for b in range(len(builds))))
            ahead.append(" -> ".join(str(sum(results[(s, b, m)] < v for s, v in rows)) for b in range(len(builds))))
        print("%s (%d): means %s, VQF %.3f; ahead of VQF %s" % (
            kind, n, " / ".join(means), sum(v for _, v in rows) / n, " / ".join(ahead)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
