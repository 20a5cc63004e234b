# SPDX-License-Identifier: GPL-3.0-or-later
"""Plots for the benchmark: estimated vs true roll, pitch, heading over time, and the error."""
import numpy as np

import peers


def _break_wraps(t, deg, jump=180.0):
    """Insert NaN where an angle wraps so that the line is not drawn across the plot."""
    t = np.asarray(t, float)
    deg = np.asarray(deg, float)
    if len(deg) < 2:
        return t, deg
    cut = np.where(np.abs(np.diff(deg)) > jump)[0] + 1
    return np.insert(t, cut, np.nan), np.insert(deg, cut, np.nan)


def _wrap180(deg):
    return np.mod(np.asarray(deg, float) + 180.0, 360.0) - 180.0


def _heading_display(truth, ours):
    """Headings for plotting: the truth within +-180 deg of its circular mean (so a board facing
    north does not flip between 0 and 360), ours drawn beside the truth (truth + the wrapped
    difference, the same angle modulo 360)."""
    ok = np.isfinite(truth)
    centre = 0.0
    if ok.any():
        r = np.radians(truth[ok])
        centre = float(np.degrees(np.arctan2(np.mean(np.sin(r)), np.mean(np.cos(r)))))
    head_t = centre + _wrap180(truth - centre)
    head_o = np.where(ok, head_t + _wrap180(ours - truth), centre + _wrap180(ours - centre))
    return head_t, head_o, centre


def truth_at(tr, t):
    """The trajectory's nearest true quaternion and movement flag at times t (as build/score does)."""
    ts = tr["t"]
    i = np.clip(np.searchsorted(ts, t), 1, len(ts) - 1)
    prev_closer = (t - ts[i - 1]) < (ts[i] - t)
    i = np.where(prev_closer, i - 1, i)
    return tr["quat"][i], tr["movement"][i]


def plot_run(png, title, tr, est, others=None, window=None):
    """est: dict t, roll, pitch, yaw (degrees) of our estimator; others: {label: (t, q_ned)}
    drawn thin for comparison; window: (t0, t1) to zoom in. Writes a 4-panel PNG and returns
    the time of our largest total error among the scored samples (None if none)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(est["t"], float)
    q_true, moving = truth_at(tr, t)
    roll_t, pitch_t, yaw_t = peers.euler_from_quat(q_true)
    q_est = peers.quat_from_euler(est["roll"], est["pitch"], est["yaw"])
    finite = np.all(np.isfinite(q_true), axis=1)
    tot = np.full(len(t), np.nan)
    inc = np.full(len(t), np.nan)
    hdg = np.full(len(t), np.nan)
    if finite.any():
        tot[finite], inc[finite], hdg[finite] = peers.error_angles(q_true[finite], q_est[finite])

    fig, ax = plt.subplots(4, 1, figsize=(11, 9), sharex=True)
    fig.suptitle(title)
    head_t, head_o, centre = _heading_display(yaw_t, np.asarray(est["yaw"], float))
    panels = [("roll (deg)", roll_t, np.asarray(est["roll"], float), 0),
              ("pitch (deg)", pitch_t, np.asarray(est["pitch"], float), 1),
              ("heading (deg)", head_t, head_o, 2)]
    for label, truth, ours, k in panels:
        wrap = k == 2
        tt, tv = _break_wraps(t, truth) if wrap else (t, truth)
        ax[k].plot(tt, tv, color="black", lw=1.2, label="truth")
        te, ev = _break_wraps(t, ours) if wrap else (t, ours)
        ax[k].plot(te, ev, color="tab:red", lw=0.9, label="ours (replay)")
        for name, (to, qo) in (others or {}).items():
            r, p, y = peers.euler_from_quat(qo)
            v = [r, p, centre + _wrap180(y - centre)][k]
            tp, vp = _break_wraps(to, v) if wrap else (to, v)
            ax[k].plot(tp, vp, lw=0.6, alpha=0.7, label=name)
        ax[k].set_ylabel(label)
        ax[k].grid(True, alpha=0.3)
    ax[0].legend(loc="upper right", fontsize=8)
    ax[3].plot(t, tot, color="tab:red", lw=0.9, label="total")
    ax[3].plot(t, inc, color="tab:blue", lw=0.7, label="inclination")
    ax[3].plot(t, hdg, color="tab:green", lw=0.7, label="heading")
    if not moving.all():
        ymax = np.nanmax(tot) if np.isfinite(tot).any() else 1.0
        ax[3].fill_between(t, 0, ymax, where=~moving, color="grey", alpha=0.15, lw=0,
                           label="not scored (movement = 0)")
    ax[3].set_ylabel("error (deg)")
    ax[3].set_xlabel("time (s)")
    ax[3].grid(True, alpha=0.3)
    ax[3].legend(loc="upper right", fontsize=8)
    if window:
        ax[3].set_xlim(*window)
        for k, series in enumerate((roll_t, pitch_t)):
            inside = (t >= window[0]) & (t <= window[1])
            vals = np.concatenate([series[inside], np.asarray(est[["roll", "pitch"][k]], float)[inside]])
            vals = vals[np.isfinite(vals)]
            if len(vals):
                ax[k].set_ylim(vals.min() - 5, vals.max() + 5)
        inside = (t >= window[0]) & (t <= window[1]) & np.isfinite(tot)
        if inside.any():
            ax[3].set_ylim(0, np.nanmax(tot[inside]) * 1.1 + 0.1)
    fig.tight_layout()
    fig.savefig(png, dpi=90)
    plt.close(fig)
    scored = moving & np.isfinite(tot)
    return float(t[scored][np.argmax(tot[scored])]) if scored.any() else None
