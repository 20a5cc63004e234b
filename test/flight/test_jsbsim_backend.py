#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks of the JSBSim flight backend (sim/flight, issue 22), one group per run:

    build/venv/bin/python test/flight/test_jsbsim_backend.py GROUP --work DIR [--tools build]

GROUP is one of:
  protocol      the servo packet parser and the JSON reply against ArduPilot's SITL JSON
                readme (layout, magic, newline framing, fields, frame count: repeat, reset,
                frame rate), the rc script, and one real UDP round trip to the backend
  trim          20 s with no pulses on any output from the trimmed start: height within 1 m,
                bank and pitch change within 1 deg, airspeed within 0.5 m/s; the propeller's
                vibration has the stated amplitude and leaves the flight itself alone; the
                aircraft's lift and drag tables are make_aero_tables.py's
  signs         OUT1 above 1500 rolls right, below rolls left; OUT2 above its trim pitches the
                nose up; OUT4 above 1500 yaws the nose right; more OUT3 is more speed; a
                positive upset moment rolls right, and only from its start time; the mixed
                airframes (--airframe): the right elevon up and the left down roll right,
                the left ruddervator up and the right down yaw right, each pair up pitches up
  trajectory    a flown turn as a trajectory file: integrating its gyro reproduces its truth
                quaternion, its specific force rotated to earth plus g is the velocity's
                derivative in the true-state log, level flight reads -g on z, the turn holds 30 deg of bank with
                |f| = g / cos(bank) and no side force, the field is the stated one; with
                --tools, build/replay runs on it and build/score scores it
  determinism   the same seed gives the same bytes (gzip included), another seed does not
Exit 1 with the reasons on any failure.
"""
import argparse
import csv
import gzip
import io
import json
import math
import os
import socket
import struct
import subprocess
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "test", "support"))
sys.path.insert(0, os.path.join(ROOT, "sim", "flight"))
from soft_assert import finish, soft_assert  # noqa: E402

import flightio  # noqa: E402
import flightmodel  # noqa: E402
import jsbsim_backend  # noqa: E402
import jsonlink  # noqa: E402

FLY = os.path.join(ROOT, "sim", "flight", "fly.py")
BACKEND = os.path.join(ROOT, "sim", "flight", "jsbsim_backend.py")
G = flightmodel.G0


def packet(frame_rate, frame_count, pwm, magic=18458):
    """Built here from the readme's layout, not with the module under test."""
    n = 16 if magic == 18458 else 32
    pwm = list(pwm) + [0] * (n - len(pwm))
    return struct.pack("<HHI%dH" % n, magic, frame_rate, frame_count, *pwm)


