// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Mission/MissionProtocol: an upload as QGroundControl and Mission Planner do it
// (MISSION_ITEM_INT) and as an old ground station does (MISSION_ITEM, MISSION_REQUEST),
// downloaded back equal; a ground station that stops half way (re-requests, then
// cancelled, the old mission whole), refused commands and frames (the old mission
// whole), items out of order, too many, a lost final ACK, clear, set current, fence
// and rally lists; a ground station's "fly to here" (current 2) taken apart from them.
#include <gtest/gtest.h>

#include <vector>

#include "MissionFixture.h"
#include "MissionProtocol.h"

namespace {

using mission::Reply;
using mission::Result;

mission::Item item(uint16_t seq, uint16_t command, int32_t lat_e7, int32_t lon_e7, float z_m, bool int_form = true,
                   uint8_t frame = mission::kFrameGlobalRelativeAltInt) {
    mission::Item it = {};
    it.seq = seq;
    it.command = command;
    it.frame = frame;
    it.autocontinue = 1;
    it.x = lat_e7;
    it.y = lon_e7;
    it.z = z_m;
    it.int_form = int_form;
    return it;
}

// The route a ground station plans: home, a takeoff, three waypoints, a loiter of 2 turns
// counter-clockwise, DO_CHANGE_SPEED, DO_JUMP to 2 three times, RTL.
std::vector<mission::Item> route(bool int_form) {
    const uint8_t frame = int_form ? mission::kFrameGlobalRelativeAltInt : mission::kFrameGlobalRelativeAlt;
    std::vector<mission::Item> r;
    r.push_back(item(0, 16, 71350450, -731194210, 1028.0f, int_form, int_form ? mission::kFrameGlobalInt : 0));
    mission::Item t = item(1, 22, 0, 0, 40.0f, int_form, frame);
    t.param1 = 15.0f;
    r.push_back(t);
    r.push_back(item(2, 16, 71395450, -731194210, 60.0f, int_form, frame));
    r.push_back(item(3, 16, 71395450, -731149210, 80.5f, int_form, frame));
    r.push_back(item(4, 16, 71350450, -731149210, 60.0f, int_form, int_form ? mission::kFrameGlobalInt : 0));
    mission::Item lt = item(5, 18, 71370450, -731170000, 70.0f, int_form, frame);
    lt.param1 = 2.0f;
    lt.param3 = -80.0f;
    r.push_back(lt);
    mission::Item sp = item(6, 178, 0, 0, 0.0f, int_form, mission::kFrameMission);
    sp.param1 = 0.0f;
    sp.param2 = 18.5f;
    sp.param3 = -1.0f;
    r.push_back(sp);
    mission::Item j = item(7, 177, 0, 0, 0.0f, int_form, mission::kFrameMission);
    j.param1 = 2.0f;
    j.param2 = 3.0f;
    r.push_back(j);
    r.push_back(item(8, 20, 0, 0, 0.0f, int_form, mission::kFrameMission));
    return r;
}

// Uploads `items` as a ground station that answers every request; returns the final reply.
Reply upload(mission::MissionProtocol& p, const std::vector<mission::Item>& items, uint32_t& now_ms,
             Reply::Kind expect_request = Reply::kRequestInt) {
    Reply r = p.on_count((uint16_t)items.size(), 0, now_ms);
    for (size_t i = 0; i < items.size(); ++i) {
        EXPECT_EQ(r.kind, i == 0 ? Reply::kRequestInt : expect_request) << i;
        EXPECT_EQ(r.seq, i);
        now_ms += 50;
        r = p.on_item(items[i], now_ms);
    }
    return r;
}

void expect_same(const mission::Item& a, const mission::Item& b) {
    EXPECT_EQ(a.seq, b.seq);
    EXPECT_EQ(a.command, b.command);
    EXPECT_EQ(a.x, b.x) << a.seq;
    EXPECT_EQ(a.y, b.y) << a.seq;
    EXPECT_FLOAT_EQ(a.z, b.z) << a.seq;
    EXPECT_FLOAT_EQ(a.param1, b.param1) << a.seq;
    EXPECT_FLOAT_EQ(a.param2, b.param2) << a.seq;
    EXPECT_FLOAT_EQ(a.param3, b.param3) << a.seq;
}

TEST(MissionProtocol, UploadThenDownloadEqual) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 1000;
    const std::vector<mission::Item> items = route(true);
    const Reply done = upload(p, items, now);
    EXPECT_EQ(done.kind, Reply::kAck);
    EXPECT_EQ(done.result, Result::kAccepted);
    EXPECT_EQ(p.changes(), 1u);
    EXPECT_FALSE(p.uploading());
    EXPECT_EQ(f.store.count(), 8u);

