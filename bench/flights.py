# SPDX-License-Identifier: GPL-3.0-or-later
"""`make bench`'s flights (issue 22): the estimator in flight beside the peers.

The flights come from sim/flight/fly.py --all (the JSBSim Rascal flown by fly.py's
STABILIZE stand-in, written as trajectory files: ideal sensor values and the true
quaternion at 400 Hz). Ours runs through build/replay (the firmware's drivers and DCM on
the simulated chips), the peers through bench/peers.py, all scored with the same metric.
The worst roll error over the 60 s turn is printed: the turn's centripetal acceleration is
what fools an accelerometer-corrected filter; ours also with `replay --airspeed` at the
trim speed (a configured cruise speed, TRIM_ARSPD_CM, given to the centripetal correction).
When the closed-loop turn tests have run (ctest flight.closed_loop.turn: the ELF in simavr
flying the model itself with the airspeed sensor; flight.closed_loop.turn_cruise: without
it, TRIM_ARSPD_CM set), their worst roll errors are reported too.

    flight_section(build, out_dir, run_replay, peer_names, log) -> markdown lines
"""
import os
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FLY = os.path.join(REPO, "sim", "flight", "fly.py")
FLIGHT_SOURCES = os.path.join(REPO, "sim", "flight")
FLIGHTS = ("cruise", "turn", "figure8", "gusty", "upset", "climb")
TURN_FROM_S, TURN_TO_S = 5.0, 65.0  # fly.py's turn: the stick held for 30 deg from 5 to 65 s
TRIM_AIRSPEED_M_S = 18.0  # fly.py's trim speed: the configured cruise speed of a board without a pitot
# The closed-loop turns (test/flight/test_closed_loop.py): ctest group, what the board knows.
CLOSED_LOOP_TURNS = (("turn", "with the airspeed sensor"),
                     ("turn_cruise", "without it, TRIM_ARSPD_CM %d" % round(TRIM_AIRSPEED_M_S * 100)))


def newest_source_mtime():
    newest = 0.0
    for root, _, files in os.walk(FLIGHT_SOURCES):
        for f in files:
            if f.endswith((".py", ".xml", ".csv")):
                newest = max(newest, os.path.getmtime(os.path.join(root, f)))
    return newest


def up_to_date(paths):
    """Every file there and newer than sim/flight's sources (else fly.py writes it again)."""
    return all(os.path.exists(p) for p in paths) and min(os.path.getmtime(p) for p in paths) > newest_source_mtime()


def make_flights(flight_dir, log):
    """fly.py --all into flight_dir unless its files are newer than sim/flight's sources."""
    paths = {n: os.path.join(flight_dir, n + ".csv.gz") for n in FLIGHTS}
    if not up_to_date(paths.values()):
        log("flights: sim/flight/fly.py --all %s" % os.path.relpath(flight_dir, REPO))
        r = subprocess.run([sys.executable, FLY, "--all", flight_dir], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True, timeout=3600)
        if r.returncode != 0:
            return None, "fly.py --all failed (exit %d): %s" % (r.returncode, r.stderr.strip()[-300:])
    return {n: p for n, p in paths.items() if os.path.exists(p)}, None


# Flights in turbulence on seeds no tuning has used (bench/motions.py's SEEDS): the
# straight gusty flight, and the turn and the figure-eight in light turbulence (fly.py
# --gust 1). What found the turn's runaway in turbulence (issue 24): kept in the bench.
TURBULENT_SEEDS = (4057, 18233, 90511)
TURBULENT_FLIGHTS = (("gusty", None), ("turn", 1), ("figure8", 1))


# The firmware samples from its loop's start (pipeline::kLoopStartMs, after the compass's
# self-test); fly.py's flights begin trimmed in still air at t = 0, the gusts growing from
# zero. The peers run from t = 0: VQF from the loop's start sees what the board sees (on
# the gusty flights most of VQF's lead over ours was its calm first sample, README
# "Flying in simulation").
LOOP_START_S = 0.35
# ... and the first line of a start that is never still (pipeline::kStartupDeadlineSteps,
# 1.3 s of samples): where ours is scored from.
FIRST_LINE_S = LOOP_START_S + 1.3


