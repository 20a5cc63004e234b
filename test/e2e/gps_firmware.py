#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""End-to-end checks of the firmware's GPS port (firmware/GpsPort, lib/GPS) in apm25sim.

  gps_firmware.py run --tools BUILD_DIR --work WORK_DIR [--only NAME ...]

Checks (each prints 'ok NAME' or 'FAIL NAME: why'; the exit status is 1 if any failed):
  factory   a factory-new u-blox (NMEA at 9600): found at 38400 after the probes, configured,
            a 3D fix said within 5 s of the model's first fix (at 3 s, and at 9 s); then 40 s
            of 5 Hz UBX: no sample missed (no "loop overrun", `status` overruns 0), the `gps`
            lines' position within 5 m and 6 m of the truth, the fix fresh (age < 0.5 s),
            frames at 4 a fix and 5 fixes a second, no byte lost, `status` naming the GPS
  nmea      a module that only speaks NMEA: found at 9600 as NMEA, a 3D fix, its position
  none      no module: "no GPS found" once, nothing else about the GPS, no sample missed
  type0     GPS_TYPE 0 saved: not a byte sent on UART1, nothing said but `status`'s "off"
  faults    each fault of the model in a window: reported, no sample missed, recovered
            (no-fix, silent, deaf, garbage, glitch, too few satellites, a 2D fix)

Python's standard library only; the firmware and apm25sim from BUILD_DIR (make firmware tools).
"""
import argparse
import math
import os
import re
import subprocess
import sys

# The simulator models' checks' helpers (this folder): a failure, a check, a run, a scenario file.
from gps_baro_models import HOME, Failure, check, north_east_m, run, scenario


class Run:
    """One apm25sim run of the firmware at rest: its stamped lines and its counters."""

    def __init__(self, tools, work, seconds, *extra, typed=None, typed_at=None):
        args = [os.path.join(tools, 'apm25sim'), '--elf', os.path.join(tools, 'firmware.elf'), '--trajectory',
                scenario(tools, work, 'rest', 60), '--seconds', str(seconds), '--stamp', '--verbose'] + list(extra)
        if typed is not None:
            path = os.path.join(work, 'typed_%d.txt' % os.getpid())
            with open(path, 'w') as f:
                f.write(typed)
            args += ['--input', path, '--input-at', str(typed_at)]
        r = run(args)
        check(r.returncode == 0, '%s: exit %d\n%s' % (' '.join(extra), r.returncode, r.stderr[-2000:]))
        self.args = ' '.join(extra)
        self.stderr = r.stderr
        self.lines = []  # (t, text)
        for line in r.stdout.splitlines():
            t, _, text = line.partition(' ')
            try:
                self.lines.append((float(t), text))
            except ValueError:
                pass
        check(len(self.lines) > 100, '%s: too few lines:\n%s' % (self.args, r.stdout[:2000]))
        self.check_no_sample_missed()

    def gps(self):
        return [(t, text) for t, text in self.lines if text.startswith('# gps: ')]

    def first(self, pattern, after=0.0):
        """The time of the first line after `after` that matches pattern (a regex), or None."""
        for t, text in self.lines:
            if t >= after and re.search(pattern, text):
                return t
        return None

    def need(self, pattern, after=0.0, before=1e9):
        t = self.first(pattern, after)
        check(t is not None and t <= before, '%s: no line /%s/ in %.1f..%.1f s; the GPS said:\n%s' % (
            self.args, pattern, after, before, self.said()))
        return t

    def said(self):
        return '\n'.join('  %.3f %s' % l for l in self.gps())

    def counters(self, part):
        for line in self.stderr.splitlines():
            if line.startswith('# apm25sim: ' + part + ' '):
                return {k: v for k, v in re.findall(r'(\w+)=(\S+)', line)}
        raise Failure('no "%s" counters in:\n%s' % (part, self.stderr))

    def check_no_sample_missed(self):
        for t, text in self.lines:
            check('loop overrun' not in text, '%s: a sample was missed at %.3f s: %s' % (self.args, t, text))
            check('nan' not in text.lower().split(), '%s: NaN at %.3f s: %s' % (self.args, t, text))
        status = [text for t, text in self.lines if text.startswith('# load ')]
        for text in status:
            check(' overruns 0,' in text, '%s: %s' % (self.args, text))


def gps_reply(run, after):
    """The `gps` command's two lines after `after`: their fields."""
    lines = [text for t, text in run.lines if t >= after and text.startswith('# gps: ')]
    pos = next((l for l in lines if re.match(r'# gps: (3D|2D|no) fix, \d+ satellites, hdop', l)), None)
    speed = next((l for l in lines if re.match(r'# gps: [\d.]+ m/s, course', l)), None)
    check(pos and speed, '%s: no `gps` reply after %.1f s:\n%s' % (run.args, after, run.said()))
    m = re.match(r'# gps: (\w+) fix, (\d+) satellites, hdop ([\d.]+), (-?[\d.]+) (-?[\d.]+), (-?[\d.]+) m$', pos)
    check(m, 'the `gps` line: ' + pos)
    n = re.match(r'# gps: ([\d.]+) m/s, course (-?[\d.]+), age (\d+) ms, frames (\d+), bad (\d+), lost (\d+)$', speed)
    check(n, 'the `gps` line: ' + speed)
    return {'fix': m.group(1), 'sats': int(m.group(2)), 'hdop': float(m.group(3)), 'lat': float(m.group(4)),
            'lon': float(m.group(5)), 'alt': float(m.group(6)), 'speed': float(n.group(1)), 'age_ms': int(n.group(3)),
            'frames': int(n.group(4)), 'bad': int(n.group(5)), 'lost': int(n.group(6))}


