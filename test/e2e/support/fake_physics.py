# SPDX-License-Identifier: GPL-3.0-or-later
"""A tiny physics backend for ArduPilot's SITL JSON interface (ArduPilot's
libraries/SITL/examples/JSON/readme.md), for apm25sim's --physics tests: the board holds a
fixed attitude at rest. Standard library only.

Each servo packet (uint16 magic 18458, uint16 frame_rate, uint32 frame_count, uint16 pwm[16],
little-endian) is answered to its sender with one JSON state line. A new frame_count steps
physics time by 1/frame_rate; a repeated one is answered again without stepping (the
readme's resend). Prints 'port N' on stdout once listening.

  --port N              UDP port on 127.0.0.1 (0: any free one)
  --attitude R,P,Y      degrees, sent as `attitude` (default 0,0,0)
  --quaternion          send the attitude as `quaternion` instead
  --rc W1,...,W8        send `rc` with these widths (us); --rc-dead-from T: `rc` empty from T s
  --airspeed V          send `airspeed` V m/s
  --log FILE            one CSV row per packet: frame_count,frame_rate,pwm1..pwm16
  --silent-after N      stop answering after frame N (the link's timeout test)
  --garbage-after N     answer frames after N with text that is not a state
  --late N              a loaded machine's race, deterministically: frame N is
                        answered only once it came again (apm25sim sent it again after its
                        1 s time-out); the answer to that resend, the same state, is held
                        and sent just before the next frame's answer, when apm25sim already
                        waits for that frame
  --twice               answer every packet twice
  --time-back-after N   from frame N + 1 on, the timestamps are 1 s earlier (the backend's
                        time went back, e.g. a physics restarted under the same port)
"""
import argparse
import json
import math
import socket
import struct
import sys

MAGIC = 18458
PACKET = struct.Struct('<HHI16H')
GRAVITY = 9.80665


def quaternion(roll, pitch, yaw):
    """Body to NED, Z-Y-X (w, x, y, z)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return [cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--port', type=int, default=9002)
    ap.add_argument('--attitude', default='0,0,0')
    ap.add_argument('--quaternion', action='store_true')
    ap.add_argument('--rc')
    ap.add_argument('--rc-dead-from', type=float)
    ap.add_argument('--airspeed', type=float)
    ap.add_argument('--log')
    ap.add_argument('--silent-after', type=int)
    ap.add_argument('--garbage-after', type=int)
    ap.add_argument('--late', type=int)
    ap.add_argument('--twice', action='store_true')
    ap.add_argument('--time-back-after', type=int)
    args = ap.parse_args()
    roll, pitch, yaw = (math.radians(float(v)) for v in args.attitude.split(','))
    # Specific force at rest: R^T (0, 0, -g).
    accel = [GRAVITY * math.sin(pitch), -GRAVITY * math.sin(roll) * math.cos(pitch),
             -GRAVITY * math.cos(roll) * math.cos(pitch)]
    rc = [float(v) for v in args.rc.split(',')] if args.rc else None

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(('127.0.0.1', args.port))
    print('port', sock.getsockname()[1], flush=True)
    log = open(args.log, 'w') if args.log else None
    last_frame = None
    t = 0.0
    late_waiting = False  # --late: frame N received once, not answered yet
    held = None           # --late: the resend's answer, sent before the next frame's
    while True:
        data, sender = sock.recvfrom(1024)
        if len(data) != PACKET.size:
            continue
        fields = PACKET.unpack(data)
        magic, rate, frame = fields[0], fields[1], fields[2]
        if magic != MAGIC:
            continue
        if log:
            log.write(','.join(str(v) for v in fields[1:]) + '\n')
            log.flush()
        if args.silent_after is not None and frame > args.silent_after:
            continue
        new_frame = frame != last_frame
        if new_frame:
            if last_frame is not None:
                t += 1.0 / rate
            last_frame = frame
        back = 1.0 if args.time_back_after is not None and frame > args.time_back_after else 0.0
        state = {'timestamp': 1.5 + t - back, 'imu': {'gyro': [0, 0, 0], 'accel_body': accel},
                 'position': [0, 0, -10], 'velocity': [0, 0, 0]}
        if args.quaternion:
            state['quaternion'] = quaternion(roll, pitch, yaw)
        else:
            state['attitude'] = [roll, pitch, yaw]
        if args.airspeed is not None:
            state['airspeed'] = args.airspeed
        if rc:
            dead = args.rc_dead_from is not None and t >= args.rc_dead_from
            state['rc'] = {} if dead else {'rc_%d' % (i + 1): w for i, w in enumerate(rc)}
        text = '\n' + json.dumps(state) + '\n'
        if args.garbage_after is not None and frame > args.garbage_after:
            text = 'hello\n'
        if args.late is not None and frame == args.late:
            if new_frame:
                late_waiting = True  # the first send: no answer until it comes again
                continue
            if late_waiting:
                late_waiting = False
                sock.sendto(text.encode(), sender)  # the first send's late answer
                held = text                         # the resend's, held
                continue
        if held is not None and new_frame:
            sock.sendto(held.encode(), sender)
            held = None
        sock.sendto(text.encode(), sender)
        if args.twice:
            sock.sendto(text.encode(), sender)


if __name__ == '__main__':
    try:
        main()
    except KeyboardInterrupt:
        sys.exit(0)