def vqf_from_loop_start(tr):
    """VQF's score on the trajectory's samples from LOOP_START_S, scored from FIRST_LINE_S."""
    import numpy as np
    import peers
    i0 = int(np.searchsorted(tr["t"], LOOP_START_S))
    cut = {k: v[i0:] for k, v in tr.items()}
    return peers.score(cut["quat"], peers.PEERS["VQF"](cut), cut["movement"] & (cut["t"] >= FIRST_LINE_S))


def turbulent_kind(name, gust):
    return name + ("_gust%d" % gust if gust is not None else "")


def airspeed_variants(state_log):
    """Ours as the board would know its speed: not at all (replay's default, what a
    hand-held board does), a configured cruise speed (TRIM_ARSPD_CM, no pitot) and the
    airspeed sensor (the flight's logged airspeed, read every 8 steps as the firmware reads
    the MPXV7002DP on A0): (file suffix, label, replay's arguments) each."""
    return (("", "", ()),
            ("_cruise", ", cruise speed", ("--airspeed", "%g" % TRIM_AIRSPEED_M_S)),
            ("_sensor", ", airspeed sensor", ("--airspeed-log", state_log)))


def make_turbulent_flights(flight_dir, log, flights=TURBULENT_FLIGHTS, seeds=TURBULENT_SEEDS):
    """fly.py --flight NAME [--gust G] --seed S for each (NAME, G) of flights and S of
    seeds, cached as make_flights' are: {file stem: (kind, trajectory, state log)}."""
    out = {}
    for name, gust in flights:
        kind = turbulent_kind(name, gust)
        for seed in seeds:
            stem = "%s_s%d" % (kind, seed)
            traj, state = os.path.join(flight_dir, stem + ".csv.gz"), os.path.join(flight_dir, stem + "_log.csv")
            if not up_to_date((traj, state)):
                cmd = [sys.executable, FLY, "--flight", name, "--seed", str(seed), "--out", traj, "--log", state,
                       "--quiet"] + (["--gust", str(gust)] if gust is not None else [])
                log("flights: " + " ".join(os.path.relpath(c, REPO) if os.sep in c else c for c in cmd[1:]))
                r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=1800)
                if r.returncode != 0:
                    log("flights: %s failed (exit %d): %s" % (stem, r.returncode, r.stderr.strip()[-300:]))
                    continue
            out[stem] = (kind, traj, state)
    return out


def worst_roll_error_replay(traj, est_path):
    """(worst |roll error| deg, its time s, true roll, estimated roll) over the turn, from
    replay's t,roll,pitch,yaw against the trajectory's truth at the nearest sample."""
    import numpy as np
    import peers
    tr = peers.load_trajectory(traj)
    true_roll, _, _ = peers.euler_from_quat(tr["quat"])
    est = np.loadtxt(est_path, delimiter=",", skiprows=1, ndmin=2)
    worst = (0.0, float("nan"), float("nan"), float("nan"))
    for t, roll in zip(est[:, 0], est[:, 1]):
        if not TURN_FROM_S <= t <= TURN_TO_S:
            continue
        i = min(int(np.searchsorted(tr["t"], t)), len(tr["t"]) - 1)
        err = (roll - true_roll[i] + 180.0) % 360.0 - 180.0
        if abs(err) > abs(worst[0]):
            worst = (float(err), float(t), float(true_roll[i]), float(roll))
    return worst


def worst_roll_error_peer(tr, q):
    import numpy as np
    import peers
    true_roll, _, _ = peers.euler_from_quat(tr["quat"])
    roll, _, _ = peers.euler_from_quat(q)
    m = (tr["t"] >= TURN_FROM_S) & (tr["t"] <= TURN_TO_S) & np.isfinite(roll)
    err = (roll[m] - true_roll[m] + 180.0) % 360.0 - 180.0
    return float(err[np.argmax(np.abs(err))]) if len(err) else float("nan")


