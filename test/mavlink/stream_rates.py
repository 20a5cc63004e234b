#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The stream rates on the simulated board over TCP, with pymavlink (issue 46).

    build/venv/bin/python test/mavlink/stream_rates.py --tools build --work DIR

Runs build/firmware.elf in `apm25sim --serial tcp:0 --speed 1 --eeprom FILE` on the rest
scenario and counts messages by the board's own clock (their time_boot_ms) over WINDOW_S
seconds after each request has settled:
  - before any request, the SR0_ defaults: RC_CHANNELS, SERVO_OUTPUT_RAW, SCALED_PRESSURE
    5 Hz, SYS_STATUS 1 Hz, VFR_HUD 4 Hz, SYSTEM_TIME, MISSION_CURRENT and HEARTBEAT 1 Hz,
    ATTITUDE 50 Hz;
  - PARAM_SET SR0_RAW_SENS 2: SCALED_PRESSURE at 2 Hz, answered by its PARAM_VALUE;
  - REQUEST_DATA_STREAM RC_CHANNELS (3) at 2 Hz: RC_CHANNELS and SERVO_OUTPUT_RAW at 2 Hz,
    SCALED_PRESSURE still 2; SR0_RC_CHAN read back 2; start_stop 0: neither sent;
  - ALL at 10 Hz: every stream at 10 Hz, HEARTBEAT still 1 Hz;
  - SET_MESSAGE_INTERVAL ATTITUDE 40000 us: ATTITUDE 25 Hz, the others 10; GET_MESSAGE_INTERVAL
    answered with MESSAGE_INTERVAL (ATTITUDE 40000, RC_CHANNELS 100000, RAW_IMU -1) and
    ACCEPTED; SET for RAW_IMU (not sent) and HEARTBEAT DENIED;
  - ALL at 50 Hz: more than the link carries: every interval stretched alike to the cap
    (lib/MavLink/StreamRates.h), the bytes measured within 75 % of 11520 B/s;
  - ALL at 3 Hz saved ("saved" once), the same request again not saved;
  - no sample missed: SYS_STATUS's errors_count1 (the missed samples) 0, no "overrun" text.
A second run on the same EEPROM (a power cycle): the streams at 3 Hz, SR0_RC_CHAN 3; the
console's `rate 20` with SR0_EXTRA1 50: ATTITUDE at 20 Hz (one an output line).
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
GROUPS = ("RC_CHANNELS", "SERVO_OUTPUT_RAW", "SCALED_PRESSURE", "SYS_STATUS", "VFR_HUD", "SYSTEM_TIME",
          "MISSION_CURRENT")
COUNTED = GROUPS + ("ATTITUDE", "HEARTBEAT")

# The link's cap (StreamRates.h): 75 % of 11520 B/s less HEARTBEAT's 21; the frames at their
# longest, in the table's order: SCALED_PRESSURE, SYS_STATUS, GPS_RAW_INT, RC_CHANNELS,
# SERVO_OUTPUT_RAW, GLOBAL_POSITION_INT, ATTITUDE, VFR_HUD, SYSTEM_TIME, BATTERY_STATUS,
# NAV_CONTROLLER_OUTPUT (planned for whether or not a navigation mode flies: its bytes are
# there when one starts), MISSION_CURRENT.
FRAME_BYTES = (28, 66, 64, 54, 33, 40, 40, 32, 24, 53, 38, 18)
BUDGET = 8640 - 21