def check_position(run, g):
    north, east = north_east_m(g['lat'], g['lon'], HOME)
    check(math.hypot(north, east) < 5.0, '%s: %.1f m N %.1f m E of the truth' % (run.args, north, east))
    check(abs(g['alt'] - HOME[2]) < 6.0, '%s: height %.2f m, truth %.1f' % (run.args, g['alt'], HOME[2]))


# --- the checks --------------------------------------------------------------------------------

def check_factory(tools, work):
    for fix_after in (9.0, 3.0):  # the second run is typed to
        r = Run(tools, work, 45 if fix_after == 3.0 else 15, '--gps-fix-after', str(fix_after),
                typed='gps\r\nstatus\r\n' if fix_after == 3.0 else None, typed_at=44)
        found = r.need(r'^# gps: found, u-blox at 38400 baud$', 0.3, 9.0)
        r.need(r'^# gps: configured: 5 Hz, POSLLH STATUS SOL VELNED, dynamic model 8$', found, found + 1.0)
        r.need(r'^# gps: 3D fix, 10 satellites$', fix_after, fix_after + 5.0)
        check(r.first(r'^# gps: no GPS found') is None, 'a u-blox was there:\n' + r.said())
        port = r.counters('GPS')
        check(port['rate_ms'] == '200' and port['baud'] == '38400' and port['out'] == '0x0001',
              'the module is not at 5 Hz UBX at 38400: %s' % port)
        check(port['naks'] == '0', 'a configuration message was refused: %s' % port)
    g = gps_reply(r, 44)
    check(g['fix'] == '3D' and g['sats'] == 10 and abs(g['hdop'] - 1.66) < 0.02, str(g))
    check_position(r, g)
    check(g['age_ms'] < 500, 'the fix is %d ms old' % g['age_ms'])
    check(g['bad'] == 0 and g['lost'] == 0, 'bytes lost or bad on a clean line: %s' % g)
    # 4 frames a fix, 5 fixes a second, for the ~37 s since the configuration
    check(4 * 5 * 35 < g['frames'] < 4 * 5 * 45, 'frames %d in 45 s' % g['frames'])
    r.need(r'^# gps: u-blox at 38400 baud, 3D fix, 10 satellites$', 44)
    r.need(r'^# load \d+%, overruns 0,', 44)


def check_nmea(tools, work):
    r = Run(tools, work, 20, '--gps', 'nmea', typed='gps\r\n', typed_at=19)
    found = r.need(r'^# gps: found, NMEA at 9600 baud$', 0.3, 8.0)
    r.need(r'^# gps: 3D fix, 10 satellites$', found, found + 2.5)
    check(r.first(r'^# gps: configured') is None, 'an NMEA module is not configured:\n' + r.said())
    g = gps_reply(r, 19)
    check(g['fix'] == '3D' and g['age_ms'] < 1500, str(g))
    check_position(r, g)


def check_none(tools, work):
    r = Run(tools, work, 20, '--gps', 'none', typed='status\r\n', typed_at=19)
    said = r.need(r'^# gps: no GPS found \(4800-115200 baud\); still looking$', 7.0, 8.0)
    others = [text for t, text in r.gps() if t != said and text != '# gps: searching']
    check(not others, 'said with no GPS: %s' % others)
    r.need(r'^# gps: searching$', 19)


