#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The board in its airframe: AHRS_ORIENTATION and the level calibration.

    build/venv/bin/python test/mavlink/level_orientation.py --tools build --work DIR

1. Level, over TCP with pymavlink (apm25sim --serial): a level airframe at rest whose
   board sits rolled 2 deg and pitched 3 deg in it, flying STABILIZE with centred sticks
   (--rc) and its outputs measured on the pins (--servo-log). Before the calibration the
   board reads 2 and 3 deg and STABILIZE moves the aileron and elevator off trim; then, in
   MANUAL, MAV_CMD_PREFLIGHT_CALIBRATION param5 2 (Mission Planner's Calibrate Level,
   MAVProxy's ahrstrim) is ACCEPTED, "cal level" is said, the board sends AHRS_TRIM_X/Y's
   PARAM_VALUEs unasked (as ArduPilot does for a value it sets), they read back as 2 and
   3 deg (within 0.05 deg: a count of the accelerometer is 0.03 deg), ATTITUDE reads level
   (within 0.1 deg) and STABILIZE again holds the airframe level: OUT1 and OUT2 within 3 us
   of their trim. A second level calibration on a board rocking in roll is refused with its
   reason and leaves the trims as they were.
2. Orientation, on the text output: the tilt tour (build/scenario, still for 3 s first)
   run with the board as its arrow says, and again with the board mounted at
   ROLL_180_YAW_90 (10) and at YAW_45 (1) (apm25sim --orientation, `set AHRS_ORIENTATION`
   typed at 1.5 s, while still): every angle line from 5 s on within 0.2 deg of the plain
   run's angles at its time (roll, pitch and heading; measured 0.10, 0.05, 0.07).
3. The six-position accelerometer calibration (param5 1, ACCELCAL_VEHICLE_POS) on injected
   offsets and scales: the six INS_ACC* values announced unasked, then read back.
Exit 1 with every failure listed.
"""
import bisect
import csv
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from gcs_link import Board, command  # noqa: E402
from pymavlink.dialects.v20 import common as mavlink2  # noqa: E402
from sim_run import tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

G = 9.80665
EARTH_UT = (20.0, 0.0, 45.0)
TRIM_ROLL_DEG, TRIM_PITCH_DEG = 2.0, 3.0


def rot(roll, pitch, yaw):
    """R = Rz Ry Rx (body -> NED), rows."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw),
                              math.sin(yaw))
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


def body_of(r, v):
    return [sum(r[i][j] * v[i] for i in range(3)) for j in range(3)]  # R^T v


def quat(roll, pitch, yaw):
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr, cy * sp * cr + sy * cp * sr,
            sy * cp * cr - cy * sp * sr)


def write_tilted_board(path, seconds, rock_from_s):
    """A level airframe at rest, its board rolled and pitched by the trims (the board's
    values); from rock_from_s on, rocked in roll (+-5 deg at 0.5 Hz)."""
    pitch = math.radians(TRIM_PITCH_DEG)
    w_rad_s = 2.0 * math.pi * 0.5
    with open(path, "w") as f:
        f.write("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz\n")
        t = 0.0
        while t <= seconds + 1e-9:
            u = max(0.0, t - rock_from_s)
            roll = math.radians(TRIM_ROLL_DEG + 5.0 * math.sin(w_rad_s * u))
            roll_rate = math.radians(5.0) * w_rad_s * math.cos(w_rad_s * u) if t >= rock_from_s else 0.0
            r = rot(roll, pitch, 0.0)
            a = body_of(r, (0.0, 0.0, -G))
            m = body_of(r, EARTH_UT)
            q = quat(roll, pitch, 0.0)
            # Yaw constant: the body rates of the Z-Y-X angles are (roll', 0, 0) here.
            f.write("%.3f,%s\n" % (t, ",".join("%.7f" % v for v in [roll_rate, 0.0, 0.0] + a + m + list(q))))
            t += 0.01


def no_overrun(board, what):
    """Nothing cost a sample (the firmware says "loop overrun" when one is missed)."""
    overruns = [m.text for _, m in board.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "%s: samples missed: %r" % (what, overruns))


