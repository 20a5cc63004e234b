#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The firmware flying fly.py's flights in closed loop (sim/flight/closed_loop.py: the ELF in
apm25sim, the JSBSim backend) with apm25sim's u-blox and with `--gps none`, both without a
pitot; the board's printed attitude scored against the backend's truth (build/score, total
RMSE from the first line), and VQF on the backend's trajectory (its ideal IMU, from the
firmware's loop start, flights.vqf_from_loop_start) for reference.

    build/venv/bin/python bench/closed_loop_gps.py --seeds 45101 [--flights turn:1,...]
        [--tools build] [--out DIR] [--jobs 2]
"""
import argparse
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

from fresh_flights import flight_list, seed_list, vqf_late  # noqa: E402
from gps_flights import DEFAULT_FLIGHTS  # noqa: E402

CLOSED_LOOP = os.path.join(REPO, "sim", "flight", "closed_loop.py")


def estimate_from_serial(serial, est):
    """The board's `roll:.. pitch:.. yaw:..` lines (apm25sim --stamp) as t,roll,pitch,yaw."""
    with open(serial) as f, open(est, "w") as out:
        out.write("t,roll,pitch,yaw\n")
        for line in f:
            t, _, text = line.strip().partition(" ")
            if not text.startswith("roll:"):
                continue
            v = dict(p.split(":", 1) for p in text.split())
            out.write("%s,%s,%s,%s\n" % (t, v["roll"], v["pitch"], v["yaw"]))


def fly(job):
    name, gust, seed, gps, tools, out = job
    stem = "%s_gust%d_s%d_%s" % (name, gust, seed, gps)
    base = os.path.join(out, stem)
    cmd = [sys.executable, CLOSED_LOOP, "--flight", name, "--gust", str(gust), "--seed", str(seed), "--no-airspeed",
           "--gps", gps, "--stamp", "--out", base + "_serial.txt", "--trajectory", base + ".csv.gz",
           "--log", base + "_log.csv", "--sim", os.path.join(tools, "apm25sim"),
           "--elf", os.path.join(tools, "firmware.elf"), "--timeout", "2300"]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        return stem, None, "closed_loop.py exit %d: %s" % (r.returncode, r.stderr.strip()[-200:])
    estimate_from_serial(base + "_serial.txt", base + "_estimate.csv")
    s = subprocess.run([os.path.join(tools, "score"), "--trajectory", base + ".csv.gz", "--estimate",
                        base + "_estimate.csv"], capture_output=True, text=True).stdout
    total = float(s.split("total_rmse_deg=")[1].split()[0]) if "total_rmse_deg=" in s else float("nan")
    return stem, (total, vqf_late(base + ".csv.gz")), None


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--seeds", required=True, type=seed_list)
    p.add_argument("--flights", default=DEFAULT_FLIGHTS, type=flight_list)
    p.add_argument("--tools", default=os.path.join(REPO, "build"))
    p.add_argument("--out", default=os.path.join(REPO, "build", "closed_loop_gps"))
    p.add_argument("--jobs", type=int, default=2)
    a = p.parse_args()
    os.makedirs(a.out, exist_ok=True)
    jobs = [(name, gust if gust is not None else 2, seed, gps, a.tools, a.out)
            for name, gust in a.flights for seed in a.seeds for gps in ("ublox", "none")]
    with ThreadPoolExecutor(a.jobs) as pool:
        results = {stem: (r, err) for stem, r, err in pool.map(fly, jobs)}
    print("%-28s %9s %9s %7s" % ("flight (total RMSE, deg)", "GPS", "no GPS", "VQF"))
    ahead = 0
    for name, gust, seed, gps, _, _ in jobs:
        if gps != "ublox":
            continue
        key = "%s_gust%d_s%d_" % (name, gust, seed)
        (g, ge), (n, ne) = results[key + "ublox"], results[key + "none"]
        if ge or ne:
            print("%-28s %s" % (key, ge or ne))
            continue
        print("%-28s %9.3f %9.3f %7.3f" % (key, g[0], n[0], g[1]))
        ahead += g[0] < n[0] and g[0] < g[1]
    print("with the GPS ahead of both VQF and no GPS: %d of %d" % (ahead, len(jobs) // 2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
