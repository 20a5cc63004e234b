#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""MAVProxy's own compass calibration on the simulated board over TCP.

    build/venv/bin/python test/mavlink/mavproxy_mag_cal.py --tools build --work DIR

Starts `apm25sim --serial tcp:0 --speed 1` on the compass tumble (hard iron (8, -5, 3) uT, 3 %
soft iron on x: still 5 s, turned every way for 30 s) and MAVProxy with its calibration module,
types `magcal start` 5 s (wall) after the board started (the simulated time is never ahead of the
wall's), and checks what MAVProxy prints:
  - "DO_START_MAG_CAL: ACCEPTED";
  - "Calibration of compass 0 SUCCESS: fitness F" with F under 5 (mGauss): MAVProxy decoded
    MAG_CAL_REPORT;
  - its automatic DO_ACCEPT_MAG_CAL (after an autosaved run: nothing left to do) ACCEPTED, and the
    board's "AP: saved";
  - `param fetch` of COMPASS_OFS_X, _Y, _Z then prints ArduPilot's offsets for the hard iron,
    (-80, 50, -30) mGauss within 3.
Exit 1 with every failure listed.
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from mavproxy_session import Session  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

WANT_MGAUSS = {"X": -80.0, "Y": 50.0, "Z": -30.0}
BOUND_MGAUSS = 3.0


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "tumble", ["--hard-iron", "8,-5,3", "--soft-iron", "1.03,1,1"],
                               "tumble_hard_soft_iron.csv")
    started = time.time()
    session = Session(args, ["--trajectory", trajectory], "param,mode,calibration")
    out, type_line = session.out, session.type_line
    try:
        out.wait(r"Received (\d+) parameters", "the parameter list")
        time.sleep(max(0.0, 5.0 - (time.time() - started)))
        type_line("magcal start")
        soft_assert(out.wait(r"DO_START_MAG_CAL: ACCEPTED", "the start's ACK"), "magcal start not accepted")
        report = out.wait(r"Calibration of compass 0 (\w+): fitness ([-0-9.]+)", "the calibration's report")
        soft_assert(report and report.group(1) == "SUCCESS" and 0.0 < float(report.group(2)) < 5.0,
                    "report: %s" % (report and report.group(0)))
        soft_assert(out.wait(r"DO_ACCEPT_MAG_CAL: ACCEPTED", "the accept's ACK"), "MAVProxy's accept refused")
        soft_assert(out.wait(r"AP: saved", "the board's 'saved'"), "the calibration was not saved")
        got = {}
        for axis in "XYZ":
            type_line("param fetch COMPASS_OFS_" + axis)
            m = out.wait(r"COMPASS_OFS_%s = ([-0-9.e]+)" % axis, "COMPASS_OFS_" + axis)
            got[axis] = float(m.group(1)) if m else None
        soft_assert(all(got[a] is not None and abs(got[a] - WANT_MGAUSS[a]) <= BOUND_MGAUSS for a in "XYZ"),
                    "COMPASS_OFS %r, expected %r within %.0f mGauss" % (got, WANT_MGAUSS, BOUND_MGAUSS))
        print("# MAVProxy: magcal start, %s, accepted and saved; COMPASS_OFS %s"
              % (report and report.group(0), " ".join("%s %.2f" % (a, got[a]) for a in "XYZ" if got[a] is not None)))
    finally:
        session.stop()


if __name__ == "__main__":
    main()
    sys.exit(finish("MAVProxy compass calibration", "MAVProxy's magcal on the simulated board: all checks passed"))
