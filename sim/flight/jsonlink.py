# SPDX-License-Identifier: GPL-3.0-or-later
"""ArduPilot's SITL JSON interface, the physics backend's side
(ArduPilot libraries/SITL/examples/JSON/readme.md):

- the autopilot sends a binary UDP packet to the backend (port 9002): little-endian
  uint16 magic = 18458, uint16 frame_rate, uint32 frame_count, uint16 pwm[16]
  (or magic 29569 and pwm[32]);
- the backend replies to the sender's address with one JSON object, preceded and
  terminated by a newline: timestamp (s, absolute physics time), imu {gyro, accel_body}
  (body frame), position and velocity (NED, m and m/s), attitude (roll, pitch, yaw rad)
  and/or quaternion (used if both), optional airspeed, velocity_wind, rc {rc_1..};
- frame_count increments by one a frame; the same count again is a re-sent frame
  (answered again, the physics not stepped); a smaller count means the autopilot restarted
  (the backend resets the vehicle).

Also the autopilot's side (pack_servo_packet, parse_reply) for the stand-in and the tests.
"""
import json
import struct

MAGIC_16 = 18458
MAGIC_32 = 29569
_HEADER = struct.Struct("<HHI")
PACKET_16 = struct.Struct("<HHI16H")
PACKET_32 = struct.Struct("<HHI32H")


class PacketError(ValueError):
    pass


def parse_servo_packet(data):
    """(frame_rate, frame_count, pwm tuple) of a servo packet; PacketError if it is not one."""
    if len(data) < _HEADER.size:
        raise PacketError("servo packet of %d bytes, shorter than its header" % len(data))
    magic = _HEADER.unpack_from(data)[0]
    layout = {MAGIC_16: PACKET_16, MAGIC_32: PACKET_32}.get(magic)
    if layout is None:
        raise PacketError("servo packet magic %d, expected %d or %d" % (magic, MAGIC_16, MAGIC_32))
    if len(data) != layout.size:
        raise PacketError("servo packet of %d bytes, magic %d wants %d" % (len(data), magic, layout.size))
    fields = layout.unpack(data)
    if fields[1] == 0:
        raise PacketError("servo packet with frame rate 0")
    return fields[1], fields[2], fields[3:]


def pack_servo_packet(frame_rate, frame_count, pwm):
    pwm = list(pwm) + [0] * (16 - len(pwm))
    if len(pwm) == 16:
        return PACKET_16.pack(MAGIC_16, frame_rate, frame_count & 0xFFFFFFFF, *pwm)
    pwm = pwm + [0] * (32 - len(pwm))
    return PACKET_32.pack(MAGIC_32, frame_rate, frame_count & 0xFFFFFFFF, *pwm)


NO_RC = "no rc field"


def make_reply(state, rc=NO_RC, airspeed=True):
    """The JSON frame for a state dict of flightmodel.FlightModel.state(). rc: the channel
    widths (us); None for a receiver without signal, sent as an rc object with no channels
    (the readme has no word for a lost receiver; apm25sim --physics reads an empty rc as a
    dead one, ArduPilot's SITL keeps its last channels); NO_RC for no rc field at all.
    airspeed False: no airspeed field (the field is optional: an aeroplane without a pitot)."""
    body = {
        "timestamp": state["t"],
        "imu": {"gyro": list(state["gyro"]), "accel_body": list(state["accel"])},
        "position": list(state["position"]),
        "quaternion": list(state["quat"]),
        "attitude": list(state["euler"]),
        "velocity": list(state["velocity"]),
        "airspeed": state["airspeed"],
        "velocity_wind": list(state["wind"]),
    }
    if not airspeed:
        del body["airspeed"]
    if rc is None:
        body["rc"] = {}
    elif rc is not NO_RC:
        body["rc"] = {"rc_%d" % (i + 1): int(round(w)) for i, w in enumerate(rc)}
    return ("\n" + json.dumps(body, separators=(",", ":")) + "\n").encode("ascii")


def parse_reply(data):
    """The JSON object of a reply frame (checks the newline framing and the mandatory fields)."""
    text = data.decode("ascii")
    if not (text.startswith("\n") and text.endswith("\n")):
        raise PacketError("JSON frame not enclosed in newlines")
    obj = json.loads(text)
    for key in ("timestamp", "imu", "position", "velocity"):
        if key not in obj:
            raise PacketError("JSON frame without %s" % key)
    if "gyro" not in obj["imu"] or "accel_body" not in obj["imu"]:
        raise PacketError("JSON frame without imu gyro / accel_body")
    if "quaternion" not in obj and "attitude" not in obj:
        raise PacketError("JSON frame without attitude or quaternion")
    return obj


class FrameTracker:
    """What to do with each frame count: 'step', 'repeat' (answer again, no step) or 'reset'."""

    def __init__(self):
        self.last = None
        self.missed = 0
        self.repeats = 0
        self.resets = 0

    def classify(self, frame_count):
        last, self.last = self.last, frame_count
        if last is None:
            return "step"
        if frame_count == last:
            self.repeats += 1
            return "repeat"
        if frame_count < last:
            self.resets += 1
            return "reset"
        self.missed += frame_count - last - 1
        return "step"