def check_protocol(work):
    rate, count, pwm = jsonlink.parse_servo_packet(packet(400, 7, [1100, 1200, 1300, 1400] + [1500] * 12))
    soft_assert((rate, count, pwm[:4], len(pwm)) == (400, 7, (1100, 1200, 1300, 1400), 16),
                "16-channel packet parsed as %r" % ((rate, count, pwm[:4], len(pwm)),))
    rate, count, pwm = jsonlink.parse_servo_packet(packet(1000, 2 ** 32 - 1, list(range(1000, 1032)), magic=29569))
    soft_assert((rate, count, pwm[31], len(pwm)) == (1000, 2 ** 32 - 1, 1031, 32), "32-channel packet parsed wrong")
    for bad, why in ((packet(400, 1, [1500])[:-2], "short"), (packet(400, 1, [1500]) + b"\0\0", "long"),
                     (struct.pack("<HHI16H", 18459, 400, 1, *([1500] * 16)), "wrong magic"),
                     (packet(0, 1, [1500]), "frame rate 0"), (b"", "empty")):
        try:
            jsonlink.parse_servo_packet(bad)
            soft_assert(False, "a %s packet was accepted" % why)
        except jsonlink.PacketError:
            pass

    script_path = os.path.join(work, "rc.csv")
    with open(script_path, "w") as f:
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n0.5,1600,1500,1200,1500,1500,1500,1500,1900\n"
                "1.0,,,,,,,,\n1.5,1400,1500,1200,1500,1500,1500,1500,1100\n")
    script = flightio.RcScript.load(script_path)
    soft_assert(script.at(0.2) is None, "rc before the first row is not 'no signal'")
    soft_assert(script.at(0.7)[0] == 1600, "rc row at 0.5 s not in force at 0.7 s")
    soft_assert(script.at(1.2) is None, "an empty rc row is not 'no signal'")
    soft_assert(script.at(2.0)[7] == 1100, "the last rc row does not hold")
    with open(os.path.join(work, "bad_rc.csv"), "w") as f:
        f.write("t,ch1,ch2\n0,1500,1500\n")
    try:
        flightio.RcScript.load(os.path.join(work, "bad_rc.csv"))
        soft_assert(False, "an rc file with a wrong header was accepted")
    except ValueError:
        pass

    backend = jsbsim_backend.Backend(jsbsim_backend.parse_args(["--quiet", "--rc", script_path]))
    trim_pwm = [round(w) for w in backend.model.trim.widths_us()]

    def ask(rate, count):
        return backend.handle(packet(rate, count, trim_pwm))

    first = ask(400, 0)
    text = first.decode("ascii")
    soft_assert(text.startswith("\n") and text.endswith("\n") and text.count("\n") == 2,
                "reply is not one JSON object between newlines: %r" % text[:40])
    obj = json.loads(text)
    for key in ("timestamp", "imu", "position", "velocity", "quaternion", "attitude", "airspeed", "velocity_wind"):
        soft_assert(key in obj, "reply without %s" % key)
    soft_assert(len(obj["imu"]["gyro"]) == 3 and len(obj["imu"]["accel_body"]) == 3, "imu vectors not of 3")
    soft_assert(abs(obj["timestamp"] - 1 / 400) < 1e-12, "first timestamp %r, not 1/400 s" % obj["timestamp"])
    soft_assert(abs(math.sqrt(sum(v * v for v in obj["quaternion"])) - 1) < 1e-9, "quaternion not unit")
    soft_assert(abs(obj["imu"]["accel_body"][2] + G * math.cos(obj["attitude"][1])) < 0.02,
                "trimmed level flight: accel_body z %.3f, not -g cos(pitch)" % obj["imu"]["accel_body"][2])
    soft_assert(abs(obj["position"][2] + 100.0) < 0.01, "position down %.3f, not -100 m" % obj["position"][2])
    soft_assert(abs(obj["airspeed"] - 18.0) < 0.05, "airspeed %.3f, not 18" % obj["airspeed"])
    soft_assert(obj.get("rc") == {}, "before the script's first row rc is %r, not {} (no signal)" % obj.get("rc"))
    soft_assert(ask(400, 0) == first, "a repeated frame count was not answered with the same reply")
    t1 = json.loads(ask(400, 1))["timestamp"]
    soft_assert(abs(t1 - 2 / 400) < 1e-12, "after a repeat, the next frame is at %r s, not 2/400" % t1)
    t2 = json.loads(ask(100, 2))["timestamp"]
    soft_assert(abs(t2 - t1 - 0.01) < 1e-12, "a 100 Hz frame advanced %r s, not 0.01" % (t2 - t1))
    for count in range(3, 300):
        obj = json.loads(ask(400, count))
    soft_assert(obj.get("rc", {}).get("rc_1") == 1600 and obj["rc"].get("rc_8") == 1900 and len(obj["rc"]) == 8,
                "rc at %.3f s is %r, not the script's row" % (obj["timestamp"], obj.get("rc")))
    soft_assert(backend.tracker.missed == 0, "frames counted missed: %d" % backend.tracker.missed)
    for count in range(300, 440):
        obj = json.loads(ask(400, count))
    soft_assert(obj.get("rc") == {}, "rc at %.3f s (the script's empty row) is %r, not {}" % (obj["timestamp"], obj.get("rc")))
    ask(400, 450)
    soft_assert(backend.tracker.missed == 10, "10 skipped counts gave missed = %d" % backend.tracker.missed)
    reset = json.loads(ask(400, 0))
    soft_assert(abs(reset["timestamp"] - 1 / 400) < 1e-12 and abs(reset["position"][0]) < 0.1,
                "frame count back to 0 did not restart the flight (t %r, north %r)"
                % (reset["timestamp"], reset["position"][0]))
    soft_assert(backend.handle(b"\x00" * 40) is None, "a packet with a bad magic got a reply")
    backend.close_outputs()
    silent = jsbsim_backend.Backend(jsbsim_backend.parse_args(["--quiet", "--rc", "none"]))
    soft_assert("rc" not in json.loads(silent.handle(packet(400, 0, trim_pwm))), "--rc none still sent an rc field")
    silent.close_outputs()
    # No pitot: the replies carry no airspeed (the field is optional), the rest unchanged.
    bare = jsbsim_backend.Backend(jsbsim_backend.parse_args(["--quiet", "--rc", script_path, "--no-airspeed"]))
    bare_obj = jsonlink.parse_reply(bare.handle(packet(400, 0, trim_pwm)))
    soft_assert("airspeed" not in bare_obj, "--no-airspeed still sent an airspeed")
    soft_assert(bare_obj["position"] == json.loads(first)["position"], "--no-airspeed changed the flight")
    bare.close_outputs()

    # One real round trip over UDP: the reply goes back to the sender's address and port.
    port_file = os.path.join(work, "port")
    if os.path.exists(port_file):
        os.remove(port_file)  # a previous run's port
    proc = subprocess.Popen([sys.executable, BACKEND, "--quiet", "--port", "0", "--port-file", port_file,
                             "--seconds", "0.01", "--idle-timeout", "20"])
    try:
        for _ in range(3000):
            if os.path.exists(port_file) and open(port_file).read().endswith("\n"):
                break
            if proc.poll() is not None:
                break
            time.sleep(0.01)
        port = int(open(port_file).read())
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.settimeout(20)
        replies = []
        for count in range(4):
            sock.sendto(packet(400, count, trim_pwm), ("127.0.0.1", port))
            replies.append(json.loads(sock.recv(4096)))
        sock.close()
        soft_assert(abs(replies[-1]["timestamp"] - 0.01) < 1e-12, "UDP: 4 frames at 400 Hz end at %r s"
                    % replies[-1]["timestamp"])
        soft_assert(replies[0]["rc"]["rc_3"] == trim_pwm[2], "default pilot: throttle %r, not the trim %d"
                    % (replies[0]["rc"]["rc_3"], trim_pwm[2]))
        soft_assert(proc.wait(timeout=30) == 0, "backend exit status %r after --seconds" % proc.returncode)
    finally:
        if proc.poll() is None:
            proc.kill()


