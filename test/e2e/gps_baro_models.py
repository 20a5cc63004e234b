#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""End-to-end checks of apm25sim's GPS (UART1) and MS5611 (SPI, chip select 40) models.

  gps_baro_models.py run --tools BUILD_DIR --work WORK_DIR [--only NAME ...]

Checks (each prints 'ok NAME' or 'FAIL NAME: why'; the exit status is 1 if any failed):
  help           --help names the new options and faults; bad values are refused
  undisturbed    the firmware runs with neither model attached (--gps none --baro none) and
                 prints its lines; the firmware now drives both parts, so what the models do
                 to it is checked by e2e.GpsPort (test/e2e/gps_firmware.py) and test_baro.cpp
  probe          a small AVR program (support/avr/gps_baro_probe.cpp) talks to both parts through
                 simavr as a driver would: the PROM and its CRC-4, a read before the end of
                 a conversion (0), D1/D2 that the datasheet's arithmetic turns into the
                 standard atmosphere's pressure at the field, NMEA at 9600 (garbage at
                 38400), $PUBX,41 then CFG-MSG / CFG-RATE ACKed and NAV messages at 5 Hz
  trajectory     the probe on a trajectory file with n,e,d columns and another --home: the
                 position it reads is that home plus n,e,d
  kinds          --gps nmea (no ACK, NMEA only), --gps none and --baro none (nothing there)
  physics        the probe flying a JSON backend (a straight line north at 15 m/s, 50 m up):
                 the position it reads is the backend's 0.2 s earlier, within the noise; the
                 --physics-log file carries n,e,d
  live           --physics json with --serial tcp:PORT at --speed 1: a TCP client receives the
                 firmware's serial output while the board flies, at the wall clock's pace

