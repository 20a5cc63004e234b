#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Cross-validation of the estimator's settings: tune on one half of the recordings, score on the other.

    python3 bench/tune.py [--build DIR] [--data DIR] [--jobs N] [--set NAME=VALUE ...]
                          [--grid NAME=V1,V2,... ...] [--cv] [--no-scenarios]

The 15 BROAD recordings are split into two folds that each hold every kind: sorted by trial
number, alternate ones go to fold A and fold B (A: 01 05 09 14 21 26 30 34, B: 03 07 11 16 24
28 32). Without --grid it scores the settings given (default: the firmware's) on every
recording and on the scenarios with a realistic uncalibrated board (`scenario NAME --preset
uncalibrated`), beside VQF on the same files, per recording, per kind and per fold.

With --grid it cross-validates: every combination of the grid's values is scored on fold A,
the best (lowest mean total) is then scored on fold B, and the other way round; the figure
that counts is the mean over the two held-out folds. The scenarios are not part of the
choice (they are the check that the gains hold on a different world).

--cv is --grid with the project's grid (bench.CV_GRID, the one `make bench` reports).
`make tune` runs `tune.py --cv` (the Makefile variable TUNE_ARGS replaces --cv).
"""
import argparse
import itertools
import os
import subprocess
import sys
from multiprocessing import Pool

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

import bench  # noqa: E402  (helpers: venv, cache keys, score parsing)

# Kinds of motion and disturbance, from the trial's name (BROAD's groups, README of the data).
KINDS = [("rotation", ("rotation",)), ("translation", ("translation", "combined")),
         ("tapping/vibration", ("tapping", "vibration")), ("magnet beside", ("stationary_magnet",)),
         ("magnet attached", ("attached_magnet",))]


def kind_of(trial):
    for kind, keys in KINDS:
        if any(k in trial for k in keys):
            return kind
    return "other"


def folds_of(trials):
    """Alternate trials (sorted by number) into folds A and B: each holds every kind."""
    ordered = sorted(trials)
    return {"A": ordered[0::2], "B": ordered[1::2]}


def run_ours(args):
    """bench.task_replay with replay --set: (label, settings, score or None, error)."""
    label, traj, sets, build, est_dir = args
    tag = bench.slug(" ".join(sets))[:60] or "defaults"
    est = os.path.join(est_dir, "%s-%s.csv" % (label, tag))
    _, _, score, err, _ = bench.task_replay((label, traj, est, os.path.join(build, "replay"),
                                             os.path.join(build, "score"), sets))
    if os.path.exists(est):
        os.remove(est)
    return label, tuple(sets), score, err


def run_vqf(args):
    """VQF's score on one file, from bench's peer cache or computed into it (bench.task_peers)."""
    label, traj, cache_dir = args
    key = bench.peer_cache_key(bench.file_hash(traj))
    cached = bench.load_cached_peer(cache_dir, key, "VQF")
    if cached is None:
        cached = bench.task_peers((label, traj, ["VQF"], cache_dir, key))[2]["VQF"]
    return label, cached


# Sensor errors of a real board (scenario's options): "+uncal" the whole uncalibrated board
# (gyro bias and drift, accel offset and scale, hard and soft iron, noise, quantisation);
# "+imu" the same inertial errors with a calibrated compass (after `cal mag`).
SENSOR_ERRORS = [("+uncal", ["--preset", "uncalibrated"]),
                 ("+imu", ["--preset", "uncalibrated", "--hard-iron", "0,0,0", "--soft-iron", "1,1,1"])]


def scenario_files(build, out_dir):
    """The project's scenarios with the sensor errors of SENSOR_ERRORS."""
    scen = os.path.join(build, "scenario")
    paths = {}
    d = os.path.join(out_dir, "scenarios")
    os.makedirs(d, exist_ok=True)
    for suffix, options in SENSOR_ERRORS:
        for name in bench.list_scenarios(build):
            p = os.path.join(d, name + suffix + ".csv")
            if not os.path.exists(p):
                with open(p, "w") as f:
                    r = subprocess.run([scen, name] + options, stdout=f, stderr=subprocess.PIPE, text=True)
                if r.returncode != 0:
                    bench.log("scenario %s failed: %s" % (name, r.stderr.strip()))
                    os.remove(p)
                    continue
            paths[name + suffix] = p
    return paths


def mean(vals):
    vals = [v for v in vals if v is not None]
    return sum(vals) / len(vals) if vals else float("nan")


def score_sets(pool, files, sets, build, est_dir):
    tasks = [(label, path, list(sets), build, est_dir) for label, path in files.items()]
    out = {}
    for label, _, s, err in pool.imap_unordered(run_ours, tasks):
        if err:
            bench.log("%s: %s" % (label, err))
        out[label] = s
    return out


def table(trials, scen, ours, vqf, folds):
    rows = []
    for t in trials:
        o, v = ours.get(t), vqf.get(t)
        fold = "A" if t in folds["A"] else "B"
        rows.append([t, kind_of(t), fold, "%.2f / %.2f / %.2f" % (o["total"], o["incl"], o["heading"]) if o else "–",
                     "%.2f" % v["total"] if v else "–", "%+.2f" % (o["total"] - v["total"]) if o and v else "–"])
    out = [bench.md_table(["recording", "kind", "fold", "ours total / incl / heading °", "VQF total °",
                           "ours − VQF"], rows), ""]
    rows = []
    for kind, _ in KINDS:
        ts = [t for t in trials if kind_of(t) == kind]
        if not ts:
            continue
        o = mean([ours[t]["total"] for t in ts if ours.get(t)])
        v = mean([vqf[t]["total"] for t in ts if vqf.get(t)])
        rows.append([kind, len(ts), "%.2f" % o, "%.2f" % v, "%+.2f" % (o - v)])
    for name, ts in sorted(folds.items()):
        o = mean([ours[t]["total"] for t in ts if ours.get(t)])
        v = mean([vqf[t]["total"] for t in ts if vqf.get(t)])
        rows.append(["fold " + name, len(ts), "%.2f" % o, "%.2f" % v, "%+.2f" % (o - v)])
    o = mean([ours[t]["total"] for t in trials if ours.get(t)])
    v = mean([vqf[t]["total"] for t in trials if vqf.get(t)])
    rows.append(["all", len(trials), "%.2f" % o, "%.2f" % v, "%+.2f" % (o - v)])
    out += [bench.md_table(["group", "n", "ours total °", "VQF total °", "ours − VQF"], rows), ""]
    if scen:
        rows = []
        for n in scen:
            o, v = ours.get(n), vqf.get(n)
            ok = o and v and (o["total"] <= 1.1 * v["total"] or o["total"] <= v["total"] + 0.15)
            rows.append([n, "%.2f / %.2f / %.2f" % (o["total"], o["incl"], o["heading"]) if o else "–",
                         "%.2f" % v["total"] if v else "–", "%.2f" % (o["total"] / v["total"]) if o and v else "–",
                         "yes" if ok else "NO"])
        out += [bench.md_table(["scenario (uncalibrated board)", "ours total / incl / heading °", "VQF total °",
                                "ours / VQF", "≤ 1.1× or +0.15°"], rows), ""]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("BUILD") or "build")
    ap.add_argument("--data", default=os.path.join(os.path.dirname(REPO), "shared", "data", "broad"))
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--grid", action="append", default=[], metavar="NAME=V1,V2,...")
    ap.add_argument("--cv", action="store_true", help="cross-validate the project's grid (bench.CV_GRID)")
    ap.add_argument("--no-scenarios", action="store_true")
    ap.add_argument("--no-venv", action="store_true")
    args = ap.parse_args()
    build = os.path.abspath(os.path.join(REPO, args.build))
    if args.cv and not args.grid:
        args.grid = list(bench.CV_GRID)
    if not args.no_venv:
        bench.ensure_venv(build)
    out_dir = os.path.join(build, "tune")
    est_dir = os.path.join(out_dir, "estimates")
    cache_dir = os.path.join(build, "bench", "cache")
    for d in (out_dir, est_dir, cache_dir):
        os.makedirs(d, exist_ok=True)

    recordings = {}
    if os.path.isdir(args.data):
        for f in sorted(os.listdir(args.data)):
            if f.endswith(".csv.gz") or f.endswith(".csv"):
                recordings[bench.trial_name(f)] = os.path.join(args.data, f)
    if not recordings:
        bench.log("no recordings in %s: nothing to cross-validate (it needs ../shared/data/broad)" % args.data)
        return 0
    scen = {} if args.no_scenarios else scenario_files(build, out_dir)
    trials = sorted(recordings)
    folds = folds_of(trials)
    files = dict(recordings)
    files.update(scen)

    with Pool(args.jobs) as pool:
        vqf = dict(pool.imap_unordered(run_vqf, [(l, p, cache_dir) for l, p in files.items()]))
        if not args.grid:
            ours = score_sets(pool, files, args.set, build, est_dir)
            print("\nSettings: %s\n" % (" ".join(args.set) or "the firmware's"))
            print(table(trials, list(scen), ours, vqf, folds))
            return 0

    cv = cross_validate(build, recordings, args.grid, args.jobs, args.set)
    print("\nCross-validated (each fold scored with the settings tuned on the other):\n")
    print(table(trials, [], cv["per_trial"], vqf, folds))
    rows = [[c] + ["%.3f" % v for v in cv["combos"][c]] for c in cv["combos"]]
    print(bench.md_table(["combination", "fold A mean total °", "fold B mean total °"], rows))
    return 0


