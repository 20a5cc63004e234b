// SPDX-License-Identifier: GPL-3.0-or-later
// apm25sim's --fault language (sim/harness/FaultSpec): the grammar, any number of
// windows per kind, and an error for an overlap or a malformed SPEC.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "FaultSpec.h"
#include "Trajectory.h"

namespace {

struct Parts {
    sim::Trajectory trajectory;
    sim::Mpu6000Model mpu{trajectory};
    sim::Hmc5883Model mag{trajectory};
    sim::BusFaults bus;
    std::string error;
    bool apply(const std::string& spec) {
        error.clear();
        return sim::apply_fault_spec(spec, mpu, mag, bus, error);
    }
};

TEST(FaultSpec, SplitsTargetKindValueAndWindow) {
    sim::FaultSpec f;
    std::string error;
    ASSERT_TRUE(sim::parse_fault_spec("mpu:absent@2.5-3", f, error)) << error;
    EXPECT_EQ(f.what, "mpu:absent");
    EXPECT_FALSE(f.has_value);
    EXPECT_TRUE(f.has_window);
    EXPECT_DOUBLE_EQ(f.window.start_s, 2.5);
    EXPECT_DOUBLE_EQ(f.window.end_s, 3.0);

    ASSERT_TRUE(sim::parse_fault_spec("mpu:whoami=0x70", f, error)) << error;
    EXPECT_EQ(f.what, "mpu:whoami");
    EXPECT_TRUE(f.has_value);
    EXPECT_EQ(f.value, "0x70");
    EXPECT_FALSE(f.has_window);
    EXPECT_TRUE(f.window.active(0.0));
    EXPECT_TRUE(f.window.active(1e9));

    ASSERT_TRUE(sim::parse_fault_spec("mag:overflow@.5", f, error)) << error;
    EXPECT_DOUBLE_EQ(f.window.start_s, 0.5);
    EXPECT_FALSE(f.window.active(0.49));
    EXPECT_TRUE(f.window.active(1e9));
}

TEST(FaultSpec, MalformedSpecsAreErrorsNamingTheSpec) {
    const char* bad[] = {
        "",  "mpu",  ":absent",  "mpu:",  "mpu:absent@",  "mpu:absent@-1",  "mpu:absent@+1",
        "mpu:absent@2-",  "mpu:absent@3-2",  "mpu:absent@2-2",  "mpu:absent@nan",  "mpu:absent@inf",
        "mpu:absent@1e3",  "mpu:absent@2-3x",  "mpu:absent@2@3",  "mpu:absent@ 2",  "mpu:absent@2..3",
        "mpu:absent=",  "mpu:absent@2-3-4",  "@2:mpu",  "mpu:whoami=",
    };
    for (const char* spec : bad) {
        sim::FaultSpec f;
        std::string error;
        EXPECT_FALSE(sim::parse_fault_spec(spec, f, error)) << "'" << spec << "' was accepted";
        EXPECT_NE(error.find(std::string("'") + spec + "'"), std::string::npos) << error;
    }
}

TEST(FaultSpec, ManyWindowsOfOneKindAllHold) {
    Parts p;
    ASSERT_TRUE(p.apply("mpu:absent@2-3")) << p.error;
    ASSERT_TRUE(p.apply("mpu:absent@4.5-4.6")) << p.error;
    ASSERT_TRUE(p.apply("mpu:absent@3-4")) << p.error;  // touching [2,3) is no overlap
    ASSERT_TRUE(p.apply("mpu:absent@10")) << p.error;
    const sim::TimeWindows& w = p.mpu.faults().absent;
    EXPECT_EQ(w.windows().size(), 4u);
    EXPECT_FALSE(w.active(1.99));
    EXPECT_TRUE(w.active(2.0));
    EXPECT_TRUE(w.active(3.5));
    EXPECT_FALSE(w.active(4.0));
    EXPECT_TRUE(w.active(4.55));
    EXPECT_FALSE(w.active(4.6));
    EXPECT_FALSE(w.active(9.99));
    EXPECT_TRUE(w.active(1e6));
    // Other kinds untouched.
    EXPECT_FALSE(p.mpu.faults().frozen.ever());
    EXPECT_FALSE(p.mag.faults().absent.ever());
}

TEST(FaultSpec, EveryWindowedKindReachesItsField) {
    Parts p;
    const std::vector<std::pair<std::string, const sim::TimeWindows*>> kinds = {
        {"mpu:absent", &p.mpu.faults().absent},
        {"mpu:int-stuck-low", &p.mpu.faults().int_stuck_low},
        {"mpu:frozen", &p.mpu.faults().frozen},
        {"gyro:saturate", &p.mpu.faults().gyro_saturate},
        {"accel:saturate", &p.mpu.faults().accel_saturate},
        {"imu:spike", &p.mpu.faults().spike},
        {"mag:absent", &p.mag.faults().absent},
        {"mag:overflow", &p.mag.faults().overflow},
        {"mag:spike", &p.mag.faults().spike},
        {"mag:drdy-stuck-low", &p.mag.faults().drdy_stuck_low},
        {"mag:drdy-stuck-high", &p.mag.faults().drdy_stuck_high},
        {"i2c:sda-low", &p.bus.i2c_sda_low},
    };
    for (const auto& k : kinds) {
        ASSERT_TRUE(p.apply(k.first + "@1-2")) << p.error;
        ASSERT_TRUE(p.apply(k.first + "@5-6")) << p.error;
        EXPECT_EQ(k.second->windows().size(), 2u) << k.first;
        EXPECT_TRUE(k.second->active(1.5) && k.second->active(5.5)) << k.first;
        EXPECT_FALSE(k.second->active(3.0)) << k.first;
        EXPECT_FALSE(p.apply(k.first + "=1@7-8")) << k.first << " took a value";
    }
}

TEST(FaultSpec, OverlappingWindowsOfOneKindAreRefused) {
    Parts p;
    ASSERT_TRUE(p.apply("mag:absent@2-3")) << p.error;
    EXPECT_FALSE(p.apply("mag:absent@2.5-4"));
    EXPECT_NE(p.error.find("overlaps"), std::string::npos) << p.error;
    EXPECT_FALSE(p.apply("mag:absent@1-2.01"));
    EXPECT_FALSE(p.apply("mag:absent@1"));    // from 1 s to the end covers [2,3)
    EXPECT_FALSE(p.apply("mag:absent"));      // the whole run
    EXPECT_FALSE(p.apply("mag:absent@2-3"));  // the same window twice
    // Refused SPECs change nothing.
    EXPECT_EQ(p.mag.faults().absent.windows().size(), 1u);
    EXPECT_FALSE(p.mag.faults().absent.active(3.5));
    // Overlap across kinds is fine (two faults at once).
    EXPECT_TRUE(p.apply("mpu:absent@2-3")) << p.error;
    EXPECT_TRUE(p.apply("mag:overflow@2-3")) << p.error;
}

TEST(FaultSpec, IdentityFaultsHoldForTheWholeRunOnce) {
    Parts p;
    ASSERT_TRUE(p.apply("mpu:whoami=0x70")) << p.error;
    EXPECT_EQ(p.mpu.faults().who_am_i, 0x70);
    EXPECT_FALSE(p.apply("mpu:whoami=0x71"));  // twice
    EXPECT_EQ(p.mpu.faults().who_am_i, 0x70);
    EXPECT_FALSE(p.apply("mpu:whoami=256"));
    EXPECT_FALSE(p.apply("mag:id=H44@1-2"));  // a window would be ignored: refused
    EXPECT_FALSE(p.apply("mag:id=H4"));
    ASSERT_TRUE(p.apply("mag:id=H44")) << p.error;
    EXPECT_EQ(p.mag.faults().id[2], '4');
    EXPECT_FALSE(p.apply("mag:id=ABC"));
}

TEST(FaultSpec, UnknownKindIsAnError) {
    Parts p;
    EXPECT_FALSE(p.apply("mpu:melted@1-2"));
    EXPECT_NE(p.error.find("unknown"), std::string::npos) << p.error;
    EXPECT_FALSE(p.apply("baro:absent"));
}

}  // namespace