Python's standard library only. Builds the probe with avr-g++ against the Arduino core that
the project's Makefile builds (mk/build.mk), into WORK_DIR.
"""
import argparse
import json
import math
import os
import re
import socket
import struct
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PROJECT = os.path.abspath(os.path.join(HERE, '..', '..'))
ARDUINO_AVR = '/usr/share/arduino/hardware/arduino/avr'
HOME = (7.135045, -73.119421, 1028.0)
PROM_EXAMPLE = [40127, 36924, 23317, 23282, 33464, 28312]


# --- the datasheets, written out ------------------------------------------------------------

def an520_crc4(words):
    """AN520's CRC-4 of the MS5611 PROM (word 7's low byte taken as 0)."""
    w = list(words)
    w[7] &= 0xFF00
    rem = 0
    for cnt in range(16):
        rem ^= (w[cnt >> 1] & 0xFF) if cnt % 2 else (w[cnt >> 1] >> 8)
        for _ in range(8):
            rem = ((rem << 1) ^ 0x3000) if rem & 0x8000 else (rem << 1)
    return (rem >> 12) & 0xF


def tdiv(a, b):
    """C's integer division (towards zero), as the datasheet's arithmetic does it."""
    q = abs(a) // abs(b)
    return q if (a >= 0) == (b > 0) else -q


def ms5611_compensate(c, d1, d2):
    """MS5611-01BA03: first and second order compensation; Pa and 0.01 degC."""
    dt = d2 - c[5] * 256
    temp = 2000 + tdiv(dt * c[6], 1 << 23)
    off = c[2] * 65536 + tdiv(c[4] * dt, 128)
    sens = c[1] * 32768 + tdiv(c[3] * dt, 256)
    if temp < 2000:
        t2 = tdiv(dt * dt, 1 << 31)
        off2 = tdiv(5 * (temp - 2000) ** 2, 2)
        sens2 = tdiv(5 * (temp - 2000) ** 2, 4)
        if temp < -1500:
            off2 += 7 * (temp + 1500) ** 2
            sens2 += tdiv(11 * (temp + 1500) ** 2, 2)
        temp -= t2
        off -= off2
        sens -= sens2
    return tdiv(tdiv(d1 * sens, 1 << 21) - off, 1 << 15), temp


def isa_pressure(alt_m):
    return 101325.0 * (1.0 - 2.25577e-5 * alt_m) ** 5.25588


def north_east_m(lat_deg, lon_deg, home):
    """Metres north and east of home (WGS-84 radii of curvature at home)."""
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    lat0 = math.radians(home[0])
    w = 1 - e2 * math.sin(lat0) ** 2
    h = home[2] + 10.0
    north = math.radians(lat_deg - home[0]) * (a * (1 - e2) / w ** 1.5 + h)
    east = math.radians(lon_deg - home[1]) * (a / math.sqrt(w) + h) * math.cos(lat0)
    return north, east


# --- tools ------------------------------------------------------------------------------------

class Failure(Exception):
    pass


def check(condition, why):
    if not condition:
        raise Failure(why)


def run(args, timeout=600, **kw):
    return subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout, text=True, **kw)


def build_probe(work):
    core = os.path.join(work, 'core')
    r = run(['make', '--no-print-directory', '-s', '-C', PROJECT, '-f', 'mk/build.mk', 'BUILD=' + core,
             os.path.join(core, 'avr', 'core.a')])
    if r.returncode != 0:
        raise Failure('the Arduino core did not build: ' + r.stderr[-2000:])
    elf = os.path.join(work, 'gps_baro_probe.elf')
    flags = ['-mmcu=atmega2560', '-DF_CPU=16000000L', '-DARDUINO=10819', '-DARDUINO_AVR_MEGA2560',
             '-DARDUINO_ARCH_AVR', '-Os', '-flto', '-std=gnu++11', '-fno-exceptions', '-fno-threadsafe-statics',
             '-fno-rtti', '-DDECIMAL_DIG=__DECIMAL_DIG__', '-I' + ARDUINO_AVR + '/cores/arduino',
             '-I' + ARDUINO_AVR + '/variants/mega', '-I' + ARDUINO_AVR + '/libraries/SPI/src']
    tmp = elf + '.tmp.%d' % os.getpid()
    r = run(['avr-g++'] + flags + [os.path.join(HERE, 'support', 'avr', 'gps_baro_probe.cpp'), os.path.join(core, 'avr', 'core.a'),
                                   '-Wl,--gc-sections', '-fuse-linker-plugin', '-lm', '-o', tmp])
    if r.returncode != 0:
        raise Failure('the probe did not build: ' + r.stderr[-2000:])
    os.replace(tmp, elf)
    return elf


def scenario(tools, work, name, seconds):
    path = os.path.join(work, '%s_%gs.csv' % (name, seconds))
    if not os.path.exists(path):
        with open(path + '.tmp', 'w') as out:
            r = subprocess.run([os.path.join(tools, 'scenario'), name, '--seconds', str(seconds)], stdout=out,
                               stderr=subprocess.PIPE, text=True)
        if r.returncode != 0:
            raise Failure('scenario %s: %s' % (name, r.stderr))
        os.replace(path + '.tmp', path)
    return path


def apm25sim(tools, elf, *args, timeout=600):
    return run([os.path.join(tools, 'apm25sim'), '--elf', elf] + list(args), timeout=timeout)


def counters(stderr, part):
    """The key=value counters of one of --verbose's '# apm25sim: PART ...' lines."""
    for line in stderr.splitlines():
        if line.startswith('# apm25sim: ' + part + ' '):
            return {k: v for k, v in re.findall(r'(\w+)=(\S+)', line)}
    raise Failure('no "%s" counters in:\n%s' % (part, stderr))


def probe_lines(stdout):
    """The probe's lines by their first word (the --stamp time dropped)."""
    lines = {}
    for line in stdout.splitlines():
        words = line.split()
        if len(words) >= 2:
            lines[words[1]] = words[2:]
    return lines


def with_position(src, dst, north, east, down):
    """A copy of a trajectory file with constant n,e,d columns."""
    with open(src) as f, open(dst, 'w') as out:
        for i, line in enumerate(f):
            line = line.rstrip('\n')
            out.write(line + (',n,e,d\n' if i == 0 else ',%g,%g,%g\n' % (north, east, down)))
    return dst