def announced(b, since, names, what):
    """The PARAM_VALUEs of names the board sent unasked after b.msgs[since] (a calibration
    that writes parameters tells the ground station, as ArduPilot): the set of those seen."""
    seen = set()

    def take(m):
        if m.get_type() == "PARAM_VALUE" and m.param_id in names:
            seen.add(m.param_id)
        return len(seen) == len(names)
    for _, m in b.msgs[since:]:
        take(m)
    if len(seen) < len(names):
        b.pump(take, what, timeout_s=60)
    return seen


def servo_widths(path, out, t0, t1):
    with open(path) as f:
        return [float(r["width_us"]) for r in csv.DictReader(f) if int(r["out"]) == out and t0 <= float(r["t"]) < t1]


def attitude_between(board, t0, t1):
    return [m for t, m in board.msgs if m.get_type() == "ATTITUDE" and t0 <= t < t1]


def level(args):
    traj = os.path.join(args.work, "tilted_board.csv")
    write_tilted_board(traj, 30.0, rock_from_s=22.0)
    rc_path = os.path.join(args.work, "stabilize.csv")
    with open(rc_path, "w") as f:  # sticks centred, throttle low; STABILIZE (channel 8 high), MANUAL, STABILIZE
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n")
        for t, ch8 in ((0.5, 1900), (5.0, 1100), (14.0, 1900)):
            f.write("%.1f,1500,1500,1100,1500,1500,1500,1500,%d\n" % (t, ch8))
    servo_log = os.path.join(args.work, "level_servos.csv")
    b = Board(args.tools, args.work, "level", ["--trajectory", traj, "--rc", rc_path, "--servo-log", servo_log,
                                               "--seconds", "28"])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT") is None:
        b.stop()
        return
    b.pump(lambda m: m.get_type() == "ATTITUDE" and b.t_s >= 6.0, "ATTITUDE at 6 s")
    before = attitude_between(b, 5.0, 6.0)
    if soft_assert(before, "no ATTITUDE before the calibration"):
        r = max(abs(math.degrees(m.roll) - TRIM_ROLL_DEG) for m in before)
        p = max(abs(math.degrees(m.pitch) - TRIM_PITCH_DEG) for m in before)
        print("before: the board reads its tilt within %.3f deg roll, %.3f deg pitch" % (r, p))
        soft_assert(r < 0.1 and p < 0.1, "before the calibration the board does not read its 2/3 deg tilt")
    since = len(b.msgs)
    command(b, mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, 0, 0, 0, 0, 2)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, "COMMAND_ACK of the level calibration")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "level calibration ACK %r" % ack)
    said = b.pump(lambda m: m.get_type() == "STATUSTEXT" and "cal level" in m.text and "keep" not in m.text,
                  "the level calibration's verdict")
    print("said: %s" % (said.text if said else None))
    soft_assert(said is not None and "trim roll" in said.text, "level calibration verdict %r" % said)
    told = announced(b, since, ("AHRS_TRIM_X", "AHRS_TRIM_Y"), "the new trims' PARAM_VALUEs, unasked")
    soft_assert(len(told) == 2, "the level calibration's trims announced: only %r" % sorted(told))
    t_done = b.t_s
    trims = {}
    for name in ("AHRS_TRIM_X", "AHRS_TRIM_Y"):
        b.conn.mav.param_request_read_send(1, 1, name.encode(), -1)
        v = b.param(name, "PARAM_VALUE " + name)
        trims[name] = math.degrees(v.param_value) if v else float("nan")
    print("trims: roll %.3f pitch %.3f deg (set 2, 3)" % (trims["AHRS_TRIM_X"], trims["AHRS_TRIM_Y"]))
    soft_assert(abs(trims["AHRS_TRIM_X"] - TRIM_ROLL_DEG) < 0.05, "AHRS_TRIM_X %.3f deg" % trims["AHRS_TRIM_X"])
    soft_assert(abs(trims["AHRS_TRIM_Y"] - TRIM_PITCH_DEG) < 0.05, "AHRS_TRIM_Y %.3f deg" % trims["AHRS_TRIM_Y"])
    b.pump(lambda m: m.get_type() == "ATTITUDE" and b.t_s >= t_done + 6.0, "ATTITUDE 6 s after")
    after = attitude_between(b, t_done + 1.0, t_done + 6.0)
    if soft_assert(after, "no ATTITUDE after the calibration"):
        r = max(abs(math.degrees(m.roll)) for m in after)
        p = max(abs(math.degrees(m.pitch)) for m in after)
        print("after: level within %.3f deg roll, %.3f deg pitch" % (r, p))
        soft_assert(r < 0.1 and p < 0.1, "after the calibration the level airframe reads %.3f roll %.3f pitch" % (r, p))
    # Rocking (from 22 s): refused, the trims kept.
    b.pump(lambda m: m.get_type() == "ATTITUDE" and b.t_s >= 23.0, "ATTITUDE at 23 s")
    command(b, mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, 0, 0, 0, 0, 2)
    refused = b.pump(lambda m: m.get_type() == "STATUSTEXT" and "cal level: board moved" in m.text,
                     "the refusal of a level calibration while rocking", timeout_s=120)
    print("while rocking: %s" % (refused.text if refused else None))
    b.conn.mav.param_request_read_send(1, 1, b"AHRS_TRIM_X", -1)
    v = b.param("AHRS_TRIM_X", "PARAM_VALUE AHRS_TRIM_X after the refusal")
    soft_assert(v is not None and abs(math.degrees(v.param_value) - trims["AHRS_TRIM_X"]) < 1e-4,
                "a refused calibration changed AHRS_TRIM_X")
    b.stop()
    no_overrun(b, "level")
    # STABILIZE with centred sticks: off trim before (the board's tilt), on trim after
    # (from a new STABILIZE at 14 s: the integrators of the first one were reset in MANUAL).
    soft_assert(t_done < 13.0, "the calibration ended at %.1f s, after MANUAL" % t_done)
    for out, name in ((1, "aileron"), (2, "elevator")):
        pre, post = servo_widths(servo_log, out, 4.0, 5.0), servo_widths(servo_log, out, 16.0, 21.5)
        if not soft_assert(pre and post, "no OUT%d pulses" % out):
            continue
        off_pre = max(abs(w - 1500.0) for w in pre)
        off_post = max(abs(w - 1500.0) for w in post)
        print("OUT%d (%s): up to %.1f us off trim before, %.1f us after" % (out, name, off_pre, off_post))
        soft_assert(off_pre > 10.0, "OUT%d only %.1f us off trim before the calibration" % (out, off_pre))
        soft_assert(off_post <= 3.0, "OUT%d %.1f us off trim on a level airframe after it" % (out, off_post))


