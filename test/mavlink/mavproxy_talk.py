#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""MAVProxy's view of the conversation on the simulated board over TCP.

    build/venv/bin/python test/mavlink/mavproxy_talk.py --tools build --work DIR

Starts `apm25sim --serial tcp:0 --speed 1` on mavproxy_session.py's still, banked board and
`mavproxy.py --master tcp:... --default-modules param,mode,wp,fence,rally,misc`, typing
into its console as a user does, and checks what it prints:
  - never "fence breach" (MAVProxy says it for a SYS_STATUS without the geofence's health
    bit), over the whole session;
  - `version` (REQUEST_MESSAGE 148): the board sends AUTOPILOT_VERSION, which
    `status AUTOPILOT_VERSION` shows: flight_sw_version decodes (as MAVProxy does) to the
    start-up line's version, official; capabilities PARAM_FLOAT, MISSION_INT and MAVLINK2;
  - `wp list`, `fence list`, `rally list` each answered ("Requesting 1 waypoints": home alone
    at seq 0, as ArduPilot, from a blank EEPROM; "0 fence items", "0 rally items"), never waited for;
  - `status SYSTEM_TIME` shows the board's clock (time_boot_ms within the session).
Exit 1 with every failure listed.
"""
import os
import re
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from mavproxy_session import Lines, write_banked  # noqa: E402
from sim_run import tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402


def firmware_version(root):
    """(major, minor, patch) of firmware/Version.h."""
    text = open(os.path.join(root, "firmware", "Version.h")).read()
    return tuple(int(re.search(r"#define APM25_VERSION_%s (\d+)" % k, text).group(1))
                 for k in ("MAJOR", "MINOR", "PATCH"))


def main():
    args = tools_and_work()
    root = os.path.dirname(os.path.dirname(HERE))
    trajectory = os.path.join(args.work, "banked.csv")
    write_banked(trajectory)
    sim_log = open(os.path.join(args.work, "apm25sim.stderr"), "w")
    sim = subprocess.Popen([os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
                            "--trajectory", trajectory, "--serial", "tcp:0", "--speed", "1"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    first = sim.stderr.readline()
    sim_log.write(first)
    port = re.search(r"tcp:127\.0\.0\.1:(\d+)", first)
    if not port:
        sim.kill()
        sys.exit("apm25sim did not serve: %r" % first)
    mavproxy = os.path.join(os.path.dirname(sys.executable), "mavproxy.py")
    mp_log = open(os.path.join(args.work, "mavproxy.out"), "w")
    mp = subprocess.Popen([sys.executable, mavproxy, "--master", "tcp:127.0.0.1:" + port.group(1), "--no-state",
                           "--default-modules", "param,mode,wp,fence,rally,misc", "--target-system", "1"],
                          stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, bufsize=1,
                          cwd=args.work)
    out = Lines(mp.stdout, mp_log)

    def type_line(cmd):
        mp.stdin.write(cmd + "\n")
        mp.stdin.flush()

    try:
        m = out.wait(r"Received (\d+) parameters", "the parameter list")
        soft_assert(m is not None, "no parameter list")
        # `version` sends REQUEST_MESSAGE 148 (MAVProxy does not show that command's ACK);
        # `status` shows the AUTOPILOT_VERSION that came.
        type_line("version")
        time.sleep(2)
        type_line("status AUTOPILOT_VERSION")
        m = out.wait(r"AUTOPILOT_VERSION \{capabilities : (\d+), flight_sw_version : (\d+)", "AUTOPILOT_VERSION", 60)
        if m:
            from MAVProxy.modules.lib.mp_util import decode_flight_sw_version
            caps, sw = int(m.group(1)), int(m.group(2))
            want = firmware_version(root) + ("official",)
            soft_assert(decode_flight_sw_version(sw) == want, "flight_sw_version %d decodes to %r, expected %r"
                        % (sw, decode_flight_sw_version(sw), want))
            soft_assert(caps == 2 | 4 | 8192, "capabilities %d: PARAM_FLOAT | MISSION_INT | MAVLINK2 expected" % caps)
            # The commit's hash the build wrote (mk/build.mk), as 8 characters.
            gen = os.path.join(args.tools, "avr", "gen", "git_version.h")
            h = re.search(r'"([0-9a-f]{8})"', open(gen).read()) if os.path.exists(gen) else None
            if h:
                custom = re.search(r"flight_custom_version : \[([0-9, ]+)\]", m.string)
                got = bytes(int(x) for x in custom.group(1).split(",")) if custom else b""
                soft_assert(got == h.group(1).encode(), "flight_custom_version %r, the build's %s" % (got, h.group(1)))
        for cmd, what in (("wp list", "1 waypoints"), ("fence list", "0 fence items"), ("rally list", "0 rally items")):
            type_line(cmd)
            soft_assert(out.wait(r"Requesting %s" % what, "`%s`'s answer" % cmd, 60),
                        "`%s` not answered with %s" % (cmd, what))
        type_line("status SYSTEM_TIME")
        m = out.wait(r"SYSTEM_TIME \{time_unix_usec : (\d+), time_boot_ms : (\d+)", "SYSTEM_TIME", 60)
        soft_assert(m and int(m.group(2)) > 1000, "SYSTEM_TIME %r" % (m and m.group(0)))
        time.sleep(3)
        breaches = [line.strip() for line in out.seen if "fence breach" in line]
        soft_assert(not breaches, "MAVProxy said %r" % breaches)
        print("# MAVProxy: no fence breach, version %s, wp list home alone, fence/rally lists empty, SYSTEM_TIME shown"
              % ".".join(str(v) for v in firmware_version(root)))
    finally:
        type_line("exit")
        try:
            mp.wait(timeout=30)
        except subprocess.TimeoutExpired:
            mp.kill()
        mp_log.close()
        sim.terminate()
        sim.wait()
        sim_log.write(sim.stderr.read())


if __name__ == "__main__":
    main()
    sys.exit(finish("MAVProxy conversation", "MAVProxy: no fence breach, version, the mission lists"))
