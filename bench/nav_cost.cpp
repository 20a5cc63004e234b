// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of the navigation (lib/Nav's L1 and TECS, lib/Mission's executor) on the
// ATmega2560: a bare program (no Arduino core) that runs each step between the cycle
// markers apm25sim --profile counts (section id to GPIOR0 at the start, GPIOR1 at the
// end), 20 times each on a moving aircraft so that the branches taken are a flight's.
//
//   section 1  L1Control::update_waypoint + nav_roll_cd   (10 Hz)
//   section 2  L1Control::update_loiter + nav_roll_cd     (10 Hz, loitering instead)
//   section 3  Tecs::update_pitch_throttle, with a pitot  (10 Hz)
//   section 4  Tecs::update_pitch_throttle, without       (10 Hz)
//   section 5  Tecs::update_50hz                          (50 Hz)
//   section 7  MissionExecutor::update + height_demand_m  (10 Hz, on a leg)
//   section 6  the whole run
//
// Build (until `make bench` does it):
//   avr-g++ -mmcu=atmega2560 -DF_CPU=16000000L -Os -flto -std=gnu++11 -fno-exceptions
//     -fno-rtti -fno-threadsafe-statics -ffunction-sections -fdata-sections -mcall-prologues
//     -mrelax $(for d in lib/*/; do echo -I$d; done) -Wl,--gc-sections bench/nav_cost.cpp
//     lib/Nav/{L1Control,Tecs,Location}.cpp lib/LinAlg/LinAlg.cpp lib/Mission/*.cpp
//     lib/Settings/{Settings,RecordSlots}.cpp ... -lm -o nav_cost.elf
//   build/apm25sim --elf nav_cost.elf --trajectory rest.csv --seconds 0.5 --profile p.csv
#include <avr/io.h>
#include <stdint.h>

#include "L1Control.h"
#include "MissionExecutor.h"
#include "MissionStore.h"
#include "NeVector.h"
#include "Tecs.h"

namespace {

volatile float g_sink;
volatile float g_wobble = 0.37f;  // keeps the compiler from folding the inputs

inline void begin(uint8_t id) { GPIOR0 = id; }
inline void end(uint8_t id) { GPIOR1 = id; }

// The first mission area only, in RAM (the EEPROM's bytes 1284..2689).
uint8_t g_area[mission::kAreaSize];
uint8_t read_byte(void*, uint16_t a) {
    const uint16_t i = (uint16_t)(a - mission::kMissionStart);
    return i < sizeof g_area ? g_area[i] : 0xFF;
}
void write_byte(void*, uint16_t a, uint8_t v) {
    const uint16_t i = (uint16_t)(a - mission::kMissionStart);
    if (i < sizeof g_area) g_area[i] = v;
}

}  // namespace

int main() {
    begin(6);
    for (uint16_t i = 0; i < sizeof g_area; ++i) g_area[i] = 0xFF;
    nav::Location home;
    home.lat_e7 = 71350450;
    home.lon_e7 = -731194210;
    home.alt_cm = 102800;
    const nav::LocalMap map(home);
    mission::MissionStore store(mission::Eeprom{nullptr, &read_byte, &write_byte});
    store.load();
    store.begin_upload();
    mission::Command wp;
    wp.id = mission::kNavWaypoint;
    const nav::Location a = map.moved(home, 500.0f, 0.0f);
    wp.lat_e7 = a.lat_e7;
    wp.lon_e7 = a.lon_e7;
    wp.alt_cm = 15000;
    store.write(0, wp);
    const nav::Location b = map.moved(home, 500.0f, 400.0f);
    wp.lat_e7 = b.lat_e7;
    wp.lon_e7 = b.lon_e7;
    store.write(1, wp);
    store.commit(2);

    nav::L1Control l1(nav::kL1Defaults);
    nav::Tecs tecs(nav::kTecsDefaults);
    const mission::ExecutorParams params = mission::kExecutorDefaults;
    mission::MissionExecutor exec(store, map, home, params);
    mission::NavState s = {nav::ne(10.0f, 20.0f), 60.0f, 0u};
    exec.start(s);
    nav::TecsInput in = {120.0f, 15.0f, 14.0f, true, 1.0f, 0.9f, 0.05f, nav::TecsStage::kNormal, 0};
    for (uint8_t i = 0; i < 20; ++i) {
        const float w = g_wobble * (float)i;
        s.pos_m = nav::ne(10.0f + 15.0f * (float)i, 20.0f - w);
        const nav::NorthEast vel = nav::ne(15.0f, 1.0f + w);
        begin(1);
        l1.update_waypoint(s.pos_m, vel, exec.target().prev_m, exec.target().next_m);
        g_sink = (float)l1.nav_roll_cd(4500);
        end(1);
        begin(2);
        l1.update_loiter(s.pos_m, vel, nav::ne(300.0f, 0.0f), 60.0f, 1);
        g_sink = (float)l1.nav_roll_cd(4500);
        end(2);
        begin(5);
        tecs.update_50hz(60.0f + w, 0.1f * w, 0.05f - 0.1f * w, 0.02f);
        end(5);
        in.eas_m_s = 14.0f + w;
        in.have_airspeed = true;
        begin(3);
        tecs.update_pitch_throttle(in, 0.1f);
        end(3);
        in.have_airspeed = false;
        begin(4);
        tecs.update_pitch_throttle(in, 0.1f);
        end(4);
        g_sink = tecs.pitch_dem_rad() + tecs.throttle_dem();
        s.now_ms += 100;
        begin(7);
        exec.update(s, l1);
        g_sink = exec.height_demand_m(s);
        end(7);
    }
    end(6);
    for (;;) {
    }
}