def capped_interval_ms(hz):
    """Every stream asked at hz: the interval plan() gives (the same Q8 stretch)."""
    ms = 1000 // hz
    load = sum(b * 1000 // ms for b in FRAME_BYTES)
    stretch = (load * 256 + BUDGET - 1) // BUDGET if load > BUDGET else 256
    return (ms * stretch + 255) >> 8


def rates(b, what):
    """The counted messages' rates (Hz, by the board's clock) and bytes a second over WINDOW_S
    after SETTLE_S."""
    t0 = b.t_s
    b.pump(lambda m: b.t_s > t0 + SETTLE_S + WINDOW_S + 0.3, what)
    lo, hi = t0 + SETTLE_S, t0 + SETTLE_S + WINDOW_S
    out = {}
    for name in COUNTED:
        n = sum(1 for t, m in b.msgs if m.get_type() == name and lo < t <= hi)
        out[name] = n / WINDOW_S
    out["bytes"] = sum(len(m.get_msgbuf()) for t, m in b.msgs if lo < t <= hi) / WINDOW_S
    print("# %s: %s" % (what, ", ".join("%s %.2f" % (k, v) for k, v in out.items())))
    return out


def near(got, want, what):
    # One message more or less in the window (its edges fall between two).
    tol = 1.25 / WINDOW_S
    soft_assert(abs(got - want) <= tol, "%s: %.2f Hz, want %.2f" % (what, got, want))


def request(b, stream, hz, start=1):
    b.conn.mav.request_data_stream_send(1, 1, stream, hz, start)


def param(b, name):
    b.conn.mav.param_request_read_send(1, 1, name.encode(), -1)
    m = b.param(name, "PARAM_VALUE %s" % name)
    return m.param_value if m else None


def command_ack(b, cmd, *params):
    p = list(params) + [0.0] * (7 - len(params))
    b.conn.mav.command_long_send(1, 1, cmd, 0, *p)
    m = b.ack(cmd, "COMMAND_ACK %d" % cmd)
    return m.result if m else None


def message_interval(b, msgid):
    """GET_MESSAGE_INTERVAL: (MESSAGE_INTERVAL's interval_us, the ACK's result); the
    MESSAGE_INTERVAL comes first, as ArduPilot sends it."""
    start = len(b.msgs)
    b.conn.mav.command_long_send(1, 1, mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, 0, msgid, 0, 0, 0, 0, 0, 0)
    ack = b.ack(mavlink2.MAV_CMD_GET_MESSAGE_INTERVAL, "GET_MESSAGE_INTERVAL's ACK")
    got = [m for _, m in b.msgs[start:] if m.get_type() == "MESSAGE_INTERVAL" and m.message_id == msgid]
    soft_assert(len(got) == 1, "GET_MESSAGE_INTERVAL %d: %d MESSAGE_INTERVAL before the ACK" % (msgid, len(got)))
    return (got[0].interval_us if got else None), (ack.result if ack else None)


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
    while time.time() < end and raw.count(b"\nroll:") < 2 * hz:
        data = b.conn.recv(4096)
        raw += data or b""
        if not data:
            time.sleep(0.05)
    b.last_hb = 0
    hb = b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after `rate %d`" % hz, 120)
    soft_assert(hb is not None, "MAVLink never came back after `rate %d`" % hz)


def no_missed_samples(b, run):
    errors = [m.errors_count1 for _, m in b.msgs if m.get_type() == "SYS_STATUS"]
    soft_assert(errors and max(errors) == 0, "%s: SYS_STATUS says samples were missed: %s" % (run, sorted(set(errors))))
    overruns = [m.text for _, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "%s: samples missed: %r" % (run, overruns))


def first_session(args, trajectory, eeprom):
    b = Board(args.tools, args.work, "rates1", ["--trajectory", trajectory, "--eeprom", eeprom])
    try:
        if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
            return
        b.pump(lambda m: b.t_s > 2.0, "the estimator to start")
        r = rates(b, "the SR0_ defaults")
        for name, hz in (("RC_CHANNELS", 5), ("SERVO_OUTPUT_RAW", 5), ("SCALED_PRESSURE", 5), ("SYS_STATUS", 1),
                         ("VFR_HUD", 4), ("SYSTEM_TIME", 1), ("HEARTBEAT", 1), ("ATTITUDE", 50),
                         ("MISSION_CURRENT", 1)):
            near(r[name], hz, "%s at the defaults" % name)

        b.conn.mav.param_set_send(1, 1, b"SR0_RAW_SENS", 2, mavlink2.MAV_PARAM_TYPE_UINT8)
        m = b.param("SR0_RAW_SENS", "PARAM_VALUE SR0_RAW_SENS")
        soft_assert(m is not None and m.param_value == 2, "PARAM_SET SR0_RAW_SENS 2: %r" % m)
        r = rates(b, "SR0_RAW_SENS 2 by PARAM_SET")
        near(r["SCALED_PRESSURE"], 2, "SCALED_PRESSURE after PARAM_SET SR0_RAW_SENS 2")
        near(r["RC_CHANNELS"], 5, "RC_CHANNELS after PARAM_SET SR0_RAW_SENS 2")

        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 2)
        r = rates(b, "RC_CHANNELS stream at 2 Hz")
        near(r["RC_CHANNELS"], 2, "RC_CHANNELS after REQUEST_DATA_STREAM 3 at 2 Hz")
        near(r["SERVO_OUTPUT_RAW"], 2, "SERVO_OUTPUT_RAW after REQUEST_DATA_STREAM 3 at 2 Hz")
        near(r["SCALED_PRESSURE"], 2, "SCALED_PRESSURE (another group) after REQUEST_DATA_STREAM 3")
        soft_assert(param(b, "SR0_RC_CHAN") == 2, "SR0_RC_CHAN after REQUEST_DATA_STREAM 3 at 2 Hz")

        request(b, mavlink2.MAV_DATA_STREAM_RC_CHANNELS, 2, 0)
        r = rates(b, "RC_CHANNELS stream stopped")
        soft_assert(r["RC_CHANNELS"] == 0.0 and r["SERVO_OUTPUT_RAW"] == 0.0,
                    "RC_CHANNELS stream stopped, still sent: %r" % r)
        near(r["SCALED_PRESSURE"], 2, "SCALED_PRESSURE with the RC_CHANNELS stream stopped")

        request(b, mavlink2.MAV_DATA_STREAM_ALL, 10)
        r = rates(b, "every stream at 10 Hz")
        for name in GROUPS + ("ATTITUDE",):
            near(r[name], 10, "%s after MAV_DATA_STREAM_ALL at 10 Hz" % name)
        near(r["HEARTBEAT"], 1, "HEARTBEAT after MAV_DATA_STREAM_ALL at 10 Hz")

        result = command_ack(b, mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, 30, 40000)
        soft_assert(result == mavlink2.MAV_RESULT_ACCEPTED, "SET_MESSAGE_INTERVAL ATTITUDE 40000 us: %s" % result)
        r = rates(b, "ATTITUDE at 40000 us")
        near(r["ATTITUDE"], 25, "ATTITUDE after SET_MESSAGE_INTERVAL 40000 us")
        near(r["RC_CHANNELS"], 10, "RC_CHANNELS beside ATTITUDE's own interval")
        for msgid, want in ((30, 40000), (65, 100000), (0, 1000000), (27, -1)):
            got, result = message_interval(b, msgid)
            soft_assert(got == want and result == mavlink2.MAV_RESULT_ACCEPTED,
                        "GET_MESSAGE_INTERVAL %d: %s (%s), want %d ACCEPTED" % (msgid, got, result, want))
        for msgid in (27, 0):
            result = command_ack(b, mavlink2.MAV_CMD_SET_MESSAGE_INTERVAL, msgid, 100000)
            soft_assert(result == mavlink2.MAV_RESULT_DENIED, "SET_MESSAGE_INTERVAL %d: %s, want DENIED"
                        % (msgid, result))

        request(b, mavlink2.MAV_DATA_STREAM_ALL, 50)
        r = rates(b, "every stream at 50 Hz: the cap")
        cap_hz = 1000.0 / capped_interval_ms(50)
        for name in GROUPS + ("ATTITUDE",):
            soft_assert(cap_hz - 1.0 <= r[name] <= cap_hz + 1.25 / WINDOW_S,
                        "%s at 50 Hz asked, over the link: %.2f Hz, want the cap %.2f" % (name, r[name], cap_hz))
        soft_assert(r["bytes"] <= 8640, "the streams took %.0f B/s, more than 75 %% of the link" % r["bytes"])
        got, _ = message_interval(b, 65)
        soft_assert(got == capped_interval_ms(50) * 1000, "GET_MESSAGE_INTERVAL RC_CHANNELS at the cap: %s, want %d"
                    % (got, capped_interval_ms(50) * 1000))

        saves = lambda: sum(1 for _, m in b.msgs if m.get_type() == "STATUSTEXT" and m.text == "saved")
        before = saves()
        request(b, mavlink2.MAV_DATA_STREAM_ALL, 3)
        saved = b.pump(lambda m: m.get_type() == "STATUSTEXT" and m.text == "saved", "'saved' after ALL at 3 Hz")
        soft_assert(saved is not None, "REQUEST_DATA_STREAM ALL at 3 Hz not saved")
        request(b, mavlink2.MAV_DATA_STREAM_ALL, 3)
        r = rates(b, "every stream at 3 Hz, asked twice")
        near(r["RC_CHANNELS"], 3, "RC_CHANNELS after ALL at 3 Hz")
        soft_assert(saves() == before + 1, "ALL at 3 Hz twice: saved %d times, want once (set_and_save_ifchanged)"
                    % (saves() - before))
    finally:
        b.stop()
    no_missed_samples(b, "run 1")