# --- a physics backend: ArduPilot's SITL JSON interface, flying north ---------------------

class LineNorthBackend:
    """Answers each servo packet (uint16 magic 18458, uint16 rate, uint32 frame, uint16
    pwm[16]) with a state: level, heading north, 15 m/s north, 50 m above home."""
    SPEED = 15.0
    HEIGHT = 50.0

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(('127.0.0.1', 0))
        self.sock.settimeout(0.5)
        self.port = self.sock.getsockname()[1]
        self.stop = False
        self.frames = 0
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        packet = struct.Struct('<HHI16H')
        last, t = None, 0.0
        while not self.stop:
            try:
                data, sender = self.sock.recvfrom(1024)
            except socket.timeout:
                continue
            if len(data) != packet.size:
                continue
            magic, rate, frame = packet.unpack(data)[:3]
            if magic != 18458:
                continue
            if frame != last:
                if last is not None:
                    t += 1.0 / rate
                last = frame
                self.frames += 1
            state = {'timestamp': t, 'imu': {'gyro': [0, 0, 0], 'accel_body': [0, 0, -9.80665]},
                     'position': [self.SPEED * t, 0.0, -self.HEIGHT], 'velocity': [self.SPEED, 0.0, 0.0],
                     'attitude': [0, 0, 0]}
            self.sock.sendto(('\n' + json.dumps(state) + '\n').encode(), sender)

    def close(self):
        self.stop = True
        self.thread.join()
        self.sock.close()


# --- the checks --------------------------------------------------------------------------------

def check_help(tools, work):
    r = run([os.path.join(tools, 'apm25sim'), '--help'])
    check(r.returncode == 0, r.stderr)
    for text in ('--gps ublox|nmea|none', '--gps-baud B', '--gps-fix-after S', '--gps-latency S', '--baro ms5611|none',
                 '--baro-noise HPA', '--baro-temp C', '--home LAT,LON,ALT_M', '--seed N', 'PUBX,41', 'CFG-NAV5',
                 'NAV-VELNED', 'gps:no-fix', 'gps:silent', 'gps:deaf', 'gps:garbage', 'gps:glitch[=M]', 'gps:sats=N',
                 'baro:absent', 'baro:stuck', 'baro:spike', 'movement,n,e,d'):
        check(text in r.stdout, "--help does not say '%s'" % text)
    firmware = os.path.join(tools, 'firmware.elf')
    traj = scenario(tools, work, 'rest', 1)
    for bad in (['--gps', 'sirf'], ['--gps-baud', '12345'], ['--home', '7,-73'], ['--baro', 'bmp085'],
                ['--gps', 'none', '--fault', 'gps:no-fix@1-2'], ['--fault', 'gps:sats@1-2']):
        r = apm25sim(tools, firmware, '--trajectory', traj, *bad)
        check(r.returncode == 1 and r.stderr, '%s: exit %d, %s' % (' '.join(bad), r.returncode, r.stderr))


STAMP_SLACK_S = 2e-6


def check_undisturbed(tools, work):
    firmware = os.path.join(tools, 'firmware.elf')
    traj = scenario(tools, work, 'tilt_tour', 8)
    without = apm25sim(tools, firmware, '--trajectory', traj, '--stamp', '--gps', 'none', '--baro', 'none')
    check(without.returncode == 0, 'without the models: exit %d\n%s' % (without.returncode, without.stderr))
    check(without.stdout.count('\n') > 100, 'the firmware printed too little:\n' + without.stdout[:2000])
    runs = {
    }
    for what, extra in runs.items():
        r = apm25sim(tools, firmware, '--trajectory', traj, '--stamp', '--baro', 'none', *extra)
        check(r.returncode == 0, '%s: exit %d\n%s' % (what, r.returncode, r.stderr))
        if r.stdout != without.stdout:
            # The same lines, each at the same instant within STAMP_SLACK_S: simavr services a
            # model's cycle timer between the firmware's instructions, which may move the cycle a
            # UART byte is seen to leave by an instruction, across the stamp's microsecond.
            a, b = without.stdout.splitlines(), r.stdout.splitlines()

            def same(x, y):
                tx, _, lx = x.partition(' ')
                ty, _, ly = y.partition(' ')
                try:
                    return lx == ly and abs(float(tx) - float(ty)) <= STAMP_SLACK_S
                except ValueError:
                    return x == y
            first = next((i for i in range(min(len(a), len(b))) if not same(a[i], b[i])), min(len(a), len(b)))
            if first < max(len(a), len(b)):
                raise Failure('%s: the output differs from line %d:\n  without: %s\n  with:    %s' % (
                    what, first + 1, a[first] if first < len(a) else '(end)', b[first] if first < len(b) else '(end)'))


