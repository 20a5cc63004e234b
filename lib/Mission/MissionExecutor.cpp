// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionExecutor.h"

#include <stddef.h>
#include <string.h>

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

bool MissionExecutor::read(uint8_t index, Command& c) {
    if (store_.sequence() != cache_sequence_ || store_.current_area() != cache_area_) {
        cache_[0].index = cache_[1].index = kNone;  // another mission: nothing kept holds
        cache_sequence_ = store_.sequence();
        cache_area_ = store_.current_area();
    }
    for (const Cached& e : cache_) {
        if (e.index == index) {
            c = e.command;
            return true;
        }
    }
    if (!store_.read(index, c)) return false;
    Cached& e = cache_[cache_next_];
    e.index = index;
    e.command = c;
    cache_next_ ^= 1u;
    return true;
}

uint8_t MissionExecutor::walk(uint8_t from, Walk mode, Command& c) {
    uint8_t i = from;
    // Each command is passed at most twice without a navigation command between: a loop
    // of DO_JUMPs only is the end (AP_Mission's endless-loop check).
    for (uint16_t guard = 0; guard < 2u * kMaxCommands + 2u; ++guard) {
        if (!read(i, c)) return kNone;
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
    start_nav(next, nav, s);
    // The DO_ commands after it act now (AP_Mission's do commands of this leg), up to the
    // next navigation command or DO_JUMP (the first read the last look-ahead's, cached).
    for (uint8_t i = (uint8_t)(next + 1u); i < store_.count(); ++i) {
        Command c;
        if (!read(i, c) || is_nav(c.id) || c.id == kDoJump) break;
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

nav::NorthEast MissionExecutor::place_m(const Command& c, const NavState& s) {
    if (!c.has_place()) return s.pos_m;
    const float north = map_.north_m_per_e7();
    const float east = map_.east_m_per_e7();
    Placed key;
    key.lat_e7 = c.lat_e7;
    key.lon_e7 = c.lon_e7;
    key.home_lat_e7 = home_.lat_e7;
    key.home_lon_e7 = home_.lon_e7;
    memcpy(&key.north_bits, &north, sizeof north);
    memcpy(&key.east_bits, &east, sizeof east);
    if (memcmp(&key, &placed_, offsetof(Placed, m)) == 0) return placed_.m;
    nav::Location l;
    l.lat_e7 = c.lat_e7;
    l.lon_e7 = c.lon_e7;
    key.m = map_.offset_m(home_, l);
    placed_ = key;
    return key.m;
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
    ahead_ = kAheadDone;
    ahead_index_ = kNone;
    const int16_t r = params_.loiter_radius_m;
    loiter_at(centre, height_m, (float)(r < 0 ? -r : r), r < 0 ? (int8_t)-1 : (int8_t)1, s);
    setup_slope(s, false);
    leg_started();
}

void MissionExecutor::start_nav(uint8_t index, const Command& c, const NavState& s) {
    const bool after_waypoint = target_.kind == TargetKind::kWaypoint && index_ != kNone;
    const nav::NorthEast last_next = target_.next_m;
    index_ = index;
    command_ = c;
    // The turn at a waypoint, for the turn distance, is the look-ahead's (to the next
    // navigation command's place; beyond 90 degrees the turn distance is whole: 90 until
    // then).
    turn_angle_deg_ = 90.0f;
    turn_pending_ = false;
    ahead_ = kAheadTurn;
    ahead_index_ = kNone;
    const int16_t wp_loiter = params_.loiter_radius_m;
    const float default_radius = (float)(wp_loiter < 0 ? -wp_loiter : wp_loiter);
    const int8_t dir = c.loiter_ccw ? (int8_t)-1 : (int8_t)1;
    switch (c.id) {
    case kNavWaypoint: {
        target_.kind = TargetKind::kWaypoint;
        target_.prev_m = after_waypoint ? last_next : s.pos_m;
        target_.next_m = place_m(c, s);
        target_.height_m = height_of(c);
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
}

void MissionExecutor::look_at_turn() {
    Command n;
    ahead_index_ = walk((uint8_t)(index_ + 1u), kPeek, n);
    ahead_ = kAheadFollower;
    if (command_.id != kNavWaypoint || ahead_index_ == kNone || !n.has_place() || n.id == kNavTakeoff) return;
    // The turn's sine and cosine times the two legs' lengths; its angle once within the
    // whole turn distance (verify), and only for a turn under 90 degrees.
    const nav::NorthEast next_leg = place_m(n, NavState()) - target_.next_m;
    turn_cross_ = nav::cross(leg_m_, next_leg);
    turn_dot_ = nav::dot(leg_m_, next_leg);
    turn_pending_ = turn_dot_ >= 0.0f;
}

void MissionExecutor::look_ahead() {
    switch (ahead_) {
    case kAheadTurn:
        look_at_turn();
        break;
    case kAheadFollower: {
        // The command after the next navigation command: the first the DO_ loop reads when
        // that one starts (advance), and the next look-ahead's.
        Command c;
        if (ahead_index_ != kNone) read((uint8_t)(ahead_index_ + 1u), c);
        ahead_ = kAheadDone;
        break;
    }
    default:
        break;
    }
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
            if (ahead_ < kAheadFollower) look_at_turn();  // a leg too short for the look-ahead
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
    const uint8_t ahead = ahead_;
    if (!verify(s, l1)) {
        if (ahead_ == ahead) look_ahead();  // one piece a step: none when verify looked
        return;
    }
    reached_seq_ = current_seq();
    ++reached_count_;
    advance((uint8_t)(index_ + 1u), s);
}

}  // namespace mission
