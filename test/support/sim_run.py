# SPDX-License-Identifier: GPL-3.0-or-later
"""What the Python tests that run the firmware in apm25sim share: their command line
(--tools: the build directory with apm25sim, scenario and firmware.elf; --work: a folder
of their own) and a scenario's trajectory written there."""
import argparse
import os
import subprocess


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
