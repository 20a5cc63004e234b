// SPDX-License-Identifier: GPL-3.0-or-later
// The mission's pure logic, as AP_Mission and ArduPlane's commands_logic run it: which
// navigation command flies now, what it asks of the guidance (a leg, a loiter, a climb)
// and when it is done; DO_JUMP's counts; DO_CHANGE_SPEED; the end of the mission.
//
// - Commands come from the MissionStore by index (index i = MAVLink's seq i + 1; seq 0 is
//   home). Places become metres north and east of home on the navigator's local map.
// - Advancing from a command walks on: DO_JUMP jumps to its target while its repeat count
//   lasts (-1: for ever; counts reset by start(); kMaxJumps tracked, a DO_JUMP beyond them
//   is done, as AP_Mission's AP_MISSION_JUMP_TIMES_MAX), DO_CHANGE_SPEED acts at once, and
//   the first navigation command found starts. As AP_Mission, the DO_ commands that follow
//   a navigation command act when it starts (on the way to it).
// - NAV_WAYPOINT: the leg from the last waypoint (from here after a takeoff, a loiter or at
//   the start); reached within the L1 turn distance (WP_RADIUS, no further than L1, less
//   for a gentle turn to the next leg) or once past the line through it perpendicular to
//   the leg (ArduPlane's verify_nav_wp and location_passed_point).
// - LOITER_UNLIM never ends; LOITER_TURNS counts the turns flown about the centre from the
//   capture of the circle; LOITER_TIME its seconds from the capture (verify_loiter_*).
// - RETURN_TO_LAUNCH: a loiter at home at ALT_HOLD_RTL, done within WP_RADIUS of home or
//   on its circle (verify_RTL); NAV_TAKEOFF: full throttle at its pitch, done at its height.
// - The end of the mission (no navigation command left): loiter at home at ALT_HOLD_RTL,
//   as ArduPlane 3.x's exit_mission_callback (a LOITER_UNLIM at home; later ArduPlanes
//   switch to RTL, which flies the same); complete() says so. return_home() is RTL mode's.
// - The look-ahead: what the step that reaches a waypoint needs (the next navigation
//   command, its place, the turn to it, the command after it) is found a piece a step
//   before (look_ahead()) and kept (the last two commands read, the last place worked
//   out), so that step reads no EEPROM and maps no place.
// - The height: ArduPlane's glide slope. When a command starts, a change of height of
//   GLIDE_SLOPE_MIN or more is spread along the leg (in AUTO above 20 m or descending; in
//   RTL descending only); a smaller one is asked for at once (TECS limits its rate).
#pragma once

#include <stdint.h>

#include "L1Control.h"
#include "Location.h"
#include "MissionStore.h"

namespace mission {

struct ExecutorParams {
    float wp_radius_m;        // WP_RADIUS: m, 1..32767 (ArduPlane 30)
    int16_t loiter_radius_m;  // WP_LOITER_RAD: m, negative counter-clockwise (60)
    int32_t rtl_alt_cm;       // ALT_HOLD_RTL: cm above home; -1 the height RTL starts at (10000)
    float glide_slope_min_m;  // GLIDE_SLOPE_MIN: m, 0 spreads every change (15)
};
constexpr ExecutorParams kExecutorDefaults = {30.0f, 60, 10000, 15.0f};

enum class TargetKind : uint8_t { kNone, kWaypoint, kLoiter, kTakeoff };

// What the guidance flies: L1's update_waypoint(prev, next) or update_loiter(next, radius,
// direction); TECS's height (height_demand_m()).
struct NavTarget {
    TargetKind kind;
    nav::NorthEast prev_m;   // where the leg starts (a loiter: where it started)
    nav::NorthEast next_m;   // the waypoint, the loiter's centre
    float radius_m;
    int8_t direction;        // 1 clockwise, -1 counter-clockwise
    float height_m;          // above home, at next
    float slope_m;           // the glide slope: at prev the demand is height_m - slope_m
    int16_t takeoff_pitch_cd;
};

// The aircraft now: metres from home, height above home, the board's milliseconds.
struct NavState {
    nav::NorthEast pos_m;
    float height_m;
    uint32_t now_ms;
};

class MissionExecutor {
public:
    static constexpr uint8_t kMaxJumps = 6;
    static constexpr uint8_t kNone = 0xFF;

    // constexpr: a static executor needs no start-up code.
    constexpr MissionExecutor(const MissionStore& store, const nav::LocalMap& map, const nav::Location& home,
                              const ExecutorParams& params)
        : store_(store), map_(map), home_(home), params_(params) {}

    // AUTO entered: DO_JUMP counts reset, on from seq (MISSION_SET_CURRENT's out of AUTO),
    // from the first command when seq is not 1..count.
    void start(const NavState& s, uint16_t seq = 1);
    // MISSION_SET_CURRENT: on from seq (1..count), its leg from here (the plane turns to it,
    // as ArduPlane's next_wp_crosstrack = false); false for another seq.
    bool set_current(uint16_t seq, const NavState& s);
    // RTL mode: loiter at home at ALT_HOLD_RTL.
    void return_home(const NavState& s);
    // GUIDED mode (ArduPlane's set_guided_WP): loiter on WP_LOITER_RAD about the place of
    // `to` at its height (a ground station's "fly to here"); nullptr, or a command without a
    // place: where the aircraft is, at its height now.
    void guide_to(const Command* to, const NavState& s);
    // Each navigation step, after the guidance's: done yet, and on to the next command (on a
    // loiter, the radial is L1's: its update_loiter on target() comes first).
    void update(const NavState& s, const nav::L1Control& l1);

