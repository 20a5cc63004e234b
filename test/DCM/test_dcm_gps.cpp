// SPDX-License-Identifier: GPL-3.0-or-later
// The GPS-aided gravity reference (lib/DCM/GpsAid.h) and the GPS course as the heading
// without a compass: the observation's sign and scale, the lag's pairing, what ends the
// aiding; the whole estimator in a coordinated turn and an acceleration it would read as
// tilt without the GPS, and a heading taken from the course.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "Dcm.h"
#include "GpsAid.h"
#include "dcm_test_support.h"

namespace {

using dcm_test::kG;
using linalg::Matrix3f;
using linalg::Vector3f;
using linalg::Vector3l;

constexpr float kDeg = 3.14159265f / 180.0f;
// Accel units per m/s^2 for the part's tests (any scale: the observation is in the same).
constexpr float kUnits = 1000.0f;

Vector3l units_of(const Vector3f& v) {
    return Vector3l(std::lround(v.x * kUnits), std::lround(v.y * kUnits), std::lround(v.z * kUnits));
}
Vector3f m_s2_of(const Vector3l& v) { return Vector3f((float)v.x, (float)v.y, (float)v.z) * (1.0f / kUnits); }

// n windows of the same earth-frame specific force.
void windows(dcm::GpsAccel& gps, const Vector3f& f_ef_m_s2, int n = 10) {
    for (int i = 0; i < n; ++i) gps.add_window(units_of(f_ef_m_s2));
}

// Accelerating north at 2 m/s^2 while the estimate is right: the earth-frame specific
// force is (2, 0, -g); the GPS's velocities grow by 0.4 m/s every 0.2 s. What is left is
// gravity alone, at the scale of the windows' means.
TEST(GpsAccel, TheObservationIsTheSpecificForceLessTheGpsAcceleration) {
    dcm::GpsAccel gps;
    Vector3l obs;
    const Vector3f f(2.0f, 0.0f, -kG);
    windows(gps, f);
    EXPECT_FALSE(gps.on_velocity(Vector3f(10.0f, 0, 0), 0.0f, 1.0f, kUnits, obs));  // the first: no pair
    // At 5 Hz the GPS's interval lies 1.25 sums back: two sums before this fix's.
    for (int i = 1; i <= 2; ++i) {
        windows(gps, f);
        EXPECT_FALSE(gps.on_velocity(Vector3f(10.0f + 0.4f * (float)i, 0, 0), 0.2f, 1.0f, kUnits, obs));
        EXPECT_FALSE(gps.aiding());
    }
    windows(gps, f);
    ASSERT_TRUE(gps.on_velocity(Vector3f(11.2f, 0, 0), 0.2f, 1.0f, kUnits, obs));
    EXPECT_TRUE(gps.aiding());
    const Vector3f g = m_s2_of(obs);
    EXPECT_NEAR(g.x, 0.0f, 0.01f);
    EXPECT_NEAR(g.y, 0.0f, 0.01f);
    EXPECT_NEAR(g.z, -kG, 0.01f);
}

// A tilt error of 3 deg about north (the estimate's east axis is the true one turned
// down): the estimate's earth-frame specific force in a straight, level, steady flight
// is gravity turned by the error, and the GPS's acceleration is zero: the observation
// is gravity as the estimate sees it, its direction the tilt error; with AHRS_GPS_GAIN 0.5
// half the GPS's acceleration comes off.
TEST(GpsAccel, TheGainScalesTheGpsAcceleration) {
    dcm::GpsAccel gps;
    Vector3l obs;
    const float e = 3.0f * kDeg;
    const Vector3f f(4.0f, -kG * std::sin(e), -kG * std::cos(e));  // 4 m/s^2 north, and the tilt
    for (int i = 0; i < 4; ++i) {
        windows(gps, f);
        gps.on_velocity(Vector3f(0.8f * (float)i, 0, 0), i == 0 ? 0.0f : 0.2f, 0.5f, kUnits, obs);
    }
    const Vector3f g = m_s2_of(obs);
    EXPECT_NEAR(g.x, 2.0f, 0.01f);  // 4 - 0.5 * 4
    EXPECT_NEAR(std::atan2(-g.y, -g.z), e, 0.002f);  // the tilt error, whole
}

// The lag: a fix completes kGpsFixLatency_s after the end of the interval its velocity
// change covers. The accelerometer's sums are between arrivals; under an acceleration
// that ramps (a turn's entry: 4 m/s^2 a second), the interval's mean is interpolated
// between the two sums it spans, so nothing of the ramp is left; the nearest sum alone
// (one fix late) would leave the ramp over the 50 ms, 0.2 m/s^2.
void ramp(double rate_hz) {
    dcm::GpsAccel gps;
    Vector3l obs;
    const double ramp_m_s3 = 4.0, window_s = 0.02, interval_s = 1.0 / rate_hz;
    const int per_fix = (int)std::lround(interval_s / window_s);
    const double lag_s = dcm::kGpsFixLatency_s;
    int pairs = 0;
    for (int k = 0; k < 12; ++k) {
        for (int w = 0; w < per_fix; ++w) {
            const double mid_s = ((double)(k * per_fix + w) + 0.5) * window_s;  // the window's mean
            gps.add_window(units_of(Vector3f((float)(ramp_m_s3 * mid_s), 0.0f, -kG)));
        }
        const double arrival_s = (double)((k + 1) * per_fix) * window_s;
        const double then_s = arrival_s - lag_s;  // the velocity's measurement
        const float v = (float)(15.0 + 0.5 * ramp_m_s3 * then_s * then_s);
        if (gps.on_velocity(Vector3f(v, 0, 0), k == 0 ? 0.0f : (float)interval_s, 1.0f, kUnits, obs)) {
            ++pairs;
            EXPECT_NEAR(m_s2_of(obs).x, 0.0f, 0.02f) << "fix " << k << " at " << rate_hz << " Hz";
        }
    }
    EXPECT_GE(pairs, 8);
}

TEST(GpsAccel, ARampIsTakenOffWhateverTheLag) {
    ramp(5.0);
    ramp(1.0);
}

// What ends the aiding: an unusable fix at once; fixes that stop coming after the
// timeout; two fixes too far apart are no pair.
TEST(GpsAccel, AidingEndsWithoutUsableFixes) {
    dcm::GpsAccel gps;
    Vector3l obs;
    const Vector3f f(0.0f, 0.0f, -kG);
    for (int i = 0; i < 4; ++i) {
        windows(gps, f);
        gps.on_velocity(Vector3f(), 0.2f, 1.0f, kUnits, obs);
    }
    ASSERT_TRUE(gps.aiding());
    gps.stop();
    EXPECT_FALSE(gps.aiding());
    for (int i = 0; i < 3; ++i) {  // after a stop: a new chain
        windows(gps, f);
        EXPECT_FALSE(gps.on_velocity(Vector3f(), 0.2f, 1.0f, kUnits, obs));
    }
    windows(gps, f);
    EXPECT_TRUE(gps.on_velocity(Vector3f(), 0.2f, 1.0f, kUnits, obs));
    windows(gps, f, dcm::kGpsTimeoutWindows);
    EXPECT_TRUE(gps.aiding());
    windows(gps, f, 1);
    EXPECT_FALSE(gps.aiding());  // no fix for the timeout
    EXPECT_FALSE(gps.on_velocity(Vector3f(), dcm::kGpsMaxInterval_s + 0.2f, 1.0f, kUnits, obs));
}

// The whole estimator: a true motion, the ideal sensors it gives, and a u-blox's fixes
// (5 Hz, each the velocity of kGpsFixLatency_s before it arrives).
struct Flight {
    dcm::Dcm est;
    int step = 0;
    bool gps = true;
    bool compass = true;
    float gps_gain = 1.0f;