def run_probe(tools, probe, traj, *extra, seconds=8):
    r = apm25sim(tools, probe, '--trajectory', traj, '--stamp', '--verbose', '--seconds', str(seconds), *extra)
    check(r.returncode == 0, 'probe %s: exit %d\n%s\n%s' % (' '.join(extra), r.returncode, r.stdout, r.stderr))
    lines = probe_lines(r.stdout)
    check('done' in r.stdout, 'the probe did not finish:\n' + r.stdout + r.stderr)
    return lines, r


def check_probe(tools, work, probe):
    lines, r = run_probe(tools, probe, scenario(tools, work, 'rest', 8))
    prom = [int(w, 16) for w in lines['prom']]
    check(len(prom) == 8, 'PROM: %s' % lines['prom'])
    check(prom[1:7] == PROM_EXAMPLE, 'PROM C1..C6 %s, not the datasheet example %s' % (prom[1:7], PROM_EXAMPLE))
    check(prom[7] & 0xF == an520_crc4(prom), 'PROM CRC-4: word 7 %04x, AN520 gives %x' % (prom[7], an520_crc4(prom)))
    check(lines['early'] == ['0'], 'an ADC read 5 ms into a 9 ms conversion read %s, not 0' % lines['early'])
    d1, d2 = int(lines['d1'][0]), int(lines['d1'][2])
    p, temp = ms5611_compensate(prom, d1, d2)
    check(abs(p - isa_pressure(HOME[2])) < 50, 'pressure %d Pa, the standard atmosphere at %g m: %.0f Pa' % (
        p, HOME[2], isa_pressure(HOME[2])))
    check(abs(temp * 0.01 - (15 - 0.0065 * HOME[2])) < 0.05, 'temperature %.2f degC' % (temp * 0.01))
    check(lines['mismatch'][3] == '0', 'at 38400 against 9600 the probe read whole sentences: %s' % lines['mismatch'])
    check(int(lines['mismatch'][1]) > 100, 'at 38400 nothing arrived at all: %s' % lines['mismatch'])
    check(int(lines['nmea9600'][1]) >= 2 and lines['nmea9600'][3] == '0', 'NMEA at 9600: %s' % lines['nmea9600'])
    ubx = dict(zip(lines['ubx'][0::2], lines['ubx'][1::2]))
    check(ubx['acks'] == '6' and ubx['naks'] == '0', 'ACKs: %s' % ubx)
    for m in ('posllh', 'velned', 'sol'):
        check(13 <= int(ubx[m]) <= 16, '%s at 5 Hz for 3 s: %s' % (m, ubx))
    check(ubx['bad'] == '0' and ubx['step'] == '200', 'UBX: %s' % ubx)
    lat, lon, hmsl = (int(v) for v in lines['pos'])
    north, east = north_east_m(lat * 1e-7, lon * 1e-7, HOME)
    check(math.hypot(north, east) < 5.0, 'the probe at rest is %.1f m N, %.1f m E of home' % (north, east))
    check(abs(hmsl * 1e-3 - HOME[2]) < 8.0, 'hMSL %.1f m' % (hmsl * 1e-3))
    baro = counters(r.stderr, 'MS5611')
    check(baro['read_converting'] == '1' and baro['unknown'] == '0', 'MS5611 counters: %s' % baro)
    check('apm25sim: bus violation at' not in r.stderr, r.stderr)


