// SPDX-License-Identifier: GPL-3.0-or-later
// Lateral guidance: the L1 law of Park, Deyst & How ("A New Nonlinear Guidance Logic for
// Trajectory Tracking", AIAA 2004-4900) as ArduPilot's AP_L1_Control flies it, on the
// local map's north-east metres (NorthEast, from home) and the GPS ground velocity: flying
// the ground track, the wind is handled by the law itself (a crab angle is just the
// velocity's angle to the heading).
//
//   L1 = damping x period x Vg / pi                    (the look-ahead, NAVL1_PERIOD, _DAMPING)
//   eta = eta1 + eta2;  sin eta1 = xtrack / L1 clamped to +-0.7071 (45 deg capture),
//                       eta2 = the ground velocity's angle to the track
//   a_lat = 4 damping^2 x Vg^2 / L1 x sin eta          (paper eq. 1 with K = 4 zeta^2),
//                       eta limited to +-90 deg
//   bank = atan(a_lat / g) x cos pitch, within LIM_ROLL_CD
//
// Loiter (update_loiter): outside the circle the L1 law steers at the centre; on it, a PD on
// the radius error (natural frequency 2 pi / NAVL1_PERIOD, damping NAVL1_DAMPING) plus the
// centripetal Vt^2 / R; the switch from one to the other where their demands cross
// (AP_L1_Control's seamless capture), and the circle is then "captured".
//
// Angles as sines and cosines: sin(eta1 + eta2) by the sum formula, eta2's sine and cosine
// from the cross and dot products of the velocity and the track, the bearings kept as unit
// vectors (bearing_rad() turns one into an angle for telemetry). The leg's length and unit
// vector are worked out when the leg changes, the gains when the parameters do
// (L1Coefficients); per step one atan (the bank: fast_atan, no divide within 45 degrees),
// two square roots (|v|, cos eta1) and one divide (1 / |v|); no sin, cos or asin.
// Signs: cross-track error positive left of the track (ArduPilot's A_air % AB), lateral
// acceleration and bank positive to the right.
#pragma once

#include <stdint.h>

#include "Location.h"

namespace nav {

struct L1Params {
    float period_s;  // NAVL1_PERIOD: s, 1..60; the period of the track's oscillation after a step
    float damping;   // NAVL1_DAMPING: 0.6..1.0; its damping ratio
};
// ArduPlane 3.x's defaults (APM25.md records 25 s for 2.7x, 17 s later).
constexpr L1Params kL1Defaults = {20.0f, 0.75f};

// Worked out from L1Params (L1Control refreshes them when a parameter's bits change).
struct L1Coefficients {
    float period_s, damping;  // the parameters they come from
    float l1_per_vg;          // damping period / pi: L1 = this x Vg, s
    float vg_per_l1;          // its inverse, 1/s
    float acc_per_vg;         // K_L1 Vg^2 / L1 / Vg = 4 pi damping / period, 1/s
    float loiter_kx;          // omega^2 (omega = 2 pi / period), the loiter PD's, 1/s^2
    float loiter_kv;          // 2 damping omega, 1/s
};

class L1Control {
public:
    explicit L1Control(const L1Params& params) : params_(params) { set_coefficients(); }
    // A static object's (constexpr: no start-up code): set_coefficients() before the first
    // update (the firmware's configure(), once the settings are loaded; not in a step).
    struct CoefficientsSetLater {};
    constexpr L1Control(const L1Params& params, CoefficientsSetLater) : params_(params) {}
    // The coefficients from the parameters (the updates do it again when a parameter's
    // bits changed).
    void set_coefficients();

    // Track the line from prev to next (metres from home), at position pos_m with the GPS
    // ground velocity vel_m_s. Behind prev by more than L1 (beyond +-135 deg of the
    // track), it flies to prev first; more than 3 s past next, back to next.
    void update_waypoint(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& prev_m,
                         const NorthEast& next_m);
    // Circle about centre_m at radius_m; direction 1 clockwise, -1 counter-clockwise
    // (WP_LOITER_RAD's sign).
    void update_loiter(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& centre_m, float radius_m,
                       int8_t direction);

    // The lateral acceleration demand, m/s^2, positive to the right.
    float lateral_accel_m_s2() const { return lat_acc_m_s2_; }
    // The bank it needs, centi-degrees within +-lim_roll_cd (LIM_ROLL_CD); cos_pitch: the
    // attitude's (ArduPilot scales by it; 1 when not known).
    int16_t nav_roll_cd(int16_t lim_roll_cd, float cos_pitch = 1.0f) const;
    // Metres off the track (positive left of it); on a loiter, the distance outside the circle.
    float crosstrack_error_m() const { return crosstrack_m_; }
    // Towards the L1 point (nav_bearing; a unit vector: on a leg the track's turned by
    // eta1, worked out when asked for), and the metres to the waypoint or the loiter's
    // centre (target_bearing).
    NorthEast nav_direction() const;
    const NorthEast& to_target_m() const { return to_target_m_; }
    float nav_bearing_rad() const;
    float target_bearing_rad() const;
    float l1_distance_m() const { return l1_m_; }
    // Where to switch to the next waypoint: within WP_RADIUS but no further than L1
    // (AP_L1_Control::turn_distance); for a turn of less than 90 deg, that times turn/90.
    float turn_distance_m(float wp_radius_m) const;
    float turn_distance_m(float wp_radius_m, float turn_angle_deg) const;
    // On the loiter circle (AP_L1_Control::reached_loiter_target): the circle's law flies.
    bool loiter_captured() const { return circling_; }

private:
    // sin(eta) limited to +-90 deg, from eta's sine and cosine and the sign of eta when
    // beyond 90 deg; holds the last side when the target is behind (ArduPilot's
    // _prevent_indecision).
    float limited_sin_eta(float sin_eta, float cos_eta, bool eta_positive, const NorthEast& vel, float speed);
    // set_coefficients() again when a parameter's bits changed.
    void refresh_coefficients();
    // The leg's length and unit vector again when prev or next moved (a new leg).
    void refresh_leg(const NorthEast& prev_m, const NorthEast& next_m);

    const L1Params& params_;
    L1Coefficients k_ = {};
    // The leg of the last update_waypoint, its length and unit vector (prev to next).
    NorthEast leg_prev_m_ = {0.0f, 0.0f};
    NorthEast leg_next_m_ = {0.0f, 0.0f};
    NorthEast leg_unit_ = {1.0f, 0.0f};
    float leg_len_m_ = 0.0f;
    float lat_acc_m_s2_ = 0.0f;
    float crosstrack_m_ = 0.0f;
    float l1_m_ = 0.0f;
    // nav_direction(): nav_dir_, turned by the angle of cosine nav_cos1_ and sine nav_sin1_
    // when nav_turned_ (on a leg: the track's direction and eta1).
    NorthEast nav_dir_ = {1.0f, 0.0f};
    float nav_cos1_ = 1.0f;
    float nav_sin1_ = 0.0f;
    bool nav_turned_ = false;
    NorthEast to_target_m_ = {1.0f, 0.0f};
    int8_t behind_side_ = 0;  // the sign of eta when it was beyond 162 deg last step, else 0
    bool circling_ = false;
};

}  // namespace nav
