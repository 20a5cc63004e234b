#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The MAVLink conversation's rules on the simulated board over TCP, with pymavlink.

    build/venv/bin/python test/mavlink/gcs_talk.py --tools build --work DIR

Runs build/firmware.elf in `apm25sim --serial tcp:0 --speed 1` on the rest scenario and
talks to it as gcs_link.py's ground station does (a HEARTBEAT from system 255 each wall
second). Checks:
  - a burst: 20 PARAM_SETs written back to back in one TCP write (700 bytes, 61 ms of the
    link) are all applied and each answered by a PARAM_VALUE with the value set, and a
    PARAM_REQUEST_READ of each afterwards reads it back;
  - text inside the MAVLink stream acts on nothing: `set RLL2SRV_P 3` and `mode plot`
    lines among garbage bytes leave RLL2SRV_P at its value and the port in MAVLink (its
    HEARTBEATs go on);
  - three returns in a row give the text console back (its `help` reply as text, then angle
    lines), and the next HEARTBEAT switches to MAVLink again;
  - MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN: param1 2 (shutdown) UNSUPPORTED; param1 1 ACCEPTED, then
    the board starts again (a watchdog reset: an ATTITUDE's time_boot_ms from 0, HEARTBEAT again);
then a second run with a client that sends no HEARTBEAT: `set SERIAL0_PROTOCOL 2` typed
into the text console switches the board to MAVLink, and pymavlink's plain
wait_heartbeat() hears it.
Exit 1 with every failure listed. No timing assertion.
"""
import os
import re
import socket
import sys
import time

from pymavlink import mavutil
from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from gcs_link import Board  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

# 20 parameters of three types, each to a value in its range other than its default.
BURST = ([("RLL2SRV_P", 0.5), ("RLL2SRV_I", 0.05), ("RLL2SRV_D", 0.03), ("PTCH2SRV_P", 0.9), ("PTCH2SRV_I", 0.2),
          ("PTCH2SRV_D", 0.05)]
         + [("SERVO%d_TRIM" % n, 1450 + n) for n in range(1, 9)]
         + [("RC%d_TRIM" % n, 1480 + n) for n in range(1, 6)] + [("RC8_REVERSED", 1)])


def burst(b):
    assert len(BURST) == 20
    start = len(b.msgs)
    raw = b"".join(b.conn.mav.param_set_encode(1, 1, name.encode(), value, mavlink2.MAV_PARAM_TYPE_REAL32)
                   .pack(b.conn.mav) for name, value in BURST)
    b.conn.write(raw)  # one write: the frames back to back on the link
    want = {name for name, _ in BURST}

    def all_answered(m):
        return want <= {x.param_id for _, x in b.msgs[start:] if x.get_type() == "PARAM_VALUE"}
    b.pump(all_answered, "a PARAM_VALUE for each of the 20 PARAM_SETs")
    got = {}
    for _, m in b.msgs[start:]:
        if m.get_type() == "PARAM_VALUE":
            got.setdefault(m.param_id, []).append(m.param_value)
    answered = [n for n, _ in BURST if n in got]
    applied = [n for n, v in BURST if n in got and abs(got[n][0] - v) < 1e-4]
    soft_assert(len(answered) == 20 and len(applied) == 20, "burst of 20 PARAM_SETs: %d answered, %d applied: %r"
                % (len(answered), len(applied), {n: got.get(n) for n, v in BURST}))
    soft_assert(all(len(v) == 1 for v in got.values()), "a PARAM_SET answered twice: %r" % got)
    for name, value in BURST:
        b.conn.mav.param_request_read_send(1, 1, name.encode(), -1)
        pv = b.param(name, "PARAM_REQUEST_READ %s after the burst" % name)
        soft_assert(pv is not None and abs(pv.param_value - value) < 1e-4, "%s read back: %r" % (name, pv))
    print("# burst: 20 PARAM_SETs back to back, %d answered, %d applied and read back" % (len(answered), len(applied)))


def text_in_mavlink(b):
    b.conn.write(b"\x00\x55garbage\r\nset RLL2SRV_P 3\r\n\x07zz\nmode plot\r\nset RLL2SRV_P 3\n")
    t0 = b.t_s
    b.pump(lambda m: b.t_s > t0 + 2.5, "2.5 s after the text lines")
    hbs = [t for t, m in b.msgs if m.get_type() == "HEARTBEAT" and t > t0 + 0.5]
    soft_assert(len(hbs) >= 2, "HEARTBEATs after `mode plot` typed in MAVLink: %d (the link silenced?)" % len(hbs))
    b.conn.mav.param_request_read_send(1, 1, b"RLL2SRV_P", -1)
    pv = b.param("RLL2SRV_P", "RLL2SRV_P after the text lines")
    soft_assert(pv is not None and abs(pv.param_value - BURST[0][1]) < 1e-4,
                "RLL2SRV_P after `set RLL2SRV_P 3` typed in MAVLink: %r (was %.2f)" % (pv, BURST[0][1]))
    print("# text in MAVLink: `set` and `mode plot` did nothing, %d HEARTBEATs after" % len(hbs))


def escape(b):
    """Three returns: the text console (its help as text, then angle lines), until the next HEARTBEAT."""
    b.conn.write(b"\r\r\r")
    raw = b""
    end = time.time() + 120
    while time.time() < end and not (b"# rate <Hz>" in raw and raw.count(b"\nroll:") >= 5):
        data = b.conn.recv(4096)
        if data:
            raw += data
        else:
            time.sleep(0.05)
    text = raw
    soft_assert(b"# rate <Hz>" in text and text.count(b"\nroll:") >= 5,
                "after three returns: no text console (%d bytes: %r)" % (len(text), text[-300:]))
    # The ground station's next HEARTBEAT: MAVLink again.
    b.last_hb = 0
    t0 = b.t_s
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the escape and a GCS HEARTBEAT", 120)
    soft_assert(hb is not None, "MAVLink never came back after the escape")
    print("# three returns: text console (%d angle lines), back to MAVLink on a HEARTBEAT (at %.1f s)"
          % (text.count(b"\nroll:"), t0))


def reboot(b):
    """MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN: 2 refused, 1 ACKed, then a watchdog reset: the clock starts again."""
    b.conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, 0, 2, 0, 0, 0, 0, 0, 0)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, "COMMAND_ACK for a shutdown (param1 2)")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_UNSUPPORTED, "shutdown: %r" % ack)
    b.conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, 0, 1, 0, 0, 0, 0, 0, 0)
    ack = b.ack(mavlink2.MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN, "COMMAND_ACK for the reboot")
    soft_assert(ack is not None and ack.result == mavlink2.MAV_RESULT_ACCEPTED, "reboot: %r" % ack)
    acked_at = b.t_s
    # A watchdog reset: the firmware starts again, in its text mode until the ground
    # station's next HEARTBEAT (pump sends one a second), its clock from 0.
    again = b.pump(lambda m: m.get_type() == "ATTITUDE" and m.time_boot_ms < acked_at * 1000 - 1000,
                   "an ATTITUDE whose time_boot_ms restarted after the reboot", 240)
    soft_assert(again is not None, "no restart after the reboot's ACK at %.2f s" % acked_at)
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the reboot", 120)
    soft_assert(hb is not None, "no HEARTBEAT after the reboot")
    if again is not None:
        print("# reboot: shutdown UNSUPPORTED, reboot ACCEPTED at %.2f s, then time_boot_ms %d ms: started again"
              % (acked_at, again.time_boot_ms))


def serial0_protocol(args, trajectory):
    """A client that never sends a HEARTBEAT: SERIAL0_PROTOCOL 2 makes the board speak MAVLink."""
    log = open(os.path.join(args.work, "protocol.stderr"), "w")
    import subprocess
    proc = subprocess.Popen([os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
                             "--trajectory", trajectory, "--serial", "tcp:0", "--speed", "1"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    line = proc.stderr.readline()
    log.write(line)
    port = re.search(r"tcp:127\.0\.0\.1:(\d+)", line)
    try:
        if not port:
            soft_assert(False, "apm25sim did not serve: %r" % line)
            return
        conn = mavutil.mavlink_connection("tcp:127.0.0.1:%s" % port.group(1), source_system=255,
                                          autoreconnect=False)
        hb = conn.wait_heartbeat(timeout=8)
        soft_assert(hb is None, "a HEARTBEAT before SERIAL0_PROTOCOL was set: the default is text: %r" % hb)
        conn.write(b"set SERIAL0_PROTOCOL 2\r\n")
        hb = conn.wait_heartbeat(timeout=60)
        soft_assert(hb is not None and hb.get_srcSystem() == 1 and hb.type == mavlink2.MAV_TYPE_FIXED_WING,
                    "wait_heartbeat() after SERIAL0_PROTOCOL 2: %r" % hb)
        att = conn.recv_match(type="ATTITUDE", blocking=True, timeout=30)
        soft_assert(att is not None, "no ATTITUDE after SERIAL0_PROTOCOL 2")
        print("# SERIAL0_PROTOCOL 2: wait_heartbeat() heard the board without sending anything")
        conn.close()
    finally:
        proc.terminate()
        proc.wait()
        log.write(proc.stderr.read())
        log.close()


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "rest")
    b = Board(args.tools, args.work, "talk", ["--trajectory", trajectory])
    try:
        if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
            return
        b.pump(lambda m: b.t_s > 2.0, "the estimator to start")
        burst(b)
        text_in_mavlink(b)
        escape(b)
        reboot(b)
    finally:
        b.stop()
    overruns = [m.text for _, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "samples missed: %r" % overruns)
    serial0_protocol(args, trajectory)


if __name__ == "__main__":
    main()
    sys.exit(finish("MAVLink conversation", "bursts, text in MAVLink, the escape and SERIAL0_PROTOCOL as designed"))
