// SPDX-License-Identifier: GPL-3.0-or-later
// The MS5611 barometer in simavr (firmware/Baro, lib/MS5611, apm25sim's register model):
// the height above home over a trajectory with height changes, a board without the chip,
// and each of the model's faults reported, survived and recovered from, with no sample
// missed and the bus check (pin 40 high whenever the MPU6000 is selected) never failing
// (apm25sim's exit status 3).
//
// The height is read as a user would: `baro` typed at the console, its reply's
// height compared with the trajectory's -d at the instant the reply left the UART.
// The commands are spaced by empty lines (each '\n' one character time, 87 us at 115200
// baud, which the console ignores).
#include <cmath>
#include <fstream>
#include <sstream>

#include "e2e_support.h"

namespace {

// A command every `period_s`, as typed: the command, then newlines to fill the period.
std::string spaced_commands(const std::string& command, double period_s, int count) {
    const double char_s = 10.0 / 115200.0;
    const size_t pad = (size_t)(period_s / char_s) - command.size() - 2u;
    std::string one = command + "\r\n" + std::string(pad, '\n');
    std::string all;
    for (int i = 0; i < count; ++i) all += one;
    return all;
}

// The heights of the "# baro ok: P Pa, T C, H m, V m/s, ..." replies: (stamp, H).
std::vector<std::pair<double, double>> baro_heights(const std::vector<e2e::Line>& lines) {
    std::vector<std::pair<double, double>> out;
    for (const e2e::Line& l : lines) {
        if (l.text.rfind("# baro ok: ", 0) != 0) continue;
        const size_t at = l.text.find(" C, ");
        if (at == std::string::npos || l.text.find(" m, ", at) == std::string::npos) continue;
        out.emplace_back(l.t_s, std::atof(l.text.c_str() + at + 4));
    }
    return out;
}

size_t count_lines(const std::vector<e2e::Line>& lines, const std::string& needle, double from_s = 0.0) {
    size_t n = 0;
    for (const e2e::Line& l : lines) n += l.t_s >= from_s && l.text.find(needle) != std::string::npos;
    return n;
}

// Nothing that says a sample was missed, nothing non-finite, the run whole.
void expect_undisturbed(const e2e::SimRun& run, double seconds) {
    EXPECT_EQ(run.result.exit_code, 0) << "3: the bus check failed\n" << run.result.err;
    EXPECT_FALSE(e2e::has_non_finite(run.lines));
    EXPECT_EQ(count_lines(run.lines, "loop overrun"), 0u) << e2e::dump(run, 400);
    EXPECT_EQ(count_lines(run.lines, "nan"), 0u);
    ASSERT_FALSE(run.lines.empty());
    EXPECT_GT(run.lines.back().t_s, seconds - 0.5);
    EXPECT_GT(e2e::angle_lines(run.lines, seconds - 1.0, seconds).size(), 40u) << "angle lines to the end";
}

// Height profile (m above home) of the trajectory: still, up 3 m/s to 30 m, held,
// down 2 m/s to 10 m, held, up 1 m/s to 20 m, held.
double true_height_m(double t) {
    struct Leg { double t0, h0, rate; };
    const Leg legs[] = {{0, 0, 0}, {4, 0, 3}, {14, 30, 0}, {20, 30, -2}, {30, 10, 0}, {34, 10, 1}, {44, 20, 0}};
    double h = 0;
    for (const Leg& l : legs)
        if (t >= l.t0) h = l.h0 + l.rate * (t - l.t0);
    return h;
}

// The rest scenario's IMU columns with n,e,d columns from height(t), as a trajectory file.
std::string with_heights(const std::string& name, double seconds, double (*height_m)(double)) {
    const std::string rest = e2e::scenario_csv("rest", seconds);
    std::ifstream in(rest);
    const std::string path = e2e::work_dir() + "/" + name + "." + std::to_string(getpid()) + ".csv";
    std::ofstream out(path);
    std::string line;
    std::getline(in, line);
    out << line << ",n,e,d\n";
    while (std::getline(in, line)) {
        char ned[64];
        std::snprintf(ned, sizeof ned, ",0,0,%.4f\n", -height_m(std::atof(line.c_str())));
        out << line << ned;
    }
    return path;
}

TEST(Baro, HeightAboveHomeWithinOneAndAHalfMetresRms) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const double seconds = 50.0;
    // The board at rest (the scenario's IMU columns) with the n,e,d columns of the profile.
    const std::string path = with_heights("baro_heights", seconds, true_height_m);
    const std::string input = e2e::input_file("baro_heights", spaced_commands("baro", 0.25, 180));
    const e2e::SimRun run = e2e::run_sim_file(e2e::firmware_elf(), path, seconds, "--input " + input + " --input-at 3");
    unlink(input.c_str());
    unlink(path.c_str());
    expect_undisturbed(run, seconds);
    ASSERT_TRUE(e2e::find_report(run.lines, "# baro: MS5611, ground", {"GND_ABS_PRESS"})) << e2e::dump(run);

