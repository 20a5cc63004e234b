// SPDX-License-Identifier: GPL-3.0-or-later
// Rate-limited warnings on the firmware's serial output are deferred, never dropped:
// two bursts of MPU6000 spikes 1 s apart (inside the 2 s limit) give two reports, the
// second counting every spike the first did not.
#include <cstdio>

#include "e2e_support.h"

namespace {

std::vector<const e2e::Line*> lines_with(const std::vector<e2e::Line>& lines, const std::string& text) {
    std::vector<const e2e::Line*> found;
    for (const e2e::Line& l : lines)
        if (l.text.find(text) != std::string::npos) found.push_back(&l);
    return found;
}

TEST(Warnings, TwoSpikeBurstsOneSecondApartGiveTwoReports) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 7.5,
                                         "--fault imu:spike@3-3.05 --fault imu:spike@4-4.05");
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const std::vector<const e2e::Line*> reports = lines_with(run.lines, "# warn: MPU6000 spike");
    ASSERT_EQ(reports.size(), 2u) << e2e::dump(run, 600);
    EXPECT_GE(reports[0]->t_s, 3.0);
    EXPECT_LT(reports[0]->t_s, 3.1) << reports[0]->text;  // at once
    EXPECT_NE(reports[0]->text.find("previous sample used instead (1 so far)"), std::string::npos) << reports[0]->text;
    // The rest when the 2 s are over: every spike of both bursts counted.
    EXPECT_GE(reports[1]->t_s, 5.0);
    EXPECT_LT(reports[1]->t_s, 5.1) << reports[1]->text;
    unsigned more = 0, so_far = 0;
    ASSERT_EQ(std::sscanf(reports[1]->text.c_str(), "# warn: MPU6000 spike: %u more samples replaced (%u so far)",
                          &more, &so_far), 2)
        << reports[1]->text;
    EXPECT_EQ(more + 1, so_far);
    EXPECT_GE(so_far, 2u * 9u) << "two bursts of 50 ms of spikes";
    std::printf("# %.2f s: %s\n# %.2f s: %s\n", reports[0]->t_s, reports[0]->text.c_str(), reports[1]->t_s,
                reports[1]->text.c_str());
}

}  // namespace