def angle_lines(stdout):
    rows = []
    for line in stdout.splitlines():
        parts = line.split(" ", 1)
        if len(parts) != 2 or not parts[1].startswith("roll:"):
            continue
        v = dict(kv.split(":") for kv in parts[1].split())
        rows.append((float(parts[0]), float(v["roll"]), float(v["pitch"]), float(v["yaw"])))
    return rows


def run_text(args, traj, name, orientation, seconds):
    cmd = [os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
           "--trajectory", traj, "--seconds", str(seconds), "--stamp"]
    if orientation:
        inp = os.path.join(args.work, name + ".in")
        with open(inp, "w") as f:
            f.write("set AHRS_ORIENTATION %d\n" % orientation)
        cmd += ["--orientation", str(orientation), "--input", inp, "--input-at", "1.5"]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=1200)
    with open(os.path.join(args.work, name + ".out"), "w") as f:
        f.write(p.stdout)
    soft_assert(p.returncode == 0, "%s: apm25sim exited %d" % (name, p.returncode))
    soft_assert("overrun" not in p.stdout, "%s: samples missed" % name)
    return angle_lines(p.stdout)


def orientation(args):
    traj = os.path.join(args.work, "tilt_tour.csv")
    with open(traj, "wb") as f:
        subprocess.run([os.path.join(args.tools, "scenario"), "tilt_tour"], stdout=f, check=True)
    seconds = 30
    plain = run_text(args, traj, "plain", 0, seconds)
    times = [r[0] for r in plain]
    for rot_n, rot_name in ((10, "ROLL_180_YAW_90"), (1, "YAW_45")):
        mounted = run_text(args, traj, "orientation%d" % rot_n, rot_n, seconds)
        worst = [0.0, 0.0, 0.0]
        n = 0
        for t, r, p, y in mounted:
            if t < 5.0:
                continue
            # The plain run's angles at this line's time (the lines' phases differ by the
            # input's bytes): linear between its two lines around it.
            i = bisect.bisect_left(times, t)
            if i == 0 or i >= len(plain):
                continue
            t0, t1 = plain[i - 1][0], plain[i][0]
            if t1 - t0 > 0.05:
                continue
            u = (t - t0) / (t1 - t0)
            ref = []
            for k in (1, 2, 3):
                a, b2 = plain[i - 1][k], plain[i][k]
                if k != 2:  # roll and heading wrap at +-180 / 360
                    b2 = a + (b2 - a + 180.0) % 360.0 - 180.0
                ref.append(a + u * (b2 - a))
            n += 1
            d = [abs((v - w + 180.0) % 360.0 - 180.0) for v, w in zip((r, p, y), ref)]
            worst = [max(worst[k], d[k]) for k in range(3)]
        print("%s (%d): %d lines, worst roll %.3f pitch %.3f heading %.3f deg off the plain board's" %
              (rot_name, rot_n, n, worst[0], worst[1], worst[2]))
        soft_assert(n > 500, "%s: only %d lines to compare" % (rot_name, n))
        soft_assert(worst[0] < 0.2 and worst[1] < 0.2 and worst[2] < 0.2,
                    "%s: roll %.3f pitch %.3f heading %.3f deg off" % (rot_name, worst[0], worst[1], worst[2]))