    const auto heights = baro_heights(run.lines);
    ASSERT_GT(heights.size(), 150u) << e2e::dump(run, 200);
    double sum2 = 0.0, worst = 0.0;
    for (const auto& h : heights) {
        const double err = h.second - true_height_m(h.first);
        sum2 += err * err;
        worst = std::max(worst, std::fabs(err));
    }
    const double rms = std::sqrt(sum2 / (double)heights.size());
    std::printf("height above home: RMS %.2f m, worst %.2f m over %zu readings\n", rms, worst, heights.size());
    EXPECT_LT(rms, 1.5);
    EXPECT_LT(worst, 4.0);
}

// The climb of a "# baro ok: P Pa, T C, H m, V m/s, ..." line.
double climb_of(const std::string& text) {
    const size_t at = text.find(" m, ");
    return at == std::string::npos ? NAN : std::atof(text.c_str() + at + 4);
}

double climbing_4_m_s(double t) { return t < 1.5 ? 0.0 : 4.0 * (t - 1.5); }

// GND_TEMP stands for the ground's temperature while it is not 0: the height scales with
// it (T0 in kelvin: 40 degC against the chip's 8.32 is 313.15 / 281.47 = 1.113); back at 0,
// the chip's own again, and the height and climb track the truth.
TEST(Baro, GndTempScalesTheHeightAndZeroGivesTheChipsBack) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const double seconds = 11.0;
    const std::string path = with_heights("baro_gnd_temp", seconds, climbing_4_m_s);
    const double char_s = 10.0 / 115200.0;
    auto pad = [&](double s) { return std::string((size_t)(s / char_s), '\n'); };
    const std::string input = e2e::input_file(
        "baro_gnd_temp", "set GND_TEMP 40\r\n" + pad(2.5) + "baro\r\n" + pad(0.5) + "set GND_TEMP 0\r\n" + pad(3.0) +
                             "baro\r\n");
    const e2e::SimRun run = e2e::run_sim_file(e2e::firmware_elf(), path, seconds, "--input " + input + " --input-at 3");
    unlink(input.c_str());
    unlink(path.c_str());
    expect_undisturbed(run, seconds);
    const auto heights = baro_heights(run.lines);
    ASSERT_EQ(heights.size(), 2u) << e2e::dump(run, 100);
    // The height is the 10 Hz update's before the reply (~0.1 s), its climb state restarted
    // when GND_TEMP moved the reference 2.5 s before: against the truth 0.1 s back, within 5 %
    // (without GND_TEMP the ratio would be 1.00).
    const double warm = heights[0].second / climbing_4_m_s(heights[0].first - 0.1);
    std::printf("GND_TEMP 40: %.2f m at %.2f s, %.3f of the truth; then %.2f m against %.2f m\n", heights[0].second,
                heights[0].first, warm, heights[1].second, climbing_4_m_s(heights[1].first));
    EXPECT_NEAR(warm, 313.15 / 281.47, 0.05);
    EXPECT_NEAR(heights[1].second, climbing_4_m_s(heights[1].first), 1.0);
    const e2e::Line* last = nullptr;
    for (const e2e::Line& l : run.lines)
        if (l.text.rfind("# baro ok: ", 0) == 0) last = &l;
    ASSERT_TRUE(last);
    EXPECT_NEAR(climb_of(last->text), 4.0, 1.0) << last->text;
}

