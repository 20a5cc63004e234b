#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""tools/view.py renders frames headlessly (Agg) from recorded streams that this test writes
itself, in each form the firmware can send (plot, csv, quat lines and MAVLink 2 ATTITUDE
frames packed by pymavlink, with "# " lines and STATUSTEXT mixed in), and the horizon is
where the angles put it.

    build/venv/bin/python test/view/test_view.py --view tools/view.py --work DIR

The horizon geometry comes from the frames' layout.json (the horizon's pixel box and
pixels per degree); the expected boundary is computed here from the angles: nose up by p
moves the horizon down by p * px_per_deg, a roll r turns it by r counter-clockwise about
the centre. The sky/ground boundary is found as the first ground-coloured pixel going
down a column, at 20 degrees left and right of the centre (clear of the aircraft symbol
and the pitch ladder). Exit 1 with the reasons on any failure.
"""
import argparse
import json
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from soft_assert import failures, finish, soft_assert  # noqa: E402

TOLERANCE_PX = 2.5  # the white horizon line is 1.5 pt (~2 px) wide at 100 dpi


def quat_from_euler_deg(roll, pitch, yaw):
    """Body -> earth, q = qz(yaw) qy(pitch) qx(roll), scalar first."""
    cr, sr = math.cos(math.radians(roll) / 2), math.sin(math.radians(roll) / 2)
    cp, sp = math.cos(math.radians(pitch) / 2), math.sin(math.radians(pitch) / 2)
    cy, sy = math.cos(math.radians(yaw) / 2), math.sin(math.radians(yaw) / 2)
    return (cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr)


def write_stream(path, form, roll, pitch, heading, n=60):
    with open(path, "wb") as f:
        f.write(b"# apm25-attitude 0.1.0: recorded by test_view.py\n")
        if form == "plot":
            for _ in range(n):
                f.write(b"roll:%.2f pitch:%.2f yaw:%.2f\n" % (roll, pitch, heading))
        elif form == "csv":
            f.write(b"t_ms,roll,pitch,yaw\n")
            for i in range(n):
                f.write(b"%d,%.2f,%.2f,%.2f\n" % (3000 + 20 * i, roll, pitch, heading))
        elif form == "quat":
            q = quat_from_euler_deg(roll, pitch, heading)
            for i in range(n):
                f.write(b"qw:%.4f qx:%.4f qy:%.4f qz:%.4f\n" % q)
                if i == n // 2:
                    f.write(b"gx:0.12 gy:-0.06 gz:0.00 ax:0.012 ay:-0.003 az:-1.001 mx:20.1 my:0.3 mz:45.2\n")
        elif form == "mavlink":
            mav = mavlink2.MAVLink(f, srcSystem=1, srcComponent=1)
            yaw = math.radians(heading if heading <= 180 else heading - 360)
            for i in range(n):
                if i % 50 == 0:
                    mav.heartbeat_send(mavlink2.MAV_TYPE_GENERIC, mavlink2.MAV_AUTOPILOT_GENERIC, 0, 0,
                                       mavlink2.MAV_STATE_ACTIVE)
                if i == 10:
                    mav.statustext_send(mavlink2.MAV_SEVERITY_WARNING, b"warn: compass overflow")
                    f.write(b"# mode mavlink\n")  # console answers stay text in this mode
                mav.attitude_send(3000 + 20 * i, math.radians(roll), math.radians(pitch), yaw, 0.0, 0.0, 0.0)
        else:
            raise ValueError(form)


def render(view, stream, frames_dir):
    r = subprocess.run([sys.executable, view, "--file", stream, "--frames", frames_dir, "--frame-every", "1000",
                        "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=240)
    soft_assert(r.returncode == 0, "%s: view.py exit %d: %s" % (stream, r.returncode, r.stdout[-500:]))
    with open(os.path.join(frames_dir, "layout.json")) as f:
        layout = json.load(f)
    pngs = sorted(p for p in os.listdir(frames_dir) if p.endswith(".png"))
    soft_assert(len(pngs) == 1, "%s: %d frames, expected 1" % (stream, len(pngs)))
    img = mpimg.imread(os.path.join(frames_dir, pngs[-1]))[:, :, :3] if pngs else None
    return layout, img, r.stdout


def hex_rgb(h):
    return np.array([int(h[i:i + 2], 16) / 255.0 for i in (1, 3, 5)])


def boundary_row(img, layout, x_deg):
    """First ground-coloured row going down the column x_deg from the horizon's centre."""
    hp = layout["horizon_px"]
    ppd = layout["px_per_deg"]
    col = int(round((hp["x0"] + hp["x1"]) / 2 + x_deg * ppd))
    top, bottom = int(math.ceil(hp["top"])) + 2, int(hp["bottom"]) - 2
    pix = img[top:bottom, col, :]
    ground = np.linalg.norm(pix - hex_rgb(layout["ground"]), axis=1) < 0.08
    sky = np.linalg.norm(pix - hex_rgb(layout["sky"]), axis=1) < 0.08
    rows = np.nonzero(ground)[0]
    return (top + rows[0] if len(rows) else None), int(sky.sum()), int(ground.sum())


