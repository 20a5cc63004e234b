# SPDX-License-Identifier: GPL-3.0-or-later
"""The peer filters from PyPI, run on a trajectory exactly as recorded, and the
dataset's error metric in numpy.

Frames. The trajectory (../shared/SIM.md) is in the board's body frame, x forward,
y right, z down (FRD), with accel as specific force in m/s^2 (level: az = -9.81), gyro
rad/s, mag uT, and the true quaternion rotates body -> earth north-east-down (NED).
Every peer below works in a z-up sensor frame (FLU: x forward, y left, z up, which is
the BROAD recordings' own sensor frame, turned back 180 deg about x) and returns a
body -> earth quaternion against its own z-up earth frame:
  vqf (VQF, BasicVQF)   earth ENU (x east, y north, z up), acc m/s^2, gyro rad/s
  ahrs Madgwick         earth NWU (magnetic reference on x), inputs normalised
  ahrs Mahony           earth ENU (magnetic reference on y), inputs normalised
  imufusion (NWU)       earth NWU, gyro deg/s, acc in g
so q_NED<-FRD = Q_NED<-EARTH (x) q (x) Q_FLU<-FRD, where Q_FLU<-FRD is 180 deg about x,
Q_NED<-NWU is 180 deg about x, and Q_NED<-ENU swaps x and y and flips z (180 deg
about (1,1,0)/sqrt 2).
"""
import gzip
import math

import numpy as np

R2 = math.sqrt(0.5)
Q_X180 = np.array([0.0, 1.0, 0.0, 0.0])        # FLU<-FRD, NED<-NWU
Q_NED_FROM_ENU = np.array([0.0, R2, R2, 0.0])  # NED<-ENU


def quat_mul(a, b):
    """Hamilton product, scalar first; a and b (N,4) or (4,)."""
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def quat_conj(q):
    q = np.array(q, float)
    q[..., 1:] *= -1.0
    return q


def to_ned(q, earth):
    """Body(FLU) -> earth(`earth`) quaternions to body(FRD) -> earth(NED)."""
    left = {"NWU": Q_X180, "ENU": Q_NED_FROM_ENU}[earth]
    return quat_mul(quat_mul(left, q), Q_X180)


def euler_from_quat(q):
    """Aerospace Z-Y-X Euler angles (degrees) of body->earth quaternions: roll, pitch, yaw."""
    w, x, y, z = np.moveaxis(np.asarray(q, float), -1, 0)
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.degrees(roll), np.degrees(pitch), np.degrees(yaw)