def fly_model(model, seconds, widths):
    for _ in range(int(round(seconds * 400))):
        model.set_widths(widths)
        model.step(1 / 400)
    return model.state()


def check_aero_tables():
    """The XML's lift and drag tables are what make_aero_tables.py computes from the cited
    coefficients (a coefficient edited in one place and not the other fails here)."""
    import xml.etree.ElementTree as et
    import make_aero_tables
    root = et.parse(os.path.join(ROOT, "sim", "flight", "aircraft", "rascal110", "rascal110.xml")).getroot()
    for name, formula in (("aero/force/lift_alpha", make_aero_tables.lift), ("aero/force/drag_alpha", make_aero_tables.drag)):
        function = [f for f in root.iter("function") if f.get("name") == name]
        if not soft_assert(len(function) == 1, "no function %s in the aircraft" % name):
            continue
        values = [float(v) for v in function[0].find(".//tableData").text.split()]
        pairs = list(zip(values[0::2], values[1::2]))
        worst = max(abs(value - formula(alpha)) for alpha, value in pairs)
        soft_assert(len(pairs) > 50 and worst < 1e-3, "%s: %d rows, off the formula by %.4f" % (name, len(pairs), worst))


def check_trim(work):
    check_aero_tables()
    model = flightmodel.FlightModel()
    start = model.state()
    worst = {"height": 0.0, "roll": 0.0, "pitch": 0.0, "speed": 0.0}
    for _ in range(20 * 50):
        s = fly_model(model, 0.02, [0] * 16)
        worst["height"] = max(worst["height"], abs(s["position"][2] - start["position"][2]))
        worst["roll"] = max(worst["roll"], abs(math.degrees(s["euler"][0])))
        worst["pitch"] = max(worst["pitch"], abs(math.degrees(s["euler"][1] - start["euler"][1])))
        worst["speed"] = max(worst["speed"], abs(s["airspeed"] - start["airspeed"]))
    soft_assert(worst["height"] < 1.0, "trim: height changed by %.2f m in 20 s" % worst["height"])
    soft_assert(worst["roll"] < 1.0, "trim: bank reached %.2f deg" % worst["roll"])
    soft_assert(worst["pitch"] < 1.0, "trim: pitch moved %.2f deg" % worst["pitch"])
    soft_assert(worst["speed"] < 0.5, "trim: airspeed moved %.2f m/s" % worst["speed"])
    soft_assert(model.trim.residual < 1e-3, "trim residual %.2e" % model.trim.residual)
    # Propeller vibration: at the IMU only, of the stated amplitude, not in the dynamics.
    shaken = flightmodel.FlightModel(vibration_m_s2=2.0)
    still = flightmodel.FlightModel()
    trim_widths = [round(w) for w in still.trim.widths_us()]
    ays, azs, same = [], [], True
    for _ in range(400):
        a, b = fly_model(shaken, 1 / 400, trim_widths), fly_model(still, 1 / 400, trim_widths)
        ays.append(a["accel"][1] - b["accel"][1])
        azs.append(a["accel"][2] - b["accel"][2])
        same = same and a["quat"] == b["quat"] and a["position"] == b["position"]
    rms = math.sqrt(sum(v * v for v in ays) / len(ays))
    soft_assert(abs(rms - 2.0 / math.sqrt(2)) < 0.05, "vibration 2 m/s^2: y rms %.3f, not 1.414" % rms)
    soft_assert(abs(sum(azs) / len(azs)) < 0.05, "vibration has a mean of %.3f m/s^2 on z" % (sum(azs) / len(azs)))
    soft_assert(same, "the vibration changed the flight itself")
    print("trim: throttle %.3f, OUT1..4 %s us, alpha %.2f deg; 20 s hands off: height %.3f m, bank %.3f deg,"
          " pitch %.3f deg, speed %.3f m/s" % (model.trim.throttle, [round(w) for w in model.trim.widths_us()],
                                                math.degrees(model.trim.alpha_rad), worst["height"], worst["roll"],
                                                worst["pitch"], worst["speed"]))


