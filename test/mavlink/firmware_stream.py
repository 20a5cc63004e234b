#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The firmware's MAVLink stream, decoded by pymavlink as a ground station would (issue 12).

    build/venv/bin/python test/mavlink/firmware_stream.py --tools build --work DIR

Runs build/firmware.elf in build/apm25sim twice on the same 12 s of the tilt tour with the
HMC5883L unplugged from 6 to 7 s: once with `mode csv` typed at 3 s (the reference angles,
time-stamped), once with `mode mavlink` typed at 3 s. Checks, for the MAVLink run:
  - everything after the reply to `mode mavlink` decodes: no bad CRC, no stray byte;
  - HEARTBEAT about once a second (every ~50 ATTITUDE), a fixed wing ArduPilot in MANUAL (no receiver);
  - RC_CHANNELS and SERVO_OUTPUT_RAW at 5 Hz (no receiver: no channels, outputs at trim);
  - SCALED_PRESSURE with them: the standard atmosphere's pressure and temperature at the field;
  - ATTITUDE at the output rate (50 Hz: time_boot_ms 20 +- 6 ms apart, 20 on average, none missing), its
    roll, pitch and yaw equal to the csv run's at the same time_boot_ms within 0.01 rad;
  - SYS_STATUS each second, the compass' health bit cleared while it is unplugged, the
    barometer present, enabled and healthy;
  - STATUSTEXT for the fault ("HMC5883L", severity error) and its recovery.
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

RATE_HZ = 50
SECONDS = 12
FAULT = "mag:absent@6-7"


