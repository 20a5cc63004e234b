// SPDX-License-Identifier: GPL-3.0-or-later
#include "L1Control.h"

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

// v / |v|, or `fallback` when |v| is below min_len.
NorthEast unit_or(const NorthEast& v, float min_len, const NorthEast& fallback, float& len) {
    len = length(v);
    if (len < min_len) return fallback;
    return v * (1.0f / len);
}

}  // namespace

float L1Control::limited_sin_eta(float sin_eta, float cos_eta, bool eta_positive, const NorthEast& vel_unit) {
    const int8_t side = eta_positive ? 1 : -1;
    // Beyond 162 deg on the other side than last step, the target behind (more than 120 deg
    // off the course): keep turning the way it was (ArduPilot's _prevent_indecision).
    int8_t used = side;
    if (cos_eta < kCos162) {
        if (behind_side_ != 0 && behind_side_ != side && dot(vel_unit, target_dir_) < kCos120) used = behind_side_;
        behind_side_ = used;
    } else {
        behind_side_ = 0;
    }
    if (cos_eta >= 0.0f && used == side) return sin_eta;  // within +-90 deg: as it is
    return (float)used;  // limited to +-90 deg: sin = +-1
}

void L1Control::update_waypoint(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& prev_m,
                                const NorthEast& next_m) {
    const float k_l1 = 4.0f * params_.damping * params_.damping;
    circling_ = false;

    // The track's direction: prev to next, else here to next, else the way it flies.
    NorthEast ab = next_m - prev_m;
    float ab_len = length(ab);
    float vg;
    NorthEast vel_unit = unit_or(vel_m_s, kMinGroundSpeed_m_s, nav_dir_, vg);
    NorthEast ab_unit;
    if (ab_len > 1e-3f) {
        ab_unit = ab * (1.0f / ab_len);
    } else {
        float to_next_len;
        ab_unit = unit_or(next_m - pos_m, 1e-3f, vel_unit, to_next_len);
    }
    // Below 0.1 m/s the velocity's direction means nothing: the track's at 0.1 m/s
    // (ArduPilot takes the compass heading there).
    NorthEast vel = vel_m_s;
    if (vg < kMinGroundSpeed_m_s) {
        vg = kMinGroundSpeed_m_s;
        vel_unit = ab_unit;
        vel = ab_unit * vg;
    }
    l1_m_ = kInvPi * params_.damping * params_.period_s * vg;
    const float inv_l1 = 1.0f / l1_m_;
    const float inv_vg = 1.0f / vg;

    const NorthEast a_air = pos_m - prev_m;
    crosstrack_m_ = cross(a_air, ab_unit);
    const float along_m = dot(a_air, ab_unit);
    const float a_dist_m = length(a_air);

    float sin_eta, cos_eta;
    bool eta_positive;
    if (a_dist_m > l1_m_ && along_m < -kSin45 * (a_dist_m > 1.0f ? a_dist_m : 1.0f)) {
        // Behind prev, beyond +-135 deg of the track: fly to prev.
        nav_dir_ = a_air * (-1.0f / a_dist_m);
        target_dir_ = nav_dir_;
        const float xvel = cross(vel, nav_dir_);
        sin_eta = xvel * inv_vg;
        cos_eta = dot(vel, nav_dir_) * inv_vg;
        eta_positive = xvel >= 0.0f;
    } else if (along_m > ab_len + vg * kPassedB_s) {
        // 3 s past next: back to next.
        float len;
        nav_dir_ = unit_or(next_m - pos_m, 1e-3f, ab_unit, len);
        target_dir_ = nav_dir_;
        const float xvel = cross(vel, nav_dir_);
        sin_eta = xvel * inv_vg;
        cos_eta = dot(vel, nav_dir_) * inv_vg;
        eta_positive = xvel >= 0.0f;
    } else {
        // eta2: the velocity's angle to the track; eta1: the angle to the L1 point.
        const float xvel = cross(vel, ab_unit);
        const float sin2 = xvel * inv_vg;
        const float cos2 = dot(vel, ab_unit) * inv_vg;
        const float sin1 = linalg::constrain(crosstrack_m_ * inv_l1, -kSin45, kSin45);
        const float cos1 = linalg::safe_sqrt(1.0f - sin1 * sin1);
        sin_eta = sin1 * cos2 + cos1 * sin2;
        cos_eta = cos1 * cos2 - sin1 * sin2;
        // |eta1| <= 45 deg, so beyond 90 deg eta has eta2's sign.
        eta_positive = xvel >= 0.0f;
        nav_dir_ = rotated(ab_unit, cos1, sin1);
        float len;
        target_dir_ = unit_or(next_m - pos_m, 1e-3f, ab_unit, len);
    }
    const float s = limited_sin_eta(sin_eta, cos_eta, eta_positive, vel_unit);
    lat_acc_m_s2_ = k_l1 * vg * vg * inv_l1 * s;
}

