// SPDX-License-Identifier: GPL-3.0-or-later
// The mission over MAVLink: lib/Mission's MissionProtocol and MissionStore on the board's
// EEPROM, as the MAVLink mission service describes it and ArduPilot answers it:
//
//   upload    MISSION_COUNT -> MISSION_REQUEST_INT 0 <- MISSION_ITEM_INT 0 ... -> MISSION_ACK
//             (MISSION_REQUEST / MISSION_ITEM for old ground stations; retries, time-outs)
//   download  MISSION_REQUEST_LIST -> MISSION_COUNT; MISSION_REQUEST(_INT) -> MISSION_ITEM(_INT)
//   MISSION_CLEAR_ALL -> MISSION_ACK; MISSION_SET_CURRENT -> MISSION_CURRENT, the executor moved
//   MISSION_CURRENT when the current command changes, MISSION_ITEM_REACHED when one is reached
//   fence, rally: empty lists; a clear or an empty upload accepted, an upload refused
//
// Seq 0 is home (ArduPilot's): Position's home, zeros before one; an upload's item 0 is
// taken and not stored. A refused item (NAV_LAND 21 among the commands) ends the upload
// with its MISSION_ACK and an "# error: mission item N: command C not supported" line
// (a STATUSTEXT).
//
// The EEPROM is written from the loop, a byte a pass while it is ready (an AVR byte takes
// 3.4 ms: a command's 14 bytes 48 ms): a store operation's bytes go into a queue, and the
// commit runs in steps (MissionStore::commit_step). The settings' save writes the same way,
// each only when the EEPROM is ready, so the two never write at once. The reply to an item
// (the next request, or the ACK once committed) waits until its bytes are written, and a
// mission frame waits in the parser while they are: every store operation starts on an
// empty queue, so the EEPROM sees the protocol's writes in order and a power cut at any
// moment leaves the mission before whole (MissionStore.h).
#pragma once

#include <stdint.h>

#include "MissionReporter.h"
#include "MissionStore.h"

#include "MavLink.h"
#include "MissionCommand.h"
#include "Text.h"

namespace mission_link {

// The mission loaded from the EEPROM (setup()).
void begin();

// A frame of the mission protocols (GcsLink's gcs_request task).
bool is_mission_frame(uint8_t msgid);
// A reply waits or the EEPROM is being written: a mission frame stays in the parser.
bool busy();
void take(const mav::Received& rx);
// The store task, each loop pass: a queued byte written or a commit step (when the EEPROM
// is ready), the upload's time-outs.
void service();
// A reply to send (its room is the caller's to check: two frames, a STATUSTEXT after an ACK),
// or the executor's news (MISSION_ITEM_REACHED, MISSION_CURRENT).
bool reply_due();
void send_reply();

// The store, for the navigation's executor (AUTO): loaded by begin(); it reads only the
// area in use, which an upload never writes (it writes the other, then switches).
extern mission::MissionStore store;
// For the navigation (AUTO): the stored commands, read when the EEPROM is ready
// (eeprom_is_ready(): a read waits for a write's end, up to 3.4 ms). index 0 is seq 1.
uint8_t count();
bool read(uint8_t index, mission::Command& c);
// Moves with each mission committed (restart the executor when it does).
uint16_t changes();
// The current command's seq (MISSION_CURRENT's): the executor's, or MISSION_SET_CURRENT's.
uint16_t current_seq();
// MAV_CMD_DO_SET_MISSION_CURRENT's seq (MAVProxy's `wp set`): as MISSION_SET_CURRENT; false
// but for 1..count.
bool set_current(uint16_t seq);
// Between MISSION_SET_CURRENT and the executor (NavModes): its start() when AUTO is entered,
// its follow() each step of AUTO.
extern mission::MissionReporter reporter;

// `mission`: part 0 the count, then a command a part ("# seq: id p1 lat lon alt").
bool print(uint8_t part, const text::Sink* out);

}  // namespace mission_link