def run(tools, work, trajectory, command):
    path = os.path.join(work, command.replace(" ", "_") + ".in")
    with open(path, "w") as f:
        f.write(command + "\n")
    r = subprocess.run([os.path.join(tools, "apm25sim"), "--elf", os.path.join(tools, "firmware.elf"),
                        "--trajectory", trajectory, "--seconds", str(SECONDS), "--input", path,
                        "--input-at", "3", "--fault", FAULT], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if r.returncode != 0:
        sys.exit("apm25sim exited %d: %s" % (r.returncode, r.stderr.decode(errors="replace")[-500:]))
    return r.stdout


def csv_angles(out):
    """time_ms -> (roll, pitch, heading) in degrees, from the csv rows after the header."""
    rows = {}
    text = out.decode(errors="replace")
    body = text[text.find("t_ms,roll,pitch,yaw"):]
    for line in body.splitlines()[1:]:
        parts = line.split(",")
        if len(parts) == 4 and not line.startswith("#"):
            try:
                rows[int(parts[0])] = tuple(float(p) for p in parts[1:])
            except ValueError:
                pass
    return rows


def angle_diff_rad(a, b):
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "tilt_tour")

    reference = csv_angles(run(args.tools, args.work, trajectory, "mode csv"))
    soft_assert(len(reference) > 400, "csv run: %d rows" % len(reference))
    out = run(args.tools, args.work, trajectory, "mode mavlink")

    # Text until the reply to the command (which is itself the first STATUSTEXT), then
    # nothing but frames.
    start = out.find(b"\xfd")
    if not soft_assert(start > 0 and out[:start].count(b"roll:") > 20, "no MAVLink after the text lines"):
        return
    mav = mavlink2.MAVLink(None)
    mav.robust_parsing = True  # a bad frame comes back as BAD_DATA instead of raising
    msgs = mav.parse_buffer(out[start:]) or []
    bad = [m for m in msgs if m.get_type() == "BAD_DATA"]
    soft_assert(not bad and mav.total_receive_errors == 0,
          "%d bad frames, %d receive errors: %r" % (len(bad), mav.total_receive_errors, bad[:3]))
    types = [m.get_type() for m in msgs]
    soft_assert(set(types) <= {"HEARTBEAT", "ATTITUDE", "SYS_STATUS", "STATUSTEXT", "RC_CHANNELS", "SERVO_OUTPUT_RAW",
                               "SCALED_PRESSURE", "GPS_RAW_INT", "GLOBAL_POSITION_INT", "VFR_HUD", "HOME_POSITION",
                               "SYSTEM_TIME", "MISSION_CURRENT"},
                "unexpected: %r" % set(types))
    soft_assert(msgs and msgs[0].get_type() == "STATUSTEXT" and msgs[0].text == "mode mavlink",
          "first frame: the reply to the command, got %r" % (msgs[:1],))
    seqs = [m.get_seq() for m in msgs]
    soft_assert(all((b - a) % 256 == 1 for a, b in zip(seqs, seqs[1:])), "sequence numbers with gaps")

    # ATTITUDE at the output rate, equal to the csv angles.
    att = [m for m in msgs if m.get_type() == "ATTITUDE"]
    span_s = SECONDS - 3
    soft_assert(len(att) >= (span_s - 0.2) * RATE_HZ, "%d ATTITUDE in %d s (%d Hz expected)" % (len(att), span_s, RATE_HZ))
    steps = [b.time_boot_ms - a.time_boot_ms for a, b in zip(att, att[1:])]
    # time_boot_ms is millis() when the line is made: a line due on a step that corrects
    # the heading goes out one 5 ms step later (the pipeline keeps heavy work apart), plus
    # a millisecond of jitter; none missing (a missing one would leave a 35+ ms step).
    soft_assert(steps and all(abs(s - 1000 // RATE_HZ) <= 6 for s in steps), "ATTITUDE intervals %r" % sorted(set(steps)))
    soft_assert(steps and abs(sum(steps) / len(steps) - 1000 / RATE_HZ) < 0.2, "ATTITUDE mean interval off")
    compared = 0
    worst = 0.0
    # The row of the same sample: millis() is read when the step starts, which the work of
    # the pass before moves by up to ~1 ms across a millisecond's edge (the rows are 20 ms
    # apart, so +-1 ms names one row).
    for a in att:
        ref = next((reference[t] for t in (a.time_boot_ms, a.time_boot_ms - 1, a.time_boot_ms + 1)
                    if t in reference), None)
        if ref is None:
            continue
        compared += 1
        worst = max(worst, angle_diff_rad(a.roll, math.radians(ref[0])), angle_diff_rad(a.pitch, math.radians(ref[1])),
                    angle_diff_rad(a.yaw, math.radians(ref[2])))
    soft_assert(compared >= 0.95 * len(att), "only %d of %d ATTITUDE matched a csv row by time" % (compared, len(att)))
    soft_assert(worst <= 0.01, "ATTITUDE differs from the csv angles by %.4f rad" % worst)
    soft_assert(any(abs(a.rollspeed) > 0.2 for a in att), "rollspeed never shows the tour's roll rate")

    # HEARTBEAT each second: ~50 ATTITUDE between two.
    hb_at = [i for i, m in enumerate(msgs) if m.get_type() == "HEARTBEAT"]
    soft_assert(len(hb_at) >= span_s - 1, "%d HEARTBEAT in %d s" % (len(hb_at), span_s))
    for a, b in zip(hb_at, hb_at[1:]):
        n = sum(1 for m in msgs[a:b] if m.get_type() == "ATTITUDE")
        soft_assert(45 <= n <= 55, "%d ATTITUDE between two HEARTBEAT (one a second expected)" % n)
    for i in hb_at:
        hb = msgs[i]
        soft_assert(hb.type == mavlink2.MAV_TYPE_FIXED_WING and hb.autopilot == mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA
                    and hb.custom_mode == 0 and hb.mavlink_version == 3, "HEARTBEAT %r" % hb)

    # The radio and servo pages' streams, 5 Hz: no receiver, so no channels, outputs at trim
    # and the throttle (OUT3) at its failsafe value, SERVO3_MIN.
    rc = [m for m in msgs if m.get_type() == "RC_CHANNELS"]
    servo = [m for m in msgs if m.get_type() == "SERVO_OUTPUT_RAW"]
    soft_assert(abs(len(rc) - 5 * span_s) <= 5 and len(servo) == len(rc),
                "%d RC_CHANNELS, %d SERVO_OUTPUT_RAW in %d s (5 Hz expected)" % (len(rc), len(servo), span_s))
    soft_assert(all(m.chancount == 0 for m in rc), "RC_CHANNELS with channels and no receiver")
    soft_assert(all([m.servo1_raw, m.servo2_raw, m.servo3_raw, m.servo4_raw] == [1500, 1500, 1000, 1500] for m in servo),
                "SERVO_OUTPUT_RAW not at trim: %r" % servo[:1])

    # SCALED_PRESSURE with them: the MS5611 model at the field (1028 m: 895.7 hPa, 8.32 degC).
    baro = [m for m in msgs if m.get_type() == "SCALED_PRESSURE"]
    soft_assert(len(baro) == len(rc), "%d SCALED_PRESSURE for %d RC_CHANNELS" % (len(baro), len(rc)))
    soft_assert(all(abs(m.press_abs - 895.7) < 0.5 and abs(m.temperature - 832) <= 2 and m.press_diff == 0
                    for m in baro), "SCALED_PRESSURE %r" % baro[:1])

    # SYS_STATUS: the compass bit follows the fault; the barometer's bits are set throughout.
    status = [m for m in msgs if m.get_type() == "SYS_STATUS"]
    soft_assert(len(status) == len(hb_at), "%d SYS_STATUS for %d HEARTBEAT" % (len(status), len(hb_at)))
    mag = mavlink2.MAV_SYS_STATUS_SENSOR_3D_MAG
    soft_assert(any(not (s.onboard_control_sensors_health & mag) for s in status), "compass never unhealthy")
    soft_assert(status and status[-1].onboard_control_sensors_health & mag, "compass not healthy again at the end")
    soft_assert(all(0 < s.load <= 1000 for s in status), "load %r" % [s.load for s in status])
    pressure = mavlink2.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
    soft_assert(all(s.onboard_control_sensors_present & s.onboard_control_sensors_enabled &
                    s.onboard_control_sensors_health & pressure for s in status), "barometer bits %r" % [
                        (s.onboard_control_sensors_present, s.onboard_control_sensors_health) for s in status])

    # STATUSTEXT for the fault and its recovery.
    texts = [m for m in msgs if m.get_type() == "STATUSTEXT"]
    soft_assert(any("HMC5883L" in t.text and t.severity == mavlink2.MAV_SEVERITY_ERROR for t in texts),
          "no error STATUSTEXT for the unplugged compass: %r" % [t.text for t in texts])
    soft_assert(any(t.text.startswith("recovered") and "HMC5883L" in t.text for t in texts), "no recovery STATUSTEXT")
    print("# %d frames: %d ATTITUDE (worst %.4f rad from csv), %d HEARTBEAT, %d SYS_STATUS, %d STATUSTEXT"
          % (len(msgs), len(att), worst, len(hb_at), len(status), len(texts)))


if __name__ == "__main__":
    main()
    sys.exit(finish("MAVLink stream", "pymavlink decoded the firmware's stream as expected"))