def closed_loop_turn(build, name="turn"):
    """A closed-loop turn test's log (true and estimated bank), if it ran: its worst error."""
    path = os.path.join(build, "host", "closed_loop_" + name, name + "_bank.csv")
    if not os.path.exists(path):
        return None
    worst = None
    with open(path) as f:
        next(f)
        for line in f:
            t, true_bank, est_bank, err, height = (float(v) for v in line.split(","))
            if t >= TURN_FROM_S and height > 1.0 and (worst is None or abs(err) > abs(worst[1])):
                worst = (t, err, true_bank, est_bank)
    return path, worst


# The uncalibrated preset's IMU errors, the compass left calibrated (bench/motions.py's +imu).
IMU_ERRORS = ("--preset", "uncalibrated", "--hard-iron", "0,0,0", "--soft-iron", "1,1,1")


def make_imu_flights(build, flights, flight_dir, log):
    """Each flight of make_turbulent_flights through `scenario --from` with IMU_ERRORS (the
    flight's seed for the noise), cached while newer than its source and the scenario tool:
    {stem+imu: (kind, trajectory, state log)}."""
    import gzip
    scenario = os.path.join(build, "scenario")
    out = {}
    for stem, (kind, traj, state) in flights.items():
        path = os.path.join(flight_dir, stem + "+imu.csv.gz")
        fresh = os.path.exists(path) and os.path.getmtime(path) > max(os.path.getmtime(traj), os.path.getmtime(scenario))
        if not fresh:
            seed = stem.rsplit("_s", 1)[1]
            cmd = [scenario, "--from", traj] + list(IMU_ERRORS) + ["--seed", seed]
            log("flights: scenario --from %s %s --seed %s" % (os.path.relpath(traj, REPO), " ".join(IMU_ERRORS), seed))
            r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=600)
            if r.returncode != 0:
                log("flights: %s+imu failed (exit %d): %s" % (stem, r.returncode, r.stderr.decode()[-300:]))
                continue
            with gzip.open(path + ".tmp", "wb") as f:
                f.write(r.stdout)
            os.replace(path + ".tmp", path)
        out[stem + "+imu"] = (kind, path, state)
    return out