    const NavTarget& target() const { return target_; }
    // TECS's height demand now: along the glide slope.
    float height_demand_m(const NavState& s) const;
    // MISSION_CURRENT's seq (0 in RTL mode or without a mission; the last one after the end).
    uint16_t current_seq() const { return index_ == kNone ? 0u : (uint16_t)(index_ + 1u); }
    uint16_t current_command() const { return command_.id; }
    bool complete() const { return complete_; }
    // MISSION_ITEM_REACHED: the seq last reached, and a count that moves with each.
    uint16_t reached_seq() const { return reached_seq_; }
    uint8_t reached_count() const { return reached_count_; }
    // DO_CHANGE_SPEED's airspeed (cm/s, 0: none asked) and throttle (%, -1: none asked).
    uint16_t airspeed_cm_s() const { return airspeed_cm_s_; }
    int8_t throttle_pct() const { return throttle_pct_; }
    // LOITER_TURNS' turns flown since the capture (radians).
    float loiter_angle_rad() const { return loiter_sum_rad_; }

private:
    struct Jump {
        uint8_t index;
        int16_t runs;
    };
    enum Walk : uint8_t { kPeek = 0, kRun = 1 };
    // The index of the navigation command reached from `from` (kNone: the end), and the
    // command itself in `nav` (read once: a read is 14 EEPROM bytes unpacked).
    uint8_t walk(uint8_t from, Walk mode, Command& nav);
    // store_.read through the cache of the last two commands read (a read is 14 EEPROM
    // bytes unpacked): the look-ahead reads the commands a leg's end needs, so that the
    // step that reaches the waypoint finds them here.
    bool read(uint8_t index, Command& c);
    void advance(uint8_t from, const NavState& s);
    void apply_do(const Command& c);
    void start_nav(uint8_t index, const Command& c, const NavState& s);
    // The look-ahead, a piece a step from the step after the one that started the command:
    // the navigation command after this one and the turn to it, then the command after
    // that into the cache (the DO_ commands' first read when it starts).
    void look_ahead();
    void look_at_turn();
    void loiter_at(const nav::NorthEast& centre, float height_m, float radius_m, int8_t direction,
                   const NavState& s);
    // RTL's and GUIDED's circle: WP_LOITER_RAD about centre, out of the mission.
    void loiter_default(const nav::NorthEast& centre, float height_m, const NavState& s);
    void setup_slope(const NavState& s, bool auto_mode);
    // The leg's constants, once per command started (target_'s prev and next set).
    void leg_started();
    bool verify(const NavState& s, const nav::L1Control& l1);
    bool loiter_progress(const NavState& s, const nav::L1Control& l1);
    int16_t* jump_runs(uint8_t index);
    nav::NorthEast place_m(const Command& c, const NavState& s);
    float height_of(const Command& c) const;
    float rtl_height_m(const NavState& s) const;

    const MissionStore& store_;
    const nav::LocalMap& map_;
    const nav::Location& home_;
    const ExecutorParams& params_;
    Command command_;                  // the navigation command flying
    NavTarget target_ = {TargetKind::kNone, {0.0f, 0.0f}, {0.0f, 0.0f}, 0.0f, 1, 0.0f, 0.0f, 0};
    Jump jumps_[kMaxJumps] = {};
    nav::NorthEast radial_ = {0.0f, 0.0f};  // the last unit vector from the loiter's centre
    // The leg from target_.prev_m to next_m, and that over its length squared (for the
    // glide slope), worked out when a command starts.
    nav::NorthEast leg_m_ = {0.0f, 0.0f};
    nav::NorthEast leg_per_len2_ = {0.0f, 0.0f};
    bool leg_over_1m_ = false;         // long enough to spread a slope along
    bool leg_has_line_ = false;        // longer than 0.1 m: has a line across its end
    float loiter_sum_rad_ = 0.0f;
    float turn_angle_deg_ = 90.0f;     // to the next leg, for the turn distance
    // The turn's sine and cosine times the two legs' lengths, when a leg starts; its angle
    // once within the whole turn distance of the waypoint (not at the leg's start, which
    // has the store's reads to do).
    float turn_cross_ = 0.0f;
    float turn_dot_ = 0.0f;
    bool turn_pending_ = false;
    // The look-ahead's progress for the command flying (Ahead), and what it found: the
    // index of the navigation command after it (kNone: the end, or not looked yet).
    enum Ahead : uint8_t { kAheadTurn, kAheadFollower, kAheadDone };
    uint8_t ahead_ = kAheadDone;
    uint8_t ahead_index_ = kNone;
    // The commands cache: the last two read, of the store's mission cache_sequence_ in
    // cache_area_ (a commit changes both); cache_next_ the one to replace.
    struct Cached {
        uint8_t index;
        Command command;
    };
    Cached cache_[2] = {{kNone, Command()}, {kNone, Command()}};
    uint16_t cache_sequence_ = 0;
    uint8_t cache_area_ = 0xFF;
    uint8_t cache_next_ = 0;
    // The last place worked out (a command's latitude and longitude to metres: ~1 000
    // cycles), with what it came from: the look-ahead's, used again when that command
    // starts. The map's scales as bits (a float's == is a call).
    struct Placed {
        int32_t lat_e7, lon_e7, home_lat_e7, home_lon_e7;
        uint32_t north_bits, east_bits;
        nav::NorthEast m;
    };
    Placed placed_ = {0, 0, 0, 0, 0u, 0u, {0.0f, 0.0f}};
    uint32_t loiter_start_ms_ = 0;
    uint16_t airspeed_cm_s_ = 0;
    uint16_t reached_seq_ = 0;
    int8_t throttle_pct_ = -1;
    uint8_t index_ = kNone;
    uint8_t reached_count_ = 0;
    bool loiter_captured_ = false;
    bool complete_ = false;
};

}  // namespace mission
