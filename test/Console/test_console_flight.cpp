// SPDX-License-Identifier: GPL-3.0-or-later
// The console's flight commands (lib/Console): set, get, flight, rc, servo, params parsed,
// queued and answered.
#include <gtest/gtest.h>

#include <string>

#include "Console.h"
#include "Params.h"
#include "Settings.h"

TEST(FlightConsole, SetGetFlightShowParse) {
    console::Command c = console::parse_line("set RLL2SRV_P 0.55");
    ASSERT_EQ(c.id, console::CommandId::Set);
    EXPECT_EQ(c.arg, params::find("RLL2SRV_P"));
    EXPECT_EQ(c.value, 5500);
    c = console::parse_line("set servo1_min 1100");
    ASSERT_EQ(c.id, console::CommandId::Set);
    EXPECT_EQ(c.value, 1100 * console::kParamScale);
    EXPECT_EQ(console::parse_line("set SERVO1_MIN 1100.5").error, console::Error::ParamRange);
    EXPECT_EQ(console::parse_line("set SERVO1_MIN 3000").error, console::Error::ParamRange);
    EXPECT_EQ(console::parse_line("set NOPE 1").error, console::Error::UnknownParam);
    EXPECT_EQ(console::parse_line("set RLL2SRV_P").error, console::Error::MissingArgument);
    EXPECT_EQ(console::parse_line("set RLL2SRV_P x").error, console::Error::BadNumber);
    EXPECT_EQ(console::parse_line("get LIM_ROLL_CD").id, console::CommandId::Get);
    EXPECT_EQ(console::parse_line("flight stabilize").arg, 1);
    EXPECT_EQ(console::parse_line("flight manual").arg, 0);
    EXPECT_EQ(console::parse_line("flight acro").error, console::Error::BadFlightMode);
    EXPECT_EQ(console::parse_line("flight FBWA").arg, 2);  // the row of lib/Flight/Modes.h
    c = console::parse_line("arm");
    EXPECT_EQ(c.id, console::CommandId::Flight);
    EXPECT_EQ(c.arg, console::kArm);
    EXPECT_EQ(console::parse_line("DISARM").arg, console::kDisarm);
    EXPECT_EQ(console::parse_line("arm now").error, console::Error::ExtraArgument);
    c = console::parse_line("set FLTMODE3 4");
    EXPECT_EQ(c.error, console::Error::NoSuchMode);
    EXPECT_EQ(c.arg, params::find("FLTMODE3"));
    EXPECT_EQ(console::parse_line("set FLTMODE3 5").id, console::CommandId::Set);
    EXPECT_EQ(console::parse_line("rc").arg, console::kShowRc);
    EXPECT_EQ(console::parse_line("servo").arg, console::kShowServo);
    EXPECT_EQ(console::parse_line("params").arg, console::kShowParams);
    EXPECT_EQ(console::parse_line("GPS").id, console::CommandId::Show);
    EXPECT_EQ(console::parse_line("gps").arg, console::kShowGps);
    EXPECT_EQ(console::parse_line("gps now").error, console::Error::ExtraArgument);
    EXPECT_EQ(console::parse_line("baro").id, console::CommandId::Show);
    EXPECT_EQ(console::parse_line("BARO").arg, console::kShowBaro);
    EXPECT_EQ(console::parse_line("baro 1").error, console::Error::ExtraArgument);
    EXPECT_EQ(console::parse_line("Mission").id, console::CommandId::Show);
    EXPECT_EQ(console::parse_line("mission").arg, console::kShowMission);
    EXPECT_EQ(console::parse_line("mission 2").error, console::Error::ExtraArgument);
    EXPECT_EQ(console::parse_line("arm").arg, console::kArm);  // the words after mission keep theirs
    EXPECT_EQ(console::parse_line("disarm").arg, console::kDisarm);
    EXPECT_EQ(console::parse_line("rate 5").value, 5);  // the words after gps and baro keep their ids
    EXPECT_EQ(console::parse_line("rc 1").error, console::Error::ExtraArgument);
    // Through the queue, across the ring's wrap.
    console::CommandQueue q;
    for (int round = 0; round < 30; ++round) {
        for (const char* line : {"set RLL2SRV_D -0.0", "set LIM_PITCH_MIN -2000", "get RC8_TRIM", "flight stabilize",
                                 "servo", "set RC1_MIN 3000", "params", "gps", "baro", "arm", "disarm",
                                 "flight fbwa", "set FLTMODE2 1"}) {
            const console::Command in = console::parse_line(line);
            ASSERT_TRUE(q.push(in));
            const console::Command back = q.pop();
            EXPECT_EQ(back.id, in.id) << line;
            EXPECT_EQ(back.error, in.error) << line;
            EXPECT_EQ(back.arg, in.arg) << line;
            EXPECT_EQ(back.value, in.value) << line;
        }
    }
}

TEST(FlightConsole, SetAndGetReplies) {
    std::string out;
    const text::Sink sink{&out, [](void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }};
    settings::Settings s = settings::defaults();
    EXPECT_TRUE(console::apply_setting(console::parse_line("set ptch2srv_p 0.7"), s, &sink));
    EXPECT_EQ(out, "# PTCH2SRV_P 0.7000\n");
    out.clear();
    console::apply_setting(console::parse_line("get RC3_MAX"), s, &sink);
    EXPECT_EQ(out, "# RC3_MAX 2000\n");
    out.clear();
    console::apply_setting(console::parse_line("set SERVO1_MIN 1600"), s, &sink);
    EXPECT_NE(out.find("# error: SERVO1_MIN"), std::string::npos) << out;
    EXPECT_EQ(s.flight.servo[0].min_us, 1000);
    out.clear();
    console::print_error(console::parse_line("set RLL2SRV_P 9"), &sink);
    EXPECT_EQ(out, "# error: RLL2SRV_P must be 0.1000..4.0000; nothing changed\n");
    out.clear();
    console::print_error(console::parse_line("set FLTMODE2 4"), &sink);
    EXPECT_EQ(out, "# error: FLTMODE2 must be a mode of this board: 0 manual, 2 stabilize, 5 fbwa, 1 circle, 6 fbwb, "
                   "7 cruise, 10 auto, 11 rtl, 12 loiter, 15 guided; nothing changed\n");
    out.clear();
    console::print_error(console::parse_line("flight acro"), &sink);
    EXPECT_EQ(out, "# error: flight manual or stabilize or fbwa or circle or fbwb or cruise or auto or rtl or loiter "
                   "or guided; nothing changed\n");
}