def expected_row(layout, x_deg, roll, pitch):
    """Row of the horizon at column x_deg: the line R(roll) * (u, -pitch), u free."""
    hp = layout["horizon_px"]
    mid = (hp["top"] + hp["bottom"]) / 2
    r = math.radians(roll)
    u = (x_deg - pitch * math.sin(r)) / math.cos(r)
    y_deg = u * math.sin(r) - pitch * math.cos(r)
    return mid - y_deg * layout["px_per_deg"]


CASES = [  # form, roll, pitch, heading
    ("plot", 0.0, 0.0, 0.0),
    ("plot", 0.0, 10.0, 45.0),
    ("csv", 0.0, -15.0, 200.0),
    ("quat", 20.0, 0.0, 90.0),
    ("quat", 0.0, 12.5, 300.0),
    ("mavlink", -10.0, 5.0, 270.0),
]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--view", required=True)
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    for i, (form, roll, pitch, heading) in enumerate(CASES):
        name = "%d_%s_r%g_p%g" % (i, form, roll, pitch)
        stream = os.path.join(args.work, name + ".stream")
        frames = os.path.join(args.work, name)
        if os.path.isdir(frames):
            for p in os.listdir(frames):
                os.remove(os.path.join(frames, p))
        write_stream(stream, form, roll, pitch, heading)
        layout, img, out = render(args.view, stream, frames)
        if img is None:
            continue
        w, h = layout["image_px"]
        soft_assert(img.shape[0] == h and img.shape[1] == w, "%s: image %r, expected %dx%d" % (name, img.shape, w, h))
        # Drawn: many colours, not one flat fill.
        soft_assert(float(img.std()) > 0.1 and len(np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0)) > 50,
              "%s: the frame looks blank" % name)
        if form == "mavlink":
            soft_assert("60 samples" in out and "0 bad" in out, "%s: view.py said %r" % (name, out.strip()))
        for x_deg in (-20.0, 20.0):
            got, n_sky, n_ground = boundary_row(img, layout, x_deg)
            want = expected_row(layout, x_deg, roll, pitch)
            soft_assert(n_sky > 20 and n_ground > 20, "%s x=%g: %d sky, %d ground pixels" % (name, x_deg, n_sky, n_ground))
            if soft_assert(got is not None, "%s x=%g: no ground found" % (name, x_deg)):
                soft_assert(abs(got - want) <= TOLERANCE_PX,
                      "%s x=%g: horizon at row %d, expected %.1f" % (name, x_deg, got, want))
        print("%-28s horizon rows as expected" % name if not failures else "%-28s checked" % name)
    return finish("view frames", "view frames: %d streams rendered, horizon where the angles put it" % len(CASES))


if __name__ == "__main__":
    sys.exit(main())