def check_trajectory(tools, work, probe):
    home = (45.5, 7.25, 240.0)
    traj = with_position(scenario(tools, work, 'rest', 8), os.path.join(work, 'rest_ned.csv'), 300.0, -120.0, -40.0)
    lines, r = run_probe(tools, probe, traj, '--home', '%g,%g,%g' % home, '--baro-noise', '0')
    lat, lon, hmsl = (int(v) for v in lines['pos'])
    north, east = north_east_m(lat * 1e-7, lon * 1e-7, home)
    check(abs(north - 300) < 5 and abs(east + 120) < 5, 'at %.1f m N, %.1f m E of home, not 300, -120' % (north, east))
    check(abs(hmsl * 1e-3 - 280.0) < 8, 'hMSL %.1f m, not 280' % (hmsl * 1e-3))
    prom = [int(w, 16) for w in lines['prom']]
    p, _ = ms5611_compensate(prom, int(lines['d1'][0]), int(lines['d1'][2]))
    check(abs(p - isa_pressure(280.0)) < 2, 'pressure %d Pa at 280 m, ISA %.0f' % (p, isa_pressure(280.0)))


def check_kinds(tools, work, probe):
    traj = scenario(tools, work, 'rest', 8)
    lines, r = run_probe(tools, probe, traj, '--gps', 'nmea')
    ubx = dict(zip(lines['ubx'][0::2], lines['ubx'][1::2]))
    check(ubx['acks'] == '0' and ubx['posllh'] == '0', 'an NMEA-only module answered UBX: %s' % ubx)
    check(int(lines['nmea9600'][1]) >= 2, 'the NMEA module at 9600: %s' % lines['nmea9600'])
    # It heard the PUBX,41 at 9600 (ignored), then the CFG messages at 38400 as garbage.
    gps = counters(r.stderr, 'GPS')
    check(int(gps['nmea_only_ignored']) >= 33 and gps['baud'] == '9600' and gps['acks'] == '0', gps)
    lines, r = run_probe(tools, probe, traj, '--gps', 'none', '--baro', 'none')
    check(lines['mismatch'][1] == '0' and lines['nmea9600'][1] == '0', 'nothing on the GPS port, yet: %s %s' % (
        lines['mismatch'], lines['nmea9600']))
    check(all(w == '0' for w in lines['prom']) and lines['d1'] == ['0', 'd2', '0'], 'nobody behind pin 40, yet %s %s' % (
        lines['prom'], lines['d1']))
    check('GPS' not in r.stderr and 'MS5611' not in r.stderr, r.stderr)


def check_physics(tools, work, probe):
    backend = LineNorthBackend()
    log = os.path.join(work, 'line_north_log.csv')
    try:
        r = apm25sim(tools, probe, '--physics', 'json:127.0.0.1:%d' % backend.port, '--seconds', '8', '--stamp',
                     '--verbose', '--physics-timeout', '20', '--physics-log', log)
    finally:
        backend.close()
    check(r.returncode == 0, 'exit %d\n%s' % (r.returncode, r.stderr))
    # The log carries the position: the same flight as a trajectory file.
    with open(log) as f:
        header = f.readline().strip()
        rows = [line.strip().split(',') for line in f]
    check(header.endswith(',movement,n,e,d'), 'the physics log header: ' + header)
    t_last, n_last = float(rows[-1][0]), float(rows[-1][15])
    check(abs(n_last - LineNorthBackend.SPEED * t_last) < 0.1 and rows[-1][17] == '-50.000',
          'the physics log row: %s' % rows[-1])
    lines = probe_lines(r.stdout)
    check('pos' in lines, r.stdout)
    lat, lon, hmsl = (int(v) for v in lines['pos'])
    north, east = north_east_m(lat * 1e-7, lon * 1e-7, HOME)
    # The last NAV-POSLLH came before 'ubx' was printed: its time is the line's, less up to
    # one 200 ms epoch; it reports the position 0.2 s before it left the module.
    t_ubx = float(next(l.split()[0] for l in r.stdout.splitlines() if ' ubx ' in ' ' + l))
    expected_hi = LineNorthBackend.SPEED * (t_ubx - 0.2)
    expected_lo = LineNorthBackend.SPEED * (t_ubx - 0.45)
    check(expected_lo - 4 < north < expected_hi + 4 and abs(east) < 4,
          'at %.1f m N, %.1f m E; the backend 0.2 s earlier: %.1f..%.1f m N' % (north, east, expected_lo, expected_hi))
    check(abs(hmsl * 1e-3 - (HOME[2] + LineNorthBackend.HEIGHT)) < 8, 'hMSL %.1f m' % (hmsl * 1e-3))
    prom = [int(w, 16) for w in lines['prom']]
    p, _ = ms5611_compensate(prom, int(lines['d1'][0]), int(lines['d1'][2]))
    check(abs(p - isa_pressure(HOME[2] + 50)) < 50, 'pressure %d Pa 50 m up, ISA %.0f' % (p, isa_pressure(HOME[2] + 50)))


