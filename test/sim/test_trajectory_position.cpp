// SPDX-License-Identifier: GPL-3.0-or-later
// Trajectory files' optional n,e,d columns, the physics backend's position and velocity in
// the samples, and the local frame that turns them into latitude and longitude.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "Geodesy.h"
#include "SitlJson.h"
#include "Trajectory.h"

namespace {

std::string write_temp(const std::string& text) {
    char path[] = "/tmp/sim_models_traj_XXXXXX";
    const int fd = mkstemp(path);
    if (fd >= 0) close(fd);
    std::ofstream(path) << text;
    return path;
}

const char* const kRow = "0,0,-9.81,20,0,45,1,0,0,0";  // ax..qz

TEST(TrajectoryPosition, NedColumnsAreReadInAnyOrderAndGiveTheVelocity) {
    const std::string path = write_temp(
        std::string("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,movement,n,e,d\n") +
        "0,0,0,0,0,0,-9.81,20,0,45,1,0,0,0,1,0,0,0\n"
        "1,0,0,0,0,0,-9.81,20,0,45,1,0,0,0,1,10,-4,-2\n"
        "2,0,0,0,0,0,-9.81,20,0,45,1,0,0,0,0,20,-8,-4\n");
    sim::Trajectory t;
    ASSERT_TRUE(t.load(path)) << t.error();
    unlink(path.c_str());
    EXPECT_TRUE(t.has_position());
    EXPECT_FALSE(t[2].movement);
    EXPECT_DOUBLE_EQ(t[1].ned_m[0], 10.0);
    EXPECT_DOUBLE_EQ(t[1].ned_m[2], -2.0);
    for (size_t k = 0; k < t.size(); ++k) {
        EXPECT_DOUBLE_EQ(t[k].vel_ned_m_s[0], 10.0);
        EXPECT_DOUBLE_EQ(t[k].vel_ned_m_s[1], -4.0);
        EXPECT_DOUBLE_EQ(t[k].vel_ned_m_s[2], -2.0);
    }
    const sim::TrajectorySample mid = t.at(1.5);
    EXPECT_DOUBLE_EQ(mid.ned_m[0], 15.0);
    EXPECT_DOUBLE_EQ(t.at(9.0).ned_m[0], 20.0);  // held after the end

    const std::string reordered = write_temp(std::string("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,d,n,e\n") +
                                             "0,0,0,0," + kRow + ",-3,1,2\n");
    sim::Trajectory r;
    ASSERT_TRUE(r.load(reordered)) << r.error();
    unlink(reordered.c_str());
    EXPECT_DOUBLE_EQ(r[0].ned_m[0], 1.0);
    EXPECT_DOUBLE_EQ(r[0].ned_m[1], 2.0);
    EXPECT_DOUBLE_EQ(r[0].ned_m[2], -3.0);
    EXPECT_TRUE(r[0].movement);
}

TEST(TrajectoryPosition, WithoutNedTheBoardStaysAtTheOrigin) {
    const std::string path =
        write_temp(std::string("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,movement\n") + "0,0,0,0," + kRow + ",1\n");
    sim::Trajectory t;
    ASSERT_TRUE(t.load(path)) << t.error();
    unlink(path.c_str());
    EXPECT_FALSE(t.has_position());
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(t[0].ned_m[i], 0.0);
        EXPECT_EQ(t[0].vel_ned_m_s[i], 0.0);
    }
}

TEST(TrajectoryPosition, PartialPositionColumnsAreAnError) {
    const std::string path =
        write_temp(std::string("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,n,e\n") + "0,0,0,0," + kRow + ",1,2\n");
    sim::Trajectory t;
    EXPECT_FALSE(t.load(path));
    unlink(path.c_str());
    EXPECT_NE(t.error().find("n,e,d"), std::string::npos) << t.error();
}

TEST(TrajectoryPosition, ThePhysicsBackendsPositionAndVelocityReachTheSample) {
    sim::PhysicsState state;
    std::string error;
    ASSERT_TRUE(sim::parse_physics_state(
        "{\"timestamp\":1.5,\"imu\":{\"gyro\":[0,0,0],\"accel_body\":[0,0,-9.8]},\"position\":[100,-20,-35],"
        "\"velocity\":[18,1,-0.5],\"attitude\":[0,0,0]}",
        state, error))
        << error;
    const double field[3] = {20, 0, 45};
    const sim::TrajectorySample s = sim::physics_sample(state, 0.5, field);
    EXPECT_DOUBLE_EQ(s.ned_m[0], 100.0);
    EXPECT_DOUBLE_EQ(s.ned_m[2], -35.0);
    EXPECT_DOUBLE_EQ(s.vel_ned_m_s[0], 18.0);
    EXPECT_DOUBLE_EQ(s.vel_ned_m_s[2], -0.5);
}

TEST(TrajectoryPosition, TheLocalFrameMapsMetresToDegreesAtTheField) {
    const sim::LocalFrame frame(sim::GeodeticPoint{sim::kHomeLat_deg, sim::kHomeLon_deg, sim::kHomeAlt_m});
    const double ned[3] = {1000.0, -500.0, -120.0};
    const sim::GeodeticPoint p = frame.to_geodetic(ned);
    // A degree of latitude is ~110.6 km at 7 deg N, of longitude ~110.5 km x cos(7.1 deg).
    EXPECT_NEAR((p.lat_deg - sim::kHomeLat_deg) * 110.6e3, 1000.0, 1.5);
    EXPECT_NEAR((p.lon_deg - sim::kHomeLon_deg) * 111.32e3 * std::cos(sim::kHomeLat_deg * M_PI / 180.0), -500.0, 1.0);
    EXPECT_DOUBLE_EQ(p.alt_m, 1148.0);
    double back[3];
    frame.to_ned(p, back);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], ned[i], 1e-6);
    // ECEF: the equator at the prime meridian is (a, 0, 0).
    double ecef[3];
    sim::geodetic_to_ecef(0.0, 0.0, 0.0, ecef);
    EXPECT_NEAR(ecef[0], 6378137.0, 1e-6);
    sim::geodetic_to_ecef(90.0, 0.0, 0.0, ecef);
    EXPECT_NEAR(ecef[2], 6356752.314, 1e-3);  // the semi-minor axis
}

TEST(TrajectoryPosition, StandardAtmosphere) {
    EXPECT_NEAR(sim::isa_pressure_pa(0.0), 101325.0, 1e-6);
    EXPECT_NEAR(sim::isa_pressure_pa(1000.0), 89874.6, 1.0);  // ICAO table: 898.75 hPa
    EXPECT_NEAR(sim::isa_temperature_c(1000.0), 8.5, 1e-9);
    EXPECT_NEAR(sim::isa_altitude_m(sim::isa_pressure_pa(1028.0)), 1028.0, 1e-6);
}

}  // namespace
