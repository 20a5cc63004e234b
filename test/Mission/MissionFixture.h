// SPDX-License-Identifier: GPL-3.0-or-later
// A mission in a fake EEPROM at the thesis' field, for the executor's and the flight's
// host tests: places given in metres north and east of home.
#pragma once

#include <initializer_list>

#include "FakeEeprom.h"
#include "Location.h"
#include "MissionCommand.h"
#include "MissionStore.h"

namespace testmission {

inline nav::Location field() {
    nav::Location l;
    l.lat_e7 = 71350450;
    l.lon_e7 = -731194210;
    l.alt_cm = 102800;
    return l;
}

struct Fixture {
    testeeprom::FakeEeprom eeprom;
    mission::MissionStore store{eeprom.port()};
    nav::Location home = field();
    nav::LocalMap map{home};

    mission::Command at(uint16_t id, float north_m, float east_m, float height_m) const {
        mission::Command c;
        c.id = id;
        const nav::Location l = map.moved(home, north_m, east_m);
        c.lat_e7 = l.lat_e7;
        c.lon_e7 = l.lon_e7;
        c.alt_cm = (int32_t)(height_m * 100.0f);
        return c;
    }
    mission::Command wp(float north_m, float east_m, float height_m) const {
        return at(mission::kNavWaypoint, north_m, east_m, height_m);
    }
    static mission::Command jump(uint16_t target_seq, int32_t repeat) {
        mission::Command c;
        c.id = mission::kDoJump;
        c.p1 = target_seq;
        c.lat_e7 = repeat;
        return c;
    }
    void upload(std::initializer_list<mission::Command> commands) {
        store.load();
        store.begin_upload();
        uint8_t i = 0;
        for (const mission::Command& c : commands) store.write(i++, c);
        store.commit(i);
    }
};

}  // namespace testmission