def check_signs(work):
    model = flightmodel.FlightModel()
    trim = [round(w) for w in model.trim.widths_us()]

    def pulse(channel, width, seconds):
        model.reset()
        widths = list(trim)
        widths[channel] = width
        return fly_model(model, seconds, widths)

    right = pulse(0, 2000, 1.0)
    left = pulse(0, 1000, 1.0)
    soft_assert(math.degrees(right["euler"][0]) > 20 and right["gyro"][0] > 0,
                "OUT1 2000 us for 1 s: bank %.1f deg, p %.2f rad/s (want right roll)"
                % (math.degrees(right["euler"][0]), right["gyro"][0]))
    soft_assert(math.degrees(left["euler"][0]) < -20, "OUT1 1000 us: bank %.1f deg" % math.degrees(left["euler"][0]))
    up = pulse(1, trim[1] + 200, 0.5)
    down = pulse(1, trim[1] - 200, 0.5)
    pitch0 = math.degrees(model.trim.alpha_rad)
    soft_assert(math.degrees(up["euler"][1]) > pitch0 + 3 and up["gyro"][1] > 0,
                "OUT2 trim+200 us: pitch %.1f deg, q %.2f (want nose up)" % (math.degrees(up["euler"][1]), up["gyro"][1]))
    soft_assert(math.degrees(down["euler"][1]) < pitch0 - 3, "OUT2 trim-200 us: pitch %.1f deg"
                % math.degrees(down["euler"][1]))
    yaw = pulse(3, 2000, 0.5)
    soft_assert(yaw["gyro"][2] > 0.05, "OUT4 2000 us: yaw rate %.3f rad/s (want nose right)" % yaw["gyro"][2])
    upset = flightmodel.FlightModel(upsets=[(0.5, 0.5, 20.0)])
    calm = fly_model(upset, 0.5, trim)
    after = fly_model(upset, 1.5, trim)
    soft_assert(abs(math.degrees(calm["euler"][0])) < 0.5 and math.degrees(after["euler"][0]) > 30,
                "--upset 0.5,0.5,20: bank %.1f deg before, %.1f deg 1.5 s after (want calm, then > 30 right)"
                % (math.degrees(calm["euler"][0]), math.degrees(after["euler"][0])))
    # The mixed airframes (--airframe) by their geometry: the right elevon up and the left
    # down roll right, both up pitch up; the left ruddervator up and the right down yaw the
    # nose right, both up pitch up; a pair with a width missing holds its surfaces.
    def mixed(airframe, changes, seconds):
        model.reset()
        widths = [1500, 1500, trim[2], 1500]
        for i, w in changes.items():
            widths[i] = w
        for _ in range(int(round(seconds * 400))):
            model.set_widths(flightmodel.unmix(airframe, widths))
            model.step(1 / 400)
        return model.state()

    soft_assert(flightmodel.unmix("elevons", [1250, 1750, 1100, 1600]) == [2000, 1500, 1100, 1600] and
                flightmodel.unmix("elevons", [1400, 1700, 1100, 1600]) == [1800, 1600, 1100, 1600] and
                flightmodel.unmix("vtail", [1300, 1700, 1100, 1450]) == [1300, 1650, 1100, 1750] and
                flightmodel.unmix("vtail", [1300, 1000, 1100, 2000]) == [1300, 1500, 1100, 1000] and
                flightmodel.unmix("vtail", [1300, 1700, 1100, 0]) == [1300, 0, 1100, 0] and
                flightmodel.unmix("elevons", [0, 1700, 1100]) == [0, 0, 1100, 0] and
                flightmodel.unmix("plain", [1300, 1700, 1100, 1450, 1900]) == [1300, 1700, 1100, 1450],
                "unmix: a pair's sum and difference, within full throw, held without a pulse")
    roll_right = mixed("elevons", {0: 1300, 1: 1700}, 1.0)
    elevons_up = mixed("elevons", {0: 1600, 1: 1600}, 0.5)
    yaw_right = mixed("vtail", {1: 1750, 3: 1250}, 0.5)
    vtail_up = mixed("vtail", {1: 1600, 3: 1600}, 0.5)
    soft_assert(math.degrees(roll_right["euler"][0]) > 20 and roll_right["gyro"][0] > 0,
                "elevons: left 1300, right 1700 us for 1 s: bank %.1f deg (want right)" % math.degrees(roll_right["euler"][0]))
    soft_assert(math.degrees(elevons_up["euler"][1]) > pitch0 + 3, "elevons: both 1600 us: pitch %.1f deg (want up)"
                % math.degrees(elevons_up["euler"][1]))
    soft_assert(yaw_right["gyro"][2] > 0.05, "vtail: left 1750, right 1250 us: yaw rate %.3f rad/s (want nose right)"
                % yaw_right["gyro"][2])
    soft_assert(math.degrees(vtail_up["euler"][1]) > pitch0 + 3, "vtail: both 1600 us: pitch %.1f deg (want up)"
                % math.degrees(vtail_up["euler"][1]))
    fast = pulse(2, 1600, 5.0)
    soft_assert(fast["airspeed"] > 19.0, "OUT3 1600 us for 5 s: airspeed %.2f m/s" % fast["airspeed"])
    print("signs: OUT1 2000 us 1 s -> bank %+.1f deg; 1000 us -> %+.1f deg; OUT2 +200 us 0.5 s -> pitch %+.1f deg;"
          " OUT4 2000 us -> r %+.2f rad/s" % (math.degrees(right["euler"][0]), math.degrees(left["euler"][0]),
                                              math.degrees(up["euler"][1]), yaw["gyro"][2]))