def turbulent_report(flights, flight_dir, replay, score, run_replay, errors, log, intro):
    """Ours in the three airspeed modes and VQF on each flight of {stem: (kind, trajectory,
    state log)}: a table of the kinds' means and one of the files (markdown lines)."""
    import peers
    trows, sums, totals = [], {}, {}
    for stem, (kind, traj, state) in flights.items():
        cells = [stem]
        for suffix, what, extra in airspeed_variants(state):
            est = os.path.join(flight_dir, stem + "_estimate%s.csv" % suffix)
            _, _, ours, err, _ = run_replay(("flight %s%s" % (stem, what), traj, est, replay, score, (), extra))
            if err:
                errors.append("flight %s%s: %s" % (stem, what, err))
            cells.append("%.2f" % ours["total"] if ours else "–")
            if ours:
                sums.setdefault((kind, suffix), []).append(ours["total"])
                totals[(stem, suffix)] = ours["total"]
        if "VQF" in peers.PEERS:
            tr = peers.load_trajectory(traj)
            s_vqf = peers.score(tr["quat"], peers.PEERS["VQF"](tr), tr["movement"])
            s_late = vqf_from_loop_start(tr)
            cells += ["%.2f" % s_vqf["total"], "%.2f" % s_late["total"]]
            sums.setdefault((kind, "vqf"), []).append(s_vqf["total"])
            sums.setdefault((kind, "vqf_late"), []).append(s_late["total"])
            totals[(stem, "vqf")] = s_vqf["total"]
            totals[(stem, "vqf_late")] = s_late["total"]
        trows.append(cells)
        log("flight %s: %s" % (stem, " | ".join(cells[1:])))
    kinds = []
    for name, gust in TURBULENT_FLIGHTS:
        kind = turbulent_kind(name, gust)
        vals = [sums.get((kind, k)) for k in ("", "_cruise", "_sensor", "vqf", "vqf_late")]
        kinds.append("| %s (mean of %d) | " % (kind, len(vals[0] or [])) +
                     " | ".join("%.2f" % (sum(v) / len(v)) if v else "–" for v in vals) + " |")
    # Issue 24 asks each flight to be ahead of VQF: how many are, per airspeed mode.
    ahead = {}
    for peer in ("vqf", "vqf_late"):
        ahead[peer] = []
        for suffix in ("", "_cruise", "_sensor"):
            pairs = [(totals[(stem, suffix)], totals[(stem, peer)]) for stem in flights
                     if (stem, suffix) in totals and (stem, peer) in totals]
            ahead[peer].append("%d of %d" % (sum(o < v for o, v in pairs), len(pairs)))
    late = "VQF from %g s" % LOOP_START_S
    return [intro, "",
            "| flight | ours | ours, cruise %g m/s | ours, airspeed sensor | VQF | %s |" % (TRIM_AIRSPEED_M_S, late),
            "|---|---|---|---|---|---|"] + kinds + [""] + \
           ["Files where ours is ahead of VQF: %s (without an airspeed / with the cruise speed / with the "
            "sensor); of %s (the peer from the firmware's first sample, scored from our first line: the "
            "flights begin trimmed in still air at t = 0): %s." % (" / ".join(ahead["vqf"]), late,
                                                                  " / ".join(ahead["vqf_late"])), ""] + \
           ["| file | ours | ours, cruise | ours, sensor | VQF | %s |" % late, "|---|---|---|---|---|---|"] + \
           ["| " + " | ".join(r) + " |" for r in sorted(trows)] + [""]


