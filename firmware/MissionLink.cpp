// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionLink.h"

#include <avr/eeprom.h>

#include "ArduinoCore.h"
#include "MissionProtocol.h"
#include "NavModes.h"
#include "Port.h"
#include "Position.h"
#include "Vehicle.h"

namespace mission_link {

// The write queue: one store operation's bytes, consecutive (a command's 14, the commit's
// header 5, a marker 1), written a byte a pass by service().
static struct {
    uint16_t address;
    uint8_t count, next;
    uint8_t bytes[mission::kCommandBytes];
} queue;

static void write_now(uint16_t address, uint8_t value) { eeprom_update_byte((uint8_t*)address, value); }
static void write_next() {
    write_now((uint16_t)(queue.address + queue.next), queue.bytes[queue.next]);
    ++queue.next;
}

static void queue_byte(void*, uint16_t address, uint8_t value) {
    if (queue.next == queue.count) {
        queue.address = address;
        queue.count = queue.next = 0;
    }
    if (queue.count == sizeof queue.bytes || address != queue.address + queue.count) {
        // Not a byte of the run queued (never, one operation at a time): written in order, waiting.
        while (queue.next < queue.count) write_next();
        write_now(address, value);
        return;
    }
    queue.bytes[queue.count++] = value;
}

static uint8_t read_byte(void*, uint16_t address) { return eeprom_read_byte((const uint8_t*)address); }

mission::MissionStore store(mission::Eeprom{nullptr, read_byte, queue_byte});
static mission::MissionProtocol protocol(store);

// The reply waiting: MissionProtocol's, or kAnswer, a download's request answered when
// sent (the item read from the EEPROM then). 9 bytes.
constexpr uint8_t kAnswer = 0x80u;
constexpr uint8_t kSayRefused = 0x81u;  // after the ACK, in a pass of its own: the refusal's line
static struct {
    uint8_t kind;           // mission::Reply::Kind, or kAnswer
    uint8_t result;         // kAck: mission::Result; kAnswer: MISSION_REQUEST_INT
    uint8_t type;           // mission_type
    uint8_t sysid, compid;  // the ground station (the upload's: its retries go there too)
    uint16_t seq;           // requested, counted or current
    uint16_t refused;       // kAck ending an upload: the command refused (0: none)
} pending;
static bool check_commit = false;  // an ACK ACCEPTED of a commit: ERROR if it did not verify
static uint16_t sequence_before = 0;
mission::MissionReporter reporter;

void begin() {
    store.set_stepped(true);
    store.load();
}

bool is_mission_frame(uint8_t msgid) {
    return (msgid >= mav::kMsgMissionItem && msgid <= mav::kMsgMissionAck && msgid != 42u && msgid != 46u) ||
           msgid == mav::kMsgMissionRequestInt || msgid == mav::kMsgMissionItemInt;
}

static bool writing() { return queue.next < queue.count || store.committing(); }

bool busy() { return pending.kind != mission::Reply::kNone || writing() || !eeprom_is_ready(); }

static void note(const mission::Reply& r) {
    pending.kind = r.kind;
    pending.result = (uint8_t)r.result;
    pending.type = r.mission_type;
    pending.seq = r.seq;
    check_commit = r.kind == mission::Reply::kAck && r.result == mission::Result::kAccepted && store.committing();
    sequence_before = store.sequence();
}

void take(const mav::Received& rx) {
    const uint32_t now_ms = millis();
    mission::Item item;
    uint16_t n = 0;
    uint8_t type = 0;
    bool int_form = false;
    mission::Reply r = {};
    pending.refused = 0;
    if (mav::decode_mission_item(rx, item)) {
        if (mission::is_guided_request(item)) {
            // "Fly to here": GUIDED, the stored mission and an upload untouched; refused:
            // ERROR (FlightIo says why).
            mission::Command c;
            mission::Result why = mission::Result::kError;
            if (mission::guided_command(item, c, why))
                why = nav_modes::fly_to(c) ? mission::Result::kAccepted : mission::Result::kError;
            r.kind = mission::Reply::kAck;
            r.result = why;
        } else {
            r = protocol.on_item(item, now_ms);
            if (r.kind == mission::Reply::kAck && r.result != mission::Result::kAccepted && item.mission_type == 0)
                pending.refused = item.command;
        }
    } else if (mav::decode_mission_count(rx, n, type)) {
        // Fence and rally: an empty upload accepted (ArduPilot's answer for an empty list).
        r = protocol.on_count(n, type, now_ms);
        if (type != 0 && n == 0) r.result = mission::Result::kAccepted;
    } else if (mav::decode_mission_request(rx, n, int_form, type)) {
        r.kind = (mission::Reply::Kind)kAnswer;
        r.seq = n;
        r.result = (mission::Result)int_form;
        r.mission_type = type;
    } else if (mav::decode_mission_request_list(rx, type)) {
        r = protocol.on_request_list(type);
    } else if (mav::decode_mission_ack(rx, type)) {
        protocol.on_ack(type);
    } else if (mav::decode_mission_clear_all(rx, type)) {
        r = protocol.on_clear_all(type);
        if (type != 0) r.result = mission::Result::kAccepted;
    } else if (mav::decode_mission_set_current(rx, n)) {
        set_current(n);  // MISSION_CURRENT is the reporter's news
    } else {
        return;
    }
    pending.sysid = rx.sysid;
    pending.compid = rx.compid;
    note(r);
}

void service() {
    if (!eeprom_is_ready()) return;
    if (queue.next < queue.count) {
        write_next();
    } else if (store.committing()) {
        store.commit_step();  // its reads after every byte queued before it is written
    } else if (pending.kind == mission::Reply::kNone) {
        const mission::Reply r = protocol.tick(millis());
        if (r.kind != mission::Reply::kNone) note(r);
    }
}

static bool protocol_reply_due() { return pending.kind != mission::Reply::kNone && !writing() && eeprom_is_ready(); }
bool reply_due() { return protocol_reply_due() || reporter.news(); }

// The executor's news: MISSION_ITEM_REACHED first (MISSION_CURRENT is on a stream too).
static void send_news() {
    uint8_t frame[mav::kMaxFrame];
    uint16_t seq;
    uint8_t n;
    if (reporter.take_reached(seq)) {
        n = port::mavlink.mission_item_reached(frame, seq);
    } else {
        reporter.take_current();
        n = port::mavlink.mission_current(frame, reporter.current_seq(), store.count());
    }
    port::send_frame(frame, n);
}

static nav::Location home() {
    const nav::Navigator& nav = position::navigator();
    return nav.home_set() ? nav.home() : nav::Location();
}

void send_reply() {
    if (!protocol_reply_due()) return send_news();
    uint8_t frame[mav::kMaxFrame];
    uint8_t n;
    const uint8_t sys = pending.sysid, comp = pending.compid;
    uint8_t kind = pending.kind;
    pending.kind = mission::Reply::kNone;
    if (kind == kSayRefused) {
        text::Writer(vehicle::out).str(TXT(TXT_ERROR "mission: command ")).u32(pending.refused)
            .str(TXT(" refused (")).u32(pending.result).chr(')').end();
        return;
    }
    mission::Reply r = {};
    if (kind == kAnswer) {
        r = protocol.on_request(pending.seq, pending.result != 0u, pending.type, home());
        kind = r.kind;
        pending.result = (uint8_t)r.result;
    }
    switch (kind) {
        case mission::Reply::kItem: n = port::mavlink.mission_item(frame, sys, comp, r.item); break;
        case mission::Reply::kCount: n = port::mavlink.mission_count(frame, sys, comp, pending.seq, pending.type); break;
        case mission::Reply::kAck:
            // Committed but not read back whole: the mission before stays, said so.
            if (check_commit && store.sequence() == sequence_before) pending.result = (uint8_t)mission::Result::kError;
            if (store.sequence() != sequence_before) reporter.forget();  // a seq asked of the mission before
            n = port::mavlink.mission_ack(frame, sys, comp, (mav::MissionResult)pending.result, pending.type);
            break;
        default:
            n = port::mavlink.mission_request(frame, sys, comp, pending.seq, kind == mission::Reply::kRequestInt,
                                              pending.type);
            break;
    }
    port::send_frame(frame, n);
    if (kind == mission::Reply::kAck && pending.refused != 0u) pending.kind = kSayRefused;
}

uint8_t count() { return store.count(); }
bool read(uint8_t index, mission::Command& c) { return store.read(index, c); }
uint16_t changes() { return store.sequence(); }
uint16_t current_seq() { return reporter.current_seq(); }
bool set_current(uint16_t seq) { return reporter.request(seq, store.count()); }

bool print(uint8_t part, const text::Sink* out) {
    text::Writer w(out);
    if (part == 0) {
        w.str(TXT("# mission: ")).u32(store.count()).str(TXT(" commands, current ")).u32(reporter.current_seq());
        if (writing()) w.str(TXT(" (being written)"));
        w.end();
        return true;
    }
    mission::Command c;
    if (writing() || !eeprom_is_ready() || !store.read((uint8_t)(part - 1u), c)) return false;
    w.str(TXT("# ")).u32(part).str(TXT(": ")).u32(c.id).chr(' ').u32(c.p1).chr(' ');
    if (mission::is_nav(c.id)) {
        w.degrees_e7(c.lat_e7).chr(' ').degrees_e7(c.lon_e7).chr(' ').fixed2((float)c.alt_cm * 0.01f);
        if (!c.relative_alt) w.str(TXT(" msl"));
        if (c.loiter_ccw) w.str(TXT(" ccw"));
    } else {
        w.i32(c.lat_e7).chr(' ').i32(c.lon_e7);
    }
    w.end();
    return true;
}

}  // namespace mission_link
