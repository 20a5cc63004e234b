#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""MAVProxy (PyPI's, in build/venv) on the simulated board over TCP, as on ArduPilot's SITL (issue 23).

    build/venv/bin/python test/mavlink/mavproxy_session.py --tools build --work DIR

Starts `apm25sim --serial tcp:0 --speed 1` (real time, as SITL) on the tilt tour and
`mavproxy.py --master tcp:127.0.0.1:PORT --no-state --default-modules param,mode`, its
console driven through stdin as a user types, and checks what it prints:
  - it fetches the whole parameter list ("Received N parameters", N = the board's count);
  - `param show RLL2SRV_P` prints the default 1.0;
  - `param set RLL2SRV_P 0.55` is saved by the board ("AP: saved") and `param show` then
    prints 0.55;
  - the prompt names the mode (MANUAL>, from HEARTBEAT's ArduPlane mode number); `mode
    STABILIZE`, `mode FBWA`, `mode MANUAL` change it (the prompt follows);
  - the board starts disarmed: `arm throttle` is refused with the board's reason (no
    receiver here: "PreArm: RC not found"), `arm throttle force` arms it (MAVProxy says
    ARMED), `disarm` disarms it (DISARMED);
  - `status ATTITUDE` prints the board's ATTITUDE: the board is held still at roll 30 deg,
    pitch 10 deg (a two-row trajectory, its last state held), and ATTITUDE says so within
    3 degrees;
  - `param set COMPASS_DEC 0.2` is taken as sent: MAVProxy, which compares the value the
    board returns with the one it sent (to 1e-5), never says "Failed to set", `param show`
    prints 0.2, and ATTITUDE's yaw then is 0.2 rad (the board points north) within 3 deg.
Exit 1 with every failure listed.
"""
import math
import os
import queue
import re
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from sim_run import serve, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

WALL_TIMEOUT_S = 120  # per line awaited: a missing one fails the test, not its time-out


class Lines:
    def __init__(self, stream, log):
        self.q = queue.Queue()
        self.log = log
        self.seen = []  # every line so far
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream):
        for line in stream:
            self.log.write(line)
            self.log.flush()  # whole in the work folder even when the test is killed
            self.seen.append(line)
            self.q.put(line)

    def wait(self, pattern, what, timeout_s=WALL_TIMEOUT_S, required=True):
        end = time.time() + timeout_s
        while time.time() < end:
            try:
                line = self.q.get(timeout=1)
            except queue.Empty:
                continue
            m = re.search(pattern, line)
            if m:
                return m
        soft_assert(not required, "MAVProxy never printed %s (%r)" % (what, pattern))
        return None


ROLL_DEG, PITCH_DEG = 30.0, 10.0
EARTH_FIELD_UT = (20.0, 0.0, 45.0)  # north, east, down


def write_banked(path):
    """A board held still at ROLL_DEG, PITCH_DEG, heading north (SIM.md's trajectory format)."""
    r, p = math.radians(ROLL_DEG), math.radians(PITCH_DEG)
    # Body -> earth: R = Rz(0) Ry(p) Rx(r); a body-frame vector is R^T times the earth one.
    R = [[math.cos(p), math.sin(p) * math.sin(r), math.sin(p) * math.cos(r)],
         [0.0, math.cos(r), -math.sin(r)],
         [-math.sin(p), math.cos(p) * math.sin(r), math.cos(p) * math.cos(r)]]

    def to_body(v):
        return [sum(R[i][j] * v[i] for i in range(3)) for j in range(3)]
    accel = to_body((0.0, 0.0, -9.80665))
    mag = to_body(EARTH_FIELD_UT)
    cr, sr, cp, sp = math.cos(r / 2), math.sin(r / 2), math.cos(p / 2), math.sin(p / 2)
    q = (cr * cp, sr * cp, cr * sp, -sr * sp)
    with open(path, "w") as f:
        f.write("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz\n")
        for t in (0.0, 1.0):
            f.write(",".join("%.6f" % v for v in [t, 0, 0, 0] + accel + mag + list(q)) + "\n")


class Session:
    """apm25sim serving the board on TCP in real time, and MAVProxy's console on it (its output
    in `out`, typed into with type_line); stop() ends both."""

    def __init__(self, args, sim_args, modules):
        self.sim_log = open(os.path.join(args.work, "apm25sim.stderr"), "w")
        self.sim, port = serve(args.tools, sim_args, self.sim_log)
        mavproxy = os.path.join(os.path.dirname(sys.executable), "mavproxy.py")
        self.mp_log = open(os.path.join(args.work, "mavproxy.out"), "w")
        self.mp = subprocess.Popen([sys.executable, mavproxy, "--master", "tcp:127.0.0.1:" + port,
                                    "--no-state", "--default-modules", modules, "--target-system", "1"],
                                   stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                   bufsize=1, cwd=args.work)
        self.out = Lines(self.mp.stdout, self.mp_log)

    def type_line(self, cmd):
        self.mp.stdin.write(cmd + "\n")
        self.mp.stdin.flush()

    def stop(self):
        self.type_line("exit")
        try:
            self.mp.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.mp.kill()
        self.mp_log.close()
        self.sim.terminate()
        self.sim.wait()
        self.sim_log.write(self.sim.stderr.read())


def main():
    args = tools_and_work()
    trajectory = os.path.join(args.work, "banked.csv")
    write_banked(trajectory)
    session = Session(args, ["--trajectory", trajectory], "param,mode,arm")
    out, type_line = session.out, session.type_line
    try:
        m = out.wait(r"Received (\d+) parameters", "the parameter list")
        soft_assert(m and int(m.group(1)) > 90, "parameters received: %s" % (m and m.group(1)))
        type_line("param show RLL2SRV_P")
        m = out.wait(r"RLL2SRV_P\s+([-0-9.e]+)", "RLL2SRV_P's value")
        soft_assert(m and abs(float(m.group(1)) - 1.0) < 1e-6, "RLL2SRV_P %s, default 1.0" % (m and m.group(1)))
        type_line("param set RLL2SRV_P 0.55")
        soft_assert(out.wait(r"AP: saved", "the board's 'saved'"), "param set not saved")
        type_line("param show RLL2SRV_P")
        m = out.wait(r"RLL2SRV_P\s+([-0-9.e]+)", "RLL2SRV_P's new value")
        soft_assert(m and abs(float(m.group(1)) - 0.55) < 1e-6, "RLL2SRV_P %s after set, 0.55" % (m and m.group(1)))
        # The prompt is the mode's name from HEARTBEAT (printed whenever it comes: look at all).
        soft_assert(any("MANUAL>" in line for line in out.seen), "MAVProxy never showed the MANUAL> prompt")
        for mode in ("STABILIZE", "FBWA", "MANUAL"):
            type_line("mode " + mode)
            soft_assert(out.wait(re.escape(mode) + ">", "the %s> prompt" % mode), "mode %s not shown" % mode)
        type_line("arm throttle")
        soft_assert(out.wait(r"PreArm: RC not found", "the board's pre-arm reason"), "no pre-arm reason")
        soft_assert(not any(line.strip() == "ARMED" for line in out.seen), "armed without a receiver")
        type_line("arm throttle force")
        soft_assert(out.wait(r"^ARMED", "ARMED"), "arm throttle force: not armed")
        type_line("disarm")
        soft_assert(out.wait(r"^DISARMED", "DISARMED"), "disarm: not disarmed")
        # The estimator has long converged by now (the gyro calibration and the parameters
        # took seconds).
        checked = 0
        for _ in range(5):
            type_line("status ATTITUDE")
            m = out.wait(r"ATTITUDE \{time_boot_ms : (\d+), roll : ([-0-9.e]+), pitch : ([-0-9.e]+), "
                         r"yaw : ([-0-9.e]+)", "status ATTITUDE")
            if not m:
                break
            roll, pitch, yaw = (float(m.group(k)) for k in (2, 3, 4))
            soft_assert(all(math.isfinite(v) and abs(v) <= math.pi for v in (roll, pitch, yaw)),
                        "ATTITUDE %r" % m.group(0))
            soft_assert(abs(math.degrees(roll) - ROLL_DEG) < 3 and abs(math.degrees(pitch) - PITCH_DEG) < 3
                        and abs(math.degrees(yaw)) < 5,
                        "ATTITUDE at %s ms: roll %.1f pitch %.1f yaw %.1f deg, the board at %.0f %.0f 0"
                        % (m.group(1), math.degrees(roll), math.degrees(pitch), math.degrees(yaw), ROLL_DEG,
                           PITCH_DEG))
            checked += 1
            time.sleep(1)
        soft_assert(checked == 5, "%d ATTITUDE shown" % checked)
        # COMPASS_DEC as sent (it was once kept in hundredths of a degree: 0.19999 came back
        # and MAVProxy said "Failed to set" after its three attempts, a second apart).
        type_line("param set COMPASS_DEC 0.2")
        soft_assert(out.wait(r"AP: saved", "the board's 'saved' of COMPASS_DEC"), "COMPASS_DEC not saved")
        failed = out.wait(r"Failed to set COMPASS_DEC.*", "a failure", timeout_s=5, required=False)
        soft_assert(failed is None, "MAVProxy: %s" % (failed and failed.group(0)))
        type_line("param show COMPASS_DEC")
        m = out.wait(r"COMPASS_DEC\s+([-0-9.e]+)", "COMPASS_DEC's new value")
        soft_assert(m and abs(float(m.group(1)) - 0.2) < 1e-6, "COMPASS_DEC %s after set, 0.2" % (m and m.group(1)))
        type_line("status ATTITUDE")
        m = out.wait(r"ATTITUDE \{time_boot_ms : (\d+), roll : ([-0-9.e]+), pitch : ([-0-9.e]+), "
                     r"yaw : ([-0-9.e]+)", "status ATTITUDE after COMPASS_DEC")
        soft_assert(m and abs(math.degrees(float(m.group(4)) - 0.2)) < 3,
                    "ATTITUDE yaw after COMPASS_DEC 0.2: %s rad" % (m and m.group(4)))
        print("# MAVProxy: parameters fetched, RLL2SRV_P and COMPASS_DEC set and saved, MANUAL> shown, the modes set, arming refused "
              "with its reason, forced, disarmed; %d ATTITUDE checked" % checked)
    finally:
        session.stop()


if __name__ == "__main__":
    main()
    sys.exit(finish("MAVProxy session", "MAVProxy showed the simulated board's parameters and attitude"))
