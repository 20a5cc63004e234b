// SPDX-License-Identifier: GPL-3.0-or-later
// The --fault language's GPS and barometer kinds (sim/harness/FaultSpec.h).
#include <gtest/gtest.h>

#include "FaultSpec.h"
#include "sim_models_support.h"

namespace {

struct Parts {
    sim::Trajectory trajectory;
    sim::Mpu6000Model mpu;
    sim::Hmc5883Model mag;
    sim::BusFaults bus;
    sim::UbloxModel gps;
    sim::Ms5611Model baro;
    Parts()
        : trajectory(rest()), mpu(trajectory), mag(trajectory), gps(trajectory, sim::UbloxOptions()),
          baro(trajectory, sim::Ms5611Options()) {}
    static sim::Trajectory rest() {
        const double still[3] = {0, 0, 0};
        return simtest::moving_trajectory(1.0, still);
    }
    sim::FaultTargets targets(bool with_gps = true, bool with_baro = true) {
        sim::FaultTargets t;
        t.mpu = &mpu;
        t.mag = &mag;
        t.bus = &bus;
        t.gps = with_gps ? &gps.faults() : nullptr;
        t.baro = with_baro ? &baro.faults() : nullptr;
        return t;
    }
};

TEST(FaultSpecGpsBaro, WindowsReachTheModels) {
    Parts p;
    std::string error;
    for (const char* spec : {"gps:no-fix@20-30", "gps:silent@40-41", "gps:deaf", "gps:garbage@5-6",
                             "baro:absent@1-2", "baro:stuck@3-4", "baro:spike@12-12.2", "gps:no-fix@35"}) {
        EXPECT_TRUE(sim::apply_fault_spec(spec, p.targets(), error)) << spec << ": " << error;
    }
    const sim::UbloxFaults& g = p.gps.faults();
    EXPECT_TRUE(g.no_fix.active(25.0));
    EXPECT_FALSE(g.no_fix.active(31.0));
    EXPECT_TRUE(g.no_fix.active(100.0));
    EXPECT_TRUE(g.silent.active(40.5));
    EXPECT_TRUE(g.deaf.active(0.0));
    EXPECT_TRUE(g.garbage.active(5.5));
    const sim::Ms5611Faults& b = p.baro.faults();
    EXPECT_TRUE(b.absent.active(1.5));
    EXPECT_TRUE(b.stuck.active(3.5));
    EXPECT_TRUE(b.spike.active(12.1));
    EXPECT_FALSE(b.spike.active(12.2));
}

TEST(FaultSpecGpsBaro, ValuedKinds) {
    Parts p;
    std::string error;
    ASSERT_TRUE(sim::apply_fault_spec("gps:glitch@40-45", p.targets(), error)) << error;
    ASSERT_TRUE(sim::apply_fault_spec("gps:glitch=120@50-51", p.targets(), error)) << error;
    ASSERT_TRUE(sim::apply_fault_spec("gps:sats=4@10-20", p.targets(), error)) << error;
    EXPECT_DOUBLE_EQ(p.gps.faults().glitch.active(42.0)->value, 50.0);  // the default 50 m
    EXPECT_DOUBLE_EQ(p.gps.faults().glitch.active(50.5)->value, 120.0);
    EXPECT_EQ(p.gps.faults().glitch.active(46.0), nullptr);
    EXPECT_DOUBLE_EQ(p.gps.faults().satellites.active(15.0)->value, 4.0);
}

TEST(FaultSpecGpsBaro, MistakesAreErrors) {
    Parts p;
    std::string error;
    EXPECT_FALSE(sim::apply_fault_spec("gps:sats@10-20", p.targets(), error));  // needs N
    EXPECT_NE(error.find("0..12"), std::string::npos) << error;
    EXPECT_FALSE(sim::apply_fault_spec("gps:sats=13", p.targets(), error));
    EXPECT_FALSE(sim::apply_fault_spec("gps:glitch=far", p.targets(), error));
    EXPECT_FALSE(sim::apply_fault_spec("gps:silent=1", p.targets(), error));
    EXPECT_FALSE(sim::apply_fault_spec("gps:lost", p.targets(), error));
    EXPECT_NE(error.find("unknown"), std::string::npos) << error;
    EXPECT_FALSE(sim::apply_fault_spec("baro:melted", p.targets(), error));
    ASSERT_TRUE(sim::apply_fault_spec("gps:glitch@1-3", p.targets(), error)) << error;
    EXPECT_FALSE(sim::apply_fault_spec("gps:glitch=10@2-4", p.targets(), error));  // overlaps
    EXPECT_NE(error.find("overlaps"), std::string::npos) << error;
    // No GPS (--gps none) or no barometer (--baro none) on the board.
    EXPECT_FALSE(sim::apply_fault_spec("gps:no-fix@1-2", p.targets(false, true), error));
    EXPECT_NE(error.find("--gps none"), std::string::npos) << error;
    EXPECT_FALSE(sim::apply_fault_spec("baro:absent", p.targets(true, false), error));
    EXPECT_NE(error.find("--baro none"), std::string::npos) << error;
    // The older kinds still go through the same entry.
    EXPECT_TRUE(sim::apply_fault_spec("mpu:absent@1-2", p.targets(false, false), error)) << error;
    EXPECT_TRUE(p.mpu.faults().absent.active(1.5));
}

TEST(FaultSpecGpsBaro, TheHelpNamesEveryKind) {
    const std::string help = sim::kFaultHelp;
    for (const char* kind : {"gps:no-fix", "gps:silent", "gps:deaf", "gps:garbage", "gps:glitch", "gps:sats",
                             "baro:absent", "baro:stuck", "baro:spike"}) {
        EXPECT_NE(help.find(kind), std::string::npos) << kind;
    }
}

}  // namespace