TEST(Baro, AbsentIsSaidOnceAndTheRestRuns) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const std::string input = e2e::input_file("baro_absent", "baro\r\nstatus\r\n");
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", 8.0, "--baro none --input " + input +
                                                                                " --input-at 6");
    unlink(input.c_str());
    expect_undisturbed(run, 8.0);
    const e2e::Line* said = e2e::find_report(run.lines, "# warn:", {"baro: MS5611 not found (PROM blank)"});
    ASSERT_TRUE(said) << e2e::dump(run);
    EXPECT_LT(said->t_s, 1.0);
    EXPECT_EQ(count_lines(run.lines, "not found"), 1u) << "said once, retried quietly";
    EXPECT_EQ(count_lines(run.lines, "# baro absent", 6.0), 2u) << "`baro` and `status` say it\n" << e2e::dump(run, 60);
    EXPECT_TRUE(e2e::find_report(run.lines, "# status:", {"estimator running"}, 6.0)) << "the rest runs";
}

struct BaroFault {
    const char* name;
    const char* spec;
    const char* said;       // the warning's words
    const char* recovered;  // the line that says it is over ("" none: the readings say it)
    double onset_s, clear_s;
};

std::ostream& operator<<(std::ostream& os, const BaroFault& c) { return os << c.spec; }

class BaroFaults : public ::testing::TestWithParam<BaroFault> {};

TEST_P(BaroFaults, ReportedSurvivedAndRecovered) {
    E2E_REQUIRE_TOOLS("firmware.elf", "apm25sim", "scenario");
    const BaroFault& c = GetParam();
    const double seconds = 12.0;
    const std::string input = e2e::input_file(std::string("baro_") + c.name, "baro\r\n");
    const e2e::SimRun run = e2e::run_sim(e2e::firmware_elf(), "rest", seconds,
                                         std::string("--fault ") + c.spec + " --input " + input + " --input-at 11.5");
    unlink(input.c_str());
    expect_undisturbed(run, seconds);
    const e2e::Line* said = e2e::find_report(run.lines, "# warn:", {c.said}, c.onset_s - 0.01);
    ASSERT_TRUE(said) << e2e::dump(run, 200);
    EXPECT_LT(said->t_s, c.onset_s + 2.0) << said->text;
    if (*c.recovered) {
        const e2e::Line* back = e2e::find_report(run.lines, "# baro:", {c.recovered}, c.clear_s - 0.01);
        ASSERT_TRUE(back) << e2e::dump(run, 200);
        EXPECT_LT(back->t_s, c.clear_s + 1.5) << back->text;
    }
    // Healthy at the end, at the ground's height: the ground kept through the fault.
    const auto heights = baro_heights(run.lines);
    ASSERT_EQ(heights.size(), 1u) << e2e::dump(run, 200);
    EXPECT_NEAR(heights[0].second, 0.0, 1.0);
}

INSTANTIATE_TEST_SUITE_P(
    Baro, BaroFaults,
    ::testing::Values(BaroFault{"Stuck", "baro:stuck@4-6", "baro: MS5611 stuck", "move again", 4.0, 6.0},
                      BaroFault{"Spike", "baro:spike@4-4.3", "baro: a reading rejected", "", 4.0, 4.3},
                      BaroFault{"AbsentInAWindow", "baro:absent@4-6", "baro: MS5611 lost", "MS5611 back", 4.0, 6.0}),
    [](const ::testing::TestParamInfo<BaroFault>& i) { return std::string(i.param.name); });

}  // namespace
