#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The ground station's compass calibration on the simulated board over TCP.

    build/venv/bin/python test/mavlink/gcs_mag_cal.py --tools build --work DIR

Runs build/firmware.elf in `apm25sim --serial tcp:0 --speed 1` on the compass tumble (build/scenario
tumble with hard iron (8, -5, 3) uT and 3 % soft iron on x: still 5 s, turned every way for 30 s,
still 15 s) and talks to it with pymavlink's ArduPilot dialect as MAVProxy's `magcal` does (the
same COMMAND_LONGs: target component 0, the compass mask 0). Checks:
  - DO_START_MAG_CAL (autosave 0) at 5 s: ACCEPTED; MAG_CAL_PROGRESS at 1-3 Hz (simulated), its
    completion_pct rising to at least 90, status RUNNING_STEP_ONE then _TWO, the cells seen
    (completion_mask) growing to at least 90 % of the 26;
  - MAG_CAL_REPORT: SUCCESS, not autosaved, fitness under 5 mGauss, ofs within 3 mGauss (0.3 uT,
    the bound of the console's `cal mag` e2e test) of ArduPilot's offsets for the hard iron
    (-80, 50, -30) mGauss, diag y/x and z/x 1.03 within 0.01;
  - COMPASS_OFS_* unchanged (0) before the accept; DO_ACCEPT_MAG_CAL: ACCEPTED, "saved", the nine
    values sent unasked as PARAM_VALUEs equal to the report's, and
    COMPASS_OFS_X/Y/Z, _DIA_*, _ODI_* read back (PARAM_REQUEST_READ) equal to the report's;
  - DO_START_MAG_CAL (MAVProxy's, autosave 1) then DO_CANCEL_MAG_CAL: both ACCEPTED, no report,
    the offsets unchanged;
  - PARAM_SET COMPASS_OFS_Y + 100 mGauss at rest: the heading moves to what the field with the
    new offset gives (predicted from the trajectory's true field and the board's roll and pitch:
    within 2 deg, the move at least 10 deg); it is saved. (Y: the tumble ends heading south, the
    horizontal field along the body's x axis, which X would only lengthen.);
  - no sample missed ("overrun");
then a second run on the same EEPROM file (a power cycle): COMPASS_OFS_* as set and accepted.
Exit 1 with every failure listed. Timing assertions are on simulated time only.
"""
import csv
import math
import os
import sys

from pymavlink import mavutil

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from gcs_link import Board  # noqa: E402
from sim_run import scenario_file, tools_and_work  # noqa: E402
from soft_assert import finish, soft_assert  # noqa: E402

mav = mavutil.mavlink  # the ArduPilot dialect: MAG_CAL_PROGRESS, DO_*_MAG_CAL
HARD_IRON_UT = (8.0, -5.0, 3.0)
SOFT_IRON_DET = 1.03
OFS_BOUND_MGAUSS = 3.0
START_S = 5.0       # the tumble starts
TUMBLE_END_S = 35.0
OFS_STEP_MGAUSS = 100.0
NAMES = ["COMPASS_%s_%s" % (k, a) for k in ("OFS", "DIA", "ODI") for a in "XYZ"]


def magcal(board, command, autosave):
    """MAVProxy's `magcal start|accept|cancel` frame (mavproxy_calibration.py): its ACK."""
    board.conn.mav.command_long_send(1, 0, command, 0, 0, 0, autosave, 0, 0, 0, 0)
    return board.ack(command, "COMMAND_ACK for %d" % command)


def read_params(board, what):
    values = {}
    for name in NAMES:
        board.conn.mav.param_request_read_send(1, 1, name.encode(), -1)
        pv = board.param(name, "PARAM_VALUE %s %s" % (name, what))
        values[name] = pv.param_value if pv is not None else None
    return values


def report_values(r):
    return dict(zip(NAMES, (r.ofs_x, r.ofs_y, r.ofs_z, r.diag_x, r.diag_y, r.diag_z, r.offdiag_x, r.offdiag_y,
                            r.offdiag_z)))


def true_field_at_rest(trajectory):
    """The body-frame field (uT) of the trajectory's last row (the plain tumble's: no sensor
    errors): the board at rest."""
    with open(trajectory) as f:
        rows = list(csv.DictReader(f))
    return [float(rows[-1][k]) for k in ("mx", "my", "mz")]


def magnetic_heading_deg(field, roll, pitch):
    """The heading a field (body frame) gives at this roll and pitch (rad): the field taken to the
    level frame (Ry(pitch) Rx(roll)), whose horizontal part is (B cos psi, -B sin psi)."""
    x, y, z = field
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    y1, z1 = cr * y - sr * z, sr * y + cr * z
    hx, hy = cp * x + sp * z1, y1
    return math.degrees(math.atan2(-hy, hx))


def angle_diff(a, b):
    return (a - b + 180.0) % 360.0 - 180.0


def mean_attitude(board, from_s, to_s):
    """Roll, pitch (rad) and yaw (deg) averaged over ATTITUDE in [from_s, to_s), after pumping to to_s."""
    board.pump(lambda m: board.t_s >= to_s, "the run to reach %.1f s" % to_s)
    atts = [m for t, m in board.msgs if m.get_type() == "ATTITUDE" and from_s <= t < to_s]
    if not atts:
        return None
    ref = math.degrees(atts[0].yaw)
    yaw = ref + sum(angle_diff(math.degrees(m.yaw), ref) for m in atts) / len(atts)
    return (sum(m.roll for m in atts) / len(atts), sum(m.pitch for m in atts) / len(atts), yaw)


def calibrate_and_accept(b):
    """The tumble's calibration, START to ACCEPT; the report or None."""
    b.pump(lambda m: b.t_s >= START_S, "the run to reach %.0f s" % START_S)
    ack = magcal(b, mav.MAV_CMD_DO_START_MAG_CAL, 0)
    soft_assert(ack is not None and ack.result == mav.MAV_RESULT_ACCEPTED, "DO_START_MAG_CAL: %r" % ack)
    started = len(b.msgs)
    report = b.pump(lambda m: m.get_type() == "MAG_CAL_REPORT", "MAG_CAL_REPORT")
    if report is None:
        return None
    progress = [(t, m) for t, m in b.msgs[started:] if m.get_type() == "MAG_CAL_PROGRESS"]
    soft_assert(len(progress) >= 20, "only %d MAG_CAL_PROGRESS" % len(progress))
    if progress:
        pcts = [m.completion_pct for _, m in progress]
        soft_assert(all(a <= b for a, b in zip(pcts, pcts[1:])) and pcts[-1] >= 90 and len(set(pcts)) >= 10,
                    "completion_pct not rising to 90: %r" % pcts)
        cells = [bin(int.from_bytes(bytes(m.completion_mask), "little")).count("1") for _, m in progress]
        soft_assert(cells[-1] >= 24 and cells[-1] > cells[0], "cells seen %r" % cells)
        statuses = [m.cal_status for _, m in progress]
        soft_assert(statuses[0] == mav.MAG_CAL_RUNNING_STEP_ONE and
                    set(statuses) <= {mav.MAG_CAL_RUNNING_STEP_ONE, mav.MAG_CAL_RUNNING_STEP_TWO},
                    "MAG_CAL_PROGRESS statuses %r" % sorted(set(statuses)))
        span = progress[-1][0] - progress[0][0]
        rate = (len(progress) - 1) / span if span > 0 else 0.0
        soft_assert(1.0 <= rate <= 3.0, "MAG_CAL_PROGRESS at %.2f Hz (simulated)" % rate)
        direction = progress[-1][1]
        norm = math.sqrt(direction.direction_x ** 2 + direction.direction_y ** 2 + direction.direction_z ** 2)
        soft_assert(abs(norm - 1.0) < 1e-3, "direction not a unit vector: %r" % direction)
        print("# %d MAG_CAL_PROGRESS at %.2f Hz, completion %d..%d %%, %d of 26 cells"
              % (len(progress), rate, pcts[0], pcts[-1], cells[-1]))
    soft_assert(report.cal_status == mav.MAG_CAL_SUCCESS and report.autosaved == 0 and report.compass_id == 0,
                "MAG_CAL_REPORT %r" % report)
    want = [-10.0 * h for h in HARD_IRON_UT]  # ArduPilot's offsets: added to the field, mGauss
    got = [report.ofs_x, report.ofs_y, report.ofs_z]
    soft_assert(all(abs(g - w) <= OFS_BOUND_MGAUSS for g, w in zip(got, want)),
                "report's offsets %r, expected %r within %.1f mGauss" % (got, want, OFS_BOUND_MGAUSS))
    soft_assert(abs(report.diag_y / report.diag_x - 1.03) < 0.01 and abs(report.diag_z / report.diag_x - 1.03) < 0.01,
                "report's diagonal %r: 3 %% on x undone" % ((report.diag_x, report.diag_y, report.diag_z),))
    soft_assert(0.0 < report.fitness < 5.0, "fitness %r mGauss" % report.fitness)
    print("# MAG_CAL_REPORT at %.2f s: ofs %.2f %.2f %.2f mGauss, diag %.4f %.4f %.4f, fitness %.2f mGauss"
          % (b.t_s, report.ofs_x, report.ofs_y, report.ofs_z, report.diag_x, report.diag_y, report.diag_z,
             report.fitness))

    before = read_params(b, "before the accept")
    soft_assert(all(before[n] == 0.0 for n in NAMES[:3]), "COMPASS_OFS_* in use before the accept: %r" % before)
    since = len(b.msgs)
    ack = magcal(b, mav.MAV_CMD_DO_ACCEPT_MAG_CAL, 1)
    soft_assert(ack is not None and ack.result == mav.MAV_RESULT_ACCEPTED, "DO_ACCEPT_MAG_CAL: %r" % ack)
    saved = b.pump(lambda m: m.get_type() == "STATUSTEXT" and m.text == "saved", "STATUSTEXT 'saved' after ACCEPT")
    soft_assert(saved is not None, "the accepted calibration was not saved")
    # The nine values told unasked (ArduPilot's PARAM_VALUE for a value the vehicle sets),
    # each the report's.
    want = report_values(report)
    told = {}

    def take(m):
        if m.get_type() == "PARAM_VALUE" and m.param_id in NAMES:
            told[m.param_id] = m.param_value
        return len(told) == len(NAMES)
    for _, m in b.msgs[since:]:
        take(m)
    if len(told) < len(NAMES):
        b.pump(take, "the accepted calibration's PARAM_VALUEs, unasked", timeout_s=60)
    soft_assert(len(told) == len(NAMES) and all(abs(told[n] - want[n]) <= 0.01 for n in NAMES),
                "announced after the accept: %r, the report's %r" % (told, want))
    after = read_params(b, "after the accept")
    soft_assert(all(after[n] is not None and abs(after[n] - want[n]) <= 0.01 for n in NAMES),
                "parameters after the accept %r, the report's %r" % (after, want))
    return report


def cancel_keeps_the_offsets(b, report):
    ack = magcal(b, mav.MAV_CMD_DO_START_MAG_CAL, 1)
    soft_assert(ack is not None and ack.result == mav.MAV_RESULT_ACCEPTED, "second DO_START_MAG_CAL: %r" % ack)
    b.pump(lambda m: m.get_type() == "MAG_CAL_PROGRESS", "MAG_CAL_PROGRESS of the second run")
    ack = magcal(b, mav.MAV_CMD_DO_CANCEL_MAG_CAL, 1)
    soft_assert(ack is not None and ack.result == mav.MAV_RESULT_ACCEPTED, "DO_CANCEL_MAG_CAL: %r" % ack)
    cancelled = len(b.msgs)
    t0 = b.t_s
    b.pump(lambda m: b.t_s >= t0 + 1.5, "time to pass after the cancel")
    late = [m.get_type() for _, m in b.msgs[cancelled:] if m.get_type() in ("MAG_CAL_REPORT", "MAG_CAL_PROGRESS")]
    soft_assert(late.count("MAG_CAL_REPORT") == 0 and late.count("MAG_CAL_PROGRESS") <= 1,
                "after the cancel: %r" % late)
    now = read_params(b, "after the cancel")
    want = report_values(report)
    soft_assert(all(now[n] is not None and abs(now[n] - want[n]) <= 0.01 for n in NAMES),
                "parameters after the cancel %r, the accepted %r" % (now, want))


def offset_moves_the_heading(b, trajectory, report):
    """PARAM_SET COMPASS_OFS_Y + OFS_STEP_MGAUSS at rest; the value set."""
    rest_from = max(b.t_s, TUMBLE_END_S + 2.0)
    before = mean_attitude(b, rest_from, rest_from + 1.0)
    if before is None:
        soft_assert(False, "no ATTITUDE at rest")
        return None
    truth = true_field_at_rest(trajectory)
    # The formula against the board before the change: the calibrated field is the true one.
    soft_assert(abs(angle_diff(magnetic_heading_deg(truth, before[0], before[1]), before[2])) < 1.5,
                "heading at rest %.2f deg, the true field gives %.2f" % (before[2],
                                                                         magnetic_heading_deg(truth, *before[:2])))
    new_y = round(report.ofs_y + OFS_STEP_MGAUSS, 2)
    b.conn.mav.param_set_send(1, 1, b"COMPASS_OFS_Y", new_y, mav.MAV_PARAM_TYPE_REAL32)
    pv = b.param("COMPASS_OFS_Y", "PARAM_VALUE for PARAM_SET COMPASS_OFS_Y")
    soft_assert(pv is not None and abs(pv.param_value - new_y) < 1e-5, "PARAM_SET COMPASS_OFS_Y %.2f -> %r"
                % (new_y, pv))
    set_at = b.t_s
    b.pump(lambda m: m.get_type() == "STATUSTEXT" and m.text == "saved", "STATUSTEXT 'saved' after the PARAM_SET")
    after = mean_attitude(b, set_at + 3.0, set_at + 4.0)
    if after is None:
        soft_assert(False, "no ATTITUDE after the PARAM_SET")
        return new_y
    # The field the board now calibrates: W (m - offset), the true field times det(soft iron)^(1/3)
    # (W has determinant 1 and undoes the 3 % on x), plus W times the offset's change (uT).
    d = OFS_STEP_MGAUSS / 10.0
    w_col = (report.offdiag_x, report.diag_y, report.offdiag_z)
    moved = [SOFT_IRON_DET ** (1.0 / 3.0) * f + d * w for f, w in zip(truth, w_col)]
    predicted = magnetic_heading_deg(moved, after[0], after[1])
    print("# COMPASS_OFS_Y %.2f -> %.2f mGauss at %.2f s: heading %.2f -> %.2f deg, predicted %.2f"
          % (report.ofs_y, new_y, set_at, before[2], after[2], predicted))
    soft_assert(abs(angle_diff(after[2], predicted)) < 2.0 and abs(angle_diff(after[2], before[2])) >= 10.0,
                "heading after COMPASS_OFS_Y %.2f: %.2f deg, predicted %.2f (before %.2f)"
                % (new_y, after[2], predicted, before[2]))
    return new_y


def main():
    args = tools_and_work()
    trajectory = scenario_file(args.tools, args.work, "tumble", ["--hard-iron", "8,-5,3", "--soft-iron", "1.03,1,1"],
                               "tumble_hard_soft_iron.csv")
    plain = scenario_file(args.tools, args.work, "tumble")  # the same motion, its true field
    eeprom = os.path.join(args.work, "eeprom.bin")
    if os.path.exists(eeprom):
        os.remove(eeprom)

    b = Board(args.tools, args.work, "session1", ["--trajectory", trajectory, "--eeprom", eeprom])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT: the board did not switch to MAVLink") is None:
        b.stop()
        return
    report = calibrate_and_accept(b)
    new_y = None
    if report is not None:
        cancel_keeps_the_offsets(b, report)
        new_y = offset_moves_the_heading(b, plain, report)
    b.stop()
    overruns = ["%.2f s: %s" % (t, m.text) for t, m in b.msgs if m.get_type() == "STATUSTEXT" and "overrun" in m.text]
    soft_assert(not overruns, "samples missed during the calibration: %r" % overruns)
    if report is None or new_y is None:
        return

    b = Board(args.tools, args.work, "session2", ["--trajectory", trajectory, "--eeprom", eeprom])
    if b.pump(lambda m: m.get_type() == "HEARTBEAT", "HEARTBEAT after the power cycle") is not None:
        now = read_params(b, "after the power cycle")
        want = report_values(report)
        want["COMPASS_OFS_Y"] = new_y
        soft_assert(all(now[n] is not None and abs(now[n] - want[n]) <= 0.01 for n in NAMES),
                    "after the power cycle %r, expected %r" % (now, want))
        print("# after the power cycle: COMPASS_OFS %.2f %.2f %.2f mGauss"
              % (now["COMPASS_OFS_X"], now["COMPASS_OFS_Y"], now["COMPASS_OFS_Z"]))
    b.stop()


if __name__ == "__main__":
    main()
    sys.exit(finish("ground station compass calibration",
                    "the ground station's compass calibration over TCP: all checks passed"))