def flight_section(build, out_dir, run_replay, peer_names, log):
    import peers
    flight_dir = os.path.join(out_dir, "flights")
    os.makedirs(flight_dir, exist_ok=True)
    paths, error = make_flights(flight_dir, log)
    rep = ["## In flight: the JSBSim Rascal 110 (issue 22)", ""]
    if error:
        log("flights: " + error)
        return rep + ["Not measured: %s." % error, ""], [error]
    replay, score = os.path.join(build, "replay"), os.path.join(build, "score")
    rows, turn_worst, errors = [], {}, []
    for name in FLIGHTS:
        traj = paths.get(name)
        if not traj:
            continue
        cells = [name]
        for suffix, what, extra in airspeed_variants(os.path.join(flight_dir, name + "_log.csv")):
            if suffix == "_sensor" and not os.path.exists(extra[1]):
                cells.append("–")
                continue
            est = os.path.join(flight_dir, name + "_estimate%s.csv" % suffix)
            _, _, ours, err, _ = run_replay(("flight %s%s" % (name, what), traj, est, replay, score, (), extra))
            if err:
                errors.append("flight %s%s: %s" % (name, what, err))
            cells.append("%.2f / %.2f / %.2f" % (ours["total"], ours["incl"], ours["heading"]) if ours else "–")
            if name == "turn" and ours:
                key = "ours (replay%s)" % ("" if not extra else " " + " ".join(
                    [extra[0], os.path.basename(extra[1])]))
                turn_worst[key] = worst_roll_error_replay(traj, est)[0]
        tr = peers.load_trajectory(traj)
        for peer in peer_names:
            try:
                q = peers.PEERS[peer](tr)
            except Exception as e:  # a peer that breaks is reported, the bench goes on
                cells.append("error")
                errors.append("flight %s, %s: %s: %s" % (name, peer, type(e).__name__, e))
                continue
            s = peers.score(tr["quat"], q, tr["movement"])
            cells.append("%.2f / %.2f / %.2f" % (s["total"], s["incl"], s["heading"]))
            if name == "turn":
                turn_worst[peer] = worst_roll_error_peer(tr, q)
        if "VQF" in peer_names:
            s = vqf_from_loop_start(tr)
            cells.append("%.2f / %.2f / %.2f" % (s["total"], s["incl"], s["heading"]))
        rows.append(cells)
        log("flight %s: %s" % (name, " | ".join(cells[1:])))
    header = ["flight", "ours", "ours, cruise %g m/s" % TRIM_AIRSPEED_M_S, "ours, airspeed sensor"] + list(peer_names) + \
             (["VQF from %g s" % LOOP_START_S] if "VQF" in peer_names else [])
    rep += ["Flights of sim/flight/fly.py (the model flown by its STABILIZE stand-in; ideal sensors at "
            "400 Hz): total / inclination / heading RMSE in degrees. Ours through `build/replay`: without "
            "an airspeed, and with the configured cruise speed (`--airspeed %g`, TRIM_ARSPD_CM: what a board "
            "without a pitot flies with), and with the airspeed sensor (`--airspeed-log`: the flight's airspeed as "
            "the firmware reads its sensor); the peers have no airspeed input. The flights begin trimmed in "
            "still air at t = 0, where the peers start; the firmware samples from its loop's start, %g s: "
            "the last column is VQF from there, scored from our first line (%g s)." % (
                TRIM_AIRSPEED_M_S, LOOP_START_S, FIRST_LINE_S), "",
            "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    rep += ["| " + " | ".join(r) + " |" for r in rows]
    rep.append("")
    if turn_worst:
        text = ", ".join("%s %.1f" % (k, v) for k, v in turn_worst.items())
        rep += ["Worst roll error during the 60 s, 30 deg turn (estimate - truth, deg): %s." % text, ""]
        log("the turn's worst roll error (deg): " + text)
    # The same in turbulence on fresh seeds: ours without / with the cruise speed / with
    # the sensor, VQF beside (the peer ours trails most there), total RMSE; and the same
    # flights as an uncalibrated board's IMU would measure them.
    turbulent = make_turbulent_flights(flight_dir, log)
    if turbulent:
        seeds = ", ".join(str(x) for x in TURBULENT_SEEDS)
        rep += turbulent_report(turbulent, flight_dir, replay, score, run_replay, errors, log,
                                "Flights in turbulence on seeds no tuning has used (`fly.py --flight NAME [--gust 1] "
                                "--seed S`, S = %s): total RMSE in degrees, ours without an airspeed / with the cruise "
                                "speed / with the airspeed sensor, and VQF." % seeds)
        with_imu = make_imu_flights(build, turbulent, flight_dir, log)
        if with_imu:
            rep += turbulent_report(with_imu, flight_dir, replay, score, run_replay, errors, log,
                                    "The same flights with an uncalibrated board's IMU (`scenario --from FILE %s "
                                    "--seed S`: the gyro's bias (1.5, -1, 0.8) deg/s and its drift, the "
                                    "accelerometer's offset and scale, datasheet noise, quantised; the compass "
                                    "calibrated). Started in the air, nothing measures the bias: total RMSE in "
                                    "degrees, as above." % " ".join(IMU_ERRORS))
    loop_texts = []
    for name, what in CLOSED_LOOP_TURNS:
        loop = closed_loop_turn(build, name)
        if loop and loop[1]:
            t, err, true_bank, est_bank = loop[1]
            loop_texts.append("%s (ctest flight.closed_loop.%s, %s): worst roll error %.1f deg at %.1f s (true %.1f, "
                              "estimate %.1f)" % (what, name, os.path.relpath(loop[0], REPO), err, t, true_bank,
                                                  est_bank))
    if loop_texts:
        text = "the board flying the turn itself, while above the ground: " + "; ".join(loop_texts)
        rep += ["In the closed loop, " + text + ".", ""]
        log(text)
    return rep, errors