def check_live(tools, work):
    """--physics json and --serial tcp:0 together, real time by default."""
    firmware = os.path.join(tools, 'firmware.elf')
    backend = LineNorthBackend()
    proc = subprocess.Popen([os.path.join(tools, 'apm25sim'), '--elf', firmware, '--physics',
                             'json:127.0.0.1:%d' % backend.port, '--serial', 'tcp:0', '--seconds', '6'],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = None
        deadline = time.time() + 30
        while port is None and time.time() < deadline:
            line = proc.stderr.readline()
            m = re.search(r'serving UART0 on tcp:127\.0\.0\.1:(\d+)', line)
            if m:
                port = int(m.group(1))
        check(port is not None, 'apm25sim did not say where it serves UART0')
        client = socket.create_connection(('127.0.0.1', port), timeout=30)
        client.settimeout(1.0)
        start = time.time()
        received = b''
        while time.time() - start < 20:
            try:
                chunk = client.recv(65536)
            except socket.timeout:
                if proc.poll() is not None:
                    break
                continue
            if not chunk:
                break
            received += chunk
        wall = time.time() - start
        client.close()
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        backend.close()
    check(proc.returncode == 0, 'exit %d\n%s' % (proc.returncode, err))
    text = received.decode('ascii', 'replace')
    check(text.count('roll:') > 100, 'the client got %d bytes, %d angle lines' % (len(received), text.count('roll:')))
    check(received.decode('ascii', 'replace') in out or len(out) >= len(text), 'stdout and the client disagree')
    # 6 simulated seconds paced at real time: at least ~5 s of wall time after the client came.
    check(wall > 4.0, '6 simulated seconds went by in %.1f s of wall time: not paced' % wall)
    check(backend.frames >= 5900, 'the backend stepped %d frames for 6 s at 1 kHz' % backend.frames)


CHECKS = ['help', 'undisturbed', 'probe', 'trajectory', 'kinds', 'physics', 'live']


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('command', choices=['run'])
    ap.add_argument('--tools', required=True)
    ap.add_argument('--work', required=True)
    ap.add_argument('--only', nargs='*', choices=CHECKS)
    args = ap.parse_args()
    tools, work = os.path.abspath(args.tools), os.path.abspath(args.work)
    os.makedirs(work, exist_ok=True)
    for need in ('apm25sim', 'scenario', 'firmware.elf'):
        if not os.path.exists(os.path.join(tools, need)):
            print('FAIL: %s missing in %s (make firmware tools)' % (need, tools))
            return 1
    failed = 0
    probe = None
    for name in args.only or CHECKS:
        try:
            if name in ('probe', 'trajectory', 'kinds', 'physics') and probe is None:
                probe = build_probe(work)
            if name in ('help', 'undisturbed'):
                globals()['check_' + name](tools, work)
            elif name == 'live':
                check_live(tools, work)
            else:
                globals()['check_' + name](tools, work, probe)
            print('ok', name, flush=True)
        except Failure as e:
            failed += 1
            print('FAIL %s: %s' % (name, e), flush=True)
        except subprocess.TimeoutExpired as e:
            failed += 1
            print('FAIL %s: timed out: %s' % (name, e), flush=True)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