# The six positions (ACCELCAL_VEHICLE_POS 1..6) as quaternions of the airframe, each held
# HOLD_S after a MOVE_S turn from the one before (the first from 0 s).
def q_axis(axis, deg):
    h = math.radians(deg) / 2.0
    q = [math.cos(h), 0.0, 0.0, 0.0]
    q[1 + axis] = math.sin(h)
    return q


POSES = [q_axis(0, 0), q_axis(0, -90), q_axis(0, 90), q_axis(1, -90), q_axis(1, 90), q_axis(0, 180)]
FIRST_MOVE_S, HOLD_S, MOVE_S = 14.0, 7.0, 2.0
ACCEL_OFFSET = (0.3, -0.25, 0.2)    # m/s^2, the board's axes
ACCEL_SCALE = (1.02, 0.98, 1.015)


def hold_start(k):
    return 0.0 if k == 0 else FIRST_MOVE_S + MOVE_S + (k - 1) * (HOLD_S + MOVE_S)


def qmul(a, b):
    return [a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]]


def slerp(a, b, u):
    d = sum(x * y for x, y in zip(a, b))
    if d < 0:
        b, d = [-x for x in b], -d
    th = math.acos(min(1.0, d))
    if th < 1e-9:
        return list(a)
    return [(math.sin((1 - u) * th) * x + math.sin(u * th) * y) / math.sin(th) for x, y in zip(a, b)]


def attitude_at(t):
    for k in range(1, len(POSES)):
        t0 = hold_start(k) - MOVE_S
        if t < t0:
            return POSES[k - 1]
        if t < t0 + MOVE_S:
            u = (t - t0) / MOVE_S
            return slerp(POSES[k - 1], POSES[k], 0.5 - 0.5 * math.cos(math.pi * u))  # eased
    return POSES[-1]


def rot_of(q):
    w, x, y, z = q
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]]


def write_six_positions(path, seconds):
    dt = 0.005
    with open(path, "w") as f:
        f.write("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz\n")
        t = 0.0
        while t <= seconds + 1e-9:
            q, q2 = attitude_at(t), attitude_at(t + dt)
            # body rate: 2 q^-1 dq/dt
            dq = qmul([q[0], -q[1], -q[2], -q[3]], q2)
            if dq[0] < 0:
                dq = [-v for v in dq]
            w = [2.0 * v / dt for v in dq[1:]]
            r = rot_of(q)
            a = body_of(r, (0.0, 0.0, -G))
            m = body_of(r, EARTH_UT)
            f.write("%.3f,%s\n" % (t, ",".join("%.7f" % v for v in w + a + m + list(q))))
            t += dt


