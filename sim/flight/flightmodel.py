# SPDX-License-Identifier: GPL-3.0-or-later
"""The Rascal 110 in JSBSim: trim, servo widths in, the true state and ideal sensor values out.

Conventions (the firmware's, issue 21; ArduPlane's output order):
  OUT1 aileron, above 1500 us rolls right; OUT2 elevator, above 1500 us pitches the nose up;
  OUT3 throttle, 1000 us off .. 2000 us full; OUT4 rudder, above 1500 us yaws the nose right.
  +-500 us is full throw. An output with no pulse (width 0) leaves its surface where it was:
  a servo without signal holds its position; before any pulse, that is the trim position.
Body axes x forward, y right, z down; earth axes north-east-down; SI units.
"""
import math
import os

import jsbsim
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
FT = 0.3048
NM_PER_LBSFT = 1.3558179483
G0 = 9.80665
EARTH_RADIUS_M = 6378137.0
# The project's earth field (sim/scenario.cpp): 49 uT at 66 deg inclination, declination 0.
EARTH_FIELD_NED_UT = (20.0, 0.0, 45.0)
SURFACE_THROW_US = 500.0
# Physics is never stepped coarser than this, whatever the servo packets' frame rate.
MAX_STEP_S = 1.0 / 400.0
# The C.G. this close to the ground is a crash (the gear sits 0.37 m below it).
CRASH_HEIGHT_M = 0.25

# Dryden turbulence at low altitude (MIL-F-8785C as tabulated by Beard & McLain, Small
# Unmanned Aircraft, Table 4.1): intensities sigma_u = sigma_v, sigma_w in m/s, scale
# lengths L_u = L_v = 200 m, L_w = 50 m.
GUST_LEVELS = {0: None, 1: (1.06, 0.7), 2: (2.12, 1.4)}
GUST_NAMES = {0: "none", 1: "light", 2: "moderate"}
GUST_SCALE_UV_M, GUST_SCALE_W_M = 200.0, 50.0
# The lift of rascal110.xml's linear range (Beard & McLain's C_L0, C_La), for the hand
# launch's angle of attack.
LIFT_AT_ZERO_ALPHA, LIFT_SLOPE_PER_RAD = 0.23, 5.61


def lift_coefficient(alpha_rad):
    return LIFT_AT_ZERO_ALPHA + LIFT_SLOPE_PER_RAD * alpha_rad


