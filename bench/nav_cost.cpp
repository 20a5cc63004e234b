// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of the navigation (lib/Nav's L1 and TECS, lib/Mission's executor) on the
// ATmega2560: a bare program (no Arduino core) that runs each step between the cycle
// markers apm25sim --profile counts (section id to GPIOR0 at the start, GPIOR1 at the
// end; sections nest), 20 times each on a moving aircraft so that the branches taken are
// a flight's. Built and run by `make nav-cost` (mk/navcost.mk), part of `make bench`;
// bench/nav.py names the sections and holds the whole step to its budget.
//
// Three navigation stacks (executor, L1, TECS), each stepped at 10 Hz in the firmware's
// order (the guidance, the executor, TECS on the executor's height):
//   a leg with a pitot     section 8: the whole step; inside it 1 L1, 3 TECS, 7 executor,
//                          and 13 the guidance (L1 and the executor)
//   the same leg, no pitot section 9: the whole step; inside it 4 TECS
//   on a loiter's circle   section 10: the whole step (pitot); inside it 2 L1, 11 executor,
//                          14 the guidance
// and section 5 TECS's 50 Hz filters (five per 10 Hz step), 6 the whole run; then 12, one
// whole step (pitot) that reaches the waypoint and starts the next leg, 15 its guidance;
// 16 the next step (the new leg's first), 17 its guidance; 18 a step within the turn
// distance of the next waypoint (the turn's angle taken), 19 its guidance.
// The first step of each stack is a leg's first for L1 (its length and unit vector).
// The objects are static (g_*) so that `avr-nm -S` gives their RAM.
#include <avr/io.h>
#include <math.h>
#include <stdint.h>

#include "L1Control.h"
#include "MissionExecutor.h"
#include "MissionStore.h"
#include "NeVector.h"
#include "Tecs.h"

namespace {

volatile float g_sink;
volatile float g_wobble = 0.37f;  // keeps the compiler from folding the inputs

// Section 0: not measured.
inline void begin(uint8_t id) {
    if (id != 0) GPIOR0 = id;
}
inline void end(uint8_t id) {
    if (id != 0) GPIOR1 = id;
}

// One mission area per store, in RAM (the EEPROM's bytes 1284..2689); ctx is the area.
uint8_t g_area_leg[mission::kAreaSize];
uint8_t g_area_loiter[mission::kAreaSize];
uint8_t read_byte(void* ctx, uint16_t a) {
    const uint16_t i = (uint16_t)(a - mission::kMissionStart);
    return i < mission::kAreaSize ? static_cast<uint8_t*>(ctx)[i] : 0xFF;
}
void write_byte(void* ctx, uint16_t a, uint8_t v) {
    const uint16_t i = (uint16_t)(a - mission::kMissionStart);
    if (i < mission::kAreaSize) static_cast<uint8_t*>(ctx)[i] = v;
}

nav::Location make_home() {
    nav::Location home;
    home.lat_e7 = 71350450;
    home.lon_e7 = -731194210;
    home.alt_cm = 102800;
    return home;
}
const nav::Location g_home = make_home();
const nav::LocalMap g_map(g_home);
const mission::ExecutorParams g_exec_params = mission::kExecutorDefaults;

mission::MissionStore g_store_leg(mission::Eeprom{g_area_leg, &read_byte, &write_byte});
mission::MissionStore g_store_loiter(mission::Eeprom{g_area_loiter, &read_byte, &write_byte});

// The stack with a pitot on the leg; its L1, TECS and executor are what `avr-nm -S` sizes.
nav::L1Control g_l1(nav::kL1Defaults);
nav::Tecs g_tecs(nav::kTecsDefaults);
mission::MissionExecutor g_exec(g_store_leg, g_map, g_home, g_exec_params);
// The same leg without a pitot, and the loiter.
nav::L1Control g_l1_np(nav::kL1Defaults);
nav::Tecs g_tecs_np(nav::kTecsDefaults);
mission::MissionExecutor g_exec_np(g_store_leg, g_map, g_home, g_exec_params);
nav::L1Control g_l1_lo(nav::kL1Defaults);
nav::Tecs g_tecs_lo(nav::kTecsDefaults);
mission::MissionExecutor g_exec_lo(g_store_loiter, g_map, g_home, g_exec_params);

void upload(mission::MissionStore& store, const mission::Command* commands, uint8_t count) {
    store.load();
    store.begin_upload();
    for (uint8_t i = 0; i < count; ++i) store.write(i, commands[i]);
    store.commit(count);
}

mission::Command place(uint16_t id, float north_m, float east_m) {
    mission::Command c;
    c.id = id;
    const nav::Location l = g_map.moved(g_home, north_m, east_m);
    c.lat_e7 = l.lat_e7;
    c.lon_e7 = l.lon_e7;
    c.alt_cm = 15000;  // 90 m above the start: spread along the leg (a glide slope)
    return c;
}

// One 10 Hz navigation step: L1 on the executor's target, the executor's verify (after the
// guidance: it takes L1's turn distance) and TECS's height demand, TECS. The sub-sections
// (0: none) are the pieces.
void step(nav::L1Control& l1, nav::Tecs& tecs, mission::MissionExecutor& exec, const mission::NavState& s,
          const nav::NorthEast& vel, nav::TecsInput& in, uint8_t guidance_id, uint8_t l1_id, uint8_t tecs_id,
          uint8_t exec_id) {
    const mission::NavTarget& t = exec.target();
    begin(guidance_id);
    begin(l1_id);
    if (t.kind == mission::TargetKind::kLoiter) {
        l1.update_loiter(s.pos_m, vel, t.next_m, t.radius_m, t.direction);
    } else {
        l1.update_waypoint(s.pos_m, vel, t.prev_m, t.next_m);
    }
    g_sink = (float)l1.nav_roll_cd(4500);
    end(l1_id);
    begin(exec_id);
    exec.update(s, l1);
    in.height_dem_m = exec.height_demand_m(s);
    end(exec_id);
    end(guidance_id);
    begin(tecs_id);
    tecs.update_pitch_throttle(in, 0.1f);
    end(tecs_id);
    g_sink = tecs.pitch_dem_rad() + tecs.throttle_dem();
}

}  // namespace

