// SPDX-License-Identifier: GPL-3.0-or-later
// The stack's high-water mark (firmware/StackPaint.cpp, apm25sim --profile's stack rows):
// the firmware paints the RAM above its static data at start-up, and after a run with a
// console session the stack has left at least 512 B of it untouched. The rows
// add up to the RAM above the static data (avr-size's .data + .bss), so a paint that did
// not happen (0 free) or a count from the wrong address would fail.
#include <fstream>
#include <sstream>

#include "e2e_support.h"

namespace {

long profile_value(const std::string& path, const std::string& row) {
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(row + ",", 0) != 0) continue;
        std::istringstream fields(line);
        std::string name, count, value;
        std::getline(fields, name, ',');
        std::getline(fields, count, ',');
        std::getline(fields, value, ',');
        return std::atol(value.c_str());
    }
    return -1;
}

TEST(Stack, HighWaterMarkLeavesAtLeast512Bytes) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::string profile = e2e::work_dir() + "/stack_profile." + std::to_string(getpid()) + ".csv";
    const std::string input = e2e::input_file("stack", "help\r\nstatus\r\nparams\r\nbaro\r\n");
    const e2e::SimRun run =
        e2e::run_sim(e2e::firmware_elf(), "rest", 5.0, "--input " + input + " --input-at 2.5 --profile " + profile);
    unlink(input.c_str());
    ASSERT_EQ(run.result.exit_code, 0) << run.result.err;
    const long used = profile_value(profile, "stack_used"), free_bytes = profile_value(profile, "stack_free");
    unlink(profile.c_str());
    const e2e::CommandResult size = e2e::run_command("avr-size -A " + e2e::firmware_elf() +
                                                     " | awk '/^\\.data|^\\.bss/ {s += $2} END {print s}'");
    ASSERT_EQ(size.exit_code, 0);
    const long static_bytes = std::atol(size.out.c_str());
    ASSERT_GT(static_bytes, 1000);
    std::printf("stack high-water mark: %ld B used, %ld B free (static RAM %ld B)\n", used, free_bytes, static_bytes);
    EXPECT_EQ(used + free_bytes + static_bytes, 8192);
    EXPECT_GT(used, 100) << "the stack was used";
    EXPECT_GE(free_bytes, 512);
}

}  // namespace
