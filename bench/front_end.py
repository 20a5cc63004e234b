#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Whose error is it, the front end's or the estimator's? (issue 24)

    build/venv/bin/python bench/front_end.py [--build DIR] [FILE.csv[.gz] ...]

make bench runs the peers on a recording as it is, ours through the sensor models (the
MPU6000's range, resolution, 42 Hz low-pass and 200 Hz rate, the HMC5883L's 75 Hz reads).
Here VQF also runs on the estimator's own input, `replay --samples`: the same samples ours
steps on. The chip's low-pass delays the gyro and accelerometer by 4.8 ms (Register Map
4.3, DLPF_CFG 3), of which ours makes up for 3 ms (output_lead_s: the end-point
integration takes back 2.5) and VQF nothing, so VQF on those samples is also scored as
ours is read, against the truth 3 ms earlier. Per file, total /
inclination / heading RMSE in degrees (the BROAD metric): ours (build/replay + build/score),
VQF on the recording, VQF on our samples, and the same scored 3 ms late. With no file
named, the BROAD recordings in ../shared/data/broad (skipped when absent).
"""
import argparse
import glob
import os
import subprocess
import sys
import tempfile

BENCH_DIR = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(BENCH_DIR)
sys.path.insert(0, BENCH_DIR)

import numpy as np  # noqa: E402

import peers  # noqa: E402

LEAD_S = 0.003  # ours: DcmSettings output_lead_s (the low-pass's 4.8 ms less the end-point integration's 2.5)


def ours(build, path, estimate):
    with open(estimate, "w") as out:
        subprocess.run([os.path.join(build, "replay"), "--trajectory", path, "--samples", estimate + ".samples"],
                       stdout=out, check=True)
    text = subprocess.run([os.path.join(build, "score"), "--trajectory", path, "--estimate", estimate],
                          capture_output=True, text=True, check=True).stdout
    kv = dict(x.split("=") for x in text.split())
    return kv["total_rmse_deg"], kv["incl_rmse_deg"], kv["heading_rmse_deg"]


def truth_earlier(tr, t, delay_s):
    """The recording's truth at t - delay_s (quaternions interpolated linearly and
    normalised: 3.5 ms apart, nearly the same rotation) and its movement flags."""
    want = t - delay_s
    i = np.clip(np.searchsorted(tr["t"], want), 1, len(tr["t"]) - 1)
    q0, q1 = tr["quat"][i - 1], tr["quat"][i].copy()
    q1[np.sum(q0 * q1, axis=1) < 0] *= -1.0  # the same hemisphere
    w = np.clip((want - tr["t"][i - 1]) / (tr["t"][i] - tr["t"][i - 1]), 0.0, 1.0)[:, None]
    q = (1.0 - w) * q0 + w * q1
    q /= np.linalg.norm(q, axis=1)[:, None]
    return q, tr["movement"][i - 1] & tr["movement"][i]


def cells(s):
    return "%.2f / %.2f / %.2f" % (s["total"], s["incl"], s["heading"])


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("files", nargs="*")
    args = ap.parse_args()
    files = args.files or sorted(glob.glob(os.path.join(os.path.dirname(REPO), "shared", "data", "broad", "*.csv.gz")))
    if not files:
        print("front_end: no recordings (../shared/data/broad absent): nothing to compare")
        return 0
    print("| file | ours | VQF, the recording | VQF, our samples | VQF, our samples, scored %g ms late |" %
          (LEAD_S * 1e3))
    print("|---|---|---|---|---|")
    sums = {}
    with tempfile.TemporaryDirectory() as tmp:
        for path in files:
            estimate = os.path.join(tmp, "estimate.csv")
            o = ours(args.build, path, estimate)
            tr = peers.load_trajectory(path)
            smp = peers.load_trajectory(estimate + ".samples")
            field = smp["mag"]
            first = int(np.argmax(np.isfinite(field).all(axis=1)))
            field[:first] = field[first]  # VQF takes no NaN: the first read stands for the steps before it
            raw = peers.score(tr["quat"], peers.run_vqf(tr), tr["movement"])
            q = peers.run_vqf(smp)
            through = peers.score(smp["quat"], q, smp["movement"])
            late_q, late_moving = truth_earlier(tr, smp["t"], LEAD_S)
            late = peers.score(late_q, q, late_moving)
            row = [dict(total=float(o[0]), incl=float(o[1]), heading=float(o[2])), raw, through, late]
            for k, s in enumerate(row):
                sums.setdefault(k, []).append(s)
            print("| %s | %s |" % (os.path.basename(path).split(".")[0], " | ".join(cells(s) for s in row)), flush=True)
    mean = [{m: sum(s[m] for s in sums[k]) / len(sums[k]) for m in ("total", "incl", "heading")} for k in range(4)]
    print("| mean of %d | %s |" % (len(files), " | ".join(cells(s) for s in mean)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