def quat_from_euler(roll, pitch, yaw):
    """Body -> NED, q = qz(yaw) qy(pitch) qx(roll), scalar first."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cy * cp * cr + sy * sp * sr, cy * cp * sr - sy * sp * cr,
            cy * sp * cr + sy * cp * sr, sy * cp * cr - cy * sp * sr)


def body_to_ned_matrix(roll, pitch, yaw):
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def surface_norm(width_us):
    return max(-1.0, min(1.0, (width_us - 1500.0) / SURFACE_THROW_US))


def throttle_norm(width_us):
    return max(0.0, min(1.0, (width_us - 1000.0) / 1000.0))


def valid_width(width_us):
    """A width a servo would follow; 0 (no pulse) and absurd values leave the surface alone."""
    return 800 <= width_us <= 2200


# The airframes an autopilot may mix for (its ELEVON_OUTPUT / VTAIL_OUTPUT), flown on the
# plain-tailed model by their geometry: each surface of a pair moves by its width's offset
# from 1500 us, above it trailing edge up (the firmware's convention, docs/flight.md).
#   elevons   OUT1 the left, OUT2 the right elevon. Both up pitch the nose up; the right
#             up and the left down take lift from the right wing and give it to the left:
#             the aeroplane rolls right. Aileron = right - left, elevator = left + right.
#   vtail     OUT2 the left, OUT4 the right ruddervator. Both up pitch the nose up; the left
#             up and the right down push the tail left (each surface's force is normal to
#             it, and the V's two normals lean inward): the nose yaws right, as a rudder's
#             trailing edge to the right does. Elevator = left + right, rudder = left - right.
# A surface so worked out is held within full throw (+-500 us about 1500); a pair with
# either width absent (0 or implausible) holds both surfaces it drives.
AIRFRAMES = ("plain", "elevons", "vtail")


def unmix(airframe, widths_us):
    """OUT1..OUT4 of an `airframe` as the plain aeroplane's aileron, elevator, throttle and
    rudder widths (the conventions above; more outputs are dropped)."""
    w = list(widths_us)[:4] + [0] * max(0, 4 - len(widths_us))
    if airframe == "plain":
        return w
    if airframe == "elevons":
        pair, into = (0, 1), (0, 1)
    elif airframe == "vtail":
        pair, into = (1, 3), (3, 1)
    else:
        raise ValueError("airframe %r: one of %s" % (airframe, ", ".join(AIRFRAMES)))
    left, right = w[pair[0]], w[pair[1]]
    if not (valid_width(left) and valid_width(right)):
        w[pair[0]] = w[pair[1]] = 0
        return w
    dl, dr = left - 1500.0, right - 1500.0
    # into[0] takes the difference (elevons: the aileron, right - left; V-tail: the rudder,
    # left - right), into[1] the sum (the elevator).
    difference = dr - dl if airframe == "elevons" else dl - dr
    w[into[0]] = 1500.0 + max(-SURFACE_THROW_US, min(SURFACE_THROW_US, difference))
    w[into[1]] = 1500.0 + max(-SURFACE_THROW_US, min(SURFACE_THROW_US, dl + dr))
    return w


class Dryden:
    """Dryden gusts in body axes, driven by a seeded generator (Beard & McLain eq. 4.15-4.17)."""

    def __init__(self, level, seed):
        self.sigma = GUST_LEVELS[level]
        self.rng = np.random.Generator(np.random.PCG64(seed))
        self.u = 0.0
        self.v = np.zeros(2)
        self.w = np.zeros(2)

    def step(self, airspeed_m_s, dt_s):
        if self.sigma is None:
            return np.zeros(3)
        sigma_uv, sigma_w = self.sigma
        va = max(airspeed_m_s, 1.0)
        noise = self.rng.standard_normal(3) / math.sqrt(dt_s)  # unit-PSD white noise
        a = va / GUST_SCALE_UV_M
        self.u += dt_s * (-a * self.u + noise[0])
        gust_u = sigma_uv * math.sqrt(2 * va / GUST_SCALE_UV_M) * self.u

        def second_order(x, scale, sigma, n):
            a2 = va / scale
            x1, x2 = x
            x1n = x1 + dt_s * x2
            x2n = x2 + dt_s * (-a2 * a2 * x1 - 2 * a2 * x2 + n)
            x[0], x[1] = x1n, x2n
            return sigma * math.sqrt(3 * va / scale) * (a2 / math.sqrt(3) * x1n + x2n)

        gust_v = second_order(self.v, GUST_SCALE_UV_M, sigma_uv, noise[1])
        gust_w = second_order(self.w, GUST_SCALE_W_M, sigma_w, noise[2])
        return np.array([gust_u, gust_v, gust_w])


class Trim:
    """The controls and attitude of steady, wings-level, unaccelerated flight."""

    def __init__(self, throttle, elevator, aileron, rudder, alpha_rad, beta_rad, residual):
        self.throttle, self.elevator, self.aileron, self.rudder = throttle, elevator, aileron, rudder
        self.alpha_rad, self.beta_rad, self.residual = alpha_rad, beta_rad, residual

    def widths_us(self):
        """OUT1..OUT4 in the firmware's conventions (elevator above 1500 = nose up)."""
        return (1500.0 + SURFACE_THROW_US * self.aileron, 1500.0 - SURFACE_THROW_US * self.elevator,
                1000.0 + 1000.0 * self.throttle, 1500.0 + SURFACE_THROW_US * self.rudder)