def second_session(args, trajectory, eeprom):
    b = Board(args.tools, args.work, "rates2", ["--trajectory", trajectory, "--eeprom", eeprom])
    try:
        if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the power cycle") is None:
            return
        b.pump(lambda m: b.t_s > 2.0, "the estimator to start")
        r = rates(b, "after the power cycle")
        for name in GROUPS + ("ATTITUDE",):
            near(r[name], 3, "%s after the power cycle (ALL at 3 Hz saved)" % name)
        soft_assert(param(b, "SR0_RC_CHAN") == 3, "SR0_RC_CHAN after the power cycle")
        b.conn.mav.param_set_send(1, 1, b"SR0_EXTRA1", 50, mavlink2.MAV_PARAM_TYPE_UINT8)
        b.param("SR0_EXTRA1", "PARAM_VALUE SR0_EXTRA1")
        console_rate(b, 20)
        r = rates(b, "SR0_EXTRA1 50 with the console's rate 20")
        near(r["ATTITUDE"], 20, "ATTITUDE with SR0_EXTRA1 50 and `rate 20`")
    finally:
        b.stop()
    no_missed_samples(b, "run 2")


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "rest")
    eeprom = os.path.join(args.work, "eeprom.bin")
    if os.path.exists(eeprom):
        os.remove(eeprom)
    first_session(args, trajectory, eeprom)
    second_session(args, trajectory, eeprom)


if __name__ == "__main__":
    main()
    sys.exit(finish("stream rates", "the SR0_ groups, the message intervals and the cap, kept over a power cycle"))