    const Reply count = p.on_request_list(0);
    EXPECT_EQ(count.kind, Reply::kCount);
    EXPECT_EQ(count.seq, 9u);
    for (uint16_t seq = 1; seq < 9; ++seq) {
        const Reply r = p.on_request(seq, true, 0, f.home);
        ASSERT_EQ(r.kind, Reply::kItem);
        EXPECT_TRUE(r.item.int_form);
        expect_same(r.item, items[seq]);
    }
    // The frames come back as sent; seq 0 is home.
    EXPECT_EQ(p.on_request(2, true, 0, f.home).item.frame, mission::kFrameGlobalRelativeAltInt);
    EXPECT_EQ(p.on_request(4, true, 0, f.home).item.frame, mission::kFrameGlobalInt);
    EXPECT_EQ(p.on_request(6, true, 0, f.home).item.frame, mission::kFrameMission);
    const Reply home = p.on_request(0, true, 0, f.home);
    EXPECT_EQ(home.item.x, f.home.lat_e7);
    EXPECT_FLOAT_EQ(home.item.z, 1028.0f);
    EXPECT_EQ(p.on_request(9, true, 0, f.home).result, Result::kInvalidSequence);
    // A restart finds it.
    mission::MissionStore again(f.eeprom.port());
    ASSERT_TRUE(again.load());
    EXPECT_EQ(again.count(), 8u);
}

TEST(MissionProtocol, OldGroundStationWithFloatItems) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 0;
    std::vector<mission::Item> items = route(false);
    for (mission::Item& it : items) {  // MISSION_ITEM carries float degrees
        it.x = mission::e7_from_degrees(mission::degrees_from_e7(it.x));
        it.y = mission::e7_from_degrees(mission::degrees_from_e7(it.y));
    }
    const Reply done = upload(p, items, now, Reply::kRequest);
    EXPECT_EQ(done.result, Result::kAccepted);
    const Reply r = p.on_request(3, false, 0, f.home);
    EXPECT_FALSE(r.item.int_form);
    EXPECT_EQ(r.item.frame, mission::kFrameGlobalRelativeAlt);
    // Float degrees: within a float's step at 73 degrees (7.6e-6 deg, 85 cm).
    EXPECT_NEAR(mission::degrees_from_e7(r.item.y), -73.1149210f, 8e-6f);
    expect_same(r.item, items[3]);
}

