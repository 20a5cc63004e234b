// SPDX-License-Identifier: GPL-3.0-or-later
// apm25sim --mission (sim/models/MissionFile): a QGC WPL 110 file into the EEPROM image, by
// lib/Mission's from_item and MissionStore's upload: the firmware's store reads it back.
#include <gtest/gtest.h>

#include <vector>

#include "MissionFile.h"
#include "MissionStore.h"

namespace {

uint8_t rd(void* ctx, uint16_t a) { return (*static_cast<std::vector<uint8_t>*>(ctx))[a]; }
void wr(void* ctx, uint16_t a, uint8_t v) { (*static_cast<std::vector<uint8_t>*>(ctx))[a] = v; }

const char* kRectangle =
    "QGC WPL 110\n"
    "0\t1\t0\t16\t0\t0\t0\t0\t7.1350450\t-73.1194210\t1028.0\t1\n"
    "1\t0\t3\t16\t0\t0\t0\t0\t7.1380000\t-73.1194210\t40.0\t1\n"
    "2\t0\t3\t16\t0\t0\t0\t0\t7.1380000\t-73.1160000\t40.0\t1\n"
    "3\t0\t3\t177\t1\t-1\t0\t0\t0\t0\t0\t1\n";

TEST(MissionFile, ARectangleGoesInAsTheFirmwaresStoreReadsIt) {
    std::vector<uint8_t> eeprom(4096, 0xFF);
    std::string error;
    ASSERT_TRUE(sim::write_mission_text(kRectangle, eeprom, error)) << error;
    mission::MissionStore store(mission::Eeprom{&eeprom, rd, wr});
    ASSERT_TRUE(store.load());
    ASSERT_EQ(store.count(), 3u) << "home (seq 0) is not stored";
    mission::Command c;
    ASSERT_TRUE(store.read(1, c));
    EXPECT_EQ(c.id, 16u);
    EXPECT_EQ(c.lat_e7, 71380000);
    EXPECT_EQ(c.lon_e7, -731160000);
    EXPECT_EQ(c.alt_cm, 4000);
    EXPECT_TRUE(c.relative_alt);
    ASSERT_TRUE(store.read(2, c));
    EXPECT_EQ(c.id, 177u);
    // A second file replaces it (the other area), as an upload would.
    const uint8_t area = store.current_area();
    ASSERT_TRUE(sim::write_mission_text("QGC WPL 110\n0 1 0 16 0 0 0 0 0 0 0 1\n1 0 3 16 0 0 0 0 7.1 -73.1 50 1\n",
                                        eeprom, error))
        << error;
    ASSERT_TRUE(store.load());
    EXPECT_EQ(store.count(), 1u);
    EXPECT_NE(store.current_area(), area);
    // The settings' bytes below the mission are never touched.
    for (uint16_t a = 0; a < mission::kMissionStart; ++a) ASSERT_EQ(eeprom[a], 0xFFu) << a;
}

TEST(MissionFile, RefusesWhatTheUploadWouldWithTheLine) {
    std::vector<uint8_t> eeprom(4096, 0xFF);
    std::string error;
    EXPECT_FALSE(sim::write_mission_text("QGC WPL 120\n", eeprom, error));
    EXPECT_NE(error.find("QGC WPL 110"), std::string::npos) << error;
    EXPECT_FALSE(sim::write_mission_text("QGC WPL 110\n0 1 0 16 0 0 0 0 0 0 0 1\n1 0 3 21 0 0 0 0 7.1 -73.1 0 1\n",
                                         eeprom, error));
    EXPECT_NE(error.find("line 3: command 21"), std::string::npos) << error;  // NAV_LAND
    EXPECT_FALSE(sim::write_mission_text("QGC WPL 110\n0 1 0 16 0 0 0 0 0 0 0 1\n2 0 3 16 0 0 0 0 7 -73 9 1\n",
                                         eeprom, error));
    EXPECT_NE(error.find("out of order"), std::string::npos) << error;
    EXPECT_FALSE(sim::write_mission_text("QGC WPL 110\n0 1 0 16 0 0 0\n", eeprom, error));
    EXPECT_NE(error.find("12 numbers"), std::string::npos) << error;
    for (uint8_t b : eeprom) ASSERT_EQ(b, 0xFFu) << "a refused file writes nothing";
}

}  // namespace
