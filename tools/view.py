#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Live attitude view: an artificial horizon with a heading tape, and roll, pitch and
heading over the last 20 s.

    view.py --port /dev/ttyACM0 [--baud 115200]           a real board (pyserial)
    view.py --sim build/apm25sim --elf build/firmware.elf --trajectory FILE.csv [--seconds S]
                                                          the board in simavr (its stdout)
    view.py --file STREAM                                 a recorded stream
    ... [--frames DIR]                                    headless: PNG frames, no window

It reads what the firmware sends in any output mode and tells them apart line by line:
plot lines `roll:.. pitch:.. yaw:..`, csv rows `t_ms,roll,pitch,yaw`, quat lines
`qw:.. qx:.. qy:.. qz:..` (turned into Euler angles), MAVLink 2 or 1 frames (ATTITUDE, by
pymavlink's parser; STATUSTEXT is printed), and `# ` lines (printed). Raw-sensor lines carry
no attitude and are skipped. Lines without a time stamp are placed at 1/--rate s apart.

With --frames DIR (matplotlib's Agg backend, no display needed) every --frame-every-th
sample and the last one are drawn to DIR/frame_NNNNN.png, and DIR/layout.json gives the
horizon's pixel geometry (for tests: where the horizon must be for given angles).

Run by `make view` with the project's virtualenv (build/venv: matplotlib, pyserial,
pymavlink, numpy).
"""
import argparse
import json
import math
import os
import queue
import subprocess
import sys
import threading
import time

SKY = "#3a7bd5"
GROUND = "#8b5a2b"
FOV_HALF_DEG = 30.0  # the horizon shows pitch -30..+30 degrees top to bottom
WINDOW_S = 20.0


# ---------------------------------------------------------------------------------------
# Decoding


def quat_to_euler_deg(w, x, y, z):
    """Body -> earth quaternion to aerospace Z-Y-X roll, pitch, heading 0..360 (degrees)."""
    roll = math.degrees(math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)))
    s = max(-1.0, min(1.0, 2.0 * (w * y - z * x)))
    pitch = math.degrees(math.asin(s))
    yaw = math.degrees(math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)))
    return roll, pitch, yaw % 360.0


def label_values(line):
    """`a:1 b:2` -> {"a": 1.0, "b": 2.0}; None if any field is not label:number."""
    out = {}
    for field in line.split():
        label, sep, value = field.partition(":")
        if not sep:
            return None
        try:
            out[label] = float(value)
        except ValueError:
            return None
    return out


class StreamDecoder:
    """Bytes in, samples (t_s, roll_deg, pitch_deg, heading_deg) out; messages to `say`."""

    def __init__(self, rate_hz=50.0, say=None):
        self.dt = 1.0 / rate_hz
        self.say = say or (lambda s: None)
        self.text = bytearray()
        self.frame = bytearray()
        self.frame_len = 0
        self.count = 0  # samples without a time stamp so far
        self.samples = []
        self.mav = None
        self.frames = 0
        self.bad_frames = 0

    def _mavlink(self):
        if self.mav is None:
            from pymavlink.dialects.v20 import common as mavlink2
            self.mav = mavlink2.MAVLink(None)
            self.mav.robust_parsing = True
        return self.mav

    def _emit(self, t, roll, pitch, heading):
        self.samples.append((t, roll, pitch, heading % 360.0))

    def _untimed(self):
        t = self.count * self.dt
        self.count += 1
        return t

    def _line(self, raw):
        line = raw.decode("ascii", "replace").strip()
        if not line:
            return
        if line.startswith("#"):
            self.say(line)
            return
        lv = label_values(line)
        if lv is not None:
            if {"roll", "pitch", "yaw"} <= lv.keys():
                self._emit(self._untimed(), lv["roll"], lv["pitch"], lv["yaw"])
            elif {"qw", "qx", "qy", "qz"} <= lv.keys():
                self._emit(self._untimed(), *quat_to_euler_deg(lv["qw"], lv["qx"], lv["qy"], lv["qz"]))
            return  # raw sensor lines and anything else in label:value form: no attitude
        parts = line.split(",")
        if len(parts) == 4:
            try:
                t_ms, roll, pitch, yaw = (float(p) for p in parts)
            except ValueError:
                return  # the csv header
            self._emit(t_ms / 1000.0, roll, pitch, yaw)

    def _frame_done(self):
        self.frames += 1
        for msg in self._mavlink().parse_buffer(bytes(self.frame)) or []:
            kind = msg.get_type()
            if kind == "BAD_DATA":
                self.bad_frames += 1
            elif kind == "ATTITUDE":
                self._emit(msg.time_boot_ms / 1000.0, math.degrees(msg.roll), math.degrees(msg.pitch),
                           math.degrees(msg.yaw))
            elif kind == "STATUSTEXT":
                self.say("# [mavlink %d] %s" % (msg.severity, msg.text))

    def feed(self, data):
        """Decodes `data`; returns the samples it completed."""
        self.samples = []
        for b in data:
            if self.frame:
                self.frame.append(b)
                if len(self.frame) == 2:
                    self.frame_len = (12 if self.frame[0] == 0xFD else 8) + b
                elif len(self.frame) == 3 and self.frame[0] == 0xFD and b & 0x01:
                    self.frame_len += 13  # signed
                if len(self.frame) == self.frame_len:
                    self._frame_done()
                    self.frame = bytearray()
            elif b in (0xFD, 0xFE):  # never in console text (printable ASCII)
                self.frame.append(b)
            elif b == 0x0A:
                self._line(bytes(self.text))
                self.text = bytearray()
            else:
                self.text.append(b)
                if len(self.text) > 4096:  # not a text stream: drop, do not grow
                    self.text = bytearray()
        return self.samples


# ---------------------------------------------------------------------------------------
# Sources: each yields chunks of bytes, then ends (None = nothing new yet, live sources)


def file_source(path):
    with open(path, "rb") as f:
        while True:
            chunk = f.read(4096)
            if not chunk:
                return
            yield chunk


def threaded(read):
    """Runs read() -> bytes (b"" at the end) in a thread; yields chunks, None when idle."""
    q = queue.Queue()

    def pump():
        while True:
            chunk = read()
            q.put(chunk)
            if not chunk:
                return

    threading.Thread(target=pump, daemon=True).start()
    while True:
        try:
            chunk = q.get(timeout=0.02)
        except queue.Empty:
            yield None
            continue
        if not chunk:
            return
        yield chunk


def sim_source(args):
    cmd = [args.sim, "--elf", args.elf, "--trajectory", args.trajectory]
    if args.seconds:
        cmd += ["--seconds", str(args.seconds)]
    if args.input:
        cmd += ["--input", args.input]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE)
    try:
        yield from threaded(lambda: os.read(proc.stdout.fileno(), 4096))
    finally:
        proc.kill()
        proc.wait()


def serial_source(port, baud):
    import serial  # pyserial
    ser = serial.Serial(port, baud, timeout=0.05)
    while True:
        chunk = ser.read(4096)  # b"" after the timeout: idle, not the end
        yield chunk if chunk else None


# ---------------------------------------------------------------------------------------
# Drawing


class View:
    def __init__(self, plt, size_px=(1280, 720), dpi=100):
        from matplotlib.patches import Polygon, Rectangle
        from matplotlib.transforms import Affine2D
        self.plt = plt
        self.Affine2D = Affine2D
        self.fig = plt.figure(figsize=(size_px[0] / dpi, size_px[1] / dpi), dpi=dpi, facecolor="#1e1e1e")
        fig = self.fig
        # Left: horizon (square, equal scale in degrees) and the heading tape below it.
        self.ax_h = fig.add_axes([0.03, 0.20, 0.42, 0.75])
        self.ax_t = fig.add_axes([0.03, 0.06, 0.42, 0.10])
        ax = self.ax_h
        ax.set_xlim(-FOV_HALF_DEG, FOV_HALF_DEG)
        ax.set_ylim(-FOV_HALF_DEG, FOV_HALF_DEG)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xticks([])
        ax.set_yticks([])
        # The world: sky and ground half-planes and a pitch ladder, moved as one.
        big = 400.0
        self.world = [ax.add_patch(Rectangle((-big, 0.0), 2 * big, big, color=SKY, lw=0)),
                      ax.add_patch(Rectangle((-big, -big), 2 * big, big, color=GROUND, lw=0))]
        self.world.append(ax.plot([-big, big], [0, 0], color="white", lw=1.5)[0])
        for p in range(-90, 91, 5):
            if p == 0:
                continue
            half = 6.0 if p % 10 == 0 else 3.0
            self.world.append(ax.plot([-half, half], [p, p], color="white", lw=1.0)[0])
            if p % 10 == 0:
                for x in (-half - 2.5, half + 2.5):
                    self.world.append(ax.text(x, p, "%d" % abs(p), color="white", fontsize=8,
                                              ha="center", va="center", clip_on=True))
        # The aircraft, fixed: wings and a centre dot.
        ax.plot([-14, -5, -3], [0, 0, -2], color="#ffd21f", lw=3, solid_capstyle="round", zorder=5)
        ax.plot([14, 5, 3], [0, 0, -2], color="#ffd21f", lw=3, solid_capstyle="round", zorder=5)
        ax.plot([0], [0], "o", color="#ffd21f", ms=5, zorder=5)
        # Roll scale: ticks on an arc at the top, and the world's roll pointer on it.
        r = 26.0
        for a in (-60, -45, -30, -20, -10, 0, 10, 20, 30, 45, 60):
            ang = math.radians(90 + a)
            inner = r - (2.0 if a % 30 else 3.0)
            ax.plot([inner * math.cos(ang), r * math.cos(ang)], [inner * math.sin(ang), r * math.sin(ang)],
                    color="white", lw=1.2, zorder=4)
        self.roll_ptr = ax.add_patch(Polygon([[0, r - 3.5], [-1.3, r - 6.0], [1.3, r - 6.0]], closed=True,
                                             color="white", zorder=4))
        self.readout = ax.text(0.02, 0.02, "", transform=ax.transAxes, color="white", fontsize=10,
                               family="monospace", va="bottom",
                               bbox=dict(facecolor="black", alpha=0.5, lw=0))
        for artist in self.world:
            artist.set_clip_path(ax.patch)
        # Heading tape.
        t = self.ax_t
        t.set_facecolor("#2b2b2b")
        t.set_ylim(0, 1)
        t.set_yticks([])
        t.tick_params(colors="white")
        for s in t.spines.values():
            s.set_color("#888888")
        # The pointer: a line over the ticks and a notch at the top, clear of the labels.
        t.plot([0, 0], [0, 0.42], color="#ffd21f", lw=2.5, zorder=5)
        t.plot([0], [0.97], "v", color="#ffd21f", ms=9, zorder=5, clip_on=False)
        self.tape_marks = []
        self.tape_label = t.text(0.5, 1.08, "", transform=t.transAxes, color="white", ha="center", va="bottom",
                                 fontsize=11, family="monospace")
        # Right: the last 20 s.
        self.ax_s = []
        names = (("roll", "deg", (-180, 180)), ("pitch", "deg", (-90, 90)), ("heading", "deg", (0, 360)))
        self.lines = []
        for i, (name, unit, lim) in enumerate(names):
            a = fig.add_axes([0.53, 0.70 - i * 0.30, 0.44, 0.25], facecolor="#2b2b2b")
            a.set_xlim(-WINDOW_S, 0)
            a.set_ylim(*lim)
            a.set_ylabel("%s (%s)" % (name, unit), color="white")
            a.tick_params(colors="white", labelsize=8)
            a.grid(color="#555555", lw=0.5)
            for s in a.spines.values():
                s.set_color("#888888")
            if i < 2:
                a.set_xticklabels([])
            else:
                a.set_xlabel("time (s, now = 0)", color="white")
            self.lines.append(a.plot([], [], color=("#ff6b6b", "#6bcB77", "#4d96ff")[i], lw=1.5)[0])
            self.ax_s.append(a)
        self.title = fig.text(0.53, 0.97, "", color="white", fontsize=10, va="top")
        self.history = []

    def add(self, samples):
        self.history.extend(samples)
        if self.history:
            t_now = self.history[-1][0]
            cut = 0
            while cut < len(self.history) and self.history[cut][0] < t_now - WINDOW_S - 1.0:
                cut += 1
            if cut:
                del self.history[:cut]

    def update(self, status=""):
        if not self.history:
            return
        t_now, roll, pitch, heading = self.history[-1]
        # Nose up moves the world down; a right roll turns it counter-clockwise (the
        # camera turns clockwise): translate by -pitch along the rotated vertical.
        tr = self.Affine2D().translate(0.0, -pitch).rotate_deg(roll) + self.ax_h.transData
        for artist in self.world:
            artist.set_transform(tr)
        self.roll_ptr.set_transform(self.Affine2D().rotate_deg(roll) + self.ax_h.transData)
        self.readout.set_text("roll  %7.2f\npitch %7.2f\nhdg   %7.2f" % (roll, pitch, heading))
        # Tape: +-60 degrees around the heading, ticks every 10, names every 45.
        for m in self.tape_marks:
            m.remove()
        self.tape_marks = []
        t = self.ax_t
        t.set_xlim(-60, 60)
        names = {0: "N", 45: "NE", 90: "E", 135: "SE", 180: "S", 225: "SW", 270: "W", 315: "NW"}
        start = int(math.floor((heading - 60) / 5.0)) * 5
        for h in range(start, start + 125, 5):
            x = h - heading
            if x < -60 or x > 60:
                continue
            hh = h % 360
            major = hh % 10 == 0
            self.tape_marks.append(t.plot([x, x], [0, 0.35 if major else 0.18], color="white", lw=1)[0])
            label = names.get(hh) if hh % 45 == 0 else ("%d" % hh if hh % 30 == 0 else None)
            if label:
                self.tape_marks.append(t.text(x, 0.66, label, color="#ffd21f" if hh in names else "white",
                                              ha="center", va="center", fontsize=9))
        t.set_xticks([])
        self.tape_label.set_text("heading %06.2f" % heading)
        # History.
        ts = [s[0] - t_now for s in self.history]
        for i, line in enumerate(self.lines):
            ys = [s[1 + i] for s in self.history]
            if i == 2:  # heading: break the line where it wraps 360 -> 0
                xs2, ys2 = [], []
                for k, y in enumerate(ys):
                    if k and abs(y - ys[k - 1]) > 180:
                        xs2.append(float("nan"))
                        ys2.append(float("nan"))
                    xs2.append(ts[k])
                    ys2.append(y)
                line.set_data(xs2, ys2)
            else:
                line.set_data(ts, ys)
        self.title.set_text("t = %.2f s   %s" % (t_now, status))

    def layout(self):
        """The horizon's pixel geometry in a saved PNG (origin top left, y down)."""
        self.fig.canvas.draw()
        bb = self.ax_h.get_window_extent()
        h_px = self.fig.get_figheight() * self.fig.dpi
        return {"horizon_px": {"x0": bb.x0, "x1": bb.x1, "top": h_px - bb.y1, "bottom": h_px - bb.y0},
                "fov_half_deg": FOV_HALF_DEG, "px_per_deg": bb.height / (2 * FOV_HALF_DEG),
                "sky": SKY, "ground": GROUND,
                "image_px": [int(round(self.fig.get_figwidth() * self.fig.dpi)), int(round(h_px))]}


# ---------------------------------------------------------------------------------------


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--port", help="serial port of a real board")
    src.add_argument("--file", help="a recorded stream (any output mode, or MAVLink)")
    src.add_argument("--sim", help="path of apm25sim (with --elf and --trajectory)")
    ap.add_argument("--baud", type=int, default=115200)
    ap.add_argument("--elf", default="build/firmware.elf")
    ap.add_argument("--trajectory")
    ap.add_argument("--seconds", type=float)
    ap.add_argument("--input", help="apm25sim --input: console commands typed into the board (e.g. mode mavlink)")
    ap.add_argument("--rate", type=float, default=50.0, help="lines per second of untimed modes (default 50)")
    ap.add_argument("--frames", help="headless: write PNG frames into this directory")
    ap.add_argument("--frame-every", type=int, default=25, help="samples between frames (default 25)")
    ap.add_argument("--size", default="1280x720", help="frame size in pixels (default 1280x720)")
    ap.add_argument("--quiet", action="store_true", help="do not print '# ' and STATUSTEXT lines")
    args = ap.parse_args(argv)
    if args.sim and not args.trajectory:
        ap.error("--sim needs --trajectory")

    import matplotlib
    headless = bool(args.frames)
    if headless:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if not headless and matplotlib.get_backend().lower() == "agg":
        # matplotlib found no display or no GUI toolkit: a window would silently not open.
        print("view: no window possible (no display, or no GUI toolkit: Debian's python3-tk, "
              "which `make deps` installs); headless frames: --frames DIR", file=sys.stderr)
        return 2

    w, h = (int(v) for v in args.size.lower().split("x"))
    view = View(plt, (w, h))
    say = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    dec = StreamDecoder(args.rate, say)
    if args.port:
        source, paced = serial_source(args.port, args.baud), False
    elif args.file:
        source, paced = file_source(args.file), not headless
    else:
        source, paced = sim_source(args), not headless
    label = args.port or args.file or os.path.basename(args.trajectory)

    if headless:
        os.makedirs(args.frames, exist_ok=True)
        with open(os.path.join(args.frames, "layout.json"), "w") as f:
            json.dump(view.layout(), f, indent=1)
        n = written = 0
        for chunk in source:
            if chunk is None:
                continue
            for s in dec.feed(chunk):
                view.add([s])
                n += 1
                if n % args.frame_every == 0:
                    view.update(label)
                    view.fig.savefig(os.path.join(args.frames, "frame_%05d.png" % written))
                    written += 1
        if n % args.frame_every != 0 and view.history:
            view.update(label)
            view.fig.savefig(os.path.join(args.frames, "frame_%05d.png" % written))
            written += 1
        print("view: %d samples, %d frames in %s (%d MAVLink frames, %d bad)"
              % (n, written, args.frames, dec.frames, dec.bad_frames))
        return 0 if n else 1

    # A window: draw at most 25 times a second; a simulated or recorded stream is paced by
    # its own time stamps so that it plays at the board's speed (the simulator is blocked
    # by the full pipe meanwhile).
    plt.ion()
    view.fig.canvas.manager.set_window_title("apm25-attitude view: " + label)
    plt.show(block=False)
    pending = []
    wall0 = stream0 = None
    last_draw = 0.0
    for chunk in source:
        if not plt.fignum_exists(view.fig.number):
            return 0
        if chunk:
            pending.extend(dec.feed(chunk))
        now = time.monotonic()
        if pending:
            if wall0 is None:
                wall0, stream0 = now, pending[0][0]
            if paced:
                due = [s for s in pending if s[0] - stream0 <= now - wall0]
                pending = pending[len(due):]
            else:
                due, pending = pending, []
            view.add(due)
        if now - last_draw > 0.04 and view.history:
            view.update(label)
            last_draw = now
            plt.pause(0.001)
        if paced and pending and chunk is not None:
            time.sleep(min(0.02, max(0.0, pending[0][0] - stream0 - (now - wall0))))
    # The stream ended: play what is left, then keep the window until it is closed.
    while pending and plt.fignum_exists(view.fig.number):
        now = time.monotonic()
        due = [s for s in pending if s[0] - stream0 <= now - wall0]
        pending = pending[len(due):]
        view.add(due)
        view.update(label)
        plt.pause(0.04)
    if plt.fignum_exists(view.fig.number):
        view.update(label + " (ended)")
        plt.ioff()
        plt.show()
    return 0


if __name__ == "__main__":
    sys.exit(main())
