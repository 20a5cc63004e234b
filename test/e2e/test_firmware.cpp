// The firmware in simavr on synthetic scenarios: start-up, accuracy at rest, gyro bias
// correction, pitch through 90 degrees, and the serial console (SIM.md serial format).
#include "e2e_support.h"

namespace {

#define REQUIRE_FIRMWARE() E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario")

double max_abs(const std::vector<e2e::Line>& lines, double e2e::Line::*angle) {
    double m = 0.0;
    for (const e2e::Line& l : lines) m = std::max(m, std::fabs(l.*angle));
    return m;
}

double mean(const std::vector<e2e::Line>& lines, double e2e::Line::*angle) {
    double sum = 0.0;
    for (const e2e::Line& l : lines) sum += l.*angle;
    return lines.empty() ? NAN : sum / (double)lines.size();
}

// Circular mean of headings (0/360 wrap), degrees.
double mean_heading(const std::vector<e2e::Line>& lines) {
    double s = 0.0, c = 0.0;
    for (const e2e::Line& l : lines) {
        s += std::sin(l.yaw * M_PI / 180.0);
        c += std::cos(l.yaw * M_PI / 180.0);
    }
    return std::atan2(s, c) * 180.0 / M_PI;
}

// Output lines per second of angle data in [from_s, to_s).
double line_rate_hz(const std::vector<e2e::Line>& lines, double from_s, double to_s) {
    return (double)e2e::angle_lines(lines, from_s, to_s).size() / (to_s - from_s);
}

TEST(Firmware, BannerThenAnglesWithin2sOfReset) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 3.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    ASSERT_FALSE(run.lines.empty()) << e2e::dump(run);
    EXPECT_EQ(run.lines.front().text.rfind("# apm25-attitude", 0), 0u) << e2e::dump(run);
    const std::vector<e2e::Line> angles = e2e::angle_lines(run.lines);
    ASSERT_FALSE(angles.empty()) << e2e::dump(run);
    EXPECT_LT(angles.front().t_s, 2.0) << e2e::dump(run);
    for (const e2e::Line& l : run.lines)
        EXPECT_TRUE(l.is_angle || l.text.rfind("# ", 0) == 0) << "neither angles nor '# ': " << l.text;
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
}

TEST(Firmware, LevelRest60sWithinHalfADegreeWithoutDrift) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 60.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
    const std::vector<e2e::Line> settled = e2e::angle_lines(run.lines, 2.0, 61.0);
    ASSERT_GT(settled.size(), 50u * 50u) << e2e::dump(run);  // ~50 Hz for 58 s
    EXPECT_LT(max_abs(settled, &e2e::Line::roll), 0.5);
    EXPECT_LT(max_abs(settled, &e2e::Line::pitch), 0.5);
    // No drift: the last 10 s agree with 2..12 s.
    const std::vector<e2e::Line> early = e2e::angle_lines(run.lines, 2.0, 12.0);
    const std::vector<e2e::Line> late = e2e::angle_lines(run.lines, 50.0, 61.0);
    EXPECT_NEAR(mean(late, &e2e::Line::roll), mean(early, &e2e::Line::roll), 0.2);
    EXPECT_NEAR(mean(late, &e2e::Line::pitch), mean(early, &e2e::Line::pitch), 0.2);
    EXPECT_NEAR(e2e::heading_diff_deg(mean_heading(late), mean_heading(early)), 0.0, 1.0);
}

TEST(Firmware, GyroBiasCorrectedWithin30s) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest_bias", 40.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
    const std::vector<e2e::Line> corrected = e2e::angle_lines(run.lines, 30.0, 41.0);
    ASSERT_GT(corrected.size(), 400u) << e2e::dump(run);
    EXPECT_LT(max_abs(corrected, &e2e::Line::roll), 1.0);
    EXPECT_LT(max_abs(corrected, &e2e::Line::pitch), 1.0);
    // Heading held by the compass: within 3 degrees of where it started.
    const std::vector<e2e::Line> start = e2e::angle_lines(run.lines, 0.0, 2.0);
    ASSERT_FALSE(start.empty());
    for (const e2e::Line& l : corrected)
        ASSERT_NEAR(e2e::heading_diff_deg(l.yaw, start.front().yaw), 0.0, 3.0) << "t=" << l.t_s << " " << l.text;
}