TEST(MissionProtocol, StationStoppingHalfWayLeavesTheOldMission) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 0;
    ASSERT_EQ(upload(p, route(true), now).result, Result::kAccepted);
    // A new upload of 6 items; the station goes after item 2.
    std::vector<mission::Item> other = {item(0, 16, 1, 1, 0), item(1, 16, 71360000, -731190000, 50.0f),
                                        item(2, 16, 71370000, -731190000, 50.0f), item(3, 16, 71380000, -731190000, 50.0f),
                                        item(4, 16, 71390000, -731190000, 50.0f), item(5, 16, 71400000, -731190000, 50.0f)};
    p.on_count(6, 0, now);
    for (uint16_t i = 0; i < 3; ++i) p.on_item(other[i], now += 100);
    EXPECT_TRUE(p.uploading());
    // Re-asked kRetries times, kRetryTimeout_ms apart, then cancelled.
    EXPECT_EQ(p.tick(now + 1499).kind, Reply::kNone);
    for (uint8_t i = 0; i < mission::MissionProtocol::kRetries; ++i) {
        now += mission::MissionProtocol::kRetryTimeout_ms;
        const Reply r = p.tick(now);
        EXPECT_EQ(r.kind, Reply::kRequestInt);
        EXPECT_EQ(r.seq, 3u);
    }
    now += mission::MissionProtocol::kRetryTimeout_ms;
    const Reply gave_up = p.tick(now);
    EXPECT_EQ(gave_up.kind, Reply::kAck);
    EXPECT_EQ(gave_up.result, Result::kOperationCancelled);
    EXPECT_FALSE(p.uploading());
    EXPECT_EQ(p.changes(), 1u);
    // The old mission, whole, now and after a restart.
    const std::vector<mission::Item> old = route(true);
    EXPECT_EQ(p.on_request_list(0).seq, 9u);
    for (uint16_t seq = 1; seq < 9; ++seq) expect_same(p.on_request(seq, true, 0, f.home).item, old[seq]);
    mission::MissionStore again(f.eeprom.port());
    ASSERT_TRUE(again.load());
    EXPECT_EQ(again.count(), 8u);
    // A late item of the dead upload is an error, not a write.
    EXPECT_EQ(p.on_item(other[3], now).result, Result::kError);
    // The station cancelling (its MISSION_ACK) ends an upload the same way.
    p.on_count(6, 0, now);
    p.on_item(other[0], now);
    p.on_ack(0);
    EXPECT_FALSE(p.uploading());
    EXPECT_EQ(f.store.count(), 8u);
}

TEST(MissionProtocol, RefusedCommandsAndFramesKeepTheOldMission) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 0;
    ASSERT_EQ(upload(p, route(true), now).result, Result::kAccepted);
    struct Case {
        mission::Item bad;
        Result result;
    };
    const Case cases[] = {
        {item(1, 21, 71360000, -731190000, 0.0f), Result::kUnsupported},     // NAV_LAND
        {item(1, 183, 0, 0, 0.0f), Result::kUnsupported},                    // DO_SET_SERVO
        {item(1, 16, 71360000, -731190000, 50.0f, true, 10), Result::kUnsupportedFrame},  // terrain
        {item(1, 16, 910000000, 0, 50.0f), Result::kInvalidParam5},
        {item(1, 16, 0, -1810000000, 50.0f), Result::kInvalidParam6},
    };
    for (const Case& c : cases) {
        p.on_count(3, 0, now);
        p.on_item(item(0, 16, 0, 0, 0.0f), now);
        const Reply r = p.on_item(c.bad, now);
        EXPECT_EQ(r.kind, Reply::kAck);
        EXPECT_EQ(r.result, c.result) << c.bad.command;
        EXPECT_FALSE(p.uploading());
        EXPECT_EQ(f.store.count(), 8u);
    }
    // Too many items for the store: refused before anything is written.
    EXPECT_EQ(p.on_count(mission::kMaxCommands + 2u, 0, now).result, Result::kNoSpace);
    EXPECT_EQ(p.on_count(mission::kMaxCommands + 1u, 0, now).kind, Reply::kRequestInt);
}

TEST(MissionProtocol, OutOfOrderLostAckAndRequestKinds) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 0;
    p.on_count(3, 0, now);
    p.on_item(item(0, 16, 0, 0, 0.0f), now);
    // Item 2 before item 1: item 1 asked for again.
    Reply r = p.on_item(item(2, 16, 71360000, -731190000, 50.0f), now);
    EXPECT_EQ(r.kind, Reply::kRequestInt);
    EXPECT_EQ(r.seq, 1u);
    p.on_item(item(1, 16, 71360000, -731190000, 50.0f), now);
    r = p.on_item(item(2, 16, 71370000, -731190000, 50.0f), now);
    EXPECT_EQ(r.result, Result::kAccepted);
    // Our ACK lost: the last item again gets the ACK again, and changes nothing.
    r = p.on_item(item(2, 16, 71370000, -731190000, 50.0f), now);
    EXPECT_EQ(r.kind, Reply::kAck);
    EXPECT_EQ(r.result, Result::kAccepted);
    EXPECT_EQ(p.changes(), 1u);
    // A station silent from the start is asked both ways in turn.
    p.on_count(2, 0, now);
    EXPECT_EQ(p.tick(now += 1500).kind, Reply::kRequest);
    EXPECT_EQ(p.tick(now += 1500).kind, Reply::kRequestInt);
}

