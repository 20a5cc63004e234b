#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A flight as a picture: the path seen from above, and the true bank against an estimate.

    build/venv/bin/python sim/flight/plot_flight.py --log build/flights/turn_log.csv \
        [--estimate turn_est.csv] [--title TEXT] --out turn.png

--log is the backend's true-state log; --estimate a CSV with columns t,roll (degrees), as
build/replay prints.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def columns(path, names):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    missing = [n for n in names if rows and n not in rows[0]]
    if not rows or missing:
        raise ValueError("%s: no rows or no column %s" % (path, ", ".join(missing)))
    return [[float(r[n]) for r in rows] for n in names]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--log", required=True)
    p.add_argument("--estimate")
    p.add_argument("--title", default="")
    p.add_argument("--out", required=True)
    p.add_argument("--until", type=float, help="draw up to this time (s), e.g. the ground")
    args = p.parse_args()
    try:
        t, north, east, down, roll = columns(args.log, ("t", "north_m", "east_m", "down_m", "roll_deg"))
        estimate = columns(args.estimate, ("t", "roll")) if args.estimate else None
        if args.until is not None:
            n = sum(1 for v in t if v <= args.until)
            t, north, east, down, roll = (c[:n] for c in (t, north, east, down, roll))
            if estimate:
                m = sum(1 for v in estimate[0] if v <= args.until)
                estimate = [c[:m] for c in estimate]
    except (OSError, ValueError) as e:
        print("plot_flight: %s" % e, file=sys.stderr)
        return 1
    fig, (path_ax, roll_ax) = plt.subplots(1, 2, figsize=(11, 4.2), gridspec_kw={"width_ratios": [1, 1.6]})
    points = path_ax.scatter(east, north, c=[-d for d in down], s=1, cmap="viridis")
    path_ax.plot(east[0], north[0], "k^", markersize=8)  # heading north at the start
    path_ax.set_aspect("equal", adjustable="datalim")
    path_ax.set_xlabel("east (m)")
    path_ax.set_ylabel("north (m)")
    path_ax.set_title("path from above (start: triangle)")
    fig.colorbar(points, ax=path_ax, label="height (m)")
    roll_ax.plot(t, roll, label="true bank", color="black")
    if estimate:
        roll_ax.plot(estimate[0], estimate[1], label="estimate", color="tab:red")
    roll_ax.set_xlabel("time (s)")
    roll_ax.set_ylabel("bank (deg)")
    roll_ax.grid(True, alpha=0.3)
    roll_ax.legend(loc="best")
    roll_ax.set_title(args.title or "bank")
    fig.tight_layout()
    fig.savefig(args.out, dpi=80)
    return 0


if __name__ == "__main__":
    sys.exit(main())