void L1Control::update_loiter(const NorthEast& pos_m, const NorthEast& vel_m_s, const NorthEast& centre_m,
                              float radius_m, int8_t direction) {
    const float omega = 2.0f * linalg::kPi / params_.period_s;
    const float kx = omega * omega;
    const float kv = 2.0f * params_.damping * omega;
    const float k_l1 = 4.0f * params_.damping * params_.damping;
    const float dir = direction < 0 ? -1.0f : 1.0f;

    float speed;
    const NorthEast vel_unit = unit_or(vel_m_s, 0.1f, nav_dir_ * -1.0f, speed);
    const float vg = speed > kMinLoiterSpeed_m_s ? speed : kMinLoiterSpeed_m_s;
    l1_m_ = kInvPi * params_.damping * params_.period_s * vg;

    // From the centre to the plane; on the centre itself, along the velocity.
    const NorthEast a_air = pos_m - centre_m;
    float dist_m;
    const NorthEast out_unit = unit_or(a_air, 0.1f, vel_unit, dist_m);

    // Capture: the L1 law steering at the centre.
    const float xvel_cap = cross(out_unit, vel_m_s);  // across the radial
    const float lvel_cap = -dot(vel_m_s, out_unit);   // inbound along the radial
    const float inv_speed = speed > 1e-3f ? 1.0f / speed : 0.0f;
    target_dir_ = out_unit * -1.0f;
    nav_dir_ = target_dir_;
    const float s = limited_sin_eta(xvel_cap * inv_speed, speed > 1e-3f ? lvel_cap * inv_speed : 1.0f,
                                    xvel_cap >= 0.0f, vel_unit);
    const float acc_capture = k_l1 * vg * vg / l1_m_ * s;

    // On the circle: PD on the radius error plus the centripetal acceleration.
    const float radial_vel = -lvel_cap;
    const float radius_err_m = dist_m - radius_m;
    crosstrack_m_ = radius_err_m;
    float acc_pd = radius_err_m * kx + radial_vel * kv;
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
    const float bank_cd = cos_pitch * linalg::fast_atan2(lat_acc_m_s2_, linalg::kGravity_m_s2) * linalg::kDegPerRad * 100.0f;
    const float lim = (float)lim_roll_cd;
    return (int16_t)linalg::constrain(bank_cd, -lim, lim);
}

float L1Control::nav_bearing_rad() const { return bearing_rad(nav_dir_); }
float L1Control::target_bearing_rad() const { return bearing_rad(target_dir_); }

float L1Control::turn_distance_m(float wp_radius_m) const { return wp_radius_m < l1_m_ ? wp_radius_m : l1_m_; }

float L1Control::turn_distance_m(float wp_radius_m, float turn_angle_deg) const {
    const float d90 = turn_distance_m(wp_radius_m);
    const float a = turn_angle_deg < 0.0f ? -turn_angle_deg : turn_angle_deg;
    return a >= 90.0f ? d90 : d90 * a * (1.0f / 90.0f);
}

}  // namespace nav
