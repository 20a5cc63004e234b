// SPDX-License-Identifier: GPL-3.0-or-later
// ArduPilot's SITL JSON interface as apm25sim speaks it (sim/models/SitlJson), without
// sockets: the servo packet's bytes, the state's fields, the sample the sensors read.
#include <gtest/gtest.h>

#include <cmath>

#include "SitlJson.h"
#include "Trajectory.h"

namespace {

const char* const kLevel =
    "{\"timestamp\":2500,\"imu\":{\"gyro\":[0.1,-0.2,0.3],\"accel_body\":[0,0,-9.81]},"
    "\"position\":[1,2,-3],\"attitude\":[0,0,0],\"velocity\":[4,5,6]}";

TEST(SitlJson, ServoPacketIsFortyLittleEndianBytes) {
    uint16_t pwm[16] = {};
    pwm[0] = 1500;
    pwm[15] = 0x1234;
    const std::string p = sim::encode_servo_packet(1000, 0x01020304u, pwm);
    ASSERT_EQ(p.size(), 40u);
    const auto byte = [&](size_t i) { return (unsigned)(unsigned char)p[i]; };
    EXPECT_EQ(byte(0) | byte(1) << 8, 18458u);
    EXPECT_EQ(byte(2) | byte(3) << 8, 1000u);
    EXPECT_EQ(byte(4), 0x04u);
    EXPECT_EQ(byte(7), 0x01u);
    EXPECT_EQ(byte(8) | byte(9) << 8, 1500u);
    EXPECT_EQ(byte(38), 0x34u);
    EXPECT_EQ(byte(39), 0x12u);
}

TEST(SitlJson, TheReadmesExampleParses) {
    sim::PhysicsState s;
    std::string error;
    ASSERT_TRUE(sim::parse_physics_state(std::string("\n") + kLevel + "\n", s, error)) << error;
    EXPECT_EQ(s.timestamp_s, 2500.0);
    EXPECT_EQ(s.gyro_rad_s[2], 0.3);
    EXPECT_EQ(s.accel_body_m_s2[2], -9.81);
    EXPECT_EQ(s.position_m[2], -3.0);
    EXPECT_EQ(s.velocity_m_s[0], 4.0);
    EXPECT_EQ(s.quat[0], 1.0);
    EXPECT_FALSE(s.has_rc);
    EXPECT_FALSE(s.has_airspeed);
    EXPECT_FALSE(s.has_wind);
}

TEST(SitlJson, QuaternionWinsOverAttitudeAndOptionalFieldsAreRead) {
    sim::PhysicsState s;
    std::string error;
    const std::string text =
        "{\"timestamp\":1.0,\"imu\":{\"gyro\":[0,0,0],\"accel_body\":[0,0,-9.81]},\"position\":[0,0,0],"
        "\"velocity\":[0,0,0],\"attitude\":[1,1,1],\"quaternion\":[0,0,0,1.2],\"airspeed\":21.5,"
        "\"velocity_wind\":[3.2,0.0,-0.7],\"rc\":{\"rc_1\":1100,\"rc_2\":1200,\"rc_3\":1300,\"rc_4\":1400,"
        "\"rc_5\":1500,\"rc_6\":1600,\"rc_7\":1700,\"rc_8\":1800,\"rc_9\":1900},\"battery\":{\"voltage\":12.1},"
        "\"name\":\"x\\\"y\",\"flag\":true,\"none\":null}";
    ASSERT_TRUE(sim::parse_physics_state(text, s, error)) << error;
    EXPECT_EQ(s.quat[3], 1.0);  // normalised
    EXPECT_EQ(s.quat[0], 0.0);
    EXPECT_TRUE(s.has_airspeed);
    EXPECT_EQ(s.airspeed_m_s, 21.5);
    EXPECT_TRUE(s.has_wind);
    EXPECT_EQ(s.velocity_wind_m_s[2], -0.7);
    EXPECT_TRUE(s.has_rc);
    EXPECT_EQ(s.rc_channels, 8);
    sim::RcRow row;
    ASSERT_TRUE(sim::physics_rc_row(s, 3.0, row, error)) << error;
    EXPECT_TRUE(row.signal);
    EXPECT_EQ(row.t_s, 3.0);
    EXPECT_EQ(row.width_us[7], 1800.0);
}

TEST(SitlJson, TheNewestStateInADatagramWins) {
    sim::PhysicsState s;
    std::string error;
    std::string two = std::string(kLevel) + "\n" + kLevel + "\n";
    two.replace(two.rfind("2500"), 4, "2501");
    ASSERT_TRUE(sim::parse_physics_state(two, s, error)) << error;
    EXPECT_EQ(s.timestamp_s, 2501.0);
}

TEST(SitlJson, MissingOrMalformedFieldsAreNamed) {
    struct Case {
        std::string from, to, says;
    };
    const Case cases[] = {
        {"\"timestamp\":2500,", "", "timestamp"},
        {"\"gyro\":[0.1,-0.2,0.3]", "\"gyro\":[0.1,-0.2]", "imu.gyro"},
        {"\"accel_body\"", "\"accel\"", "imu.accel_body"},
        {"\"position\":[1,2,-3],", "", "position"},
        {"\"velocity\":[4,5,6]", "\"velocity\":[4,5,\"6\"]", "velocity"},
        {"\"attitude\":[0,0,0],", "", "quaternion [4] or attitude [3]"},
        {"\"attitude\":[0,0,0]", "\"quaternion\":[0,0,0,0]", "unit quaternion"},
        {"{\"timestamp\"", "[\"timestamp\"", "not a JSON object"},
        {"2500", "2500,", "not a JSON object"},
        {"2500", "nan", "not a JSON object"},
        {"\"attitude\":[0,0,0]", "\"attitude\":[0,0,0],\"rc\":[1500]", "rc is not an object"},
    };
    for (const Case& c : cases) {
        std::string text = kLevel;
        const size_t at = text.find(c.from);
        ASSERT_NE(at, std::string::npos) << c.from;
        text.replace(at, c.from.size(), c.to);
        sim::PhysicsState s;
        std::string error;
        EXPECT_FALSE(sim::parse_physics_state(text, s, error)) << text;
        EXPECT_NE(error.find(c.says), std::string::npos) << text << " -> " << error;
    }
    sim::PhysicsState s;
    std::string error;
    EXPECT_FALSE(sim::parse_physics_state(" \n", s, error));
}

TEST(SitlJson, RcIsLiveWithAllEightDeadWithNoneAndAnErrorOtherwise) {
    sim::PhysicsState s;
    sim::RcRow row;
    std::string error;
    s.has_rc = true;
    ASSERT_TRUE(sim::physics_rc_row(s, 1.0, row, error));  // "rc":{}
    EXPECT_FALSE(row.signal);
    s.rc_channels = 8;  // all zero: dead too
    ASSERT_TRUE(sim::physics_rc_row(s, 1.0, row, error));
    EXPECT_FALSE(row.signal);
    s.rc_channels = 3;
    s.rc_us[0] = 1500;
    EXPECT_FALSE(sim::physics_rc_row(s, 1.0, row, error));
    EXPECT_NE(error.find("not all"), std::string::npos);
    s.rc_channels = 8;
    for (double& w : s.rc_us) w = 1500;
    s.rc_us[4] = 4000;
    EXPECT_FALSE(sim::physics_rc_row(s, 1.0, row, error));
    EXPECT_NE(error.find("rc_5"), std::string::npos) << error;
}

// The field (20, 0, 45) uT NED seen from the body: heading east (yaw 90 deg), body x points
// east and y south, so (0, -20, 45); rolled 90 deg right (yaw 0), y points down and z west,
// so (20, 45, 0).
TEST(SitlJson, TheSampleCarriesRatesForceAttitudeAndTheFieldInTheBody) {
    sim::PhysicsState s;
    std::string error;
    std::string text = kLevel;
    text.replace(text.find("\"attitude\":[0,0,0]"), 18, "\"attitude\":[0,0,1.5707963267948966]");
    ASSERT_TRUE(sim::parse_physics_state(text, s, error)) << error;
    const double field[3] = {20.0, 0.0, 45.0};
    const sim::TrajectorySample a = sim::physics_sample(s, 0.25, field);
    EXPECT_EQ(a.t_s, 0.25);
    EXPECT_EQ(a.gyro_rad_s[1], -0.2);
    EXPECT_EQ(a.accel_m_s2[2], -9.81);
    EXPECT_NEAR(a.mag_uT[0], 0.0, 1e-9);
    EXPECT_NEAR(a.mag_uT[1], -20.0, 1e-9);
    EXPECT_NEAR(a.mag_uT[2], 45.0, 1e-9);
    EXPECT_NEAR(a.quat[0], std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(a.quat[3], std::sqrt(0.5), 1e-12);
    text = kLevel;
    text.replace(text.find("\"attitude\":[0,0,0]"), 18, "\"attitude\":[1.5707963267948966,0,0]");
    ASSERT_TRUE(sim::parse_physics_state(text, s, error)) << error;
    const sim::TrajectorySample b = sim::physics_sample(s, 0.0, field);
    EXPECT_NEAR(b.mag_uT[0], 20.0, 1e-9);
    EXPECT_NEAR(b.mag_uT[1], 45.0, 1e-9);
    EXPECT_NEAR(b.mag_uT[2], 0.0, 1e-9);
}

TEST(SitlJson, TrajectoryHistoryIsTrimmedKeepingWhatInterpolationNeeds) {
    sim::Trajectory t;
    for (int i = 0; i < 10; ++i) {
        sim::TrajectorySample s{};
        s.t_s = i * 0.1;
        s.gyro_rad_s[0] = i;
        t.append(s);
    }
    EXPECT_NEAR(t.at(0.55).gyro_rad_s[0], 5.5, 1e-9);
    t.drop_before(0.55);
    ASSERT_EQ(t.size(), 5u);  // 0.5 (before 0.55) .. 0.9
    EXPECT_NEAR(t.at(0.55).gyro_rad_s[0], 5.5, 1e-9);
    EXPECT_NEAR(t.at(0.85).gyro_rad_s[0], 8.5, 1e-9);
    t.drop_before(0.0);
    EXPECT_EQ(t.size(), 5u);
}

// The race seen on a loaded machine: frame 47172 is sent again after a time-out and
// answered twice; the second answer (timestamp 47.173 s) arrives while frame 47173 is
// awaited. It is not after the last state taken: stale, dropped and counted; the next
// frame's own answer is taken. Any timestamp not after the last is stale (an older late
// answer too), and the first reply is taken whatever its time.
TEST(SitlJson, AReplyNotAfterTheLastTakenIsStale) {
    sim::ReplyClock clock;
    EXPECT_FALSE(clock.started());
    EXPECT_TRUE(clock.take(47.172));  // frame 0: any time starts the clock
    EXPECT_TRUE(clock.take(47.173));  // frame 47172's first answer
    EXPECT_FALSE(clock.take(47.173)); // its late duplicate, while 47173 is awaited
    EXPECT_FALSE(clock.take(47.170)); // an older late answer
    EXPECT_TRUE(clock.take(47.174));  // frame 47173's answer
    EXPECT_EQ(clock.taken(), 3u);
    EXPECT_EQ(clock.stale(), 2u);
    EXPECT_DOUBLE_EQ(clock.last_s(), 47.174);
    // A backend whose time went back: every answer stale, the last taken kept.
    for (int i = 0; i < 5; ++i) EXPECT_FALSE(clock.take(0.001 * (i + 1)));
    EXPECT_EQ(clock.stale(), 7u);
    EXPECT_DOUBLE_EQ(clock.last_s(), 47.174);
    // Only strictly later counts: the smallest step after is taken.
    EXPECT_TRUE(clock.take(std::nextafter(47.174, 100.0)));
}

}  // namespace
