// SPDX-License-Identifier: GPL-3.0-or-later
// The seeded motions as build/scenario writes them (issue 24): the file's gyro, integrated,
// reproduces its true quaternion; its specific force, turned to the earth frame and freed
// of gravity, integrates to a board that ends at rest; seeds change the motion, no seed is
// the fixed default; the sensor-error options leave the truth alone.
// test/sim/test_scenario_motions.cpp checks the motions' algebra (sim/Motions.h).
#include <cmath>
#include <string>

#include "Rotation.h"
#include "Trajectory.h"
#include "e2e_support.h"

namespace {

using e2e::run_command;
using e2e::tool;

const char* const kMotions[] = {"translate_slow", "translate_fast", "walk", "pendulum", "car", "tapping", "knocking",
                                "slow_rotation"};
constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kGravity_m_s2 = 9.80665;

// build/scenario NAME OPTIONS into the e2e work directory; "" when it failed.
std::string motion_file(const std::string& name, const std::string& options) {
    std::string file = name + options;
    for (char& c : file)
        if (c == ' ' || c == ',') c = '_';
    const std::string path = e2e::work_dir() + "/motion_" + file + ".csv";
    const e2e::CommandResult r = run_command(tool("scenario") + " " + name + " " + options + " > " + path);
    return r.exit_code == 0 ? path : "";
}

bool load(const std::string& path, sim::Trajectory& tr) {
    if (path.empty() || !tr.load(path)) return false;
    return tr.size() > 100;
}

sim::Quat quat_of(const sim::TrajectorySample& s) { return sim::Quat{s.quat[0], s.quat[1], s.quat[2], s.quat[3]}; }

// The angle between two attitudes, degrees.
double angle_deg(const sim::Quat& a, const sim::Quat& b) {
    const sim::Quat d = a.conj() * b;
    const double v = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    return 2.0 * std::atan2(v, std::fabs(d.w)) / kDeg;
}

// A turn by the rotation vector w (rad), as a quaternion.
sim::Quat rotation(const double w[3]) {
    const double angle = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (angle < 1e-15) return sim::Quat{1, 0, 0, 0};
    const double s = std::sin(angle / 2) / angle;
    return sim::Quat{std::cos(angle / 2), w[0] * s, w[1] * s, w[2] * s};
}

void body_to_earth(const sim::Quat& q, const double v[3], double out[3]) {
    const sim::Quat r = q * sim::Quat{0.0, v[0], v[1], v[2]} * q.conj();
    out[0] = r.x;
    out[1] = r.y;
    out[2] = r.z;
}

class MotionFile : public ::testing::TestWithParam<const char*> {
protected:
    void SetUp() override {
        if (!e2e::file_exists(tool("scenario"))) GTEST_SKIP() << "no build/scenario (make tools)";
    }
};

TEST_P(MotionFile, PhysicallyConsistent) {
    sim::Trajectory tr;
    // 1 kHz so that the 10 ms taps span enough samples to integrate.
    ASSERT_TRUE(load(motion_file(GetParam(), "--seed 11 --rate 1000"), tr)) << tr.error();
    sim::Quat q = quat_of(tr[0]);
    double velocity[3] = {0, 0, 0}, prev_a[3] = {0, 0, 0}, worst_angle = 0.0, peak_a = 0.0, still_a = 0.0;
    for (size_t k = 0; k < tr.size(); ++k) {
        const sim::TrajectorySample& s = tr[k];
        for (int i = 0; i < 3; ++i) {
            ASSERT_TRUE(std::isfinite(s.gyro_rad_s[i]) && std::isfinite(s.accel_m_s2[i]) && std::isfinite(s.mag_uT[i]))
                << "t " << s.t_s;
        }
        for (double c : s.quat) ASSERT_TRUE(std::isfinite(c)) << "t " << s.t_s;
        EXPECT_EQ(s.movement, s.t_s >= 2.0) << "t " << s.t_s;
        double a[3];
        body_to_earth(quat_of(s), s.accel_m_s2, a);
        a[2] += kGravity_m_s2;
        const double norm_a = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        peak_a = std::fmax(peak_a, norm_a);
        if (s.t_s < 2.0) still_a = std::fmax(still_a, norm_a);
        if (k > 0) {
            const double dt = s.t_s - tr[k - 1].t_s;
            double w[3];
            for (int i = 0; i < 3; ++i) {
                w[i] = 0.5 * (s.gyro_rad_s[i] + tr[k - 1].gyro_rad_s[i]) * dt;
                velocity[i] += 0.5 * (a[i] + prev_a[i]) * dt;
            }
            q = q * rotation(w);
            worst_angle = std::fmax(worst_angle, angle_deg(q, quat_of(s)));
        }
        for (int i = 0; i < 3; ++i) prev_a[i] = a[i];
    }
    EXPECT_LT(worst_angle, 0.3) << "the gyro does not integrate to the truth";
    EXPECT_LT(still_a, 0.2) << "moving in the first 2 s";
    if (std::string(GetParam()) == "slow_rotation") {
        EXPECT_LT(peak_a, 0.5) << "turned about its own centre, the board does not accelerate";
    } else {
        EXPECT_GT(peak_a, 2.0) << "the board hardly accelerates";
    }
    const double end_speed =
        std::sqrt(velocity[0] * velocity[0] + velocity[1] * velocity[1] + velocity[2] * velocity[2]);
    EXPECT_LT(end_speed, 0.1) << "the specific force does not integrate to a board that ends at rest";
    EXPECT_GE(tr.duration_s(), 60.0);
    EXPECT_LE(tr.duration_s(), 180.0);
}

TEST_P(MotionFile, SeedsChangeTheMotionNoSeedIsTheDefault) {
    const std::string name = GetParam();
    const std::string plain = motion_file(name, ""), zero = motion_file(name, "--seed 0");
    ASSERT_FALSE(plain.empty());
    EXPECT_EQ(e2e::read_text(plain), e2e::read_text(zero));
    EXPECT_EQ(e2e::read_text(plain), e2e::read_text(motion_file(name, "")));
    sim::Trajectory a, b;
    ASSERT_TRUE(load(motion_file(name, "--seed 21"), a));
    ASSERT_TRUE(load(motion_file(name, "--seed 22"), b));
    int differ = 0, compared = 0;
    for (size_t k = 0; k < a.size() && k < b.size(); k += 400) {
        ++compared;
        differ += angle_deg(quat_of(a[k]), quat_of(b[k])) > 0.1;
    }
    EXPECT_GT(differ, compared / 2) << "seeds 21 and 22 give nearly the same motion";
}

TEST_P(MotionFile, SensorErrorsLeaveTheTruth) {
    sim::Trajectory ideal, board;
    ASSERT_TRUE(load(motion_file(GetParam(), "--seed 5"), ideal));
    ASSERT_TRUE(load(motion_file(GetParam(), "--seed 5 --preset uncalibrated"), board));
    ASSERT_EQ(ideal.size(), board.size());
    double bias_dps[3] = {0, 0, 0};
    int still = 0;
    for (size_t k = 0; k < ideal.size(); ++k) {
        for (int c = 0; c < 4; ++c) ASSERT_EQ(ideal[k].quat[c], board[k].quat[c]);
        if (ideal[k].t_s < 2.0) {
            ++still;
            for (int i = 0; i < 3; ++i) bias_dps[i] += (board[k].gyro_rad_s[i] - ideal[k].gyro_rad_s[i]) / kDeg;
        }
    }
    // --preset uncalibrated: gyro bias (1.5, -1, 0.8) deg/s (scenario --help).
    EXPECT_NEAR(bias_dps[0] / still, 1.5, 0.05);
    EXPECT_NEAR(bias_dps[1] / still, -1.0, 0.05);
    EXPECT_NEAR(bias_dps[2] / still, 0.8, 0.05);
}

// --from FILE puts the same errors on a trajectory's measured columns (a flight of
// fly.py): the truth, times and movement as they were, the gyro off by the bias; without
// a noise option nothing else (a gyro bias alone moves only the gyro), with the preset
// the other columns move too.
TEST_P(MotionFile, SensorErrorsOnAFileKeepItsTruth) {
    sim::Trajectory ideal, biased, board;
    const std::string source = motion_file(GetParam(), "--seed 5");
    ASSERT_TRUE(load(source, ideal));
    const std::string biased_path = e2e::work_dir() + "/from_" + GetParam() + "_bias.csv";
    const std::string board_path = e2e::work_dir() + "/from_" + GetParam() + "_board.csv";
    ASSERT_EQ(run_command(tool("scenario") + " --from " + source + " --gyro-bias 2,-1,0.5 > " + biased_path).exit_code, 0);
    ASSERT_EQ(run_command(tool("scenario") + " --from " + source + " --preset uncalibrated > " + board_path).exit_code, 0);
    ASSERT_TRUE(load(biased_path, biased));
    ASSERT_TRUE(load(board_path, board));
    ASSERT_EQ(ideal.size(), biased.size());
    ASSERT_EQ(ideal.size(), board.size());
    const double bias_dps[3] = {2.0, -1.0, 0.5};
    double moved = 0.0;
    for (size_t k = 0; k < ideal.size(); ++k) {
        ASSERT_EQ(ideal[k].t_s, biased[k].t_s);
        ASSERT_EQ(ideal[k].movement, board[k].movement);
        for (int c = 0; c < 4; ++c) ASSERT_EQ(ideal[k].quat[c], board[k].quat[c]);
        for (int i = 0; i < 3; ++i) {
            ASSERT_NEAR((biased[k].gyro_rad_s[i] - ideal[k].gyro_rad_s[i]) / kDeg, bias_dps[i], 1e-4) << k;
            ASSERT_NEAR(biased[k].accel_m_s2[i], ideal[k].accel_m_s2[i], 1e-5 * (1.0 + std::fabs(ideal[k].accel_m_s2[i])));
            ASSERT_NEAR(biased[k].mag_uT[i], ideal[k].mag_uT[i], 1e-5 * (1.0 + std::fabs(ideal[k].mag_uT[i])));
            moved += std::fabs(board[k].accel_m_s2[i] - ideal[k].accel_m_s2[i]) + std::fabs(board[k].mag_uT[i] - ideal[k].mag_uT[i]);
        }
    }
    EXPECT_GT(moved / (double)ideal.size(), 1.0) << "the preset's accel and compass errors are on the file";
    // A file it cannot read is a clear error, not an empty file.
    const e2e::CommandResult missing = run_command(tool("scenario") + " --from " + e2e::work_dir() + "/no_such_file.csv");
    EXPECT_NE(missing.exit_code, 0);
}

INSTANTIATE_TEST_SUITE_P(Seeded, MotionFile, ::testing::ValuesIn(kMotions));

}  // namespace
