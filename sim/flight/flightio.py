# SPDX-License-Identifier: GPL-3.0-or-later
"""Files of a flight: the scripted pilot (the simulator's --rc format), the trajectory
(../shared/SIM.md) and the true-state log."""
import gzip
import io
import math

RC_HEADER = ["t"] + ["ch%d" % i for i in range(1, 9)]
TRAJECTORY_HEADER = "t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz"
LOG_HEADER = ("t,north_m,east_m,down_m,vn_m_s,ve_m_s,vd_m_s,roll_deg,pitch_deg,yaw_deg,airspeed_m_s,"
              "alpha_deg,beta_deg,p_deg_s,q_deg_s,r_deg_s,aileron,elevator,throttle,rudder,prop_rpm,"
              "wind_n_m_s,wind_e_m_s,wind_d_m_s")


class RcScript:
    """Sticks over time: CSV `t,ch1,...,ch8` (s, us); a row holds from its time until the next;
    a row with empty channels is no signal (a dead receiver); before the first row, no signal."""

    def __init__(self, rows):
        self.rows = rows  # [(t, tuple of 8 widths or None)], in time order
        self.index = 0

    @classmethod
    def load(cls, path):
        with open(path) as f:
            lines = [line.strip() for line in f if line.strip()]
        if not lines or [c.strip() for c in lines[0].split(",")] != RC_HEADER:
            raise ValueError("%s: the first line must be %s" % (path, ",".join(RC_HEADER)))
        rows = []
        for number, line in enumerate(lines[1:], start=2):
            cells = [c.strip() for c in line.split(",")]
            if len(cells) != 9:
                raise ValueError("%s:%d: %d fields, expected 9" % (path, number, len(cells)))
            try:
                t = float(cells[0])
                if all(c == "" for c in cells[1:]):
                    widths = None
                else:
                    widths = tuple(float(c) for c in cells[1:])
            except ValueError:
                raise ValueError("%s:%d: not a number (a row is all widths or all empty)" % (path, number))
            if not math.isfinite(t) or (rows and t < rows[-1][0]):
                raise ValueError("%s:%d: time %s out of order" % (path, number, cells[0]))
            if widths is not None and not all(500 <= w <= 2500 for w in widths):
                raise ValueError("%s:%d: a width outside 500-2500 us" % (path, number))
            rows.append((t, widths))
        return cls(rows)

    @classmethod
    def constant(cls, widths):
        return cls([(0.0, tuple(widths))])

    def at(self, t_s):
        """The widths in force at t_s (None: no signal). Times only grow within one flight."""
        if self.index and self.rows[self.index - 1][0] > t_s:
            self.index = 0
        while self.index < len(self.rows) and self.rows[self.index][0] <= t_s + 1e-9:
            self.index += 1
        return None if self.index == 0 else self.rows[self.index - 1][1]

    def save(self, path):
        with open(path, "w") as f:
            f.write(",".join(RC_HEADER) + "\n")
            for t, widths in self.rows:
                cells = [""] * 8 if widths is None else ["%d" % round(w) for w in widths]
                f.write("%.3f,%s\n" % (t, ",".join(cells)))


def open_text(path):
    """A text file for writing; .gz names are gzip-compressed with no time stamp, so that the
    same flight gives the same bytes."""
    if path.endswith(".gz"):
        return _GzipText(path)
    return open(path, "w")


class _GzipText(io.TextIOWrapper):
    def __init__(self, path):
        self._raw = open(path, "wb")
        super().__init__(gzip.GzipFile(filename="", mode="wb", fileobj=self._raw, mtime=0), encoding="ascii")

    def close(self):
        super().close()  # closes the GzipFile, which leaves the file it was given open
        self._raw.close()


class TrajectoryWriter:
    def __init__(self, path):
        self.path = path
        self.file = open_text(path)
        self.file.write(TRAJECTORY_HEADER + "\n")

    def write(self, s):
        g, a, m, q = s["gyro"], s["accel"], s["mag"], s["quat"]
        self.file.write("%.6f,%.7f,%.7f,%.7f,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f,%.9f,%.9f,%.9f,%.9f\n" % (
            s["t"], g[0], g[1], g[2], a[0], a[1], a[2], m[0], m[1], m[2], q[0], q[1], q[2], q[3]))

    def close(self):
        self.file.close()


class StateLog:
    def __init__(self, path):
        self.file = open_text(path)
        self.file.write(LOG_HEADER + "\n")

    def write(self, s):
        d = math.degrees
        roll, pitch, yaw = s["euler"]
        values = ([s["t"]] + list(s["position"]) + list(s["velocity"]) +
                  [d(roll), d(pitch), d(yaw) % 360.0, s["airspeed"], d(s["alpha"]), d(s["beta"])] +
                  [d(w) for w in s["gyro"]] + list(s["surfaces"]) + [s["rpm"]] + list(s["wind"]))
        self.file.write(",".join("%.6f" % v for v in values) + "\n")

    def close(self):
        self.file.close()
