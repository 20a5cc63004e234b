#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""REQUEST_DATA_STREAM's stream groups on the simulated board over TCP, with pymavlink (issue 46).

    build/venv/bin/python test/mavlink/stream_rates.py --tools build --work DIR

Runs build/firmware.elf in `apm25sim --serial tcp:0 --speed 1` on the rest scenario as
gcs_talk.py does and counts messages by the board's own clock (their time_boot_ms or
time_usec) over WINDOW_S seconds after each request has settled:
  - before any request: RC_CHANNELS, SERVO_OUTPUT_RAW, SCALED_PRESSURE at 5 Hz;
  - RC_CHANNELS stream (3) at 2 Hz: RC_CHANNELS and SERVO_OUTPUT_RAW at 2 Hz, SCALED_PRESSURE
    still 5 Hz; at 3 with start_stop 0: neither is sent;
  - MAV_DATA_STREAM_ALL at 10 Hz: all three at 10 Hz;
  - RC_CHANNELS at 50 Hz with the console's rate 50 (ATTITUDE 50 Hz): 50 Hz, the link has room;
    then the console's rate 100 (three returns, `rate 100`, a HEARTBEAT back) and 50 Hz asked
    again: capped to what 75 % of 115200 baud leaves beside ATTITUDE at 100 Hz and the
    rest (lib/MavLink/StreamRates.h): 43 Hz;
  - no sample missed (no "overrun" STATUSTEXT).
Exit 1 with every failure listed.
"""
import os
import sys
import time

from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from gcs_link import Board  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

WINDOW_S = 4.0
SETTLE_S = 1.0
GROUPS = ("RC_CHANNELS", "SERVO_OUTPUT_RAW", "SCALED_PRESSURE")

# The link's budget (StreamRates.h): 75 % of 11520 B/s; what it carries besides the groups
# at the console's rate 100 (GcsLink.cpp's fixed_link_load): HEARTBEAT 21, SYS_STATUS 66,
# SYSTEM_TIME 24, BATTERY_STATUS 53, GPS_RAW_INT 2 x 64, GLOBAL_POSITION_INT and VFR_HUD
# 4 x (40 + 32), ATTITUDE 100 x 40; SCALED_PRESSURE at 10 Hz x 28; RC_CHAN 54 + 33 bytes.
CAPPED_HZ = (8640 - (21 + 66 + 24 + 53 + 128 + 288 + 4000) - 10 * 28) // 87


def rates(b, what):
    """The groups' and ATTITUDE's rates (Hz, by the board's clock) over WINDOW_S after SETTLE_S."""
    t0 = b.t_s
    b.pump(lambda m: b.t_s > t0 + SETTLE_S + WINDOW_S + 0.3, what)
    lo, hi = t0 + SETTLE_S, t0 + SETTLE_S + WINDOW_S
    out = {}
    for name in GROUPS + ("ATTITUDE",):
        n = sum(1 for t, m in b.msgs if m.get_type() == name and lo < t <= hi)
        out[name] = n / WINDOW_S
    print("# %s: %s" % (what, ", ".join("%s %.2f Hz" % (k, v) for k, v in out.items())))
    return out


def near(got, want, what):
    # One message more or less in the window (its edges fall between two).
    tol = 1.25 / WINDOW_S
    soft_assert(abs(got - want) <= tol, "%s: %.2f Hz, want %.2f" % (what, got, want))


def request(b, stream, hz, start=1):
    b.conn.mav.request_data_stream_send(1, 1, stream, hz, start)


def console_rate(b, hz):
    """Three returns, `rate <hz>` typed into the text console, a HEARTBEAT back to MAVLink."""
    b.conn.write(b"\r\r\r")
    raw = b""
    end = time.time() + 120
    while time.time() < end and b"# rate <Hz>" not in raw:
        data = b.conn.recv(4096)
        raw += data or b""
        if not data:
            time.sleep(0.05)
    soft_assert(b"# rate <Hz>" in raw, "no text console after three returns: %r" % raw[-200:])
    b.conn.write(b"rate %d\r\n" % hz)
    end = time.time() + 30
    while time.time() < end and raw.count(b"\nroll:") < 200:
        data = b.conn.recv(4096)
        raw += data or b""
        if not data:
            time.sleep(0.05)
    b.last_hb = 0
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after `rate %d`" % hz, 120)
    soft_assert(hb is not None, "MAVLink never came back after `rate %d`" % hz)


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "rest")
    b = Board(args.tools, args.work, "rates", ["--trajectory", trajectory])
    try:
        if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
            return
        b.pump(lambda m: b.t_s > 2.0, "the estimator to start")
        r = rates(b, "before any request")
        for name in GROUPS:
            near(r[name], 5.0, "%s before any request" % name)

        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 2)
        r = rates(b, "RC_CHANNELS stream at 2 Hz")
        near(r["RC_CHANNELS"], 2.0, "RC_CHANNELS after REQUEST_DATA_STREAM 3 at 2 Hz")
        near(r["SERVO_OUTPUT_RAW"], 2.0, "SERVO_OUTPUT_RAW after REQUEST_DATA_STREAM 3 at 2 Hz")
        near(r["SCALED_PRESSURE"], 5.0, "SCALED_PRESSURE (another group) after REQUEST_DATA_STREAM 3")

        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 2, 0)
        r = rates(b, "RC_CHANNELS stream stopped")
        soft_assert(r["RC_CHANNELS"] == 0.0 and r["SERVO_OUTPUT_RAW"] == 0.0,
                    "RC_CHANNELS stream stopped, still sent: %r" % r)
        near(r["SCALED_PRESSURE"], 5.0, "SCALED_PRESSURE with the RC_CHANNELS stream stopped")

        request(b, mavlink2.MAV_DATA_STREAM_ALL, 10)
        r = rates(b, "every stream at 10 Hz")
        for name in GROUPS:
            near(r[name], 10.0, "%s after MAV_DATA_STREAM_ALL at 10 Hz" % name)

        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 50)
        r = rates(b, "RC_CHANNELS stream at 50 Hz beside ATTITUDE at 50 Hz")
        soft_assert(r["RC_CHANNELS"] >= 47.0, "RC_CHANNELS at 50 Hz with room on the link: %.2f Hz"
                    % r["RC_CHANNELS"])

        console_rate(b, 100)
        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 50)
        r = rates(b, "RC_CHANNELS stream at 50 Hz beside ATTITUDE at 100 Hz")
        soft_assert(r["ATTITUDE"] >= 90.0, "ATTITUDE after `rate 100`: %.2f Hz" % r["ATTITUDE"])
        soft_assert(CAPPED_HZ - 4.0 <= r["RC_CHANNELS"] <= CAPPED_HZ + 1.25 / WINDOW_S,
                    "RC_CHANNELS at 50 Hz asked beside ATTITUDE at 100 Hz: %.2f Hz, want the cap %d Hz"
                    % (r["RC_CHANNELS"], CAPPED_HZ))
    finally:
        b.stop()
    overruns = [m.text for _, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "samples missed: %r" % overruns)


if __name__ == "__main__":
    main()
    sys.exit(finish("stream rates", "REQUEST_DATA_STREAM's groups at the rates asked, capped by the link"))