def read_trajectory(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        reader = csv.reader(f)
        header = next(reader)
        return header, [[float(v) for v in row] for row in reader]


def quat_mul(a, b):
    return (a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3], a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1], a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0])


def quat_angle_deg(a, b):
    dot = abs(sum(x * y for x, y in zip(a, b)))
    return math.degrees(2 * math.acos(min(1.0, dot)))


def fly(args, work, name, out, extra=()):
    cmd = [sys.executable, FLY, "--quiet", "--flight", name, "--out", out] + list(extra)
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    soft_assert(result.returncode == 0, "fly.py %s failed: %s" % (name, result.stdout[-500:]))
    return result.returncode == 0


def check_trajectory(args, work):
    path = os.path.join(work, "turn.csv")
    log = os.path.join(work, "turn_log.csv")
    if not fly(args, work, "turn", path, ["--seconds", "40", "--log", log]):
        return
    header, rows = read_trajectory(path)
    soft_assert(",".join(header) == flightio.TRAJECTORY_HEADER, "header %r" % header)
    dt = rows[1][0] - rows[0][0]
    soft_assert(abs(dt - 1 / 400) < 1e-6, "sample interval %.6f s, not 1/400" % dt)
    # Integrate the gyro (body rates, exact rotation per step at the mean rate) from the first truth.
    q = tuple(rows[0][10:14])
    worst = 0.0
    for prev, row in zip(rows, rows[1:]):
        h = row[0] - prev[0]
        w = [(prev[1 + i] + row[1 + i]) / 2 for i in range(3)]
        rate = math.sqrt(sum(v * v for v in w))
        if rate > 0:
            half = rate * h / 2
            s = math.sin(half) / rate
            q = quat_mul(q, (math.cos(half), w[0] * s, w[1] * s, w[2] * s))
        worst = max(worst, quat_angle_deg(q, row[10:14]))
    soft_assert(worst < 0.5, "integrated gyro drifts %.3f deg from the truth quaternion over 40 s" % worst)
    level = [r for r in rows if 1.0 <= r[0] <= 4.5]
    az_err = max(abs(r[6] + G * math.cos(math.asin(2 * (r[10] * r[12] - r[13] * r[11])))) for r in level)
    ay_max = max(abs(r[5]) for r in level)
    soft_assert(az_err < 0.03 and ay_max < 0.03,
                "level flight: az off -g cos(pitch) by %.3f, |ay| up to %.3f m/s^2" % (az_err, ay_max))
    mag = [math.sqrt(r[7] ** 2 + r[8] ** 2 + r[9] ** 2) for r in rows]
    soft_assert(max(abs(m - math.hypot(20.0, 45.0)) for m in mag) < 0.01, "field magnitude is not |(20, 0, 45)| uT")
    turn = [r for r in rows if 15.0 <= r[0] <= 40.0]
    banks = [math.degrees(math.atan2(2 * (r[10] * r[11] + r[12] * r[13]), 1 - 2 * (r[11] ** 2 + r[12] ** 2)))
             for r in turn]
    mean_bank = sum(banks) / len(banks)
    soft_assert(abs(mean_bank - 30) < 2 and min(banks) > 27 and max(banks) < 33,
                "turn: bank %.1f..%.1f deg, mean %.1f (want 30 held)" % (min(banks), max(banks), mean_bank))
    force = [math.sqrt(r[4] ** 2 + r[5] ** 2 + r[6] ** 2) for r in turn]
    mean_force = sum(force) / len(force)
    expect = G / math.cos(math.radians(mean_bank))
    soft_assert(abs(mean_force - expect) < 0.03 * expect, "turn: |f| %.2f, not g / cos(bank) = %.2f" % (mean_force, expect))
    side = max(abs(r[5]) for r in turn)
    soft_assert(side < 0.3, "turn: side force up to %.2f m/s^2 (not coordinated)" % side)
    with open(log) as f:
        state = list(csv.DictReader(f))
    # The specific force is the acceleration less gravity: R f + g = dv/dt (velocities from the log).
    velocity = [[float(s[k]) for k in ("vn_m_s", "ve_m_s", "vd_m_s")] for s in state]
    worst_force = 0.0
    for i in range(400, len(rows) - 1, 97):
        w, x, y, z = rows[i][10:14]
        f = rows[i][4:7]
        rot = ((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
               (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
               (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)))
        h = rows[i + 1][0] - rows[i - 1][0]
        for k in range(3):
            accel = (velocity[i + 1][k] - velocity[i - 1][k]) / h
            earth = sum(rot[k][j] * f[j] for j in range(3)) + (G if k == 2 else 0.0)
            worst_force = max(worst_force, abs(earth - accel))
    soft_assert(worst_force < 0.05, "R f + g differs from dv/dt by %.3f m/s^2" % worst_force)
    yaw = [float(s["yaw_deg"]) for s in state if 20.0 <= float(s["t"]) <= 30.0]
    turned = sum((b - a + 180) % 360 - 180 for a, b in zip(yaw, yaw[1:]))
    speed = sum(float(s["airspeed_m_s"]) for s in state if 20.0 <= float(s["t"]) <= 30.0) / \
        sum(1 for s in state if 20.0 <= float(s["t"]) <= 30.0)
    rate_expect = math.degrees(G * math.tan(math.radians(mean_bank)) / speed)
    soft_assert(abs(turned / 10.0 - rate_expect) < 0.05 * rate_expect,
                "turn rate %.2f deg/s, not g tan(bank) / V = %.2f" % (turned / 10.0, rate_expect))
    print("trajectory: R f + g = dv/dt within %.4f m/s^2" % worst_force)
    print("trajectory: gyro integration within %.4f deg over 40 s; turn bank %.2f deg (%.1f..%.1f), |f| %.2f m/s^2,"
          " turn rate %.2f deg/s at %.2f m/s" % (worst, mean_bank, min(banks), max(banks), mean_force, turned / 10, speed))
    if args.tools:
        replay = subprocess.run([os.path.join(args.tools, "replay"), "--trajectory", path],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        lines = replay.stdout.splitlines()
        soft_assert(replay.returncode == 0 and lines[:1] == ["t,roll,pitch,yaw"] and len(lines) > 1000,
                    "replay on the flight: exit %d, %d lines; %s" % (replay.returncode, len(lines), replay.stderr[-200:]))
        est = os.path.join(work, "turn_est.csv")
        with open(est, "w") as f:
            f.write(replay.stdout)
        score = subprocess.run([os.path.join(args.tools, "score"), "--trajectory", path, "--estimate", est],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        soft_assert(score.returncode == 0 and "total_rmse_deg=" in score.stdout,
                    "score on the flight: exit %d: %s" % (score.returncode, score.stdout + score.stderr))
        print("replay + score on the 40 s turn: " + score.stdout.strip())


def check_determinism(args, work):
    paths = [os.path.join(work, name) for name in ("a.csv.gz", "b.csv.gz", "c.csv.gz")]
    for path, seed in zip(paths, ("5", "5", "6")):
        if not fly(args, work, "gusty", path, ["--seconds", "8", "--seed", seed]):
            return
    data = [open(p, "rb").read() for p in paths]
    soft_assert(data[0] == data[1], "the same seed gave different trajectory bytes")
    soft_assert(data[0] != data[2], "seeds 5 and 6 gave the same gusty flight")
    rows = io.StringIO(gzip.decompress(data[0]).decode()).read().count("\n")
    soft_assert(rows == 8 * 400 + 2, "8 s at 400 Hz gave %d lines" % rows)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("group", choices=("protocol", "trim", "signs", "trajectory", "determinism"))
    p.add_argument("--work", required=True)
    p.add_argument("--tools", help="directory of build/replay and build/score")
    args = p.parse_args()
    os.makedirs(args.work, exist_ok=True)
    if args.group == "protocol":
        check_protocol(args.work)
    elif args.group == "trim":
        check_trim(args.work)
    elif args.group == "signs":
        check_signs(args.work)
    elif args.group == "trajectory":
        check_trajectory(args, args.work)
    else:
        check_determinism(args, args.work)
    return finish("flight " + args.group, "flight %s: all checks passed" % args.group)


if __name__ == "__main__":
    sys.exit(main())
