#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""JSBSim physics backend for ArduPilot's SITL JSON interface: the Rascal 110 flies whatever
autopilot speaks the protocol (build/apm25sim --physics json, ArduPilot SITL with
--model JSON, or sim/flight/fly.py's stand-in).

    build/venv/bin/python sim/flight/jsbsim_backend.py [--port 9002] [--rc FILE|none]
        [--gust 0|1|2] [--seed N] [--trajectory FILE.csv[.gz]] [--log FILE.csv[.gz]]
        [--seconds S] [--airspeed 18] [--altitude 100] [--heading 0] [--upset T,SECONDS,NM ...]
        [--vibration M_S2] [--no-airspeed] [--airframe plain|elevons|vtail] [--launch V,H,PITCH]

Lock-step: one physics frame (1 / frame_rate of the packet, in JSBSim steps of at most
2.5 ms) per servo packet received, no wall clock, so a flight is the same every time.
The aeroplane starts trimmed for level flight at the given airspeed and height (north,
wings level); outputs without pulses (width 0) hold the trim. The pilot's sticks from
--rc are sent as the reply's rc channels, and no signal as an empty rc object (default:
hands off, sticks centred, throttle at the trim, ch5-ch8 1500; `--rc none` sends no rc
field). --no-airspeed leaves the replies' optional airspeed out: an aeroplane without a
pitot (apm25sim then leaves the MPXV7002DP's input A0 at 0 V, which the board reads as no
sensor). --airframe elevons or vtail reads OUT1-OUT4 as an autopilot's ELEVON_OUTPUT or
VTAIL_OUTPUT mixes them (elevons on OUT1 left and OUT2 right; ruddervators on OUT2 left and
OUT4 right; above 1500 us trailing edge up) and flies the plain-tailed model with the
aileron, elevator and rudder those surfaces make (flightmodel.unmix).
--launch V,H,PITCH starts from a hand launch instead: held (--hold) at H m above the ground,
PITCH deg nose up, wings level, then thrown at V m/s (flightmodel.FlightModel's launch).
The files hold --seconds of simulated time; after it the backend still answers (an
autopilot may run a frame longer) and exits once no packet came for --linger s (default 1);
--idle-timeout s without a packet before that stops it too.
"""
import argparse
import math
import select
import socket
import sys

import flightio
import flightmodel
import jsonlink


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bind", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    p.add_argument("--port", type=int, default=9002, help="UDP port (default 9002, 0: any free one)")
    p.add_argument("--rc", default="", help="pilot script, CSV t,ch1..ch8 (us); 'none' for no rc")
    p.add_argument("--gust", type=int, default=0, choices=sorted(flightmodel.GUST_LEVELS),
                   help="Dryden turbulence: 0 none, 1 light, 2 moderate")
    p.add_argument("--seed", type=int, default=1, help="seed of the turbulence")
    p.add_argument("--wind", default="0,0", metavar="N,E",
                   help="a steady wind from the release on: the air's velocity north and east, m/s (0,5: from the west)")
    p.add_argument("--airspeed", type=float, default=18.0, help="trim airspeed, m/s")
    p.add_argument("--altitude", type=float, default=100.0, help="start height above ground, m")
    p.add_argument("--heading", type=float, default=0.0, help="start heading, deg")
    p.add_argument("--upset", action="append", default=[], metavar="T,SECONDS,NM",
                   help="a roll moment of NM newton-metres (positive rolls right) from T for SECONDS "
                        "of simulated time; repeatable")
    p.add_argument("--vibration", type=float, default=0.0, metavar="M_S2",
                   help="propeller vibration at the IMU, amplitude at the trim's propeller speed (m/s^2)")
    p.add_argument("--hold", type=float, default=0.0, metavar="S",
                   help="hold the aeroplane still at its start attitude for S s (a launch stand: the "
                        "board starts at rest), then release it into the trimmed flight")
    p.add_argument("--launch", metavar="V,H,PITCH",
                   help="a hand launch: held at H m, PITCH deg nose up, then thrown at V m/s (e.g. 11,1.8,10)")
    p.add_argument("--no-airspeed", action="store_true",
                   help="send no airspeed in the replies (no pitot on the aeroplane; the log keeps the truth)")
    p.add_argument("--airframe", default="plain", choices=flightmodel.AIRFRAMES,
                   help="how the outputs drive the surfaces: plain (OUT1-4 aileron, elevator, throttle, "
                        "rudder), elevons (OUT1 left, OUT2 right) or vtail (OUT2 left, OUT4 right ruddervator)")
    p.add_argument("--trajectory", help="write the flight as a trajectory (../shared/SIM.md)")
    p.add_argument("--log", help="write the true state, one row a frame")
    p.add_argument("--seconds", type=float, default=0.0,
                   help="record S simulated seconds, then stop (see --linger; 0: no end)")
    p.add_argument("--idle-timeout", type=float, default=0.0,
                   help="stop after this many wall-clock seconds without a packet (0: never)")
    p.add_argument("--linger", type=float, default=1.0,
                   help="after --seconds, stop once no packet came for this many wall-clock seconds")
    p.add_argument("--port-file", help="write the bound port number here once listening")
    p.add_argument("--quiet", action="store_true")
    return p.parse_args(argv)


class Backend:
    def __init__(self, args):
        self.args = args
        upsets = []
        for spec in args.upset:
            try:
                start, length, moment = (float(v) for v in spec.split(","))
            except ValueError:
                raise ValueError("--upset %r: want T,SECONDS,NM (three numbers)" % spec)
            upsets.append((start, length, moment))
        self.model = flightmodel.FlightModel(args.airspeed, args.altitude, args.heading, args.gust, args.seed,
                                             upsets=upsets, vibration_m_s2=args.vibration, hold_s=args.hold,
                                             wind_ne_m_s=wind_arg(args.wind), launch=launch_arg(args.launch))
        trim = self.model.trim
        widths = trim.widths_us()
        if args.rc == "none":
            self.pilot = None
        elif args.rc:
            self.pilot = flightio.RcScript.load(args.rc)
        else:
            self.pilot = flightio.RcScript.constant((1500, 1500, round(widths[2]), 1500, 1500, 1500, 1500, 1500))
        self.tracker = jsonlink.FrameTracker()
        self.last_reply = None
        self.frames = 0
        self.say("# trim at %.1f m/s: OUT1 %.0f OUT2 %.0f OUT3 %.0f OUT4 %.0f us, alpha %.2f deg "
                 "(residual %.1e)" % ((args.airspeed,) + widths + (trim.alpha_rad * 57.29578, trim.residual)))
        self.open_outputs()

    def say(self, text):
        if not self.args.quiet:
            print(text, file=sys.stderr, flush=True)

    def open_outputs(self):
        self.trajectory = flightio.TrajectoryWriter(self.args.trajectory) if self.args.trajectory else None
        self.log = flightio.StateLog(self.args.log) if self.args.log else None
        self.record(self.model.state())

    def close_outputs(self):
        for out in (self.trajectory, self.log):
            if out:
                out.close()

    def record(self, state):
        if self.args.seconds > 0 and state["t"] > self.args.seconds + 1e-9:
            return  # the files hold --seconds; frames after it are answered, not recorded
        if self.trajectory:
            self.trajectory.write(state)
        if self.log:
            self.log.write(state)

    def rc_at(self, t_s):
        return jsonlink.NO_RC if self.pilot is None else self.pilot.at(t_s)

    def handle(self, data):
        """The reply to one packet (bytes), or None for a packet that is not a servo packet."""
        try:
            frame_rate, frame_count, pwm = jsonlink.parse_servo_packet(data)
        except jsonlink.PacketError as e:
            self.say("# ignored: %s" % e)
            return None
        action = self.tracker.classify(frame_count)
        if action == "repeat" and self.last_reply is not None:
            return self.last_reply
        if action == "reset":
            self.say("# frame count went back to %d: the autopilot restarted, so does the flight" % frame_count)
            self.close_outputs()
            self.model.reset()
            self.frames = 0
            self.open_outputs()
        self.model.set_widths(flightmodel.unmix(self.args.airframe, pwm[:4]))
        crashed_before = self.model.crashed_at is not None
        self.model.step(1.0 / frame_rate)
        if self.model.crashed_at is not None and not crashed_before:
            self.say("# crashed at %.3f s: the aeroplane lies still where it hit the ground" % self.model.crashed_at)
        self.frames += 1
        state = self.model.state()
        self.record(state)
        self.last_reply = jsonlink.make_reply(state, self.rc_at(state["t"]), airspeed=not self.args.no_airspeed)
        return self.last_reply

    def done(self):
        return self.args.seconds > 0 and self.model.time_s >= self.args.seconds - 1e-9

    def serve(self):
        sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        sock.bind((self.args.bind, self.args.port))
        port = sock.getsockname()[1]
        if self.args.port_file:
            with open(self.args.port_file, "w") as f:
                f.write("%d\n" % port)
        self.say("# listening on %s:%d (UDP)" % (self.args.bind, port))
        try:
            while True:
                # After --seconds, the autopilot's last frames (it may run a frame or two
                # longer) are still answered, until it falls silent for --linger s.
                wait_s = self.args.linger if self.done() else self.args.idle_timeout
                if wait_s > 0:
                    ready, _, _ = select.select([sock], [], [], wait_s)
                    if not ready:
                        if not self.done():
                            self.say("# no packet for %.0f s: stopping" % wait_s)
                        break
                data, address = sock.recvfrom(512)
                reply = self.handle(data)
                if reply is not None:
                    sock.sendto(reply, address)
        finally:
            self.close_outputs()
            sock.close()
        s = self.model.state()
        self.say("# %d frames, %.3f s simulated; %d missed, %d repeated, %d resets; end at %.1f m, %.1f m/s"
                 % (self.frames, s["t"], self.tracker.missed, self.tracker.repeats, self.tracker.resets,
                    -s["position"][2], s["airspeed"]))


def wind_arg(spec):
    try:
        north, east = (float(v) for v in spec.split(","))
    except ValueError:
        raise ValueError("--wind %r: want N,E (two numbers, m/s)" % spec)
    if not (math.isfinite(north) and math.isfinite(east)) or math.hypot(north, east) > 30.0:
        raise ValueError("--wind %r: at most 30 m/s" % spec)
    return north, east


def launch_arg(spec):
    if not spec:
        return None
    try:
        speed, height, pitch = (float(v) for v in spec.split(","))
    except ValueError:
        raise ValueError("--launch %r: want V,H,PITCH (three numbers: m/s, m, deg)" % spec)
    if not (5.0 <= speed <= 30.0 and 0.5 <= height <= 500.0 and -10.0 <= pitch <= 30.0):
        raise ValueError("--launch %r: a speed of 5-30 m/s, a height of 0.5-500 m, a pitch of -10..30 deg" % spec)
    return speed, height, pitch


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        backend = Backend(args)
    except (OSError, ValueError, RuntimeError) as e:
        print("jsbsim_backend: %s" % e, file=sys.stderr)
        return 2
    try:
        backend.serve()
    except KeyboardInterrupt:
        pass
    except OSError as e:
        print("jsbsim_backend: %s" % e, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