def cross_validate(build, recordings, grid, jobs, base_sets=()):
    """Every combination of grid (["NAME=V1,V2", ...]) on every recording; per fold, the
    combination best on the other fold. Returns dict(grid, chosen={fold: settings},
    held_out={fold: mean total}, per_trial={trial: score}, combos={settings: (mean A, mean B)})."""
    est_dir = os.path.join(build, "tune", "estimates")
    os.makedirs(est_dir, exist_ok=True)
    trials = sorted(recordings)
    folds = folds_of(trials)
    names, values = [], []
    for g in grid:
        n, v = g.split("=", 1)
        names.append(n)
        values.append(v.split(","))
    combos = [tuple(base_sets) + tuple("%s=%s" % (n, x) for n, x in zip(names, c)) for c in itertools.product(*values)]
    bench.log("cross-validation: %d combinations x %d recordings" % (len(combos), len(trials)))
    tasks = [(l, recordings[l], list(c), build, est_dir) for c in combos for l in trials]
    by_combo = {}
    with Pool(jobs) as pool:
        for label, sets, s, err in pool.imap_unordered(run_ours, tasks):
            if err:
                bench.log("%s: %s" % (label, err))
            by_combo.setdefault(sets, {})[label] = s
    fold_mean = lambda c, f: mean([by_combo[c][t]["total"] for t in folds[f] if by_combo[c].get(t)])
    out = dict(grid=" ".join(grid), chosen={}, held_out={}, per_trial={},
               combos={" ".join(c[len(base_sets):]): (fold_mean(c, "A"), fold_mean(c, "B")) for c in combos})
    for train, test in (("A", "B"), ("B", "A")):
        best = min(combos, key=lambda c: fold_mean(c, train))
        out["chosen"][test] = " ".join(best[len(base_sets):])
        out["held_out"][test] = fold_mean(best, test)
        for t in folds[test]:
            out["per_trial"][t] = by_combo[best][t]
        bench.log("tuned on %s: %s (%.3f there) -> %.3f on held-out %s" % (
            train, out["chosen"][test], fold_mean(best, train), out["held_out"][test], test))
    return out


if __name__ == "__main__":
    sys.exit(main())
