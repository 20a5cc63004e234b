// SPDX-License-Identifier: GPL-3.0-or-later
// lib/Mission/MissionCommand and MissionStore: the 14-byte packing both ways, the refused
// bytes, the two areas' layout within the EEPROM's mission bytes, and power cut at every
// byte of an upload (and within the byte, leaving garbage): the mission before it or the
// new one, whole, and never anything else.
#include <gtest/gtest.h>

#include <string.h>

#include <vector>

#include "FakeEeprom.h"
#include "MissionCommand.h"
#include "MissionStore.h"

namespace {

mission::Command waypoint(int32_t lat_e7, int32_t lon_e7, int32_t alt_cm) {
    mission::Command c;
    c.id = mission::kNavWaypoint;
    c.lat_e7 = lat_e7;
    c.lon_e7 = lon_e7;
    c.alt_cm = alt_cm;
    return c;
}

bool same(const mission::Command& a, const mission::Command& b) {
    return a.id == b.id && a.p1 == b.p1 && a.lat_e7 == b.lat_e7 && a.lon_e7 == b.lon_e7 && a.alt_cm == b.alt_cm &&
           a.relative_alt == b.relative_alt && a.loiter_ccw == b.loiter_ccw;
}

TEST(MissionCommand, PacksIntoFourteenBytesBothWays) {
    mission::Command c;
    c.id = mission::kNavLoiterTurns;
    c.p1 = (uint16_t)((80u << 8) | 3u);
    c.lat_e7 = -71350450;
    c.lon_e7 = -1794000001;
    c.alt_cm = -123456;
    c.relative_alt = false;
    c.loiter_ccw = true;
    uint8_t bytes[mission::kCommandBytes];
    mission::pack(c, bytes);
    EXPECT_EQ(bytes[0], 2u | 0x20u);  // code 2, counter-clockwise, absolute height
    mission::Command back;
    ASSERT_TRUE(mission::unpack(bytes, back));
    EXPECT_TRUE(same(c, back));
    EXPECT_EQ(mission::loiter_turns(back), 3u);
    EXPECT_EQ(mission::loiter_turns_radius_m(back), 80u);
    // Heights beyond the int24 are held at its end.
    c.alt_cm = 9000000;
    mission::pack(c, bytes);
    ASSERT_TRUE(mission::unpack(bytes, back));
    EXPECT_EQ(back.alt_cm, mission::kAltMaxCm);
    // Every supported id round trips; erased bytes and unknown codes do not unpack.
    for (uint16_t id : {16, 17, 18, 19, 20, 22, 177, 178}) {
        c.id = id;
        mission::pack(c, bytes);
        ASSERT_TRUE(mission::unpack(bytes, back));
        EXPECT_EQ(back.id, id);
        EXPECT_TRUE(mission::is_supported(id));
        EXPECT_EQ(mission::is_nav(id), id < 100);
    }
    uint8_t erased[mission::kCommandBytes];
    memset(erased, 0xFF, sizeof erased);
    EXPECT_FALSE(mission::unpack(erased, back));
    bytes[0] = 8;
    EXPECT_FALSE(mission::unpack(bytes, back));
    for (uint16_t id : {21, 0, 82, 183, 115, 16 + 256}) EXPECT_FALSE(mission::is_supported(id)) << id;
}

TEST(MissionStore, AreasFitTheEepromAboveTheSettings) {
    EXPECT_EQ(mission::area_address(0), 1284u);
    EXPECT_EQ(mission::area_address(1), 2690u);
    EXPECT_EQ(mission::area_address(1) + mission::kAreaSize, 4096u);
    // Nothing written outside the mission's bytes by a full upload and a clear.
    testeeprom::FakeEeprom e;
    mission::MissionStore store(e.port());
    EXPECT_FALSE(store.load());
    EXPECT_EQ(store.count(), 0u);
    for (int round = 0; round < 3; ++round) {
        store.begin_upload();
        for (uint8_t i = 0; i < mission::kMaxCommands; ++i) store.write(i, waypoint(i, -i, 100 * i));
        store.commit(mission::kMaxCommands);
    }
    for (uint16_t a = 0; a < mission::kMissionStart; ++a) ASSERT_EQ(e.bytes[a], 0xFFu) << a;
    mission::MissionStore again(e.port());
    ASSERT_TRUE(again.load());
    EXPECT_EQ(again.count(), mission::kMaxCommands);
    mission::Command c;
    ASSERT_TRUE(again.read(99, c));
    EXPECT_TRUE(same(c, waypoint(99, -99, 9900)));
    EXPECT_FALSE(again.read(100, c));
}

TEST(MissionStore, UploadsAlternateAndTheNewerWins) {
    testeeprom::FakeEeprom e;
    mission::MissionStore store(e.port());
    store.load();
    store.begin_upload();
    store.write(0, waypoint(1, 1, 100));
    store.commit(1);
    EXPECT_EQ(store.current_area(), 0u);
    store.begin_upload();
    store.write(0, waypoint(2, 2, 200));
    store.write(1, waypoint(3, 3, 300));
    store.commit(2);
    EXPECT_EQ(store.current_area(), 1u);
    EXPECT_EQ(store.count(), 2u);
    mission::MissionStore fresh(e.port());
    ASSERT_TRUE(fresh.load());
    EXPECT_EQ(fresh.current_area(), 1u);
    EXPECT_EQ(fresh.count(), 2u);
    // Cleared: an empty mission committed.
    store.begin_upload();
    store.commit(0);
    mission::MissionStore cleared(e.port());
    ASSERT_TRUE(cleared.load());
    EXPECT_EQ(cleared.count(), 0u);
    // A worn byte in the current area: its CRC fails, the other (older) one stands.
    e.bytes[mission::area_address(0) + 3] ^= 0x01;  // the count of the empty mission
    mission::MissionStore worn(e.port());
    ASSERT_TRUE(worn.load());
    EXPECT_EQ(worn.count(), 2u);
}

// The firmware's commit (set_stepped): the same bytes written in the same order as the
// commit at once, no step reading more than kStepBytes of commands (plus the header's 6),
// the mission before current until the last step.
struct CountingEeprom : testeeprom::FakeEeprom {
    uint32_t reads = 0;
    std::vector<uint16_t> order;  // the addresses written, in order
    static uint8_t count_read(void* ctx, uint16_t a) {
        ++static_cast<CountingEeprom*>(ctx)->reads;
        return read(ctx, a);
    }
    static void log_write(void* ctx, uint16_t a, uint8_t v) {
        static_cast<CountingEeprom*>(ctx)->order.push_back(a);
        write(ctx, a, v);
    }
    mission::Eeprom counting() { return mission::Eeprom{this, &count_read, &log_write}; }
};

TEST(MissionStore, SteppedCommitWritesWhatTheWholeOneDoesAPartAStep) {
    CountingEeprom whole, stepped;
    mission::MissionStore a(whole.counting()), b(stepped.counting());
    b.set_stepped(true);
    for (mission::MissionStore* s : {&a, &b}) {
        s->load();
        s->begin_upload();
        s->write(0, waypoint(7, 7, 700));
        s->commit(1);
    }
    while (!b.commit_step()) {}
    ASSERT_EQ(b.count(), 1u);
    for (mission::MissionStore* s : {&a, &b}) {
        s->begin_upload();
        for (uint8_t i = 0; i < mission::kMaxCommands; ++i) s->write(i, waypoint(i, -i, 100 * i));
    }
    a.commit(mission::kMaxCommands);
    stepped.reads = 0;
    b.commit(mission::kMaxCommands);
    EXPECT_TRUE(b.committing());
    EXPECT_EQ(stepped.reads, 0u) << "commit() only starts it";
    uint32_t steps = 0;
    bool done = false;
    while (!done) {
        stepped.reads = 0;
        done = b.commit_step();
        ++steps;
        EXPECT_LE(stepped.reads, (uint32_t)mission::MissionStore::kStepBytes + mission::kHeaderBytes) << steps;
        if (!done) EXPECT_EQ(b.count(), 1u) << "the mission before stays current until the end";
    }
    EXPECT_FALSE(b.committing());
    // 1400 bytes summed and read back, 64 a step: 22 + 22, the header, the marker.
    EXPECT_EQ(steps, 46u);
    EXPECT_EQ(b.count(), mission::kMaxCommands);
    EXPECT_EQ(a.count(), mission::kMaxCommands);
    EXPECT_EQ(whole.order, stepped.order);
    EXPECT_EQ(0, memcmp(whole.bytes, stepped.bytes, sizeof whole.bytes));
    mission::Command c;
    ASSERT_TRUE(b.read(99, c));
    EXPECT_TRUE(same(c, waypoint(99, -99, 9900)));
    EXPECT_TRUE(b.commit_step()) << "none under way";
}

// Uploads 5 new commands over a store holding 3 old ones (and, in the area the upload
// writes, an older mission of 2 that must never come back), with the power cut after
// `cut` writes; then a fresh start must find the old mission or the new one, whole.
void check_cut(uint32_t cut, int garbage, uint32_t& total_writes, bool& saw_new) {
    testeeprom::FakeEeprom e;
    mission::MissionStore store(e.port());
    store.load();
    store.begin_upload();
    for (uint8_t i = 0; i < 2; ++i) store.write(i, waypoint(50 + i, 50 + i, 500));
    store.commit(2);
    store.begin_upload();
    for (uint8_t i = 0; i < 3; ++i) store.write(i, waypoint(100 + i, 100 + i, 1000));
    store.commit(3);
    const uint32_t before = e.writes;
    e.power_after = before + cut;
    e.garbage = garbage;
    store.begin_upload();
    for (uint8_t i = 0; i < 5; ++i) store.write(i, waypoint(200 + i, 200 + i, 2000));
    store.commit(5);
    total_writes = e.writes - before;

    e.power_after = UINT32_MAX;
    mission::MissionStore after(e.port());
    ASSERT_TRUE(after.load()) << "cut after " << cut;
    mission::Command c;
    if (after.count() == 3) {
        for (uint8_t i = 0; i < 3; ++i) {
            ASSERT_TRUE(after.read(i, c));
            EXPECT_TRUE(same(c, waypoint(100 + i, 100 + i, 1000))) << "cut after " << cut;
        }
    } else {
        ASSERT_EQ(after.count(), 5u) << "cut after " << cut;
        for (uint8_t i = 0; i < 5; ++i) {
            ASSERT_TRUE(after.read(i, c));
            EXPECT_TRUE(same(c, waypoint(200 + i, 200 + i, 2000))) << "cut after " << cut;
        }
        saw_new = true;
    }
}

TEST(MissionStore, PowerCutAtEveryByteLeavesOneWholeMission) {
    uint32_t total = 0;
    bool saw_new = false;
    check_cut(UINT32_MAX - 1000, -1, total, saw_new);
    ASSERT_TRUE(saw_new);
    ASSERT_EQ(total, 1u + 5u * 14u + 6u);  // the marker erased, the commands, the header
    for (uint32_t cut = 0; cut <= total; ++cut) {
        for (int garbage : {-1, 0x00, 0xA5, 0x5A}) {
            bool new_one = false;
            uint32_t n = 0;
            check_cut(cut, garbage, n, new_one);
            // The new mission only once its marker is written (the last byte), whole.
            if (cut < total - 1 || (cut == total - 1 && garbage != 0xA5)) EXPECT_FALSE(new_one) << cut;
            if (cut == total) EXPECT_TRUE(new_one);
        }
    }
}

}  // namespace
