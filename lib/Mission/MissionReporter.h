// SPDX-License-Identifier: GPL-3.0-or-later
// Between the ground station and the mission's executor, as ArduPlane answers:
//
//   MISSION_SET_CURRENT seq (or MAV_CMD_DO_SET_MISSION_CURRENT)  in AUTO the executor goes
//             on from seq at its next step, the leg from where the plane is (it turns to
//             it); out of AUTO seq is where AUTO starts next (once). MISSION_CURRENT at once.
//   MISSION_CURRENT       whenever the executor's current seq changes (and on its stream,
//                         SR0_EXT_STAT: the caller's)
//   MISSION_ITEM_REACHED  once for each command the executor reaches (its reached_count())
//
// The executor is the caller's (firmware/NavModes), passed to start() and follow().
// Plain C++, host-tested; 8 bytes.
#pragma once

#include <stdint.h>

#include "MissionExecutor.h"

namespace mission {

class MissionReporter {
public:
    // MISSION_SET_CURRENT seq of a mission of `count` commands: false (no answer) but for
    // 1..count.
    bool request(uint16_t seq, uint8_t count);
    // AUTO entered: the executor started, from the seq asked for out of AUTO if any.
    void start(MissionExecutor& ex, const NavState& s);
    // Each step of AUTO, after the executor's update: the seq asked for applied (in a step
    // that reached no command: each reads commands from the EEPROM), the news noted.
    void follow(MissionExecutor& ex, const NavState& s);
    // Another mission committed: a seq asked for is forgotten.
    void forget() { asked_ = 0; }

    // MISSION_CURRENT's seq: the executor's in AUTO, else the last one (or the one asked for).
    uint16_t current_seq() const { return current_; }
    // A MISSION_ITEM_REACHED (its seq) or a MISSION_CURRENT to send now; each taken once.
    bool news() const { return reached_ != 0u || current_news_; }
    bool take_reached(uint16_t& seq);
    bool take_current();

private:
    void note_current(uint16_t seq);

    uint16_t current_ = 0;
    uint16_t asked_ = 0;    // a MISSION_SET_CURRENT not applied yet (0: none)
    uint16_t reached_ = 0;  // a MISSION_ITEM_REACHED not sent yet (0: none)
    uint8_t reached_count_ = 0;  // the executor's reached_count() when last seen
    bool current_news_ = false;
};

}  // namespace mission