TEST(MissionProtocol, ClearSetCurrentFenceAndRally) {
    testmission::Fixture f;
    mission::MissionProtocol p(f.store);
    uint32_t now = 0;
    upload(p, route(true), now);
    Reply r = p.on_set_current(3);
    EXPECT_EQ(r.kind, Reply::kCurrent);
    EXPECT_EQ(r.seq, 3u);
    EXPECT_EQ(p.on_set_current(9).kind, Reply::kNone);
    EXPECT_EQ(p.on_set_current(0).kind, Reply::kNone);
    r = p.on_clear_all(0);
    EXPECT_EQ(r.result, Result::kAccepted);
    EXPECT_EQ(p.on_request_list(0).seq, 1u);  // home alone
    EXPECT_EQ(p.changes(), 2u);
    // A count of 0 clears too.
    upload(p, route(true), now);
    EXPECT_EQ(p.on_count(0, 0, now).result, Result::kAccepted);
    EXPECT_EQ(f.store.count(), 0u);
    // Fence (1) and rally (2): empty lists; their uploads refused.
    r = p.on_request_list(1);
    EXPECT_EQ(r.kind, Reply::kCount);
    EXPECT_EQ(r.seq, 0u);
    EXPECT_EQ(r.mission_type, 1u);
    r = p.on_count(4, 2, now);
    EXPECT_EQ(r.result, Result::kUnsupported);
    EXPECT_EQ(r.mission_type, 2u);
}

// MAVProxy's `guided LAT LON ALT`: MISSION_ITEM_INT seq 0, NAV_WAYPOINT, current 2, its
// frame (above home by default, AMSL when set). A place and a height; nothing else flies.
TEST(MissionProtocol, GuidedRequestIsAPlaceAndAHeight) {
    mission::Item g = item(0, 16, 71370450, -731170000, 45.0f);
    EXPECT_FALSE(mission::is_guided_request(g));  // an upload's item
    g.current = 2;
    EXPECT_TRUE(mission::is_guided_request(g));
    mission::Command c;
    Result why = Result::kAccepted;
    ASSERT_TRUE(mission::guided_command(g, c, why));
    EXPECT_EQ(c.lat_e7, 71370450);
    EXPECT_EQ(c.lon_e7, -731170000);
    EXPECT_EQ(c.alt_cm, 4500);
    EXPECT_TRUE(c.relative_alt);
    mission::Item amsl = item(0, 16, 71370450, -731170000, 1100.0f, false, mission::kFrameGlobal);
    amsl.current = 2;
    ASSERT_TRUE(mission::guided_command(amsl, c, why));
    EXPECT_FALSE(c.relative_alt);
    EXPECT_EQ(c.alt_cm, 110000);
    mission::Item fence = g;
    fence.mission_type = 1;
    EXPECT_FALSE(mission::is_guided_request(fence));
    // Refused: no place, a DO command, a frame the board does not take.
    mission::Item none = item(0, 16, 0, 0, 45.0f);
    EXPECT_FALSE(mission::guided_command(none, c, why));
    EXPECT_EQ(why, Result::kUnsupported);
    mission::Item jump = item(0, 177, 0, 0, 0.0f, true, mission::kFrameMission);
    EXPECT_FALSE(mission::guided_command(jump, c, why));
    mission::Item body = item(0, 16, 71370450, -731170000, 45.0f, true, 11);  // TERRAIN_ALT_INT: AGL
    EXPECT_FALSE(mission::guided_command(body, c, why));
    EXPECT_EQ(why, Result::kUnsupportedFrame);
}

}  // namespace