class FlightModel:
    def __init__(self, airspeed_m_s=18.0, altitude_m=100.0, heading_deg=0.0, gust=0, seed=1,
                 latitude_deg=52.5, longitude_deg=13.4, upsets=(), vibration_m_s2=0.0, hold_s=0.0,
                 wind_ne_m_s=(0.0, 0.0), launch=None):
        """upsets: (start_s, duration_s, roll_moment_Nm) tuples, a roll moment applied from
        start_s for duration_s (positive rolls right). vibration_m_s2: the amplitude of the
        propeller's vibration at the IMU at the trim's propeller speed (see vibration()).
        hold_s: the aeroplane is held still at its start attitude for so long (on a launch
        stand: the board powers up and calibrates its gyro at rest, as on the ground), then
        released into the trimmed flight (a catapult launch at the trim's speed).
        wind_ne_m_s: a steady wind, the air's velocity north and east (m/s; (0, 5) blows from
        the west), from the release on (the trim is in still air: the aeroplane meets it as a
        gust at the start).
        launch: (speed m/s, height m, pitch deg), a hand launch instead of the trimmed start:
        the aeroplane held at that height and pitch, wings level, then thrown at that speed
        along the pitch less the angle of attack whose lift carries its weight at that speed
        (launch_alpha), its motor turning at the trim's throttle until the autopilot's
        throttle takes over. The trim (self.trim) is still the cruise's."""
        if gust not in GUST_LEVELS:
            raise ValueError("gust level %r: 0 (none), 1 (light) or 2 (moderate)" % (gust,))
        self.airspeed0, self.altitude0, self.heading0 = airspeed_m_s, altitude_m, math.radians(heading_deg)
        self.lat0, self.lon0 = math.radians(latitude_deg), math.radians(longitude_deg)
        self.gust_level, self.seed = gust, seed
        self.upsets = [tuple(float(v) for v in u) for u in upsets]
        self.vibration_m_s2 = float(vibration_m_s2)
        self.hold_s = max(0.0, float(hold_s))
        self.wind_ne_m_s = (float(wind_ne_m_s[0]), float(wind_ne_m_s[1]))
        self.launch = None if launch is None else tuple(float(v) for v in launch)
        self.crashed_at = None  # time of the crash (the ground), None while flying
        jsbsim.FGJSBBase().debug_lvl = 0  # no banner on stdout
        self.fdm = jsbsim.FGFDMExec(HERE, None)
        self.fdm.set_debug_level(0)
        self.fdm.set_aircraft_path("aircraft")
        self.fdm.set_engine_path("engine")
        if not self.fdm.load_model("rascal110"):
            raise RuntimeError("JSBSim could not load sim/flight/aircraft/rascal110")
        self.fdm.set_dt(MAX_STEP_S)
        self.trim = self._solve_trim()
        self.reset()

    # ---- trim ---------------------------------------------------------------------------
    def _set_ic(self, alpha, beta, ic=None):
        """ic: (speed m/s, height m, flight path angle rad) instead of the trim's (level at
        airspeed0 and altitude0)."""
        speed, height, gamma = ic or (self.airspeed0, self.altitude0, 0.0)
        f = self.fdm
        f["ic/lat-geod-rad"] = self.lat0
        f["ic/long-gc-rad"] = self.lon0
        f["ic/terrain-elevation-ft"] = 0.0
        f["ic/h-agl-ft"] = height / FT
        f["ic/vt-fps"] = speed / FT
        f["ic/alpha-rad"] = alpha
        f["ic/beta-rad"] = beta
        f["ic/gamma-rad"] = gamma
        f["ic/phi-rad"] = 0.0
        f["ic/psi-true-rad"] = self.heading0
        f["ic/p-rad_sec"] = 0.0
        f["ic/q-rad_sec"] = 0.0
        f["ic/r-rad_sec"] = 0.0
        for name in ("north", "east", "down"):
            f["atmosphere/wind-%s-fps" % name] = 0.0
            f["atmosphere/gust-%s-fps" % name] = 0.0

    def _set_controls(self, throttle, elevator, aileron, rudder):
        f = self.fdm
        f["fcs/throttle-cmd-norm"] = throttle
        f["fcs/elevator-cmd-norm"] = elevator
        f["fcs/aileron-cmd-norm"] = aileron
        f["fcs/rudder-cmd-norm"] = rudder

    def _residual(self, x, ic=None):
        """Body accelerations (u, v, w dot in m/s^2; p, q, r dot in rad/s^2) at the state and
        controls x = (throttle, elevator, aileron, rudder, alpha, beta), the propeller spun up
        to its steady speed there (JSBSim's own steady-state search divides by the propeller's
        speed and fails from rest for an electric motor, so the aeroplane is held at the state
        while the propeller settles: run one step, put the state back)."""
        throttle, elevator, aileron, rudder, alpha, beta = x
        f = self.fdm
        self._set_controls(throttle, elevator, aileron, rudder)
        self._set_ic(alpha, beta, ic)
        f["propulsion/set-running"] = -1
        for i in range(600):
            f.set_dt(MAX_STEP_S if i < 200 else 0.01)
            f.run_ic()
            f.run()
        f.set_dt(MAX_STEP_S)
        f.run_ic()
        return np.array([f["accelerations/udot-ft_sec2"] * FT, f["accelerations/vdot-ft_sec2"] * FT,
                         f["accelerations/wdot-ft_sec2"] * FT, f["accelerations/pdot-rad_sec2"],
                         f["accelerations/qdot-rad_sec2"], f["accelerations/rdot-rad_sec2"]])

    def _solve_trim(self):
        """Newton's method on the six body accelerations with a finite-difference Jacobian."""
        x = np.array([0.15, -0.15, 0.0, 0.0, 0.03, 0.0])
        lower = np.array([0.0, -1.0, -1.0, -1.0, -0.2, -0.2])
        upper = np.array([1.0, 1.0, 1.0, 1.0, 0.3, 0.2])
        steps = np.array([0.005, 0.005, 0.005, 0.005, 0.002, 0.002])
        r = self._residual(x)
        for _ in range(12):
            if np.max(np.abs(r)) < 1e-4:
                break
            jac = np.empty((6, 6))
            for j in range(6):
                xj = x.copy()
                xj[j] += steps[j]
                jac[:, j] = (self._residual(xj) - r) / steps[j]
            dx = np.linalg.lstsq(jac, -r, rcond=None)[0]
            x = np.clip(x + dx, lower, upper)
            r = self._residual(x)
        if np.max(np.abs(r)) > 1e-2:
            raise RuntimeError("trim did not converge: residual %s" % r)
        return Trim(*[float(v) for v in x], residual=float(np.max(np.abs(r))))

    def launch_alpha(self):
        """The hand launch's angle of attack: the lift's share of the weight grows as the trim's
        over (trim speed / launch speed)^2, at the lift slope C_La 5.61 / rad of the XML's
        linear range (8 deg at 11 m/s; the stall is at 27)."""
        speed = self.launch[0]
        cl_share = (self.airspeed0 / speed) ** 2 - 1.0
        return self.trim.alpha_rad + cl_share * lift_coefficient(self.trim.alpha_rad) / LIFT_SLOPE_PER_RAD

    # ---- flight -------------------------------------------------------------------------
    def reset(self):
        """Back to the start: time 0, at altitude, trimmed (or at the hand launch), the gust
        sequence restarted."""
        t = self.trim
        if self.launch is None:
            self._residual((t.throttle, t.elevator, t.aileron, t.rudder, t.alpha_rad, t.beta_rad))
        else:
            speed, height, pitch_deg = self.launch
            alpha = self.launch_alpha()
            self._residual((t.throttle, t.elevator, t.aileron, t.rudder, alpha, 0.0),
                           (speed, height, math.radians(pitch_deg) - alpha))
        self.time_s = 0.0
        self.crashed_at = None
        self.crash_euler = None
        self.crash_position = None
        self.surfaces = [t.aileron, t.elevator, t.throttle, t.rudder]
        self.dryden = Dryden(self.gust_level, self.seed)
        self.gust_body = np.zeros(3)
        self.wind_on = False
        self.trim_rpm = self.fdm["propulsion/engine/propeller-rpm"]
        self.prop_angle_rad = 0.0

    def set_widths(self, widths_us):
        """OUT1..OUT4 widths in us (more are ignored); 0 or implausible = no pulse: hold."""
        for i, width in enumerate(list(widths_us)[:4]):
            if not valid_width(width):
                continue
            if i == 2:
                self.surfaces[i] = throttle_norm(width)
            elif i == 1:
                self.surfaces[i] = -surface_norm(width)  # JSBSim's elevator: + is nose down
            else:
                self.surfaces[i] = surface_norm(width)
        aileron, elevator, throttle, rudder = self.surfaces
        self._set_controls(throttle, elevator, aileron, rudder)

    def step(self, dt_s):
        """Advance dt_s of simulated time (in steps of at most MAX_STEP_S)."""
        if self.crashed_at is not None:
            self.time_s += dt_s
            return
        if self.held():
            held = min(dt_s, self.hold_s - self.time_s)
            self.time_s += held
            dt_s -= held
            if dt_s <= 1e-12:
                return
        n = max(1, int(math.ceil(dt_s / MAX_STEP_S - 1e-9)))
        h = dt_s / n
        f = self.fdm
        if not self.wind_on:
            self.wind_on = True
            f["atmosphere/wind-north-fps"] = self.wind_ne_m_s[0] / FT
            f["atmosphere/wind-east-fps"] = self.wind_ne_m_s[1] / FT
        if abs(f.get_delta_t() - h) > 1e-15:
            f.set_dt(h)
        for i in range(n):
            t = self.time_s + i * h
            moment = sum(m for start, length, m in self.upsets if start - 1e-9 <= t < start + length - 1e-9)
            f["external_reactions/upset/magnitude-lbsft"] = moment / NM_PER_LBSFT
            if self.gust_level:
                self.gust_body = self.dryden.step(f["velocities/vt-fps"] * FT, h)
                rot = body_to_ned_matrix(f["attitude/phi-rad"], f["attitude/theta-rad"], f["attitude/psi-rad"])
                gust_ned = rot @ self.gust_body / FT
                f["atmosphere/gust-north-fps"] = gust_ned[0]
                f["atmosphere/gust-east-fps"] = gust_ned[1]
                f["atmosphere/gust-down-fps"] = gust_ned[2]
            f.run()
            self.prop_angle_rad = (self.prop_angle_rad +
                                   f["propulsion/engine/propeller-rpm"] * 2 * math.pi / 60 * h) % (2 * math.pi)
            if self._hit_ground():
                self.crashed_at = self.time_s + (i + 1) * h
                break
        self.time_s += dt_s

    def _hit_ground(self):
        """The C.G. within CRASH_HEIGHT_M of the ground (the gear crushed: not a landing this
        model's simple gear can take) or a state that is no longer finite: the aeroplane has
        crashed. It then lies still where it hit (the model's ground contact is not made for
        crashes: left to run, JSBSim's state grows without bound)."""
        f = self.fdm
        values = [f["position/h-agl-ft"], f["attitude/phi-rad"], f["attitude/theta-rad"], f["attitude/psi-rad"],
                  f["velocities/vt-fps"]]
        if all(math.isfinite(v) for v in values) and values[0] * FT > CRASH_HEIGHT_M:
            self.last_good = (values[1:4], self._position())
            return False
        euler, position = getattr(self, "last_good", ((0.0, 0.0, self.heading0), [0.0, 0.0, -self.altitude0]))
        self.crash_euler = tuple(euler)
        self.crash_position = [position[0], position[1], 0.0]
        return True

    def _position(self):
        f = self.fdm
        lat, lon = f["position/lat-geod-rad"], f["position/long-gc-rad"]
        return [(lat - self.lat0) * EARTH_RADIUS_M, (lon - self.lon0) * EARTH_RADIUS_M * math.cos(self.lat0),
                -f["position/h-agl-ft"] * FT]

    def held(self):
        """Still on the launch stand (hold_s)."""
        return self.time_s < self.hold_s - 1e-12

    def vibration(self):
        """The propeller's vibration at the IMU, m/s^2 body axes: a rotating imbalance at the
        shaft's frequency in y and z, and a blade-passing (twice the shaft) component a third
        as large in x, the amplitude growing with the square of the propeller's speed (a
        centrifugal force) from vibration_m_s2 at the trim's speed. A vibration of the board,
        not of the aeroplane: it is added to the specific force the IMU reads, not to the
        dynamics."""
        if not self.vibration_m_s2:
            return (0.0, 0.0, 0.0)
        rpm = self.fdm["propulsion/engine/propeller-rpm"]
        amplitude = self.vibration_m_s2 * (rpm / self.trim_rpm) ** 2
        a = self.prop_angle_rad
        return (amplitude / 3 * math.sin(2 * a), amplitude * math.sin(a), amplitude * math.cos(a))

    def state(self):
        """The true state and the ideal sensor values, SI, as a dict."""
        f = self.fdm
        crashed = self.crashed_at is not None
        if crashed:
            roll, pitch, yaw = self.crash_euler
        else:
            roll, pitch, yaw = f["attitude/phi-rad"], f["attitude/theta-rad"], f["attitude/psi-rad"]
        q = quat_from_euler(roll, pitch, yaw)
        mass_slug = f["inertia/mass-slugs"]
        # Specific force: every force but gravity (aerodynamics, thrust, ground) over the mass.
        accel = [f["forces/fb%s-total-lbs" % a] / mass_slug * FT + v for a, v in zip("xyz", self.vibration())]
        # Body rates relative to the earth: integrating them gives the NED attitude exactly.
        gyro = [f["velocities/%s-rad_sec" % a] for a in "pqr"]
        rot = body_to_ned_matrix(roll, pitch, yaw)
        held = self.held() or crashed
        if held:  # at rest on the stand: no rates, the stand's reaction against gravity
            gyro = [0.0, 0.0, 0.0]
            accel = [float(v) for v in rot.T @ np.array([0.0, 0.0, -G0])]
        mag = rot.T @ np.array(EARTH_FIELD_NED_UT)
        position = self.crash_position if crashed else self._position()
        return {
            "t": self.time_s,
            "gyro": gyro,
            "accel": accel,
            "mag": [float(m) for m in mag],
            "quat": q,
            "euler": (roll, pitch, yaw),
            "position": list(position),
            "velocity": [0.0, 0.0, 0.0] if held else [f["velocities/v-%s-fps" % a] * FT for a in ("north", "east", "down")],
            "airspeed": 0.0 if held else f["velocities/vt-fps"] * FT,
            "wind": [0.0, 0.0, 0.0] if crashed else
                    [f["atmosphere/total-wind-%s-fps" % a] * FT for a in ("north", "east", "down")],
            "alpha": 0.0 if crashed else f["aero/alpha-rad"],
            "beta": 0.0 if crashed else f["aero/beta-rad"],
            "surfaces": list(self.surfaces),
            "rpm": 0.0 if crashed else f["propulsion/engine/propeller-rpm"],
        }