def quat_from_euler(roll_deg, pitch_deg, yaw_deg):
    """Body->earth quaternion of Z-Y-X Euler angles (degrees), q = qz(yaw) qy(pitch) qx(roll)."""
    hr, hp, hy = (np.radians(np.asarray(a, float)) / 2 for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = np.cos(hr), np.sin(hr), np.cos(hp), np.sin(hp), np.cos(hy), np.sin(hy)
    return np.stack([cy * cp * cr + sy * sp * sr,
                     cy * cp * sr - sy * sp * cr,
                     cy * sp * cr + sy * cp * sr,
                     sy * cp * cr - cy * sp * sr], axis=-1)


def error_angles(q_true, q_est):
    """The dataset's per-sample errors in degrees: total, inclination, heading.

    e = q_est (x) q_true^-1, the error in the earth frame; total = its angle, heading =
    2 atan(|z|/|w|), inclination = 2 acos(sqrt(w^2 + z^2)) (same as sim/ScoreMetric.h)."""
    qt = np.asarray(q_true, float)
    qe = np.asarray(q_est, float)
    qt = qt / np.linalg.norm(qt, axis=-1, keepdims=True)
    qe = qe / np.linalg.norm(qe, axis=-1, keepdims=True)
    e = quat_mul(qe, quat_conj(qt))
    e = e / np.linalg.norm(e, axis=-1, keepdims=True)
    w, z = np.abs(e[..., 0]), np.abs(e[..., 3])
    total = 2 * np.arccos(np.clip(w, 0.0, 1.0))
    heading = 2 * np.arctan2(z, w)
    incl = 2 * np.arccos(np.clip(np.sqrt(e[..., 0] ** 2 + e[..., 3] ** 2), 0.0, 1.0))
    return np.degrees(total), np.degrees(incl), np.degrees(heading)


def score(q_true, q_est, mask):
    """RMSE (degrees) over the samples in mask with finite truth: dict total/incl/heading/samples/max."""
    ok = mask & np.all(np.isfinite(q_true), axis=1) & np.all(np.isfinite(q_est), axis=1)
    tot, inc, hdg = error_angles(q_true[ok], q_est[ok])
    rms = lambda v: float(np.sqrt(np.mean(v ** 2))) if len(v) else float("nan")
    return dict(total=rms(tot), incl=rms(inc), heading=rms(hdg), samples=int(ok.sum()),
                max_total=float(tot.max()) if len(tot) else float("nan"))


def load_trajectory(path):
    """Columns of a trajectory file as a dict of numpy arrays (t, gyr, acc, mag, quat, movement)."""
    opener = gzip.open if str(path).endswith(".gz") else open
    with opener(path, "rt") as f:
        header = f.readline().strip().split(",")
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    col = {name: i for i, name in enumerate(header)}
    out = dict(t=data[:, col["t"]],
               gyr=data[:, [col["gx"], col["gy"], col["gz"]]],
               acc=data[:, [col["ax"], col["ay"], col["az"]]],
               mag=data[:, [col["mx"], col["my"], col["mz"]]],
               quat=data[:, [col["qw"], col["qx"], col["qy"], col["qz"]]])
    out["movement"] = (data[:, col["movement"]] != 0) if "movement" in col else np.ones(len(data), bool)
    return out


def sample_period(t):
    return float(np.median(np.diff(t)))


def _flu(v):
    """FRD body vectors to FLU (180 deg about x)."""
    return np.ascontiguousarray(v * np.array([1.0, -1.0, -1.0]))


# ---------------------------------------------------------------------------
# The peers. Each takes the trajectory dict and returns (N,4) body->earth NED quaternions.

def run_vqf(tr):
    import vqf
    ts = sample_period(tr["t"])
    out = vqf.VQF(ts).updateBatch(_flu(tr["gyr"]), _flu(tr["acc"]), _flu(tr["mag"]))
    return to_ned(out["quat9D"], "ENU")


def run_basic_vqf(tr):
    import vqf
    ts = sample_period(tr["t"])
    out = vqf.BasicVQF(ts).updateBatch(_flu(tr["gyr"]), _flu(tr["acc"]), _flu(tr["mag"]))
    return to_ned(out["quat9D"], "ENU")


def run_madgwick(tr, beta=0.12):
    from ahrs.filters import Madgwick
    f = Madgwick(gyr=_flu(tr["gyr"]), acc=_flu(tr["acc"]), mag=_flu(tr["mag"]),
                 frequency=1.0 / sample_period(tr["t"]), beta=beta)
    return to_ned(f.Q, "NWU")


def run_mahony(tr, k_p=0.74, k_i=0.0012):
    from ahrs.filters import Mahony
    f = Mahony(gyr=_flu(tr["gyr"]), acc=_flu(tr["acc"]), mag=_flu(tr["mag"]),
               frequency=1.0 / sample_period(tr["t"]), k_P=k_p, k_I=k_i)
    return to_ned(f.Q, "ENU")


def run_fusion(tr):
    """x-io Fusion with its gyro bias stage, the settings of its README's advanced example:
    NWU, gain 0.5, gyroscope range 2000 deg/s, acceleration and magnetic rejection 10 deg,
    rejection timeout 5 s; bias stage defaults."""
    import imufusion
    rate = 1.0 / sample_period(tr["t"])
    ahrs = imufusion.Ahrs()
    ahrs.set_settings(imufusion.AhrsSettings(sample_rate=rate, convention=imufusion.CONVENTION_NWU,
                                             gain=0.5, gyroscope_range=2000.0,
                                             acceleration_rejection=10.0, magnetic_rejection=10.0,
                                             rejection_timeout=5.0))
    bias = imufusion.Bias()
    bias.set_settings(imufusion.BiasSettings(sample_rate=rate))
    gyr = np.degrees(_flu(tr["gyr"]))
    acc = _flu(tr["acc"]) / 9.80665
    mag = _flu(tr["mag"])
    t = tr["t"]
    q = np.empty((len(t), 4))
    for i in range(len(t)):
        dt = t[i] - t[i - 1] if i else 1.0 / rate
        ahrs.set_sample_period(float(dt))
        g = bias.update(gyr[i])
        ahrs.update(g, acc[i], mag[i])
        q[i] = ahrs.get_quaternion()
    return to_ned(q, "NWU")


PEERS = {
    "VQF": run_vqf,
    "BasicVQF": run_basic_vqf,
    "Madgwick b=0.12": run_madgwick,
    "Mahony Kp=0.74 Ki=0.0012": run_mahony,
    "Fusion (README)": run_fusion,
}

# The peers' figures on the 15 BROAD trials (../shared/data/broad/README.md and issue 5):
# mean of per-trial RMSE, total / inclination / heading, degrees.
PUBLISHED = {
    "VQF": (2.37, 0.75, 2.20),
    "BasicVQF": (3.96, 1.12, 3.73),
    "Madgwick b=0.12": (5.13, 2.98, 3.96),
    "Mahony Kp=0.74 Ki=0.0012": (8.76, 3.74, 7.72),
    "Fusion (README)": (11.17, 4.18, 9.29),
}