TEST(Firmware, PitchThrough90StaysFiniteAndContinuous) {
    REQUIRE_FIRMWARE();
    // 23.2 s: up through 90 to 120, back to 90 and down to 0 at 23 s (sim/scenario.cpp pitch90).
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "pitch90", 23.2);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
    const std::vector<e2e::Line> angles = e2e::angle_lines(run.lines);
    ASSERT_GT(angles.size(), 500u);
    double max_pitch = -90;
    for (size_t i = 1; i < angles.size(); ++i) {
        max_pitch = std::max(max_pitch, angles[i].pitch);
        // 15 deg/s at most in this scenario: 2 degrees between lines is a jump.
        ASSERT_LT(std::fabs(angles[i].pitch - angles[i - 1].pitch), 2.0)
            << "t=" << angles[i].t_s << ": " << angles[i - 1].text << " -> " << angles[i].text;
        ASSERT_LE(std::fabs(angles[i].pitch), 90.01) << angles[i].text;
        ASSERT_LE(std::fabs(angles[i].roll), 180.01) << angles[i].text;
        ASSERT_GE(angles[i].yaw, 0.0) << angles[i].text;
        ASSERT_LT(angles[i].yaw, 360.01) << angles[i].text;
    }
    EXPECT_GT(max_pitch, 85.0);
    // Back level at the end (truth within 0.7 degrees of level from 22.8 s).
    const std::vector<e2e::Line> end = e2e::angle_lines(run.lines, 22.8, 24.0);
    ASSERT_FALSE(end.empty());
    EXPECT_LT(max_abs(end, &e2e::Line::pitch), 3.0);
    EXPECT_LT(max_abs(end, &e2e::Line::roll), 3.0);
}

// --- console ----------------------------------------------------------------------

e2e::SimRun run_with_input(const std::string& name, const std::string& text, double seconds) {
    const std::string input = e2e::input_file(name, text);
    e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", seconds, "--input " + input + " --input-at 3");
    unlink(input.c_str());
    return run;
}

// Time of the first console answer ('# ' line) after the input began.
double first_answer_s(const e2e::SimRun& run, double after_s) {
    for (const e2e::Line& l : run.lines)
        if (l.t_s > after_s && !l.is_angle) return l.t_s;
    return NAN;
}

TEST(Console, HelpIsAnswered) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = run_with_input("help", "help\n", 4.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const double input_s = 3.0;
    size_t answers = 0;
    for (const e2e::Line& l : run.lines)
        if (l.t_s > input_s && !l.is_angle) ++answers;
    EXPECT_GE(answers, 2u) << e2e::dump(run, 80);
    EXPECT_TRUE(e2e::find_report(run.lines, "# ", {"rate"}, input_s)) << e2e::dump(run, 80);
}

TEST(Console, RateChangesTheOutputRate) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = run_with_input("rate", "rate 10\n", 7.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const double before_hz = line_rate_hz(run.lines, 1.5, 2.9);
    const double answer_s = first_answer_s(run, 3.0);
    ASSERT_TRUE(std::isfinite(answer_s)) << e2e::dump(run, 80);
    const double after_hz = line_rate_hz(run.lines, answer_s + 0.5, 7.0);
    EXPECT_NEAR(before_hz, 50.0, 5.0) << e2e::dump(run);
    EXPECT_NEAR(after_hz, 10.0, 1.0) << e2e::dump(run, 200);
}

TEST(Console, DeclinationMovesYaw) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = run_with_input("decl", "decl 10\n", 6.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    const double answer_s = first_answer_s(run, 3.0);
    ASSERT_TRUE(std::isfinite(answer_s)) << e2e::dump(run, 80);
    const std::vector<e2e::Line> before = e2e::angle_lines(run.lines, 1.0, 2.9);
    const std::vector<e2e::Line> after = e2e::angle_lines(run.lines, answer_s + 1.0, 7.0);
    ASSERT_FALSE(before.empty());
    ASSERT_FALSE(after.empty());
    EXPECT_NEAR(e2e::heading_diff_deg(after.back().yaw, before.back().yaw), 10.0, 1.0)
        << before.back().text << " -> " << after.back().text;
}

TEST(Console, GarbageGivesAnErrorAndChangesNothing) {
    REQUIRE_FIRMWARE();
    const e2e::SimRun run = run_with_input("garbage", "xyzzy 12 ###\n", 6.0);
    ASSERT_EQ(run.result.exit_code, 0) << e2e::dump(run);
    EXPECT_TRUE(e2e::find_report(run.lines, "# error", {""}, 0.0)) << e2e::dump(run, 80);
    const double answer_s = first_answer_s(run, 3.0);
    EXPECT_NEAR(line_rate_hz(run.lines, answer_s + 0.5, 6.0), 50.0, 5.0);
    const std::vector<e2e::Line> before = e2e::angle_lines(run.lines, 1.0, 2.9);
    const std::vector<e2e::Line> after = e2e::angle_lines(run.lines, 5.0, 7.0);
    ASSERT_FALSE(before.empty());
    ASSERT_FALSE(after.empty());
    EXPECT_NEAR(e2e::heading_diff_deg(after.back().yaw, before.back().yaw), 0.0, 1.0);
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
}

}  // namespace
