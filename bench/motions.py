#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""`make bench`'s motions on fresh seeds (issue 24, "data that cannot be overfitted").

    python3 bench/motions.py [--build DIR] [--jobs N] [--no-peers]   (alone; make bench runs it too)

The scenario tool's seeded motions (`build/scenario --list`: descriptions beginning with
`seeded:`; sim/Motions.h) are written for each seed of SEEDS, with a real board's sensor
errors (bench/tune.py SENSOR_ERRORS: +uncal the uncalibrated board, +imu the same with a
calibrated compass). Ours runs through build/replay, the peers
through bench/peers.py on the same files, all scored by build/score's metric
(bench.score_files, as the rest of the bench). Tables per file and per kind.

SEEDS is the one place the seeds are listed: bench/tune.py never scores the seeded
motions (bench.list_scenarios leaves them out of the scenarios it tunes and reports on),
so no setting was chosen on these files.

    motion_section(build, out_dir, peer_names, jobs, log) -> (markdown lines, errors)
"""
import argparse
import os
import subprocess
import sys
import time

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

import bench  # noqa: E402
import tune  # noqa: E402

SEEDS = (4057, 18233, 90511)
KINDS = [("translation", ("translate_slow", "translate_fast")), ("carrying", ("walk", "pendulum", "car")),
         ("tapping", ("tapping", "knocking")), ("rotation", ("slow_rotation",))]
# A real board's sensor errors: +uncal (hard iron and all) and +imu (a calibrated
# compass: what the motion itself does to the heading). Ideal sensors ("", []) would
# add a third of the section's time (the peers in Python are its cost).
VARIANTS = list(tune.SENSOR_ERRORS)


def kind_of(name):
    for kind, names in KINDS:
        if name in names:
            return kind
    return "other"


def label_of(name, seed, suffix):
    return "%s_s%d%s" % (name, seed, suffix)


def write_files(build, out_dir, names, log):
    """[(label, path, kind)] of every motion, seed and variant; errors."""
    scen = bench.tool(build, "scenario")
    d = os.path.join(out_dir, "motions")
    os.makedirs(d, exist_ok=True)
    files, errors = [], []
    for suffix, options in VARIANTS:
        for name in names:
            for seed in SEEDS:
                label = label_of(name, seed, suffix)
                path = os.path.join(d, label + ".csv")
                with open(path, "w") as f:
                    r = subprocess.run([scen, name, "--seed", str(seed)] + options, stdout=f, stderr=subprocess.PIPE,
                                       text=True)
                if r.returncode != 0:
                    errors.append("scenario %s --seed %d %s failed: %s" % (name, seed, " ".join(options),
                                                                           r.stderr.strip()))
                    continue
                files.append((label, path, kind_of(name)))
    return files, errors


def cell(s):
    return "%s / %s / %s" % (bench.fmt(s["total"]), bench.fmt(s["incl"]), bench.fmt(s["heading"])) if s else "–"


def mean_cell(res, labels):
    if not labels or any(l not in res for l in labels):
        return "–"
    return "%s / %s / %s" % tuple(bench.fmt(bench.mean_of(res, labels, k)) for k in ("total", "incl", "heading"))


def motion_section(build, out_dir, peer_names, jobs, log):
    t0 = time.time()
    rep = ["## Motions on fresh seeds (issue 24)", ""]
    replay, score = bench.tool(build, "replay"), bench.tool(build, "score")
    names = bench.list_scenarios(build, seeded=True) if bench.tool(build, "scenario") else []
    if not names or not replay or not score:
        log("motions: skipped (scenario, replay or score missing, or no seeded motions)")
        return rep + ["Skipped: build/scenario with seeded motions, build/replay and build/score are needed.", ""], []
    files, errors = write_files(build, out_dir, names, log)
    log("motions: %d files (%s; seeds %s; variants %s)" % (len(files), ", ".join(names),
                                                            ", ".join(map(str, SEEDS)),
                                                            ", ".join(s or "ideal" for s, _ in VARIANTS)))
    est_dir = os.path.join(out_dir, "estimates")
    cache_dir = os.path.join(out_dir, "cache")
    for d in (est_dir, cache_dir):
        os.makedirs(d, exist_ok=True)
    results, _, score_errors = bench.score_files(files, est_dir, cache_dir, replay, score, peer_names, jobs)
    errors += score_errors
    filters = [bench.OURS] + list(peer_names)
    wall_s = time.time() - t0
    rep += ["`build/scenario NAME --seed N` for the seeded motions %s and the seeds %s (bench/motions.py SEEDS: "
            "never seen by bench/tune.py). *+uncal*: `--preset uncalibrated`; *+imu*: the same with a calibrated "
            "compass. Total / inclination / heading RMSE in degrees (build/score's "
            "metric), ours through `build/replay`, the peers through bench/peers.py on the same files. "
            "Wall time of this section: %.0f s." % (", ".join(names), ", ".join(map(str, SEEDS)), wall_s), ""]
    short = [bench.OURS.split(":")[0]] + list(peer_names)
    for suffix, _ in VARIANTS:
        vname = suffix or "ideal"
        rows = []
        for kind, knames in KINDS:
            labels = [label_of(n, s, suffix) for n in knames if n in names for s in SEEDS]
            rows.append([kind, str(len(labels))] + [mean_cell(results[f], labels) for f in filters])
        labels = [label_of(n, s, suffix) for n in names for s in SEEDS]
        rows.append(["all", str(len(labels))] + [mean_cell(results[f], labels) for f in filters])
        rep += ["### Per kind, %s (mean of total / inclination / heading RMSE °)" % vname, "",
                bench.md_table(["kind", "files"] + short, rows), ""]
    for suffix, _ in VARIANTS:
        vname = suffix or "ideal"
        rows = []
        for n in names:
            for s in SEEDS:
                label = label_of(n, s, suffix)
                rows.append([label, kind_of(n)] + [cell(results[f].get(label)) for f in filters])
        rep += ["### Per file, %s (total / inclination / heading RMSE °)" % vname, "",
                bench.md_table(["file", "kind"] + short, rows), ""]
    log("motions: %d files scored in %.0f s" % (len(files), time.time() - t0))
    return rep, errors


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("BENCH_BUILD") or os.environ.get("BUILD") or "build")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--no-peers", action="store_true", help="only our estimator")
    ap.add_argument("--no-venv", action="store_true", help="use the current interpreter as it is")
    args = ap.parse_args()
    build = os.path.abspath(os.path.join(REPO, args.build))
    if not args.no_venv:
        bench.ensure_venv(build)
    import peers
    out_dir = os.path.join(build, "bench")
    rep, errors = motion_section(build, out_dir, [] if args.no_peers else list(peers.PEERS), args.jobs, bench.log)
    text = "\n".join(rep + (["## Errors", ""] + ["- " + e for e in errors] if errors else []))
    with open(os.path.join(out_dir, "motions.md"), "w") as f:
        f.write(text + "\n")
    print(text)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