int main() {
    begin(6);
    for (uint16_t i = 0; i < mission::kAreaSize; ++i) g_area_leg[i] = g_area_loiter[i] = 0xFF;
    // A right angle at the first waypoint, 53 degrees at the second (a gentle turn: its
    // angle is worked out when the leg to it starts).
    const mission::Command leg[3] = {place(mission::kNavWaypoint, 500.0f, 0.0f),
                                     place(mission::kNavWaypoint, 500.0f, 400.0f),
                                     place(mission::kNavWaypoint, 800.0f, 800.0f)};
    upload(g_store_leg, leg, 3);
    mission::Command loiter = place(mission::kNavLoiterTurns, 300.0f, 0.0f);
    loiter.p1 = 50;  // turns; the radius WP_LOITER_RAD's
    upload(g_store_loiter, &loiter, 1);

    mission::NavState s = {nav::ne(10.0f, 20.0f), 60.0f, 0u};
    mission::NavState lo = s;
    g_exec.start(s);
    g_exec_np.start(s);
    g_exec_lo.start(lo);
    nav::TecsInput in = {120.0f, 15.0f, 14.0f, true, 1.0f, 0.9f, 0.05f, nav::TecsStage::kNormal, 0};
    nav::TecsInput in_np = in;
    in_np.have_airspeed = false;
    nav::TecsInput in_lo = in;
    for (uint8_t i = 0; i < 20; ++i) {
        const float w = g_wobble * (float)i;
        for (uint8_t k = 0; k < 5; ++k) {
            begin(5);
            g_tecs.update_50hz(60.0f + w, 0.1f * w, 0.05f - 0.1f * w, 0.02f);
            end(5);
            g_tecs_np.update_50hz(60.0f + w, 0.1f * w, 0.05f - 0.1f * w, 0.02f);
            g_tecs_lo.update_50hz(60.0f + w, 0.1f * w, 0.05f - 0.1f * w, 0.02f);
        }
        // Along the leg, off its line by a wobble.
        s.pos_m = nav::ne(10.0f + 15.0f * (float)i, 20.0f - w);
        s.now_ms += 100;
        const nav::NorthEast vel = nav::ne(15.0f, 1.0f + w);
        in.eas_m_s = 14.0f + w;
        in_np.eas_m_s = in.eas_m_s;
        in_lo.eas_m_s = in.eas_m_s;
        begin(8);
        step(g_l1, g_tecs, g_exec, s, vel, in, 13, 1, 3, 7);
        end(8);
        begin(9);
        step(g_l1_np, g_tecs_np, g_exec_np, s, vel, in_np, 0, 0, 4, 0);
        end(9);
        // On the loiter's circle (60 m about 300 m north), clockwise at 15 m/s, 2 m out.
        const float angle = 0.25f * (float)i;
        const float c = cosf(angle), sn = sinf(angle);
        lo.pos_m = nav::ne(300.0f + 62.0f * c, 62.0f * sn);
        lo.now_ms = s.now_ms;
        begin(10);
        step(g_l1_lo, g_tecs_lo, g_exec_lo, lo, nav::ne(-15.0f * sn, 15.0f * c + w), in_lo, 14, 2, 0, 11);
        end(10);
    }
    // The step that reaches the leg's waypoint and starts the next leg (the executor's
    // advance: the store read, the next place, the turn to the leg after).
    s.pos_m = g_exec.target().next_m - nav::ne(10.0f, 0.0f);
    s.now_ms += 100;
    begin(12);
    step(g_l1, g_tecs, g_exec, s, nav::ne(15.0f, 1.0f), in, 15, 0, 0, 0);
    end(12);
    // The new leg's first step: L1 works its length and unit vector out, the executor the
    // turn's angle at its end.
    s.pos_m = s.pos_m + nav::ne(1.5f, 0.0f);
    s.now_ms += 100;
    begin(16);
    step(g_l1, g_tecs, g_exec, s, nav::ne(15.0f, 1.0f), in, 17, 0, 0, 0);
    end(16);
    // 25 m before the next waypoint, within the whole turn distance (30 m): the turn's angle
    // (53 degrees: 17.7 m) is taken.
    s.pos_m = g_exec.target().next_m - nav::ne(0.0f, 25.0f);
    s.now_ms += 100;
    begin(18);
    step(g_l1, g_tecs, g_exec, s, nav::ne(1.0f, 15.0f), in, 19, 0, 0, 0);
    end(18);
    end(6);
    for (;;) {
    }
}