def accel_six(args):
    truth = os.path.join(args.work, "six_positions_truth.csv")
    total_s = hold_start(5) + HOLD_S + 2.0
    write_six_positions(truth, total_s)
    traj = os.path.join(args.work, "six_positions.csv")
    with open(traj, "wb") as f:  # the accelerometer's errors (the scenario tool's model: scale .* f + offset)
        subprocess.run([os.path.join(args.tools, "scenario"), "--from", truth, "--accel-offset",
                        ",".join(str(v) for v in ACCEL_OFFSET), "--accel-scale",
                        ",".join(str(v) for v in ACCEL_SCALE)], stdout=f, check=True)
    b = Board(args.tools, args.work, "accel", ["--trajectory", traj, "--seconds", str(total_s)])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT") is None:
        b.stop()
        return
    b.pump(lambda m: m.get_type() == "ATTITUDE" and b.t_s >= 4.0, "ATTITUDE at 4 s")
    since = len(b.msgs)
    command(b, mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, 0, 0, 0, 0, 1)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION, "COMMAND_ACK of the accel calibration")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "accel calibration ACK %r" % ack)

    def asked(p):
        return b.pump(lambda m: m.get_type() == "COMMAND_LONG" and m.command == 42429 and int(m.param1) == p,
                      "ACCELCAL_VEHICLE_POS %d asked" % p)

    def confirm(p, k):
        if k < 3:  # Mission Planner's way
            command(b, 42429, p)
            a = b.ack(42429, "ACK of position %d" % p)
            return a is not None and a.result == mavlink2.MAV_RESULT_ACCEPTED
        b.conn.mav.command_ack_send(p, 1)  # MAVProxy's accelcal: COMMAND_ACK, command = the position
        return True

    prompts = []
    for k in range(6):
        p = k + 1
        if asked(p) is None:
            break
        if k == 1:
            # Confirmed while still level: refused, asked again.
            soft_assert(confirm(p, k), "position 2's early confirmation not ACCEPTED")
            r = b.pump(lambda m: m.get_type() == "STATUSTEXT" and "not in that position" in m.text,
                       "the refusal of a wrong position", timeout_s=60)
            print("wrong position: %s" % (r.text if r else None))
            if asked(p) is None:
                break
        b.pump(lambda m: b.t_s >= hold_start(k) + 1.5, "the airframe in position %d" % p)
        soft_assert(confirm(p, k), "position %d's confirmation not ACCEPTED" % p)
    done = b.pump(lambda m: m.get_type() == "COMMAND_LONG" and m.command == 42429 and m.param1 >= 16777215.0,
                  "ACCELCAL_VEHICLE_POS SUCCESS or FAILED")
    soft_assert(done is not None and done.param1 == 16777215.0, "the calibration's end: %r" % done)
    prompts = [m.text for _, m in b.msgs if m.get_type() == "STATUSTEXT" and m.text.startswith("Place vehicle")]
    soft_assert(len(prompts) == 7 and prompts[0] == "Place vehicle level and press any key",
                "the prompts: %r" % prompts)
    names = ("INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X", "INS_ACCSCAL_Y", "INS_ACCSCAL_Z")
    told = announced(b, since, names, "the six values' PARAM_VALUEs, unasked")
    soft_assert(len(told) == 6, "the accel calibration's values announced: only %r" % sorted(told))
    got = {}
    for name in names:
        b.conn.mav.param_request_read_send(1, 1, name.encode(), -1)
        v = b.param(name, "PARAM_VALUE " + name)
        got[name] = v.param_value if v else float("nan")
    b.stop()
    no_overrun(b, "six positions")
    worst_o = max(abs(got["INS_ACCOFFS_" + a] - o) for a, o in zip("XYZ", ACCEL_OFFSET))
    worst_s = max(abs(got["INS_ACCSCAL_" + a] - 1.0 / s) for a, s in zip("XYZ", ACCEL_SCALE))
    print("six positions: offsets %s (injected %s), worst %.4f m/s^2; scales %s (1/injected %s), worst %.5f" %
          (["%.4f" % got["INS_ACCOFFS_" + a] for a in "XYZ"], ACCEL_OFFSET, worst_o,
           ["%.5f" % got["INS_ACCSCAL_" + a] for a in "XYZ"], ["%.5f" % (1 / s) for s in ACCEL_SCALE], worst_s))
    soft_assert(worst_o < 0.02, "INS_ACCOFFS %.4f m/s^2 off the injected offsets" % worst_o)
    soft_assert(worst_s < 0.002, "INS_ACCSCAL %.5f off 1/the injected scales" % worst_s)


def main():
    args = tools_and_work()
    which = os.environ.get("LEVEL_PARTS", "level,orientation,accel").split(",")
    if "level" in which:
        level(args)
    if "orientation" in which:
        orientation(args)
    if "accel" in which:
        accel_six(args)


if __name__ == "__main__":
    main()
    sys.exit(finish("board orientation and level", "AHRS_ORIENTATION and the level calibration: all checks passed"))
