// SPDX-License-Identifier: GPL-3.0-or-later
#include "L1Control.h"

#include <string.h>

#include "Constants.h"
#include "LinAlg.h"
#include "NeVector.h"

namespace nav {

namespace {

constexpr float kInvPi = (float)(1.0 / linalg::dbl::kPi);
constexpr float kSin45 = 0.70710678f;          // eta1's capture limit
constexpr float kCos162 = -0.95105652f;        // cos(0.9 pi): _prevent_indecision's threshold
constexpr float kCos120 = -0.5f;               // the target more than 120 deg off the course
constexpr float kMinGroundSpeed_m_s = 0.1f;    // update_waypoint's floor
constexpr float kMinLoiterSpeed_m_s = 1.0f;    // update_loiter's floor for the gains
constexpr float kPassedB_s = 3.0f;             // past next by this long: back to next

// The same bits: a float's == is a call, and would take a NaN for a change every step.
bool same_bits(float a, float b) {
    uint32_t x, y;
    memcpy(&x, &a, sizeof x);
    memcpy(&y, &b, sizeof y);
    return x == y;
}
bool same_point(const NorthEast& a, const NorthEast& b) {
    return same_bits(a.north_m, b.north_m) && same_bits(a.east_m, b.east_m);
}

}  // namespace

void L1Control::refresh_coefficients() {
    if (!same_bits(k_.period_s, params_.period_s) || !same_bits(k_.damping, params_.damping)) set_coefficients();
}

void L1Control::set_coefficients() {
    k_.period_s = params_.period_s;
    k_.damping = params_.damping;
    k_.l1_per_vg = kInvPi * k_.damping * k_.period_s;
    k_.vg_per_l1 = 1.0f / k_.l1_per_vg;
    // K_L1 Vg^2 / L1 with K_L1 = 4 damping^2 (AP_L1_Control's): 4 damping^2 / l1_per_vg.
    k_.acc_per_vg = 4.0f * k_.damping * k_.damping * k_.vg_per_l1;
    const float omega = 2.0f * linalg::kPi / k_.period_s;
    k_.loiter_kx = omega * omega;
    k_.loiter_kv = 2.0f * k_.damping * omega;
}

void L1Control::refresh_leg(const NorthEast& prev_m, const NorthEast& next_m) {
    if (same_point(leg_prev_m_, prev_m) && same_point(leg_next_m_, next_m)) return;
    leg_prev_m_ = prev_m;
    leg_next_m_ = next_m;
    const NorthEast ab = next_m - prev_m;
    leg_len_m_ = length(ab);
    if (leg_len_m_ > 1e-3f) leg_unit_ = ab * (1.0f / leg_len_m_);
}

float L1Control::limited_sin_eta(float sin_eta, float cos_eta, bool eta_positive, const NorthEast& vel, float speed) {
    const int8_t side = eta_positive ? 1 : -1;
    // Beyond 162 deg on the other side than last step, the target behind (more than 120 deg
    // off the course: v.t < -|v||t|/2, squared): keep turning the way it was (ArduPilot's
    // _prevent_indecision).
    int8_t used = side;
    if (cos_eta < kCos162) {
        const float d = dot(vel, to_target_m_);
        const bool behind = d < 0.0f && d * d > kCos120 * kCos120 * speed * speed * length_squared(to_target_m_);
        if (behind_side_ != 0 && behind_side_ != side && behind) used = behind_side_;
        behind_side_ = used;
    } else {
        behind_side_ = 0;
    }
    if (cos_eta >= 0.0f && used == side) return sin_eta;  // within +-90 deg: as it is
    return (float)used;  // limited to +-90 deg: sin = +-1
}

void L1Control::update_waypoint(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& prev_m,
                                const NorthEast& next_m) {
    refresh_coefficients();
    refresh_leg(prev_m, next_m);
    circling_ = false;
    to_target_m_ = next_m - pos_m;

    // The track's direction: prev to next, else here to next, else the way it flies.
    float vg = length(vel_m_s);
    const float ab_len = leg_len_m_;
    NorthEast ab_unit;
    if (ab_len > 1e-3f) {
        ab_unit = leg_unit_;
    } else {
        const float to_next_len = length(to_target_m_);
        if (to_next_len > 1e-3f) {
            ab_unit = to_target_m_ * (1.0f / to_next_len);
        } else {
            ab_unit = vg > kMinGroundSpeed_m_s ? vel_m_s * (1.0f / vg) : nav_direction();
        }
    }
    nav_turned_ = false;
    // Below 0.1 m/s the velocity's direction means nothing: the track's at 0.1 m/s
    // (ArduPilot takes the compass heading there).
    NorthEast vel = vel_m_s;
    if (vg < kMinGroundSpeed_m_s) {
        vg = kMinGroundSpeed_m_s;
        vel = ab_unit * vg;
    }
    const float inv_vg = 1.0f / vg;
    l1_m_ = k_.l1_per_vg * vg;
    const float inv_l1 = k_.vg_per_l1 * inv_vg;

    const NorthEast a_air = pos_m - prev_m;
    crosstrack_m_ = cross(a_air, ab_unit);
    const float along_m = dot(a_air, ab_unit);
    // Behind prev by more than L1, beyond +-135 deg of the track: along < -0.7071 max(|a|, 1),
    // squared to spare a square root.
    bool behind_prev = false;
    if (along_m < 0.0f) {
        const float a_dist2 = length_squared(a_air);
        behind_prev = a_dist2 > l1_m_ * l1_m_ &&
                      (a_dist2 >= 1.0f ? along_m * along_m > 0.5f * a_dist2 : along_m < -kSin45);
    }

    float sin_eta, cos_eta, xvel;
    if (behind_prev || along_m > ab_len + vg * kPassedB_s) {
        // Fly to prev; or, 3 s past next, back to next.
        const NorthEast to = behind_prev ? a_air * -1.0f : to_target_m_;
        const float len = length(to);
        nav_dir_ = len > 1e-3f ? to * (1.0f / len) : ab_unit;
        if (behind_prev) to_target_m_ = to;
        xvel = cross(vel, nav_dir_);
        sin_eta = xvel * inv_vg;
        cos_eta = dot(vel, nav_dir_) * inv_vg;
    } else {
        // eta2: the velocity's angle to the track; eta1: the angle to the L1 point.
        xvel = cross(vel, ab_unit);
        const float sin2 = xvel * inv_vg;
        const float cos2 = dot(vel, ab_unit) * inv_vg;
        const float sin1 = linalg::constrain(crosstrack_m_ * inv_l1, -kSin45, kSin45);
        const float cos1 = linalg::safe_sqrt(1.0f - sin1 * sin1);
        sin_eta = sin1 * cos2 + cos1 * sin2;
        cos_eta = cos1 * cos2 - sin1 * sin2;
        // Towards the L1 point: the track turned by eta1 (for telemetry: when asked for).
        nav_dir_ = ab_unit;
        nav_cos1_ = cos1;
        nav_sin1_ = sin1;
        nav_turned_ = true;
    }
    // Beyond 90 deg eta has eta2's sign (|eta1| <= 45 deg), the sign of the cross product.
    const float s = limited_sin_eta(sin_eta, cos_eta, xvel >= 0.0f, vel, vg);
    lat_acc_m_s2_ = k_.acc_per_vg * vg * s;  // K_L1 Vg^2 / L1 sin eta
}

void L1Control::update_loiter(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& centre_m,
                              float radius_m, int8_t direction) {
    refresh_coefficients();
    nav_turned_ = false;
    const float dir = direction < 0 ? -1.0f : 1.0f;

    const float speed = length(vel_m_s);
    const float inv_speed = speed > 1e-3f ? 1.0f / speed : 0.0f;
    const float vg = speed > kMinLoiterSpeed_m_s ? speed : kMinLoiterSpeed_m_s;
    l1_m_ = k_.l1_per_vg * vg;

    // From the centre to the plane; on the centre itself, along the velocity (or north).
    const NorthEast a_air = pos_m - centre_m;
    const float dist_m = length(a_air);
    NorthEast out_unit;
    if (dist_m > 0.1f) {
        out_unit = a_air * (1.0f / dist_m);
    } else {
        out_unit = speed > 0.1f ? vel_m_s * inv_speed : ne(1.0f, 0.0f);
    }
    to_target_m_ = a_air * -1.0f;

    // Capture: the L1 law steering at the centre.
    const float xvel_cap = cross(out_unit, vel_m_s);  // across the radial
    const float lvel_cap = -dot(vel_m_s, out_unit);   // inbound along the radial
    nav_dir_ = out_unit * -1.0f;
    const float s = limited_sin_eta(xvel_cap * inv_speed, speed > 1e-3f ? lvel_cap * inv_speed : 1.0f,
                                    xvel_cap >= 0.0f, vel_m_s, speed);
    const float acc_capture = k_.acc_per_vg * vg * s;

    // On the circle: PD on the radius error plus the centripetal acceleration.
    const float radial_vel = -lvel_cap;
    const float radius_err_m = dist_m - radius_m;
    crosstrack_m_ = radius_err_m;
    float acc_pd = radius_err_m * k_.loiter_kx + radial_vel * k_.loiter_kv;
    const float vel_tangent = xvel_cap * dir;
    // Flying the wrong way round: the PD term must not turn it further the wrong way.
    if (lvel_cap < 0.0f && vel_tangent < 0.0f && acc_pd < 0.0f) acc_pd = 0.0f;
    const float half_r = 0.5f * radius_m;
    const float centripetal = vel_tangent * vel_tangent / (half_r > dist_m ? half_r : dist_m);
    const float acc_circle = dir * (acc_pd + centripetal);

    // Capture outside the circle until the circle's law asks for more turn.
    if (radius_err_m > 0.0f && dir * acc_capture < dir * acc_circle) {
        lat_acc_m_s2_ = acc_capture;
        circling_ = false;
    } else {
        lat_acc_m_s2_ = acc_circle;
        circling_ = true;
    }
}

int16_t L1Control::nav_roll_cd(int16_t lim_roll_cd, float cos_pitch) const {
    constexpr float kInvG = 1.0f / linalg::kGravity_m_s2;
    const float bank_cd = cos_pitch * linalg::fast_atan(lat_acc_m_s2_ * kInvG) * (linalg::kDegPerRad * 100.0f);
    const float lim = (float)lim_roll_cd;
    return (int16_t)linalg::constrain(bank_cd, -lim, lim);
}

NorthEast L1Control::nav_direction() const {
    return nav_turned_ ? rotated(nav_dir_, nav_cos1_, nav_sin1_) : nav_dir_;
}

float L1Control::nav_bearing_rad() const { return bearing_rad(nav_direction()); }
float L1Control::target_bearing_rad() const { return bearing_rad(to_target_m_); }

float L1Control::turn_distance_m(float wp_radius_m) const { return wp_radius_m < l1_m_ ? wp_radius_m : l1_m_; }

float L1Control::turn_distance_m(float wp_radius_m, float turn_angle_deg) const {
    const float d90 = turn_distance_m(wp_radius_m);
    const float a = turn_angle_deg < 0.0f ? -turn_angle_deg : turn_angle_deg;
    return a >= 90.0f ? d90 : d90 * a * (1.0f / 90.0f);
}

}  // namespace nav
