// SPDX-License-Identifier: GPL-3.0-or-later
// The host unit tests' checks on the target: test/e2e/support/avr/selftest.cpp, built by
// avr-gcc from the same lib/ sources as the firmware, run as an ATmega2560 in apm25sim.
// Every check must report "ok", each exactly once, and the summary must count them all
// (a check that silently did not run fails this test too).
#include "e2e_support.h"

namespace {

// The checks selftest.cpp runs, in order.
const char* const kChecks[] = {
    "linalg_ops",       "linalg_degenerate", "fast_atan2",     "euler_round_trip",
    "dcm_orthonormal",  "dcm_bias_at_rest",  "dcm_absurd_inputs", "decode_mpu6000",
    "decode_hmc5883",   "console_parse",     "settings_crc",   "format",
    "quat_raw",         "fixed_output",
};
constexpr size_t kCheckCount = sizeof kChecks / sizeof kChecks[0];

TEST(Selftest, HostTestedRoutinesPassOnTheAvr) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario");
    E2E_REQUIRE_AVR_PROGRAMS(dir);
    // The checks take ~10 simulated seconds (mostly the DCM runs); the program then idles.
    const e2e::SimRun run = e2e::run_sim(dir + "/selftest.elf", "rest", 14.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);

    std::vector<std::string> results;
    const e2e::Line* done = nullptr;
    const e2e::Line* ram = nullptr;
    for (const e2e::Line& l : run.lines) {
        if (l.text.rfind("# selftest done:", 0) == 0) done = &l;
        else if (l.text.rfind("# selftest ram:", 0) == 0) ram = &l;
        else if (l.text.rfind("# selftest ", 0) == 0 && l.text.find(": ") != std::string::npos) results.push_back(l.text);
    }
    for (const std::string& r : results)
        EXPECT_NE(r.find(": ok"), std::string::npos) << "on the ATmega2560: " << r;
    for (const char* name : kChecks) {
        const std::string prefix = std::string("# selftest ") + name + ": ";
        size_t seen = 0;
        for (const std::string& r : results) seen += r.rfind(prefix, 0) == 0;
        EXPECT_EQ(seen, 1u) << name << " reported " << seen << " times\n" << e2e::dump(run, 40);
    }
    EXPECT_EQ(results.size(), kCheckCount) << e2e::dump(run, 40);
    ASSERT_TRUE(done) << "no summary line (did the checks finish in time?)\n" << e2e::dump(run, 40);
    char expected[96];
    std::snprintf(expected, sizeof expected, "# selftest done: %zu checks, %zu ok, 0 FAIL", kCheckCount, kCheckCount);
    EXPECT_EQ(done->text, expected);

    // The program fits the 2560's 8 KB with room to spare (stack high-water mark by painting).
    ASSERT_TRUE(ram) << e2e::dump(run, 40);
    unsigned static_bytes = 0, untouched = 0;
    ASSERT_EQ(std::sscanf(ram->text.c_str(), "# selftest ram: static %u bytes, never reached by the stack %u",
                          &static_bytes, &untouched), 2) << ram->text;
    EXPECT_GT(untouched, 512u) << ram->text;
}

}  // namespace
