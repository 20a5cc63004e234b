// SPDX-License-Identifier: GPL-3.0-or-later
// MAVLink's mission protocol, the board's side, as the MAVLink mission service describes it
// and ArduPilot answers it: decoded fields in, what to send out (lib/MavLink packs the
// frames). Each input gives at most one reply.
//
//   upload    MISSION_COUNT n -> MISSION_REQUEST_INT 0 ... <- MISSION_ITEM(_INT) seq ...
//             -> MISSION_ACK ACCEPTED after item n-1 (written, committed: MissionStore)
//             Items come in order; another seq is answered with a request for the one
//             expected. Silence for kRetryTimeout_ms: the request again, up to kRetries
//             times, then MISSION_ACK OPERATION_CANCELLED. A refused item (an unsupported
//             command or frame, a place off the earth) ends the upload with its MISSION_ACK.
//             Either way, and when the ground station stops or cancels, the mission before
//             stays (the store's other area). A new MISSION_COUNT starts over. n = 0 clears.
//   download  MISSION_REQUEST_LIST -> MISSION_COUNT n; MISSION_REQUEST_INT / MISSION_REQUEST
//             seq -> MISSION_ITEM_INT / MISSION_ITEM seq (home for seq 0); the ground
//             station's MISSION_ACK ends it.
//   MISSION_CLEAR_ALL -> an empty mission committed, MISSION_ACK ACCEPTED.
//   MISSION_SET_CURRENT seq -> MISSION_CURRENT seq (the caller moves the executor).
//
// Old ground stations: an upload's first request is MISSION_REQUEST_INT; a time-out before
// the first item alternates it with MISSION_REQUEST (a station that knows only the older
// message answers that), and once items come, requests follow their kind (MISSION_ITEM ->
// MISSION_REQUEST). Both item kinds are taken at any time. Frames: GLOBAL (0) and
// GLOBAL_RELATIVE_ALT (3) and their _INT forms (5, 6) for places; DO_ commands any frame.
// Seq 0 is home (ArduPilot's): an upload's item 0 is taken and not stored. Only the
// mission (MAV_MISSION_TYPE 0): a fence or rally list is empty, an upload of one refused.
#pragma once

#include <stdint.h>

#include "Location.h"
#include "MissionCommand.h"
#include "MissionStore.h"

namespace mission {

// MAV_MISSION_RESULT
enum class Result : uint8_t {
    kAccepted = 0,
    kError = 1,
    kUnsupportedFrame = 2,
    kUnsupported = 3,
    kNoSpace = 4,
    kInvalidParam5 = 10,  // latitude
    kInvalidParam6 = 11,  // longitude
    kInvalidSequence = 13,
    kOperationCancelled = 15,
};

// MAV_FRAME
enum Frame : uint8_t {
    kFrameGlobal = 0,
    kFrameMission = 2,
    kFrameGlobalRelativeAlt = 3,
    kFrameGlobalInt = 5,
    kFrameGlobalRelativeAltInt = 6,
};

// MISSION_ITEM or MISSION_ITEM_INT's fields, decoded. x, y: 1e-7 degrees (the caller
// converts MISSION_ITEM's float degrees: e7_from_degrees).
struct Item {
    uint16_t seq;
    uint16_t command;
    uint8_t frame;
    uint8_t current;
    uint8_t autocontinue;
    float param1, param2, param3, param4;
    int32_t x, y;
    float z;             // m
    uint8_t mission_type;
    bool int_form;       // MISSION_ITEM_INT (else MISSION_ITEM)
};

int32_t e7_from_degrees(float degrees);
float degrees_from_e7(int32_t e7);

// An item as a command (false: the result to refuse it with, set in `why`).
bool from_item(const Item& item, Command& c, Result& why);
// A ground station's "fly to here" (MAVProxy's `guided`, Mission Planner's "Fly to here"):
// MISSION_ITEM(_INT) with current 2, for GUIDED and not for the stored mission (ArduPilot's
// guided request). Its place and height as a command; false: `why`, a command without a
// place (the item is then refused, the mission untouched).
inline bool is_guided_request(const Item& item) { return item.current == 2u && item.mission_type == 0u; }
bool guided_command(const Item& item, Command& c, Result& why);
// A command as the item of `seq` (int_form: MISSION_ITEM_INT's frames).
Item to_item(const Command& c, uint16_t seq, bool int_form);
// Home as seq 0: a waypoint at home, height above mean sea level.
Item home_item(const nav::Location& home, bool int_form);

// What to send.
struct Reply {
    enum Kind : uint8_t {
        kNone,
        kRequestInt,   // MISSION_REQUEST_INT seq
        kRequest,      // MISSION_REQUEST seq
        kCount,        // MISSION_COUNT count
        kItem,         // MISSION_ITEM(_INT) item (item.int_form says which)
        kAck,          // MISSION_ACK result
        kCurrent,      // MISSION_CURRENT seq
    };
    Kind kind;
    uint16_t seq;      // request, current; count for kCount
    Result result;
    uint8_t mission_type;
    Item item;
};

class MissionProtocol {
public:
    static constexpr uint16_t kRetryTimeout_ms = 1500;
    static constexpr uint8_t kRetries = 5;
    static constexpr uint8_t kTypeMission = 0;

    constexpr explicit MissionProtocol(MissionStore& store) : store_(store) {}

    Reply on_count(uint16_t count, uint8_t mission_type, uint32_t now_ms);
    Reply on_item(const Item& item, uint32_t now_ms);
    Reply on_request_list(uint8_t mission_type);
    // MISSION_REQUEST_INT (int_form) or MISSION_REQUEST; home: seq 0's place.
    Reply on_request(uint16_t seq, bool int_form, uint8_t mission_type, const nav::Location& home);
    // The ground station's MISSION_ACK (ends its download; during an upload, a cancel).
    void on_ack(uint8_t mission_type);
    Reply on_clear_all(uint8_t mission_type);
    Reply on_set_current(uint16_t seq);
    // Time-outs: call each loop pass (or at a few Hz).
    Reply tick(uint32_t now_ms);

    bool uploading() const { return state_ == State::kReceiving; }
    // Moves on with each mission committed (the caller restarts the executor on it).
    uint8_t changes() const { return changes_; }

private:
    enum class State : uint8_t { kIdle, kReceiving };
    Reply request(uint16_t seq);
    Reply ack(Result r, uint8_t mission_type = kTypeMission);
    void finish(uint8_t commands);

    MissionStore& store_;
    uint32_t last_ms_ = 0;       // the last request sent
    uint16_t count_ = 0;         // items in the upload (home included)
    uint16_t expected_ = 0;      // the next seq asked for
    uint16_t last_done_ = 0;     // the last upload's count, for a repeated last item
    State state_ = State::kIdle;
    uint8_t retries_ = 0;
    uint8_t changes_ = 0;
    bool request_int_ = true;
    bool any_item_ = false;
    bool done_recently_ = false;  // the last upload was accepted: its last item again -> ACK again
};

}  // namespace mission
