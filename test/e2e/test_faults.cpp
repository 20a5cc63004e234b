// SPDX-License-Identifier: GPL-3.0-or-later
// Every fault of apm25sim's --fault language against the firmware on a level board at
// rest: the firmware says so on serial (`# error:` / `# warn:` naming the part), keeps
// running, never prints nan/inf, and is back within bounds once the fault clears.
#include <algorithm>

#include "e2e_support.h"

namespace {

struct FaultCase {
    const char* name;                // test name suffix
    const char* spec;                // --fault SPEC
    std::vector<std::string> names;  // the report must mention one of these
    double onset_s;                  // when the fault starts
    double clear_s;                  // when it ends; < 0: never
    double seconds;                  // simulated run length
    bool angles_during;              // angle lines must continue during the fault
};

std::ostream& operator<<(std::ostream& os, const FaultCase& c) { return os << c.spec; }

// Runs end 4 s after the fault clears (the recovery is judged on the last second), or
// a few seconds after the report for the faults that last the whole run.
const std::vector<FaultCase>& cases() {
    static const std::vector<FaultCase> list = {
        // absent from the start
        {"MpuAbsentFromStart", "mpu:absent", {"MPU6000"}, 0.0, -1, 4.0, false},
        {"MagAbsentFromStart", "mag:absent", {"HMC5883L"}, 0.0, -1, 4.0, true},
        // stops answering at t and comes back at t2
        {"MpuStopsAndComesBack", "mpu:absent@3-5", {"MPU6000"}, 3.0, 5.0, 9.0, false},
        {"MagStopsAndComesBack", "mag:absent@3-5", {"HMC5883L"}, 3.0, 5.0, 9.0, true},
        {"I2cSdaHeldLow", "i2c:sda-low@3-5", {"HMC5883L", "I2C"}, 3.0, 5.0, 9.0, true},
        // stuck data-ready lines
        {"MagDrdyStuckLow", "mag:drdy-stuck-low@3-5", {"HMC5883L", "DRDY"}, 3.0, 5.0, 9.0, true},
        {"MagDrdyStuckHigh", "mag:drdy-stuck-high@3-5", {"HMC5883L", "DRDY"}, 3.0, 5.0, 9.0, true},
        {"MpuIntStuckLow", "mpu:int-stuck-low@3-5", {"MPU6000", "INT"}, 3.0, 5.0, 9.0, true},
        {"MpuFrozen", "mpu:frozen@3-5", {"MPU6000"}, 3.0, 5.0, 9.0, true},
        // wrong identity
        {"MpuWrongWhoAmI", "mpu:whoami=0x70", {"MPU6000"}, 0.0, -1, 4.0, false},
        // HMC5883L ADC overflow (-4096)
        {"MagOverflow", "mag:overflow@3-5", {"HMC5883L", "overflow"}, 3.0, 5.0, 9.0, true},
        // saturation
        {"GyroSaturated", "gyro:saturate@3-4", {"gyro", "MPU6000"}, 3.0, 4.0, 8.0, true},
        {"AccelSaturated", "accel:saturate@3-4", {"accel", "MPU6000"}, 3.0, 4.0, 8.0, true},
        // spikes of absurd values
        {"ImuSpike", "imu:spike@3-3.05", {"gyro", "accel", "MPU6000"}, 3.0, 3.05, 12.0, true},
        {"MagSpike", "mag:spike@3-5", {"HMC5883L"}, 3.0, 5.0, 9.0, true},
    };
    return list;
}


class Fault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(Fault, ReportedSurvivedAndRecovered) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const FaultCase& c = GetParam();
    const e2e::SimRun run =
        e2e::run_sim(e2e::firmware_elf(), "rest", c.seconds, std::string("--fault ") + c.spec);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_FALSE(e2e::has_non_finite(run.lines)) << e2e::dump(run, 400);

    // Reported: an error or warning naming the part, within 2 s of the onset.
    const double from_s = c.onset_s > 0 ? c.onset_s - 0.01 : 0.0;
    const e2e::Line* error = e2e::find_report(run.lines, "# error:", c.names, from_s);
    const e2e::Line* warn = e2e::find_report(run.lines, "# warn:", c.names, from_s);
    const e2e::Line* report = error ? error : warn;
    if (error && warn && warn->t_s < error->t_s) report = warn;
    ASSERT_TRUE(report) << "no '# error:' or '# warn:' line naming the part\n" << e2e::dump(run, 400);
    EXPECT_LT(report->t_s, c.onset_s + 2.0) << report->text;

    // Keeps running: output continues to the end of the run.
    ASSERT_FALSE(run.lines.empty());
    EXPECT_GT(run.lines.back().t_s, c.seconds - 1.0) << e2e::dump(run, 400);
    if (c.angles_during) {
        const double to_s = c.clear_s > 0 ? c.clear_s : c.seconds;
        const double span_s = to_s - c.onset_s;
        const size_t during = e2e::angle_lines(run.lines, c.onset_s, to_s).size();
        if (span_s >= 0.5) {
            EXPECT_GT((double)during, 0.5 * 50.0 * span_s) << "angle lines stopped during the fault";
        }
    }

    // Recovered: angle lines after the fault, level within 2 degrees and on the heading
    // it had before the fault within 3 degrees, for the last second.
    if (c.clear_s > 0) {
        const std::vector<e2e::Line> before = e2e::angle_lines(run.lines, 2.0, c.onset_s);
        ASSERT_FALSE(before.empty()) << e2e::dump(run, 400);
        const double heading_before = e2e::mean_heading(before);
        const std::vector<e2e::Line> tail = e2e::angle_lines(run.lines, c.seconds - 1.0, c.seconds + 1.0);
        ASSERT_GT(tail.size(), 20u) << e2e::dump(run, 400);
        const e2e::Line* worst_tilt = &tail.front();
        const e2e::Line* worst_heading = &tail.front();
        for (const e2e::Line& l : tail) {
            if (std::max(std::fabs(l.roll), std::fabs(l.pitch)) > std::max(std::fabs(worst_tilt->roll), std::fabs(worst_tilt->pitch)))
                worst_tilt = &l;
            if (std::fabs(e2e::heading_diff_deg(l.yaw, heading_before)) >
                std::fabs(e2e::heading_diff_deg(worst_heading->yaw, heading_before)))
                worst_heading = &l;
        }
        EXPECT_LT(std::max(std::fabs(worst_tilt->roll), std::fabs(worst_tilt->pitch)), 2.0)
            << "not level again: t=" << worst_tilt->t_s << " " << worst_tilt->text;
        EXPECT_LT(std::fabs(e2e::heading_diff_deg(worst_heading->yaw, heading_before)), 3.0)
            << "heading not back: t=" << worst_heading->t_s << " " << worst_heading->text << " (before the fault "
            << heading_before << ")";
        const e2e::Line* recovered = e2e::find_report(run.lines, "# recovered:", {""}, c.onset_s);
        if (recovered) {
            EXPECT_GE(recovered->t_s, c.clear_s - 0.01) << recovered->text;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(AllFaults, Fault, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<FaultCase>& info) { return info.param.name; });

}  // namespace
