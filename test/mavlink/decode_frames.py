#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""pymavlink, as a ground station would, decodes the frames of test/mavlink/support/mavlink_frames.cpp.

    build/venv/bin/python test/mavlink/decode_frames.py PATH/TO/mavlink_frames

Fails (exit 1, with the reason) on a bad CRC, an unexpected message or a wrong field.
"""
import math
import os
import subprocess
import sys

from pymavlink.dialects.v20 import common as mavlink2

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from soft_assert import finish, soft_assert  # noqa: E402



def main():
    data = subprocess.run([sys.argv[1]], check=True, stdout=subprocess.PIPE).stdout
    mav = mavlink2.MAVLink(None)
    mav.robust_parsing = True  # bad frames come back as MAVLink_bad_data instead of raising
    msgs = mav.parse_buffer(data) or []
    bad = [m for m in msgs if m.get_type() == "BAD_DATA"]
    soft_assert(not bad, "bad frames: %r" % bad)
    soft_assert(mav.total_receive_errors == 0, "receive errors: %d" % mav.total_receive_errors)
    types = [m.get_type() for m in msgs]
    want = ["HEARTBEAT", "ATTITUDE", "SYS_STATUS", "STATUSTEXT", "STATUSTEXT", "STATUSTEXT", "STATUSTEXT",
            "HEARTBEAT", "PARAM_VALUE", "COMMAND_ACK", "RC_CHANNELS", "SERVO_OUTPUT_RAW",
            "GPS_RAW_INT", "GLOBAL_POSITION_INT", "VFR_HUD", "HOME_POSITION",
            "AUTOPILOT_VERSION", "MISSION_COUNT", "MISSION_ACK", "TIMESYNC", "SYSTEM_TIME",
            "MISSION_ITEM_INT", "MISSION_ITEM", "MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_CURRENT",
            "MISSION_ITEM_REACHED"]
    soft_assert(types == want, "message order %r, expected %r" % (types, want))
    if types != want:
        return
    seqs = [m.get_seq() for m in msgs]
    soft_assert(seqs == list(range(len(msgs))), "sequence numbers %r" % seqs)
    for m in msgs:
        soft_assert(m.get_srcSystem() == 1 and m.get_srcComponent() == 1, "source %d/%d" % (m.get_srcSystem(),
                                                                                     m.get_srcComponent()))
    hb = msgs[0]
    soft_assert(hb.type == mavlink2.MAV_TYPE_FIXED_WING and hb.autopilot == mavlink2.MAV_AUTOPILOT_ARDUPILOTMEGA,
          "heartbeat type/autopilot %d/%d" % (hb.type, hb.autopilot))
    flags = (mavlink2.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED | mavlink2.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED |
             mavlink2.MAV_MODE_FLAG_SAFETY_ARMED)
    stabilize = flags | mavlink2.MAV_MODE_FLAG_STABILIZE_ENABLED
    soft_assert(hb.system_status == mavlink2.MAV_STATE_ACTIVE and hb.base_mode == stabilize and hb.custom_mode == 2
                and hb.mavlink_version == 3, "heartbeat state %d base_mode %d custom_mode %d version %d"
                % (hb.system_status, hb.base_mode, hb.custom_mode, hb.mavlink_version))
    soft_assert(msgs[7].system_status == mavlink2.MAV_STATE_CRITICAL and msgs[7].custom_mode == 5
                and msgs[7].base_mode == stabilize & ~mavlink2.MAV_MODE_FLAG_SAFETY_ARMED,
                "second heartbeat: critical, FBWA (the failsafe glide), disarmed")
    # pymavlink's own mode names for an ArduPlane (what MAVProxy shows).
    from pymavlink import mavutil
    soft_assert(mavutil.mode_string_v10(hb) == "STABILIZE" and mavutil.mode_string_v10(msgs[7]) == "FBWA",
                "mode names %r %r" % (mavutil.mode_string_v10(hb), mavutil.mode_string_v10(msgs[7])))

    pv, ack, rc, servo = msgs[8:12]
    soft_assert(pv.param_id == "RLL2SRV_P" and abs(pv.param_value - 0.4) < 1e-6
                and pv.param_type == mavlink2.MAV_PARAM_TYPE_REAL32 and pv.param_count == 97 and pv.param_index == 1,
                "PARAM_VALUE %r" % pv)
    soft_assert(ack.command == mavlink2.MAV_CMD_PREFLIGHT_CALIBRATION and ack.result == mavlink2.MAV_RESULT_ACCEPTED
                and ack.target_system == 255 and ack.target_component == 190, "COMMAND_ACK %r" % ack)
    soft_assert(rc.time_boot_ms == 4000 and rc.chancount == 8 and
                [getattr(rc, "chan%d_raw" % i) for i in range(1, 10)] == [1100, 1200, 1300, 1400, 1500, 1600, 1700,
                                                                         1800, 65535] and rc.rssi == 255,
                "RC_CHANNELS %r" % rc)
    soft_assert(servo.time_usec == 4000000 and servo.port == 0 and
                [getattr(servo, "servo%d_raw" % i) for i in range(1, 9)] == [1000, 1100, 1200, 1300, 1400, 1500, 1600,
                                                                            2000],
                "SERVO_OUTPUT_RAW %r" % servo)

    gps, pos, hud, home = msgs[12:16]
    soft_assert(gps.time_usec == 61234000 and gps.fix_type == mavlink2.GPS_FIX_TYPE_3D_FIX and gps.lat == 71350450
                and gps.lon == -731194210 and gps.alt == 1028123 and gps.eph == 90 and gps.epv == 65535
                and gps.vel == 1834 and gps.cog == 27012 and gps.satellites_visible == 10 and gps.h_acc == 2100,
                "GPS_RAW_INT %r" % gps)
    soft_assert(pos.time_boot_ms == 61300 and pos.lat == 71351450 and pos.lon == -731193210 and pos.alt == 1078500
                and pos.relative_alt == 50500 and (pos.vx, pos.vy, pos.vz) == (1200, -1600, -150)
                and pos.hdg == 30687, "GLOBAL_POSITION_INT %r" % pos)
    soft_assert(abs(hud.airspeed - 19.5) < 1e-6 and abs(hud.groundspeed - 20.0) < 1e-5 and hud.heading == 307
                and hud.throttle == 65 and abs(hud.alt - 1078.5) < 1e-3 and abs(hud.climb - 1.5) < 1e-6,
                "VFR_HUD %r" % hud)
    soft_assert(home.latitude == 71350450 and home.longitude == -731194210 and home.altitude == 1028000
                and list(home.q) == [1.0, 0.0, 0.0, 0.0] and home.time_usec == 0, "HOME_POSITION %r" % home)

    ver, count, mack, ts, st = msgs[16:21]
    from MAVProxy.modules.lib.mp_util import decode_flight_sw_version
    soft_assert(decode_flight_sw_version(ver.flight_sw_version) == (1, 2, 3, "official")
                and bytes(ver.flight_custom_version) == b"0123abcd"
                and ver.capabilities == (mavlink2.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                                         | mavlink2.MAV_PROTOCOL_CAPABILITY_MISSION_INT
                                         | mavlink2.MAV_PROTOCOL_CAPABILITY_MAVLINK2)
                and ver.vendor_id == 0x2341 and ver.product_id == 0x0010 and ver.uid == 0,
                "AUTOPILOT_VERSION %r (MAVProxy decodes %r)" % (ver, decode_flight_sw_version(ver.flight_sw_version)))
    soft_assert(count.count == 0 and count.mission_type == mavlink2.MAV_MISSION_TYPE_FENCE
                and count.target_system == 255 and count.target_component == 190, "MISSION_COUNT %r" % count)
    soft_assert(mack.type == mavlink2.MAV_MISSION_UNSUPPORTED and mack.mission_type == mavlink2.MAV_MISSION_TYPE_RALLY
                and mack.target_system == 255, "MISSION_ACK %r" % mack)
    soft_assert(ts.tc1 == 61234000000 and ts.ts1 == -5, "TIMESYNC %r" % ts)
    soft_assert(st.time_unix_usec == 1380812400370000 and st.time_boot_ms == 61300, "SYSTEM_TIME %r" % st)
    ii, fi, rqi, rq, cur, reached = msgs[21:27]
    for m, x, y, frame in ((ii, 71350450, -731194210, 6), (fi, 7.1350450, -73.1194210, 3)):
        soft_assert(m.seq == 5 and m.command == 18 and m.frame == frame and m.param1 == 2.0 and m.param3 == -60.0
                    and abs(m.x - x) <= (0 if frame == 6 else 1e-6) and abs(m.y - y) <= (0 if frame == 6 else 1e-5)
                    and m.z == 90.5 and m.autocontinue == 1 and m.current == 0 and m.mission_type == 0
                    and m.target_system == 255 and m.target_component == 190, "%s %r" % (m.get_type(), m))
    soft_assert(rqi.seq == 7 and rq.seq == 8 and rqi.target_system == 255 and rq.target_component == 190,
                "MISSION_REQUEST(_INT) %r %r" % (rqi, rq))
    soft_assert(cur.seq == 4 and cur.total == 10, "MISSION_CURRENT %r" % cur)
    soft_assert(reached.seq == 3, "MISSION_ITEM_REACHED %r" % reached)

    att = msgs[1]
    soft_assert(att.time_boot_ms == 123456, "time_boot_ms %d" % att.time_boot_ms)
    for name, got, exp in (("roll", att.roll, -math.radians(30)), ("pitch", att.pitch, math.radians(45)),
                           ("yaw", att.yaw, -math.radians(90)), ("rollspeed", att.rollspeed, 0.5),
                           ("pitchspeed", att.pitchspeed, -0.25), ("yawspeed", att.yawspeed, 1.5)):
        soft_assert(abs(got - exp) < 1e-6, "%s %r, expected %r" % (name, got, exp))

    ss = msgs[2]
    bits = (mavlink2.MAV_SYS_STATUS_SENSOR_3D_GYRO | mavlink2.MAV_SYS_STATUS_SENSOR_3D_ACCEL |
            mavlink2.MAV_SYS_STATUS_SENSOR_3D_MAG)
    soft_assert(ss.onboard_control_sensors_present == bits and ss.onboard_control_sensors_enabled == bits,
          "present/enabled %d/%d" % (ss.onboard_control_sensors_present, ss.onboard_control_sensors_enabled))
    soft_assert(ss.onboard_control_sensors_health == bits & ~mavlink2.MAV_SYS_STATUS_SENSOR_3D_MAG,
          "health %d" % ss.onboard_control_sensors_health)
    soft_assert(ss.load == 593 and ss.errors_count1 == 12, "load %d errors %d" % (ss.load, ss.errors_count1))
    soft_assert(ss.voltage_battery == 65535 and ss.current_battery == -1 and ss.battery_remaining == -1,
          "battery fields not 'unknown'")

    texts = msgs[3:7]
    soft_assert(texts[0].severity == mavlink2.MAV_SEVERITY_WARNING and texts[0].text == "warn: compass overflow"
          and texts[0].id == 0, "warn line %r" % texts[0])
    err = texts[1:3]
    joined = "".join(t.text for t in err)
    soft_assert(joined == "error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68); retrying every second",
          "error line chunks %r" % joined)
    soft_assert(all(t.severity == mavlink2.MAV_SEVERITY_ERROR for t in err), "error severity")
    soft_assert(err[0].id != 0 and err[0].id == err[1].id and [t.chunk_seq for t in err] == [0, 1],
          "chunk ids %r" % [(t.id, t.chunk_seq) for t in err])
    soft_assert(texts[3].severity == mavlink2.MAV_SEVERITY_INFO and texts[3].text == "status: ok", "info line")


if __name__ == "__main__":
    main()
    sys.exit(finish("pymavlink decode", "pymavlink decoded all frames as expected"))