def check_type0(tools, work):
    eeprom = os.path.join(work, 'type0_%d.eeprom' % os.getpid())
    if os.path.exists(eeprom):
        os.unlink(eeprom)
    Run(tools, work, 6, '--eeprom', eeprom, typed='set GPS_TYPE 0\r\nsave\r\n', typed_at=2)
    r = Run(tools, work, 12, '--eeprom', eeprom, typed='status\r\ngps\r\n', typed_at=11)
    os.unlink(eeprom)
    port = r.counters('GPS port')
    check(port['from_firmware'] == '0', 'GPS_TYPE 0 but the firmware sent: %s' % port)
    check(int(port['receiver_off']) > 1000, 'the module was not heard at all: %s' % port)
    said = [text for t, text in r.gps()]
    check(said == ['# gps: off (GPS_TYPE 0)'] * 2, 'said with GPS_TYPE 0: %s' % said)


FAULTS = [
    # fault, seconds, [(pattern, after, before)] in order
    ('gps:no-fix@14-20', 30, [(r'^# gps: fix lost, 2 satellites$', 14, 15.5),
                              (r'^# gps: 3D fix, 10 satellites$', 20, 21.5)]),
    ('gps:silent@14-20', 34, [(r'^# gps: lost: nothing for 4 s; looking again$', 17.5, 18.5),
                              (r'^# gps: found, u-blox at 38400 baud$', 20, 27),
                              (r'^# gps: 3D fix, 10 satellites$', 20, 28)]),
    ('gps:deaf@0-15', 34, [(r'^# gps: found, NMEA at 9600 baud$', 2, 5),
                           (r'^# gps: 3D fix, 10 satellites$', 2, 7),
                           (r'^# gps: lost: nothing for 4 s', 15, 26),
                           (r'^# gps: found, u-blox at 38400 baud$', 15, 32),
                           (r'^# gps: configured', 15, 33),
                           (r'^# gps: 3D fix, 10 satellites$', 15, 33.5)]),
    ('gps:garbage@14-24', 30, [(r'^# gps: garbage on the line: \d+ bad frames$', 14, 16)]),
    ('gps:glitch=50@14-16', 30, [(r'^# gps: glitch: 5\d\.\d\d m from where the velocity says; position rejected$', 14, 14.6),
                                 (r'^# gps: glitch over$', 16, 20.5)]),
    ('gps:sats=5@14-20', 30, [(r'^# gps: 3D fix, 5 satellites: too few \(AHRS_GPS_MINSATS 6\)$', 14, 14.6),
                              (r'^# gps: 3D fix, 10 satellites$', 20, 20.6)]),
    ('gps:sats=3@14-20', 30, [(r'^# gps: 2D fix, 3 satellites$', 14, 14.6),
                              (r'^# gps: 3D fix, 10 satellites$', 20, 20.6)]),
]


def check_faults(tools, work):
    for spec, seconds, expected in FAULTS:
        r = Run(tools, work, seconds, '--fault', spec, typed='gps\r\n', typed_at=seconds - 1)
        after = 0.0
        for pattern, lo, hi in expected:
            after = r.need(pattern, max(lo, after), hi)
        g = gps_reply(r, seconds - 1)
        check(g['fix'] == '3D' and g['sats'] == 10 and g['age_ms'] < 500, '%s: not recovered: %s' % (spec, g))
        check_position(r, g)


CHECKS = ['factory', 'nmea', 'none', 'type0', 'faults']


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('command', choices=['run'])
    ap.add_argument('--tools', required=True)
    ap.add_argument('--work', required=True)
    ap.add_argument('--only', nargs='*', choices=CHECKS)
    args = ap.parse_args()
    tools, work = os.path.abspath(args.tools), os.path.abspath(args.work)
    os.makedirs(work, exist_ok=True)
    missing = [n for n in ('apm25sim', 'scenario', 'firmware.elf') if not os.path.exists(os.path.join(tools, n))]
    if missing:
        print('FAIL: %s missing in %s (make firmware tools)' % (', '.join(missing), tools))
        return 1
    failed = 0
    for name in args.only or CHECKS:
        try:
            globals()['check_' + name](tools, work)
            print('ok', name, flush=True)
        except (Failure, subprocess.TimeoutExpired) as e:
            failed += 1
            print('FAIL %s: %s' % (name, e), flush=True)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
