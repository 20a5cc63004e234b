#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The mission protocol on the simulated board over TCP: MAVProxy's `wp`, then pymavlink.

    build/venv/bin/python test/mavlink/mission_upload.py --tools build --work DIR

First run (`apm25sim --serial tcp:0 --speed 1 --eeprom FILE`, a fresh EEPROM): MAVProxy
(`--default-modules wp`) loads a 10-item QGC WPL 110 file (a takeoff, waypoints at 100,
130, 80 m, DO_CHANGE_SPEED, LOITER_TURNS counter-clockwise, DO_JUMP, LOITER_TIME, RTL)
with `wp load`; `wp list` asks for 11 (home at seq 0) and `wp save` writes what the board
sends back: equal to the file, home aside. The console's `mission` then lists the 10.
Second run on the same EEPROM file (a power cycle), pymavlink as the ground station:
  - the mission is still there, downloaded with the old MISSION_REQUEST / MISSION_ITEM
    (float degrees: within 1e-5 degrees, a float's 24 bits);
  - an upload of 20 stopped after 10 items: the board asks again, then MISSION_ACK
    OPERATION_CANCELLED, and the download is the mission before;
  - an upload with NAV_LAND (21) refused: MISSION_ACK UNSUPPORTED and a STATUSTEXT naming
    command 21; the mission before stays;
  - MISSION_SET_CURRENT 3 answered with MISSION_CURRENT 3;
  - 100 items uploaded (MISSION_ITEM_INT) while a PARAM_SET is saved ("saved"), downloaded
    equal; MISSION_CLEAR_ALL: a download of home alone;
  - no sample missed (no "loop overrun" STATUSTEXT, SYS_STATUS errors_count1 0);
  - a power cut every 0.25 s of the 100-item upload (apm25sim --eeprom-cuts): each chip
    starts with the mission before or the new one, whole (the console's `mission`).
Exit 1 with every failure listed.
"""
import os
import re
import subprocess
import sys
import time

from pymavlink.dialects.v20 import common as mavlink2

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "support"))
from gcs_link import Board  # noqa: E402
from mavproxy_session import Lines, write_banked  # noqa: E402
from sim_run import serve, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

M = mavlink2
HOME = (7.1350450, -73.1194210, 1028.0)
# seq, frame, command, p1..p4, lat, lon, alt (QGC WPL 110's columns but current and autocontinue).
ITEMS = [
    (3, 22, 15, 0, 0, 0, 0.0, 0.0, 50.0),                     # NAV_TAKEOFF to 50 m, 15 deg
    (3, 16, 0, 0, 0, 0, 7.1360450, -73.1194210, 100.0),       # waypoints around a block
    (3, 16, 0, 0, 0, 0, 7.1360450, -73.1180210, 130.0),
    (2, 178, 0, 15, -1, 0, 0.0, 0.0, 0.0),                    # DO_CHANGE_SPEED airspeed 15 m/s
    (3, 16, 0, 0, 0, 0, 7.1350450, -73.1180210, 80.0),
    (3, 18, 2, 0, -60, 0, 7.1345450, -73.1187210, 90.0),      # LOITER_TURNS 2, 60 m ccw
    (3, 16, 0, 0, 0, 0, 7.1345450, -73.1194210, 100.0),
    (2, 177, 2, 3, 0, 0, 0.0, 0.0, 0.0),                      # DO_JUMP to seq 2, 3 times
    (3, 19, 30, 0, 0, 0, 7.1350450, -73.1194210, 100.0),      # LOITER_TIME 30 s
    (3, 20, 0, 0, 0, 0, 0.0, 0.0, 0.0),                       # RETURN_TO_LAUNCH
]
WALL_TIMEOUT_S = 120
# The EEPROM as a power cut would leave it (apm25sim --eeprom-cuts), every CUT_STEP_S over the
# 100-item upload (it starts at CUT_FROM_S of board time, the clear waits for CUT_TO_S).
CUT_FROM_S, CUT_TO_S, CUT_STEP_S = 16.0, 30.0, 0.25


def write_wpl(path):
    with open(path, "w") as f:
        f.write("QGC WPL 110\n")
        f.write("0\t1\t0\t16\t0\t0\t0\t0\t%.7f\t%.7f\t%.2f\t1\n" % HOME)
        for i, (frame, cmd, p1, p2, p3, p4, lat, lon, alt) in enumerate(ITEMS):
            f.write("%d\t0\t%d\t%d\t%g\t%g\t%g\t%g\t%.7f\t%.7f\t%.2f\t1\n"
                    % (i + 1, frame, cmd, p1, p2, p3, p4, lat, lon, alt))


def read_wpl(path):
    """The rows after home: (frame, command, p1..p4, lat, lon, alt) as floats."""
    rows = []
    with open(path) as f:
        lines = f.read().split("\n")[1:]
    for line in lines:
        cols = line.split()
        if len(cols) == 12 and int(cols[0]) > 0:
            rows.append(tuple(float(c) for c in (cols[2:11])))
    return rows


def same_item(got, want, deg_tol):
    """got, want: (frame, command, p1..p4, lat, lon, alt)."""
    return (got[0] == want[0] and got[1] == want[1] and all(abs(a - b) < 1e-4 for a, b in zip(got[2:6], want[2:6]))
            and abs(got[6] - want[6]) <= deg_tol and abs(got[7] - want[7]) <= deg_tol and abs(got[8] - want[8]) < 0.006)


def int_frame(frame):
    return {0: 5, 3: 6}.get(frame, frame)


def mavproxy_run(args, trajectory, eeprom):
    log = open(os.path.join(args.work, "run1.stderr"), "w")
    sim, port = serve(args.tools, ["--trajectory", trajectory, "--eeprom", eeprom], log)
    mp_log = open(os.path.join(args.work, "mavproxy.out"), "w")
    mp = subprocess.Popen([sys.executable, os.path.join(os.path.dirname(sys.executable), "mavproxy.py"),
                           "--master", "tcp:127.0.0.1:" + port, "--no-state", "--default-modules", "wp",
                           "--target-system", "1"],
                          stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          bufsize=1, cwd=args.work)
    out = Lines(mp.stdout, mp_log)

    def type_line(cmd):
        mp.stdin.write(cmd + "\n")
        mp.stdin.flush()

    try:
        soft_assert(out.wait(r"Detected vehicle 1:1", "the vehicle", WALL_TIMEOUT_S), "MAVProxy found no vehicle")
        mission = os.path.abspath(os.path.join(args.work, "mission.waypoints"))
        write_wpl(mission)
        type_line("wp load " + mission)
        soft_assert(out.wait(r"Sent all 11 waypoints", "the upload's end"), "`wp load` did not finish")
        time.sleep(2)
        type_line("wp list")
        soft_assert(out.wait(r"Requesting 11 waypoints", "`wp list`'s count"), "`wp list` did not get 11")
        back = os.path.abspath(os.path.join(args.work, "downloaded.waypoints"))
        if os.path.exists(back):
            os.remove(back)
        type_line("wp save " + back)
        soft_assert(out.wait(r"Saved 11 waypoints", "`wp save`"), "`wp save` did not save 11")
        if os.path.exists(back):
            got = read_wpl(back)
            want = [(int_frame(r[0]), r[1]) + tuple(float(v) for v in r[2:]) for r in ITEMS]
            soft_assert(len(got) == len(want), "downloaded %d items, uploaded %d" % (len(got), len(want)))
            for i, (g, w) in enumerate(zip(got, want)):
                # MAVProxy keeps MISSION_ITEM_INT's frames (5, 6) as sent.
                soft_assert(same_item(g, w, 1.5e-7) or same_item((int_frame(g[0]),) + g[1:], w, 1.5e-7),
                            "item %d downloaded %r, uploaded %r" % (i + 1, g, w))
            print("# MAVProxy: wp load of 10 items, wp list and wp save: %d items equal" % len(got))
    finally:
        mp.terminate()  # `exit` is the misc module's, not loaded here
        try:
            mp.wait(timeout=30)
        except subprocess.TimeoutExpired:
            mp.kill()
        mp_log.close()
        sim.terminate()  # apm25sim writes the EEPROM file and exits
        sim.wait(timeout=120)
        log.write(sim.stderr.read())
        log.close()


class Gcs:
    """The pymavlink side of the mission protocol on a gcs_link.Board."""

    def __init__(self, board):
        self.b = board
        self.mav = board.conn.mav

    def wait(self, types, what, cond=lambda m: True, timeout_s=WALL_TIMEOUT_S, quiet=False):
        return self.b.pump(lambda m: m.get_type() in types and cond(m), what, timeout_s, quiet)

    def download(self, int_form=True):
        """The board's mission, home (seq 0) included: [(frame, command, p1..p4, lat, lon, alt)]."""
        self.mav.mission_request_list_send(1, 1, 0)
        c = self.wait(("MISSION_COUNT",), "MISSION_COUNT")
        if c is None:
            return None
        items = []
        for seq in range(c.count):
            for _ in range(3):
                if int_form:
                    self.mav.mission_request_int_send(1, 1, seq, 0)
                else:
                    self.mav.mission_request_send(1, 1, seq, 0)
                m = self.wait(("MISSION_ITEM_INT", "MISSION_ITEM"), "item %d" % seq, lambda m: m.seq == seq, 10, True)
                if m is not None:
                    break
            if m is None:
                soft_assert(False, "no item %d" % seq)
                return None
            soft_assert((m.get_type() == "MISSION_ITEM_INT") == int_form, "item %d came as %s" % (seq, m.get_type()))
            scale = 1e-7 if int_form else 1.0
            items.append((m.frame, m.command, m.param1, m.param2, m.param3, m.param4, m.x * scale, m.y * scale, m.z))
        self.mav.mission_ack_send(1, 1, 0, 0)
        return items

    def upload(self, items, stop_after=None):
        """Answers the board's requests with items (home first); the MISSION_ACK, or None when
        stopped after stop_after items."""
        self.mav.mission_count_send(1, 1, len(items), 0)
        sent = set()
        while True:
            m = self.wait(("MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"), "the upload's requests")
            if m is None or m.get_type() == "MISSION_ACK":
                return m
            if stop_after is not None and len(sent) >= stop_after and m.seq not in sent:
                return None
            frame, cmd, p1, p2, p3, p4, lat, lon, alt = items[m.seq]
            self.mav.mission_item_int_send(1, 1, m.seq, int_frame(frame), cmd, 0, 1, p1, p2, p3, p4,
                                           int(round(lat * 1e7)), int(round(lon * 1e7)), alt, 0)
            sent.add(m.seq)


def check_equal(got, want, tol, what):
    if got is None:
        return
    soft_assert(len(got) == len(want) + 1, "%s: %d items, expected %d and home" % (what, len(got), len(want)))
    for i, (g, w) in enumerate(zip(got[1:], want)):
        w = (int_frame(w[0]) if g[0] in (5, 6) else w[0],) + w[1:]
        soft_assert(same_item(g, w, tol), "%s: item %d %r, expected %r" % (what, i + 1, g, w))


def console_mission(args, trajectory, eeprom):
    """The console's `mission` on a copy of the EEPROM file: (the count it says, [(seq, id)])."""
    chip = os.path.join(args.work, "listing.bin")
    with open(eeprom, "rb") as f, open(chip, "wb") as g:
        g.write(f.read())
    typed = os.path.join(args.work, "mission.in")
    with open(typed, "w") as f:
        f.write("mission\n")
    r = subprocess.run([os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
                        "--trajectory", trajectory, "--eeprom", chip, "--seconds", "4", "--input", typed,
                        "--input-at", "2"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    text = r.stdout.decode(errors="replace")
    m = re.search(r"# mission: (\d+) commands, current (\d+)", text)
    rows = [(int(a), int(b)) for a, b in re.findall(r"^# (\d+): (\d+) ", text, re.M)]
    return (int(m.group(1)) if m else None), rows, text


def pymavlink_run(args, trajectory, eeprom):
    b = Board(args.tools, args.work, "run2", ["--trajectory", trajectory, "--eeprom", eeprom,
                                              "--eeprom-cuts", "%g:%g:%g" % (CUT_FROM_S, CUT_TO_S, CUT_STEP_S)])
    g = Gcs(b)
    try:
        b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT")
        home = (0, 16, 0, 0, 0, 0, 0.0, 0.0, 0.0)
        # The power cycle kept it; the old messages (float degrees).
        check_equal(g.download(int_form=False), ITEMS, 1e-5, "after the power cycle (MISSION_ITEM)")
        # A ground station that stops half way: asked again, then cancelled; the mission before stays.
        other = [home] + [(3, 16, 0, 0, 0, 0, 7.2 + i * 1e-3, -73.2, 60.0) for i in range(19)]
        g.upload(other, stop_after=10)
        ack = g.wait(("MISSION_ACK",), "OPERATION_CANCELLED after the retries")
        soft_assert(ack is not None and ack.type == M.MAV_MISSION_OPERATION_CANCELLED, "half an upload: %r" % ack)
        check_equal(g.download(), ITEMS, 1.5e-7, "after an upload stopped half way")
        # NAV_LAND refused, said with its number; the mission before stays.
        landing = [home, other[1], (3, 21, 0, 0, 0, 0, 7.2, -73.2, 0.0), other[2]]
        ack = g.upload(landing)
        soft_assert(ack is not None and ack.type == M.MAV_MISSION_UNSUPPORTED, "NAV_LAND: %r" % ack)
        said = g.wait(("STATUSTEXT",), "the refusal's STATUSTEXT", lambda m: "mission" in m.text)
        soft_assert(said is not None and "command 21" in said.text, "NAV_LAND's STATUSTEXT: %r" % said)
        check_equal(g.download(), ITEMS, 1.5e-7, "after NAV_LAND refused")
        # MISSION_SET_CURRENT -> MISSION_CURRENT.
        g.mav.mission_set_current_send(1, 1, 3)
        cur = g.wait(("MISSION_CURRENT",), "MISSION_CURRENT")
        soft_assert(cur is not None and cur.seq == 3 and cur.total == len(ITEMS), "MISSION_CURRENT %r" % cur)
        # 100 commands, the store's all, while a PARAM_SET is saved: the settings' save and
        # the mission's writes share the EEPROM.
        full = [home] + [(3 if i % 2 else 0, 16, 0, 0, 0, 0, 7.1 + i * 1e-4, -73.1 - i * 1e-4, 50.0 + i)
                         for i in range(100)]
        b.pump(lambda m: b.t_s >= CUT_FROM_S, "board time %g s" % CUT_FROM_S)
        t0 = b.t_s
        first = len(b.msgs)
        g.mav.param_set_send(1, 1, b"RLL2SRV_P", 0.75, M.MAV_PARAM_TYPE_REAL32)
        ack = g.upload(full)
        soft_assert(ack is not None and ack.type == M.MAV_MISSION_ACCEPTED, "100 items: %r" % ack)
        print("# 100 items uploaded in %.1f s (simulated), a PARAM_SET saved meanwhile" % (b.t_s - t0))
        saved = [m for _, m in b.msgs[first:] if m.get_type() == "STATUSTEXT" and m.text == "saved"]
        if not saved:
            saved = [g.wait(("STATUSTEXT",), "the PARAM_SET's save", lambda m: m.text == "saved")]
        soft_assert(saved[0] is not None, "the settings' save during the upload never ended")
        check_equal(g.download(), full[1:], 1.5e-7, "100 items")
        soft_assert(b.t_s < CUT_TO_S, "the upload ended at %.1f s, after the cuts' window" % b.t_s)
        b.pump(lambda m: b.t_s >= CUT_TO_S, "board time %g s" % CUT_TO_S)
        # Cleared: home alone.
        g.mav.mission_clear_all_send(1, 1, 0)
        ack = g.wait(("MISSION_ACK",), "MISSION_CLEAR_ALL's ACK")
        soft_assert(ack is not None and ack.type == M.MAV_MISSION_ACCEPTED, "clear: %r" % ack)
        check_equal(g.download(), [], 0, "after MISSION_CLEAR_ALL")
        status = g.wait(("SYS_STATUS",), "SYS_STATUS")
        soft_assert(status is not None and status.errors_count1 == 0,
                    "missed samples (SYS_STATUS errors_count1): %r" % (status and status.errors_count1))
    finally:
        b.stop()
    overruns = [m.text for _, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "samples missed: %r" % overruns)
    # A power cut anywhere in the upload: the board starts with the mission before or the
    # new one, whole (the console's `mission`).
    kinds = {}
    k = 0
    while os.path.exists("%s.cut%d" % (eeprom, k)):
        n, rows, text = console_mission(args, trajectory, "%s.cut%d" % (eeprom, k))
        old = n == len(ITEMS) and [r[1] for r in rows] == [it[1] for it in ITEMS]
        new = n == 100 and [r[1] for r in rows] == [16] * 100
        soft_assert(old or new, "power cut %d at %.2f s: mission %r, %d rows" % (k, CUT_FROM_S + k * CUT_STEP_S, n,
                                                                                  len(rows)))
        kinds["old" if old else "new" if new else "other"] = kinds.get("old" if old else "new" if new else "other", 0) + 1
        k += 1
    soft_assert(kinds.get("old", 0) > 0 and kinds.get("new", 0) > 0, "the cuts saw %r" % kinds)
    print("# %d power cuts over the 100-item upload: %r" % (k, kinds))


def main():
    args = tools_and_work()
    trajectory = os.path.join(args.work, "banked.csv")
    write_banked(trajectory)
    eeprom = os.path.join(args.work, "eeprom.bin")
    for name in os.listdir(args.work):
        if name.startswith("eeprom.bin"):
            os.remove(os.path.join(args.work, name))
    mavproxy_run(args, trajectory, eeprom)
    soft_assert(os.path.exists(eeprom), "apm25sim wrote no EEPROM file")
    # The console lists what MAVProxy uploaded.
    n, rows, text = console_mission(args, trajectory, eeprom)
    soft_assert(n == len(ITEMS) and [r for r in rows] == [(i + 1, it[1]) for i, it in enumerate(ITEMS)],
                "`mission` said %r, %r" % (n, rows))
    # (MAVProxy sends -73.1187210 as -731187209: its float to int truncates.)
    soft_assert(re.search(r"^# 6: 18 15362 7\.1345450 -73\.118720\d 90\.00 ccw$", text, re.M),
                "`mission`'s LOITER_TURNS line (turns 2, radius 60 m in p1, counter-clockwise)")
    pymavlink_run(args, trajectory, eeprom)


if __name__ == "__main__":
    main()
    sys.exit(finish("mission protocol", "uploads, downloads, a power cycle, refusals, 100 items: all checks passed"))
