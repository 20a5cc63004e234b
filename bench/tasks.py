# SPDX-License-Identifier: GPL-3.0-or-later
"""The task table's figures for `make bench`: each task of firmware/Tasks.cpp, its budget,
and the cycles its profiling section took in the simulator's runs (apm25sim --profile),
average and maximum, against the budget.

The table is read from the source (the X-macro rows of SAMPLE_TASKS and LOOP_TASKS) and
the sections' ids from firmware/Board.h, so there is one table and this only reads it.
Several tasks may share a section (the reply rows): their figures are the section's.
"""
import os
import re

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
F_CPU = 16_000_000

_ROW = re.compile(r"^\s*X\(\s*(\w+)\s*,\s*([^,]+?)\s*,\s*([^,]+?)\s*,\s*(.+?)\)\s*\\?\s*$")


def read_table(path=None):
    """[(kind, name, period, budget_us, section_name, flags)] in table order."""
    path = path or os.path.join(REPO, "firmware", "Tasks.cpp")
    rows, kind = [], None
    for line in open(path):
        if line.startswith("#define SAMPLE_TASKS"):
            kind = "sample"
            continue
        if line.startswith("#define LOOP_TASKS"):
            kind = "loop"
            continue
        if kind is None:
            continue
        m = _ROW.match(line)
        if not m:
            if not line.rstrip().endswith("\\"):
                kind = None
            continue
        name, _due, _run, rest = m.groups()
        fields = [f.strip() for f in rest.split(",")]
        if kind == "sample":
            period, budget, section = fields[0], fields[1], fields[2]
            flags = ""
        else:
            period, budget, section, flags = "0", fields[0], fields[1], fields[2]
        rows.append(dict(kind=kind, name=name, period=int(period), budget_us=int(budget), section=section,
                         flags=flags))
    return rows


def read_sections(path=None):
    """{kSecName: id} from firmware/Board.h's Section enum."""
    path = path or os.path.join(REPO, "firmware", "Board.h")
    return {m.group(1): int(m.group(2)) for m in re.finditer(r"\b(kSec\w+)\s*=\s*(\d+)", open(path).read())}


def merge_runs(runs):
    """{section id: dict(count, avg, max)} over several runs' sections (count-weighted avg, max of maxima)."""
    out = {}
    for sections in runs:
        for sid, s in sections.items():
            o = out.setdefault(sid, dict(count=0, total=0.0, max=0))
            o["count"] += s["count"]
            o["total"] += s["total"]
            o["max"] = max(o["max"], s["max"])
    for o in out.values():
        o["avg"] = o["total"] / o["count"] if o["count"] else 0.0
    return out


def task_rows(runs):
    """The table's rows with their figures: budget_cycles, count, avg, max, max_us, over (max > budget)."""
    ids = read_sections()
    merged = merge_runs(runs)
    rows = []
    for r in read_table():
        sid = ids.get(r["section"])
        s = merged.get(sid) if sid is not None else None
        budget_cycles = r["budget_us"] * F_CPU // 1_000_000
        rows.append(dict(r, section_id=sid, budget_cycles=budget_cycles,
                         count=s["count"] if s else 0, avg=s["avg"] if s else None, max=s["max"] if s else None,
                         max_us=s["max"] * 1e6 / F_CPU if s else None,
                         over=bool(s and s["max"] > budget_cycles)))
    return rows


def section(runs, md_table, fmt):
    """The report's markdown section and the rows."""
    rows = task_rows(runs)
    table = []
    for r in rows:
        period = ("every %d samples" % r["period"] if r["period"] > 1 else "each sample") if r["kind"] == "sample" \
            else ("between samples" + (", always" if "kAlways" in r["flags"] else ""))
        table.append([r["name"], period, fmt(r["budget_us"]), str(r["section_id"]), fmt(r["count"]),
                      fmt(r["avg"], 0) if r["avg"] is not None else "–",
                      fmt(r["max"], 0) if r["max"] is not None else "–",
                      ("%.0f" % r["max_us"]) if r["max_us"] is not None else "–",
                      "OVER" if r["over"] else ("ok" if r["count"] else "not run")])
    over = [r["name"] for r in rows if r["over"]]
    rep = ["## The task table (firmware/Tasks.cpp)", "",
           "Every periodic job of the firmware, its budget and the cycles its profiling section took over all "
           "the profiled runs (tilt_tour and shake, on the ground and in flight, a console session, a MAVLink "
           "session); *max us* at 16 MHz. A task whose longest run exceeds its budget is marked OVER (rows that "
           "share a section show the section's figures).", "",
           md_table(["task", "runs", "budget us", "section", "count", "avg cycles", "max cycles", "max us", ""],
                    table), "",
           "Tasks over budget: %s." % (", ".join(over) if over else "none"), ""]
    return rep, rows


# What the console session types: replies of every kind (help, status's float lines, the
# parameter list, a set that reconfigures the flight, the receiver's widths, the barometer's
# lines, a save).
CONSOLE_SESSION = "help\r\nstatus\r\nparams\r\nset RLL2SRV_P 0.5\r\nrc\r\nservo\r\nbaro\r\nget RLL2SRV_P\r\nsave"


def gcs_session_bytes():
    """A ground station's first second, as MAVLink 2 bytes (pymavlink): HEARTBEAT (the port
    switches to MAVLink), the parameter list, a PARAM_SET (answered and saved), a gyro
    calibration and a save (COMMAND_LONG), then the typed status as STATUSTEXT."""
    from pymavlink.dialects.v20 import common as mavlink2

    class Sink:
        def write(self, _):
            pass

    mav = mavlink2.MAVLink(Sink(), srcSystem=255, srcComponent=190)
    mav.robust_parsing = True
    frames = [
        mav.heartbeat_encode(mavlink2.MAV_TYPE_GCS, mavlink2.MAV_AUTOPILOT_INVALID, 0, 0, 0),
        mav.param_request_list_encode(1, 1),
        mav.param_set_encode(1, 1, b"RLL2SRV_P", 0.5, mavlink2.MAV_PARAM_TYPE_REAL32),
        mav.command_long_encode(1, 1, mavlink2.MAV_CMD_PREFLIGHT_STORAGE, 0, 1, 0, 0, 0, 0, 0, 0),
    ]
    return b"".join(f.pack(mav) for f in frames) + b"status\r\n"