    // r(t), the body rate, the specific force in body axes and the NED velocity at t.
    template <class Motion>
    void run(const Motion& m, float seconds) {
        const float dt = dcm::kDefaultDcmSettings.step_s;
        const int steps = (int)std::lround(seconds / dt);
        for (int i = 0; i < steps; ++i, ++step) {
            const float t = (float)step * dt;
            Matrix3f r;
            Vector3f w, f_body, v;
            m(t, r, w, f_body, v);
            est.update(w, f_body);
            if (compass && step % 3 == 0) est.correct_heading(dcm_test::mag_for(r));
            if (gps && step % 40 == 0 && t >= dcm::kGpsFixLatency_s) {
                Matrix3f r_then;
                Vector3f w_then, f_then, v_then;
                m(t - dcm::kGpsFixLatency_s, r_then, w_then, f_then, v_then);
                est.on_gps_velocity(v_then, 0.2f, gps_gain);
            }
        }
    }
    template <class Motion>
    void start(const Motion& m) {
        Matrix3f r;
        Vector3f w, f, v;
        m(0.0f, r, w, f, v);
        // From the true gravity and field (a start's mean), so that only what follows counts.
        est.init(dcm_test::accel_for(r), dcm_test::mag_for(r), true);
    }
};

// Straight and level at 18 m/s, then from roll_in_s (after the estimator's 3 s start-up,
// with the GPS aiding) a roll at 15 deg/s into a level coordinated turn at 30 deg of bank:
// the heading turns at g tan(bank) / V and the velocity with it. The accelerometer reads
// g / cos(bank) down the body's z axis, which alone (no airspeed) the estimator takes for
// a level board.
struct CoordinatedTurn {
    float bank_rad = 30.0f * kDeg;
    float speed_m_s = 18.0f;
    float roll_in_s = 8.0f;
    float roll_rate_rad_s = 15.0f * kDeg;
    float bank_at(float t) const {
        const float in_s = t - roll_in_s;
        return in_s <= 0.0f ? 0.0f : std::min(roll_rate_rad_s * in_s, bank_rad);
    }
    void operator()(float t, Matrix3f& r, Vector3f& w, Vector3f& f, Vector3f& v) const {
        const float ramp_s = bank_rad / roll_rate_rad_s;
        const float in_s = t - roll_in_s;
        const float bank = bank_at(t);
        const float roll_rate = in_s > 0.0f && in_s < ramp_s ? roll_rate_rad_s : 0.0f;
        const float k = kG / speed_m_s;  // the heading's rate per tan(bank)
        // The heading: the integral of k tan(bank), k (-ln cos(bank)) / roll rate over the ramp.
        float heading = 0.0f;
        if (in_s > 0.0f) heading = k * -std::log(std::cos(bank)) / roll_rate_rad_s;
        if (in_s > ramp_s) heading += k * std::tan(bank_rad) * (in_s - ramp_s);
        const float rate = k * std::tan(bank);
        r = dcm::dcm_from_euler(bank, 0.0f, heading);
        w = Vector3f(roll_rate, rate * std::sin(bank), rate * std::cos(bank));
        f = Vector3f(0.0f, 0.0f, -kG / std::cos(bank));
        v = Vector3f(speed_m_s * std::cos(heading), speed_m_s * std::sin(heading), 0.0f);
    }
};

float roll_error_deg(const dcm::Dcm& est, float truth_rad) {
    return (est.euler().roll_rad - truth_rad) / kDeg;
}

// In the turn the GPS's velocity rotates: its acceleration is the centripetal one, and
// what is left is gravity. With the GPS the estimate holds the bank through the roll-in
// and 60 s of turn; without it (and no airspeed) the accelerometer pulls it toward level.
TEST(DcmGps, ACoordinatedTurnWithTheGpsKeepsItsBank) {
    const CoordinatedTurn turn;
    Flight with, without;
    without.gps = false;
    float worst_deg = 0.0f, worst_pitch_deg = 0.0f;
    for (Flight* f : {&with, &without}) {
        f->start(turn);
        f->run(turn, turn.roll_in_s);
        for (int i = 0; i < 600; ++i) {  // 0.1 s at a time
            f->run(turn, 0.1f);
            if (f != &with) continue;
            const float t = (float)f->step * dcm::kDefaultDcmSettings.step_s;
            worst_deg = std::max(worst_deg, std::fabs(roll_error_deg(f->est, turn.bank_at(t))));
            worst_pitch_deg = std::max(worst_pitch_deg, std::fabs(f->est.euler().pitch_rad / kDeg));
        }
    }
    EXPECT_TRUE(with.est.gps_aiding());
    EXPECT_FALSE(without.est.gps_aiding());
    EXPECT_LT(worst_deg, 0.5f);
    EXPECT_LT(worst_pitch_deg, 0.5f);
    EXPECT_GT(std::fabs(roll_error_deg(without.est, turn.bank_rad)), 5.0f);
}

// Level, wings level, accelerating north at 2 m/s^2 for 20 s: the accelerometer alone
// reads that as 11.5 deg of pitch up (atan(2 / g)); with the GPS's acceleration taken off
// the estimate stays level. With AHRS_GPS_GAIN 0 the GPS takes nothing off.
TEST(DcmGps, AnAccelerationIsNotReadAsPitch) {
    const auto accelerating = [](float t, Matrix3f& r, Vector3f& w, Vector3f& f, Vector3f& v) {
        r = Matrix3f::identity();
        w = Vector3f();
        const float a = t > 5.0f ? 2.0f : 0.0f;
        f = Vector3f(a, 0.0f, -kG);
        v = Vector3f(10.0f + a * (t - 5.0f), 0.0f, 0.0f);
    };
    Flight with, gain0;
    gain0.gps_gain = 0.0f;
    for (Flight* f : {&with, &gain0}) {
        f->start(accelerating);
        f->run(accelerating, 25.0f);
    }
    EXPECT_TRUE(with.est.gps_aiding());
    EXPECT_LT(std::fabs(with.est.euler().pitch_rad / kDeg), 0.5f);
    EXPECT_GT(gain0.est.euler().pitch_rad / kDeg, 8.0f);
}

// A tilt error the turn left without the GPS (the accelerometer pulled the estimate
// toward level for 30 s: degrees of roll) is taken out once the GPS's fixes come (the
// correction's sign), at the gravity loop's pace (kp 1/s behind the low-pass) and the
// compass's (the heading error the tilt left through the dip: in the turn a heading
// error reads as tilt, a_c / g of it).
TEST(DcmGps, ATiltErrorIsCorrectedInATurn) {
    const CoordinatedTurn turn;
    Flight f;
    f.gps = false;
    f.start(turn);
    f.run(turn, turn.roll_in_s + 30.0f);
    EXPECT_GT(std::fabs(roll_error_deg(f.est, turn.bank_rad)), 5.0f);
    f.gps = true;
    f.run(turn, 60.0f);
    EXPECT_LT(std::fabs(roll_error_deg(f.est, turn.bank_rad)), 0.5f);
    EXPECT_LT(std::fabs(f.est.euler().pitch_rad / kDeg), 0.5f);
}

// Without a compass the heading comes from the course (above the caller's 3 m/s): the
// first course at once, then a steady offset (a crab) followed at kp_yaw, the error's
// sign the right way.
TEST(DcmGps, TheCourseIsTheHeadingWithoutACompass) {
    dcm::Dcm est;
    const Matrix3f r = dcm::dcm_from_euler(0.0f, 0.0f, 45.0f * kDeg);
    est.init(dcm_test::accel_for(r), Vector3f(), true);  // no field: yaw starts at 0
    EXPECT_NEAR(est.euler().yaw_rad, 0.0f, 1e-3f);
    est.correct_heading_from_course(45.0f * kDeg, 40);
    EXPECT_NEAR(est.euler().yaw_rad / kDeg, 45.0f, 0.05f);
    // A course 10 deg to the right of the heading, held: 40 s at 0.1/s (time constant 10 s).
    for (int i = 0; i < 40 * 200; ++i) {
        est.update(Vector3f(), dcm_test::accel_for(r));
        if (i % 40 == 0) est.correct_heading_from_course(55.0f * kDeg, 40);
    }
    EXPECT_NEAR(est.euler().yaw_rad / kDeg, 55.0f, 0.5f);
    // Behind the nose (the course 180 deg off): turned the shorter way, at the saturated rate.
    est.correct_heading_from_course(-125.0f * kDeg, 40);
    for (int i = 0; i < 8; ++i) est.update(Vector3f(), dcm_test::accel_for(r));
    EXPECT_LT(est.euler().yaw_rad / kDeg, 55.0f);
}

}  // namespace
