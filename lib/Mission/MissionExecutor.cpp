// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionExecutor.h"

#include "Constants.h"
#include "LinAlg.h"
#include "NeVector.h"

namespace mission {

namespace {

constexpr float kTwoPi = 2.0f * linalg::kPi;
constexpr float kGlideAboveM = 20.0f;  // AUTO spreads a climb only above this (ArduPlane's 20 m)

}  // namespace

int16_t* MissionExecutor::jump_runs(uint8_t index) {
    Jump* free_slot = nullptr;
    for (Jump& j : jumps_) {
        if (j.index == index) return &j.runs;
        if (j.index == kNone && free_slot == nullptr) free_slot = &j;
    }
    if (free_slot == nullptr) return nullptr;  // beyond kMaxJumps: counted as done
    free_slot->index = index;
    free_slot->runs = 0;
    return &free_slot->runs;
}

uint8_t MissionExecutor::walk(uint8_t from, Walk mode, Command& c) {
    uint8_t i = from;
    // Each command is passed at most twice without a navigation command between: a loop
    // of DO_JUMPs only is the end (AP_Mission's endless-loop check).
    for (uint16_t guard = 0; guard < 2u * kMaxCommands + 2u; ++guard) {
        if (!store_.read(i, c)) return kNone;
        if (is_nav(c.id)) return i;
        if (c.id == kDoJump) {
            const uint16_t target_seq = c.p1;
            const int32_t repeat = c.lat_e7;
            bool jump = false;
            if (target_seq == 0 || target_seq > store_.count()) {
                jump = false;  // nowhere to go: on to the next command
            } else if (repeat < 0) {
                jump = true;
            } else if (mode == kRun) {
                int16_t* runs = jump_runs(i);
                jump = runs != nullptr && *runs < repeat;
                if (jump) ++*runs;
            } else {
                int16_t runs = 0;
                for (const Jump& j : jumps_)
                    if (j.index == i) runs = j.runs;
                jump = runs < repeat;
            }
            i = jump ? (uint8_t)(target_seq - 1u) : (uint8_t)(i + 1u);
            continue;
        }
        if (mode == kRun) apply_do(c);
        ++i;
    }
    return kNone;
}

void MissionExecutor::start(const NavState& s, uint16_t seq) {
    for (Jump& j : jumps_) j.index = kNone;
    complete_ = false;
    target_.kind = TargetKind::kNone;
    index_ = kNone;
    advance(seq != 0 && seq <= store_.count() ? (uint8_t)(seq - 1u) : (uint8_t)0u, s);
}

bool MissionExecutor::set_current(uint16_t seq, const NavState& s) {
    if (seq == 0 || seq > store_.count()) return false;
    complete_ = false;
    index_ = kNone;  // the leg from here, not from the waypoint flown to
    advance((uint8_t)(seq - 1u), s);
    return true;
}

void MissionExecutor::advance(uint8_t from, const NavState& s) {
    Command nav;
    const uint8_t next = walk(from, kRun, nav);
    if (next == kNone) {
        complete_ = true;
        return_home(s);
        return;
    }
    const uint8_t after = start_nav(next, nav, s);
    // The DO_ commands after it act now (AP_Mission's do commands of this leg), up to the
    // next navigation command or DO_JUMP: none when the next command is the navigation
    // command start_nav found.
    if (after == (uint8_t)(next + 1u)) return;
    for (uint8_t i = (uint8_t)(next + 1u); i < store_.count(); ++i) {
        Command c;
        if (!store_.read(i, c) || is_nav(c.id) || c.id == kDoJump) break;
        apply_do(c);
    }
}

void MissionExecutor::apply_do(const Command& c) {
    if (c.id != kDoChangeSpeed) return;
    // ArduPlane's do_change_speed: type 0 sets the cruise airspeed, a throttle of 1..100 %
    // the cruise throttle (type 1, the least ground speed, is not flown here).
    if (c.p1 == 0 && c.lat_e7 > 0) airspeed_cm_s_ = (uint16_t)(c.lat_e7 > 65535 ? 65535 : c.lat_e7);
    if (c.lon_e7 > 0 && c.lon_e7 <= 100) throttle_pct_ = (int8_t)c.lon_e7;
}

nav::NorthEast MissionExecutor::place_m(const Command& c, const NavState& s) const {
    if (!c.has_place()) return s.pos_m;
    nav::Location l;
    l.lat_e7 = c.lat_e7;
    l.lon_e7 = c.lon_e7;
    return map_.offset_m(home_, l);
}

float MissionExecutor::height_of(const Command& c) const {
    const int32_t above_home_cm = c.relative_alt ? c.alt_cm : c.alt_cm - home_.alt_cm;
    return (float)above_home_cm * 0.01f;
}

float MissionExecutor::rtl_height_m(const NavState& s) const {
    return params_.rtl_alt_cm < 0 ? s.height_m : (float)params_.rtl_alt_cm * 0.01f;
}

void MissionExecutor::setup_slope(const NavState& s, bool auto_mode) {
    // ArduPlane's setup_glide_slope and set_offset_altitude_location.
    float offset = target_.height_m - s.height_m;
    const bool descending = offset < 0.0f;
    if (auto_mode ? !(s.height_m > kGlideAboveM || descending) : !descending) offset = 0.0f;
    const float size = offset < 0.0f ? -offset : offset;
    if (params_.glide_slope_min_m > 0.0f && size < params_.glide_slope_min_m) offset = 0.0f;
    target_.slope_m = offset;
}

void MissionExecutor::leg_started() {
    leg_m_ = target_.next_m - target_.prev_m;
    const float len2 = nav::length_squared(leg_m_);
    leg_over_1m_ = len2 > 1.0f;
    if (leg_over_1m_) leg_per_len2_ = leg_m_ * (1.0f / len2);
    leg_has_line_ = len2 > 1e-2f;
}

void MissionExecutor::loiter_at(const nav::NorthEast& centre, float height_m, float radius_m, int8_t direction,
                                const NavState& s) {
    target_.kind = TargetKind::kLoiter;
    target_.prev_m = s.pos_m;
    target_.next_m = centre;
    target_.radius_m = radius_m;
    target_.direction = direction;
    target_.height_m = height_m;
    loiter_captured_ = false;
    loiter_sum_rad_ = 0.0f;
}

void MissionExecutor::return_home(const NavState& s) { loiter_default(nav::ne(0.0f, 0.0f), rtl_height_m(s), s); }

void MissionExecutor::guide_to(const Command* to, const NavState& s) {
    if (to != nullptr && to->has_place())
        loiter_default(place_m(*to, s), height_of(*to), s);
    else
        loiter_default(s.pos_m, s.height_m, s);
}

void MissionExecutor::loiter_default(const nav::NorthEast& centre, float height_m, const NavState& s) {
    if (!complete_) index_ = kNone;
    const int16_t r = params_.loiter_radius_m;
    loiter_at(centre, height_m, (float)(r < 0 ? -r : r), r < 0 ? (int8_t)-1 : (int8_t)1, s);
    setup_slope(s, false);
    leg_started();
}

uint8_t MissionExecutor::start_nav(uint8_t index, const Command& c, const NavState& s) {
    uint8_t after = kNone;
    const bool after_waypoint = target_.kind == TargetKind::kWaypoint && index_ != kNone;
    const nav::NorthEast last_next = target_.next_m;
    index_ = index;
    command_ = c;
    const int16_t wp_loiter = params_.loiter_radius_m;
    const float default_radius = (float)(wp_loiter < 0 ? -wp_loiter : wp_loiter);
    const int8_t dir = c.loiter_ccw ? (int8_t)-1 : (int8_t)1;
    switch (c.id) {
    case kNavWaypoint: {
        target_.kind = TargetKind::kWaypoint;
        target_.prev_m = after_waypoint ? last_next : s.pos_m;
        target_.next_m = place_m(c, s);
        target_.height_m = height_of(c);
        // The turn at its end, for the turn distance: to the next navigation command's place.
        // Beyond 90 degrees it leaves the turn distance whole: no angle needed.
        turn_angle_deg_ = 90.0f;
        turn_pending_ = false;
        Command n;
        after = walk((uint8_t)(index + 1u), kPeek, n);
        if (after != kNone && n.has_place() && n.id != kNavTakeoff) {
            const nav::NorthEast leg = target_.next_m - target_.prev_m;
            nav::Location l;
            l.lat_e7 = n.lat_e7;
            l.lon_e7 = n.lon_e7;
            const nav::NorthEast next_leg = map_.offset_m(home_, l) - target_.next_m;
            turn_cross_ = nav::cross(leg, next_leg);
            turn_dot_ = nav::dot(leg, next_leg);
            turn_pending_ = turn_dot_ >= 0.0f;
        }
        break;
    }
    case kNavLoiterUnlim:
        loiter_at(place_m(c, s), c.has_place() ? height_of(c) : s.height_m, c.p1 != 0 ? (float)c.p1 : default_radius,
                  dir, s);
        break;
    case kNavLoiterTurns: {
        const uint8_t r = loiter_turns_radius_m(c);
        loiter_at(place_m(c, s), c.has_place() ? height_of(c) : s.height_m, r != 0 ? (float)r : default_radius, dir,
                  s);
        break;
    }
    case kNavLoiterTime:
        loiter_at(place_m(c, s), c.has_place() ? height_of(c) : s.height_m, default_radius, dir, s);
        break;
    case kNavReturnToLaunch:
        loiter_at(nav::ne(0.0f, 0.0f), rtl_height_m(s), default_radius, wp_loiter < 0 ? (int8_t)-1 : (int8_t)1, s);
        break;
    case kNavTakeoff:
        target_.kind = TargetKind::kTakeoff;
        target_.prev_m = s.pos_m;
        target_.next_m = s.pos_m;
        target_.height_m = height_of(c);
        target_.takeoff_pitch_cd = (int16_t)(c.p1 > 90u ? 9000 : c.p1 * 100u);
        break;
    default:
        break;
    }
    if (c.id == kNavTakeoff) {
        target_.slope_m = 0.0f;
    } else {
        setup_slope(s, true);
    }
    leg_started();
    return after;
}

float MissionExecutor::height_demand_m(const NavState& s) const {
    if (target_.slope_m == 0.0f) return target_.height_m;
    // ArduPlane's set_target_altitude_proportion: the slope's part still ahead.
    if (!leg_over_1m_) return target_.height_m;  // no length to spread it along
    const float along = nav::dot(s.pos_m - target_.prev_m, leg_per_len2_);
    return target_.height_m - target_.slope_m * (1.0f - linalg::constrain(along, 0.0f, 1.0f));
}

bool MissionExecutor::loiter_progress(const NavState& s, const nav::L1Control& l1) {
    // Turns are counted from the capture of the circle: the sum of the small angles between
    // successive radials (their cross product, the sine: 1e-4 short at 10 Hz on 60 m). The
    // radial is L1's loiter step's (its nav direction points at the centre).
    const nav::NorthEast r = l1.nav_direction() * -1.0f;
    if (!loiter_captured_) {
        if (!l1.loiter_captured()) return false;
        loiter_captured_ = true;
        loiter_start_ms_ = s.now_ms;
        loiter_sum_rad_ = 0.0f;
    } else {
        loiter_sum_rad_ += (float)target_.direction * nav::cross(radial_, r);
    }
    radial_ = r;
    return true;
}

bool MissionExecutor::verify(const NavState& s, const nav::L1Control& l1) {
    switch (command_.id) {
    case kNavWaypoint: {
        const nav::NorthEast to_wp = target_.next_m - s.pos_m;
        const float dist2 = nav::length_squared(to_wp);
        // The turn distance is at most the whole one (a turn of 90 degrees or more): the
        // turn's angle is needed only within it, and taken there once.
        const float whole = l1.turn_distance_m(params_.wp_radius_m);
        if (dist2 <= whole * whole) {
            if (turn_pending_) {
                const float cr = turn_cross_ < 0.0f ? -turn_cross_ : turn_cross_;
                turn_angle_deg_ = linalg::fast_atan2(cr, turn_dot_) * linalg::kDegPerRad;
                turn_pending_ = false;
            }
            const float accept = l1.turn_distance_m(params_.wp_radius_m, turn_angle_deg_);
            if (dist2 <= accept * accept) return true;
        }
        return leg_has_line_ && nav::dot(to_wp, leg_m_) <= 0.0f;  // past the line across next
    }
    case kNavLoiterTurns:
        return loiter_progress(s, l1) && loiter_sum_rad_ >= (float)loiter_turns(command_) * kTwoPi;
    case kNavLoiterTime:
        return loiter_progress(s, l1) && s.now_ms - loiter_start_ms_ >= (uint32_t)command_.p1 * 1000u;
    case kNavReturnToLaunch: {
        const float r = params_.wp_radius_m;
        return nav::length_squared(s.pos_m) <= r * r || l1.loiter_captured();
    }
    case kNavTakeoff:
        return s.height_m >= target_.height_m;
    default:  // LOITER_UNLIM
        loiter_progress(s, l1);
        return false;
    }
}

void MissionExecutor::update(const NavState& s, const nav::L1Control& l1) {
    if (complete_ || index_ == kNone) return;
    if (!verify(s, l1)) return;
    reached_seq_ = current_seq();
    ++reached_count_;
    advance((uint8_t)(index_ + 1u), s);
}

}  // namespace mission
