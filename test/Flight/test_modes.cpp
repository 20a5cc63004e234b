// SPDX-License-Identifier: GPL-3.0-or-later
// The modes the board has (lib/Flight/Modes.h): ArduPlane's numbers and names, looked up
// both ways; FLTMODEn takes only these (lib/Settings).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "Modes.h"
#include "Params.h"
#include "Settings.h"

TEST(Modes, ArduPlanesNumbersAndNames) {
    const struct {
        uint8_t number;
        const char* name;
        flight::Law law;
    } want[] = {{0, "MANUAL", flight::Law::PassThrough}, {2, "STABILIZE", flight::Law::Attitude},
                {5, "FBWA", flight::Law::Attitude},        {1, "CIRCLE", flight::Law::NavigateOn},
                {6, "FBWB", flight::Law::Navigate},        {7, "CRUISE", flight::Law::Navigate},
                {10, "AUTO", flight::Law::NavigateOn},     {11, "RTL", flight::Law::NavigateOn},
                {12, "LOITER", flight::Law::NavigateOn},   {15, "GUIDED", flight::Law::NavigateOn}};
    ASSERT_EQ(flight::kModeCount, 10u);
    for (uint8_t i = 0; i < flight::kModeCount; ++i) {
        char name[flight::kModeNameMax + 1];
        flight::mode_name(i, name);
        EXPECT_STREQ(name, want[i].name);
        EXPECT_EQ(flight::mode_number(i), want[i].number);
        EXPECT_EQ(flight::mode_law(i), want[i].law);
        EXPECT_EQ(flight::mode_index(want[i].number), (int8_t)i);
        std::string lower(want[i].name);
        for (char& c : lower) c = (char)std::tolower(c);
        EXPECT_EQ(flight::mode_by_name(lower.c_str()), (int8_t)i);
        EXPECT_EQ(flight::mode_by_name(want[i].name), (int8_t)i);
    }
    for (uint8_t n : {3, 4, 8, 9, 13, 14, 16, 255}) EXPECT_FALSE(flight::mode_known(n)) << (int)n;
    EXPECT_EQ(flight::mode_by_name("fbw"), -1);
    EXPECT_EQ(flight::mode_by_name("fbwab"), -1);
    EXPECT_EQ(flight::mode_by_name("stabilizer"), -1);
    EXPECT_EQ(flight::mode_by_name(""), -1);
}

TEST(Modes, FltmodeTakesOnlyTheBoardsModes) {
    settings::Settings s = settings::defaults();
    for (const char* name : {"FLTMODE1", "FLTMODE4", "FLTMODE6"}) {
        const int16_t i = params::find(name);
        ASSERT_GE(i, 0);
        EXPECT_TRUE(params::is_flight_mode((uint16_t)i));
        EXPECT_TRUE(params::set(s, (uint16_t)i, 5.0f)) << name;
        EXPECT_EQ(params::get(s, (uint16_t)i), 5.0f);
        EXPECT_FALSE(params::set(s, (uint16_t)i, 4.0f)) << name << ": ACRO is not on this board";
        EXPECT_FALSE(params::set(s, (uint16_t)i, 8.0f)) << name << ": AUTOTUNE is not on this board";
        EXPECT_TRUE(params::set(s, (uint16_t)i, 15.0f)) << name << ": GUIDED";
        EXPECT_TRUE(params::set(s, (uint16_t)i, 11.0f)) << name;
        EXPECT_TRUE(params::set(s, (uint16_t)i, 5.0f)) << name;
        EXPECT_FALSE(params::set(s, (uint16_t)i, 3.0f)) << name;
        EXPECT_EQ(params::get(s, (uint16_t)i), 5.0f) << "nothing changed";
        EXPECT_TRUE(params::set(s, (uint16_t)i, 0.0f));
    }
    EXPECT_FALSE(params::is_flight_mode((uint16_t)params::find("FLTMODE_CH")));
    EXPECT_FALSE(params::is_flight_mode((uint16_t)params::find("RCMAP_ROLL")));
    // A record that holds a number the board lacks (an older firmware's) still loads.
    s.flight.fltmode[2] = 4;
    EXPECT_TRUE(params::all_valid(s));
}
