# SPDX-License-Identifier: GPL-3.0-or-later
"""What the Python tests that run the firmware in apm25sim share: their command line
(--tools: the build directory with apm25sim, scenario and firmware.elf; --work: a folder
of their own) and a scenario's trajectory written there."""
import argparse
import os
import re
import subprocess
import sys


def tools_and_work():
    """The parsed --tools and --work arguments; the work folder exists."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--tools", required=True, help="the build directory (apm25sim, scenario, firmware.elf)")
    ap.add_argument("--work", required=True)
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    return args


def scenario_file(tools, work, name, options=(), file_name=None):
    """build/scenario NAME [OPTIONS] written to WORK/FILE_NAME (default NAME.csv); its path."""
    path = os.path.join(work, file_name or name + ".csv")
    with open(path, "wb") as f:
        subprocess.run([os.path.join(tools, "scenario"), name] + list(options), stdout=f, check=True)
    return path


def serve(tools, extra, log):
    """apm25sim serving the board's UART0 on TCP in real time (--serial tcp:0 --speed 1, then
    EXTRA), its first stderr line written to LOG: (the process, the port). Exits when it does
    not serve."""
    proc = subprocess.Popen([os.path.join(tools, "apm25sim"), "--elf", os.path.join(tools, "firmware.elf"),
                             "--serial", "tcp:0", "--speed", "1"] + list(extra),
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    line = proc.stderr.readline()
    log.write(line)
    m = re.search(r"tcp:127\.0\.0\.1:(\d+)", line)
    if not m:
        proc.kill()
        sys.exit("apm25sim did not serve: %r" % line)
    return proc, m.group(1)
