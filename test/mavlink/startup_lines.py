#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The start-up's "# " lines in MAVLink never hold up the loop (docs/firmware.md, "Messages
never wait for the UART").

    build/venv/bin/python test/mavlink/startup_lines.py --tools build --work DIR

Runs build/firmware.elf in apm25sim (simulated time, --profile) for 4 s of the tilt tour
with a receiver in STABILIZE from 0.5 s, and a ground station's HEARTBEAT and
PARAM_REQUEST_LIST typed at 0.05 s: the board speaks MAVLink from its start, and the
parameter list streams while the start-up says its lines (the gyro calibration, STABILIZE
without an attitude, the barometer's ground, the airspeed, the gyro bias) as STATUSTEXT,
each one or two frames. A line that waited for the UART in the task that says it held the
control step up to 9 ms (147,700 cycles) and missed samples. Checks:
  - no sample missed (no "loop overrun" STATUSTEXT), and one sample's work (profile
    section 6) under the 5 ms sample period;
  - the barometer task (section 37) within its budget (firmware/Tasks.cpp);
  - every line said: the STABILIZE warning and the barometer's ground as STATUSTEXT, no
    "held back" line (PARAM_VALUE leaves room for them), and every parameter answered.
Exit 1 with every failure listed.
"""
import os
import re
import subprocess
import sys

from pymavlink.dialects.v20 import common as mavlink2

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

SECONDS = 4
CYCLES_PER_US = 16
SAMPLE_PERIOD_CYCLES = 5000 * CYCLES_PER_US
HERE = os.path.dirname(os.path.abspath(__file__))


def task_budget_us(name):
    """A loop task's budget in firmware/Tasks.cpp's table."""
    with open(os.path.join(HERE, "..", "..", "firmware", "Tasks.cpp")) as f:
        m = re.search(r"X\(%s,[^,]*,[^,]*,\s*(\d+)," % name, f.read())
    return int(m.group(1))


def profile(path):
    rows = {}
    with open(path) as f:
        for line in f:
            p = line.strip().split(",")
            if p[0].isdigit():
                rows[int(p[0])] = int(p[4])  # max cycles
    return rows


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "tilt_tour")
    rc = os.path.join(args.work, "stabilize_rc.csv")
    with open(rc, "w") as f:
        f.write("t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n0.5,1500,1500,1500,1500,1500,1500,1500,2000\n")
    gcs = mavlink2.MAVLink(None, srcSystem=255, srcComponent=190)
    typed = os.path.join(args.work, "gcs.in")
    with open(typed, "wb") as f:
        f.write(mavlink2.MAVLink_heartbeat_message(6, 8, 0, 0, 0, 3).pack(gcs)
                + mavlink2.MAVLink_param_request_list_message(1, 1).pack(gcs))
    prof = os.path.join(args.work, "profile.csv")
    run = subprocess.run([os.path.join(args.tools, "apm25sim"), "--elf", os.path.join(args.tools, "firmware.elf"),
                          "--trajectory", trajectory, "--seconds", str(SECONDS), "--rc", rc, "--input", typed,
                          "--input-at", "0.05", "--profile", prof], capture_output=True)
    soft_assert(run.returncode == 0, "apm25sim: %d %s" % (run.returncode, run.stderr[-300:]))
    mav = mavlink2.MAVLink(None)
    mav.robust_parsing = True
    msgs = mav.parse_buffer(run.stdout) or []
    texts = [m.text for m in msgs if m.get_type() == "STATUSTEXT"]
    params = {m.param_index for m in msgs if m.get_type() == "PARAM_VALUE"}
    count = max([m.param_count for m in msgs if m.get_type() == "PARAM_VALUE"] or [0])
    print("# %d STATUSTEXT, %d of %d parameters: %r" % (len(texts), len(params), count, texts))

    soft_assert(not [t for t in texts if "overrun" in t], "samples missed: %r" % texts)
    cycles = profile(prof)
    print("# max cycles: a sample's work %d, estimator %d, control %d, airspeed %d, barometer %d"
          % tuple(cycles.get(s, -1) for s in (6, 1, 13, 19, 37)))
    soft_assert(0 < cycles.get(6, 0) < SAMPLE_PERIOD_CYCLES,
                "a sample's work took %d cycles (the period: %d)" % (cycles.get(6, 0), SAMPLE_PERIOD_CYCLES))
    baro_budget = task_budget_us("baro") * CYCLES_PER_US
    soft_assert(0 < cycles.get(37, 0) <= baro_budget,
                "the barometer task took %d cycles (budget %d)" % (cycles.get(37, 0), baro_budget))
    soft_assert(any(t.startswith("warn: STABILIZE without an attitude") for t in texts),
                "the STABILIZE warning not said: %r" % texts)
    soft_assert(any(t.startswith("baro: MS5611, ground") for t in texts), "the ground's line not said: %r" % texts)
    soft_assert(not [t for t in texts if "held back" in t], "lines held back: %r" % texts)
    soft_assert(count > 100 and len(params) == count, "parameters answered: %d of %d" % (len(params), count))


if __name__ == "__main__":
    main()
    sys.exit(finish("start-up lines in MAVLink", "said without holding up the loop"))
