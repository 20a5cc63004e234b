#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Position and home as a ground station sees them: the firmware in apm25sim with the u-blox
and MS5611 models on a flight path, its MAVLink stream decoded by pymavlink.

    build/venv/bin/python test/mavlink/position_flight.py --tools build --work DIR

The path (the `rest` scenario's IMU columns with n,e,d columns added: the position models
read those, the attitude is not what is tested here): 12 s still at the origin (the GPS's
first fix at 3 s, home), then a take-off run at 3 m/s^2 to 18 m/s, a climb at 2 m/s to 40 m,
a right-hand circle of 80 m radius, a descent at 1 m/s; a 50 m GPS glitch from 40 to 42 s.
A ground station's bytes at 2 s (--input): its HEARTBEAT (the board switches to MAVLink),
MAV_CMD_GET_HOME_POSITION and MAV_CMD_DO_SET_HOME "here", both before any fix. Checks:
  - both commands answered FAILED (no home, no position yet);
  - "home: set at ..." said once (STATUSTEXT), one HOME_POSITION, within 3 m of the origin;
  - GLOBAL_POSITION_INT within 3 m of the truth at its time_boot_ms over the whole flight,
    the glitch included; relative_alt within 1.5 m RMS of the truth's height;
  - the glitch said and its end said (the GPS driver's lines);
  - GPS_RAW_INT 3D with 10 satellites, SYS_STATUS's GPS bit present and healthy after the fix;
  - GLOBAL_POSITION_INT's ground speed within 0.5 m/s of the truth's in steady flight, and
    VFR_HUD at 4 Hz;
  - no sample missed (no "overrun" STATUSTEXT).
Then a second run, 22 s of the same path, with the ground station's bytes at 8 s (home set
from the GPS at ~7 s): MAV_CMD_DO_SET_HOME at a place 100 m south and 28 m below the origin,
then MAV_CMD_REQUEST_MESSAGE 242 (a third command in the same burst would overflow the
core's 64-byte receive ring while the first waits; a ground station waits for each ACK):
both ACCEPTED, the new home said ("ground station"), the last HOME_POSITION that place, the
position 100 m further north of it and the height above it 28 m more than the truth's
(within 3 m: the barometer's datum is the GPS's height at the first fix).
Exit 1 with every failure listed.
"""
import math
import os
import subprocess
import sys

from pymavlink.dialects.v20 import common as mavlink2

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

SECONDS = 60.0
HOME = (7.135045, -73.119421, 1028.0)  # apm25sim's default --home
GLITCH = "gps:glitch=50@40-42"
RADIUS_M, SPEED_M_S = 80.0, 18.0
WGS84_A, WGS84_F = 6378137.0, 1.0 / 298.257223563
GEOID_SEPARATION_M = 10.0  # sim/models/Geodesy.h: the ellipsoid height is hMSL + 10 m


def path(t):
    """The truth: (north, east, down) m from the origin and the ground speed, at t seconds."""
    # Integrated in closed form piecewise: still, accelerate, straight, circle.
    t0, accel = 12.0, 3.0
    t_full = t0 + SPEED_M_S / accel  # 18 s
    run_m = 0.5 * accel * (t_full - t0) ** 2
    t_turn = 24.0
    if t < t0:
        n, e, v = 0.0, 0.0, 0.0
    elif t < t_full:
        n, e, v = 0.5 * accel * (t - t0) ** 2, 0.0, accel * (t - t0)
    elif t < t_turn:
        n, e, v = run_m + SPEED_M_S * (t - t_full), 0.0, SPEED_M_S
    else:
        n_turn = run_m + SPEED_M_S * (t_turn - t_full)
        a = SPEED_M_S / RADIUS_M * (t - t_turn)  # heading, rad, turning right (east)
        n, e, v = n_turn + RADIUS_M * math.sin(a), RADIUS_M * (1.0 - math.cos(a)), SPEED_M_S
    if t < 14.0:
        up = 0.0
    elif t < 34.0:
        up = 2.0 * (t - 14.0)
    elif t < 45.0:
        up = 40.0
    else:
        up = max(40.0 - (t - 45.0), 0.0)
    return n, e, -up, v


def write_flight(tools, work):
    rest = scenario_file(tools, work, "rest")
    out = os.path.join(work, "flight_ned.csv")
    with open(rest) as src, open(out, "w") as dst:
        for i, line in enumerate(src):
            line = line.rstrip("\n")
            if i == 0:
                dst.write(line + ",n,e,d\n")
                continue
            t = float(line.split(",", 1)[0])
            n, e, d, _ = path(t)
            dst.write("%s,%.4f,%.4f,%.4f\n" % (line, n, e, d))
    return out


def metres_per_degree():
    """The flat map at the origin (lib/Nav/Wgs84.h, as the simulator's truth)."""
    lat = math.radians(HOME[0])
    h = HOME[2] + GEOID_SEPARATION_M
    e2 = WGS84_F * (2.0 - WGS84_F)
    w = 1.0 - e2 * math.sin(lat) ** 2
    north = WGS84_A * (1.0 - e2) / (w * math.sqrt(w)) + h
    east = (WGS84_A / math.sqrt(w) + h) * math.cos(lat)
    return math.radians(north), math.radians(east)


def ground_station_bytes(work, name, commands):
    """A file of a ground station's HEARTBEAT and COMMAND_LONGs (command, params 1-7)."""
    gcs = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
    frames = [gcs.heartbeat_encode(mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0)]
    frames += [gcs.command_long_encode(1, 1, c, 0, *p) for c, p in commands]
    path = os.path.join(work, name)
    with open(path, "wb") as f:
        f.write(b"".join(m.pack(gcs) for m in frames))
    return path


def fly(args, flight, seconds, gcs_path, input_at, *extra):
    """The board on the path; its MAVLink messages by type."""
    r = subprocess.run([os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
                        "--trajectory", flight, "--seconds", str(seconds), "--input", gcs_path, "--input-at",
                        str(input_at)] + list(extra), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    soft_assert(r.returncode == 0, "apm25sim exited %d: %s" % (r.returncode, r.stderr.decode(errors="replace")[-500:]))
    start = r.stdout.find(b"\xfd")  # the text before the switch to MAVLink
    mav = mavlink2.MAVLink(None)
    mav.robust_parsing = True
    by_type = {}
    for m in (mav.parse_buffer(r.stdout[start:]) or []):
        by_type.setdefault(m.get_type(), []).append(m)
    return by_type


def check_ground_station_home(args, flight):
    south_m, below_m = 100.0, 28.0
    north_m_per_deg, _ = metres_per_degree()
    lat, lon, alt = HOME[0] - south_m / north_m_per_deg, HOME[1], HOME[2] - below_m
    gcs_path = ground_station_bytes(args.work, "gcs_home.bin", [
        (mavlink2.MAV_CMD_DO_SET_HOME, (0, 0, 0, 0, lat, lon, alt)),
        (mavlink2.MAV_CMD_REQUEST_MESSAGE, (242, 0, 0, 0, 0, 0, 0))])
    by_type = fly(args, flight, 22.0, gcs_path, 8.0)
    acks = [(a.command, a.result) for a in by_type.get("COMMAND_ACK", [])]
    accepted = mavlink2.MAV_RESULT_ACCEPTED
    soft_assert(acks == [(mavlink2.MAV_CMD_DO_SET_HOME, accepted), (mavlink2.MAV_CMD_REQUEST_MESSAGE, accepted)],
                "the ground station's home: ACKs %r" % acks)
    texts = [m.text for m in by_type.get("STATUSTEXT", [])]
    soft_assert(any(t.startswith("home: set at") for t in texts) and "ground station)" in "".join(texts),
                "the ground station's home not said: %r" % texts)
    homes = by_type.get("HOME_POSITION", [])
    # COMMAND_LONG carries degrees as a float: 24 bits, 5e-7 deg at 7 deg, 7e-6 deg at 73 deg.
    soft_assert(homes and abs(homes[-1].latitude - lat * 1e7) <= 10 and abs(homes[-1].longitude - lon * 1e7) <= 80
                and abs(homes[-1].altitude - alt * 1e3) <= 10,
                "the last HOME_POSITION %r, expected %.7f %.7f %.2f" % (homes[-1:] and homes[-1], lat, lon, alt))
    late = [p for p in by_type.get("GLOBAL_POSITION_INT", []) if p.time_boot_ms > 9000]
    errs = [abs(p.relative_alt * 1e-3 - (-path(p.time_boot_ms * 1e-3)[2] + below_m)) for p in late]
    soft_assert(late and max(errs) < 3.0, "height above the ground station's home off by up to %.2f m" %
                (max(errs) if errs else -1))
    north_errs = [abs((p.lat * 1e-7 - lat) * north_m_per_deg - (path(p.time_boot_ms * 1e-3)[0] + south_m))
                  for p in late]
    print("ground station's home: height above it within %.2f m, %d HOME_POSITION" % (max(errs) if errs else -1,
                                                                                      len(homes)))
    soft_assert(north_errs and max(north_errs) < 3.0, "north of the new home off by %.2f m" % max(north_errs))


def main():
    args = tools_and_work()
    flight = write_flight(args.tools, args.work)
    gcs_path = ground_station_bytes(args.work, "gcs.bin", [
        (mavlink2.MAV_CMD_GET_HOME_POSITION, (0, 0, 0, 0, 0, 0, 0)),
        (mavlink2.MAV_CMD_DO_SET_HOME, (1, 0, 0, 0, 0, 0, 0))])
    by_type = fly(args, flight, SECONDS, gcs_path, 2.0, "--fault", GLITCH)
    texts = [m.text for m in by_type.get("STATUSTEXT", [])]

    acks = {a.command: a.result for a in by_type.get("COMMAND_ACK", [])}
    soft_assert(acks.get(mavlink2.MAV_CMD_GET_HOME_POSITION) == mavlink2.MAV_RESULT_FAILED,
                "GET_HOME_POSITION before a fix: %r" % acks.get(mavlink2.MAV_CMD_GET_HOME_POSITION))
    soft_assert(acks.get(mavlink2.MAV_CMD_DO_SET_HOME) == mavlink2.MAV_RESULT_FAILED,
                "DO_SET_HOME here before a fix: %r" % acks.get(mavlink2.MAV_CMD_DO_SET_HOME))

    north_m_per_deg, east_m_per_deg = metres_per_degree()
    home_lines = [t for t in texts if t.startswith("home: set at")]
    soft_assert(len(home_lines) == 1, "home said %d times: %r" % (len(home_lines), home_lines))
    homes = by_type.get("HOME_POSITION", [])
    soft_assert(len(homes) == 1, "%d HOME_POSITION" % len(homes))
    for h in homes[:1]:
        dn = (h.latitude * 1e-7 - HOME[0]) * north_m_per_deg
        de = (h.longitude * 1e-7 - HOME[1]) * east_m_per_deg
        soft_assert(math.hypot(dn, de) < 3.0 and abs(h.altitude * 1e-3 - HOME[2]) < 5.0,
                    "home %.2f m N %.2f m E, %.2f m MSL" % (dn, de, h.altitude * 1e-3))

    positions = by_type.get("GLOBAL_POSITION_INT", [])
    soft_assert(len(positions) > 4 * 40, "%d GLOBAL_POSITION_INT in %g s" % (len(positions), SECONDS))
    worst, worst_t, height_sq, glitch_worst = 0.0, 0.0, [], 0.0
    for p in positions:
        t = p.time_boot_ms * 1e-3
        n, e, d, _ = path(t)
        err = math.hypot((p.lat * 1e-7 - HOME[0]) * north_m_per_deg - n, (p.lon * 1e-7 - HOME[1]) * east_m_per_deg - e)
        if err > worst:
            worst, worst_t = err, t
        if 40.0 <= t <= 43.0:
            glitch_worst = max(glitch_worst, err)
        height_sq.append((p.relative_alt * 1e-3 + d) ** 2)
    rms_height = math.sqrt(sum(height_sq) / len(height_sq)) if height_sq else float("nan")
    print("position: worst %.2f m at %.1f s (%.2f m in the glitch), height above home %.2f m RMS, %d reports"
          % (worst, worst_t, glitch_worst, rms_height, len(positions)))
    soft_assert(worst <= 3.0, "position %.2f m from the truth at %.1f s" % (worst, worst_t))
    soft_assert(rms_height <= 1.5, "height above home %.2f m RMS from the truth" % rms_height)

    soft_assert(any(t.startswith("gps: glitch") and "over" not in t for t in texts), "the glitch not said: %r" % texts)
    soft_assert(any("glitch over" in t for t in texts), "the glitch's end not said")

    raws = [g for g in by_type.get("GPS_RAW_INT", []) if g.time_usec > 20e6]
    soft_assert(raws and all(g.fix_type == 3 and g.satellites_visible == 10 for g in raws),
                "GPS_RAW_INT after 20 s: %r" % [(g.fix_type, g.satellites_visible) for g in raws[:3]])
    statuses = by_type.get("SYS_STATUS", [])[10:]
    gps_bit = mavlink2.MAV_SYS_STATUS_SENSOR_GPS
    soft_assert(statuses and all(s.onboard_control_sensors_present & gps_bit for s in statuses),
                "SYS_STATUS without the GPS present")
    healthy = [bool(s.onboard_control_sensors_health & gps_bit) for s in statuses]
    soft_assert(healthy.count(True) >= len(healthy) - 3, "SYS_STATUS GPS health %r" % healthy)

    huds = by_type.get("VFR_HUD", [])
    speeds = []
    for g in by_type.get("GLOBAL_POSITION_INT", []):
        t = g.time_boot_ms * 1e-3
        if 20.0 <= t <= 39.0 or 44.0 <= t <= 58.0:
            speeds.append(abs(math.hypot(g.vx, g.vy) * 0.01 - path(t)[3]))
    soft_assert(speeds and max(speeds) < 0.5, "ground speed off by up to %.2f m/s" % (max(speeds) if speeds else -1))
    soft_assert(len(huds) > 4 * 40, "%d VFR_HUD in %g s" % (len(huds), SECONDS))

    soft_assert(not any("overrun" in t for t in texts), "samples missed: %r" % [t for t in texts if "overrun" in t])
    check_ground_station_home(args, flight)
    sys.exit(finish("position flight", "position and home as a ground station sees them"))


if __name__ == "__main__":
    main()
