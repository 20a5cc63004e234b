// SPDX-License-Identifier: GPL-3.0-or-later
// Physical properties of the estimator that bugs planted in it broke without any other
// unit test noticing (issue 25): the coning term, the renormalisation's second pass,
// the compass's staleness in the rest test, the gravity window's turn and pending-step
// terms, and the float paths taken for scales the integer factors cannot hold. Each
// test drives dcm::Dcm through its public interface only.
#include <gtest/gtest.h>

#include <cmath>

#include "dcm_test_support.h"
#include "dcm_truth.h"

using namespace dcm_test;
using dcm_truth::Rot;
using dcm_truth::sampled_rate;

namespace {

// No drift correction at all: what is left is the integration alone.
dcm::DcmSettings integration_only() {
    dcm::DcmSettings s = dcm::kDefaultDcmSettings;
    s.kp_rp_1_s = s.ki_rp_1_s2 = s.ki_rp_measured_1_s2 = s.kp_yaw_1_s = s.ki_yaw_1_s2 = s.kp_startup_1_s = 0.0f;
    s.rest_bias_s = 0.0f;
    return s;
}

}  // namespace

// Coning: the body's x axis wobbles around a cone (half angle beta at f Hz), a motion
// whose rotation axis moves within every integration interval. The summed rates alone
// turn the matrix about the wrong axis a little each interval, and that error grows
// steadily (the classic coning drift about the cone's axis); Savage's two-sample term
// (2/3) A x B takes it back. The attitude after a minute of it stays within a tenth
// of a degree of the truth.
TEST(DcmRegressions, ConingMotionLeavesNoDrift) {
    static const dcm::DcmSettings settings = integration_only();
    const double beta_rad = 10.0 * linalg::kRadPerDeg, omega_rad_s = 2.0 * 3.14159265358979 * 4.0;
    // R(t) = exp(beta [u(t) x]) with u = (cos wt, sin wt, 0): the cone about earth z.
    const auto truth = [&](double t) {
        const double u[3] = {beta_rad * std::cos(omega_rad_s * t), beta_rad * std::sin(omega_rad_s * t), 0.0};
        return Rot::exp(u);
    };
    dcm::Dcm filter(settings);
    const Matrix3f start = truth(0.0).to_float();
    ASSERT_TRUE(filter.init(accel_for(start), mag_for(start)));
    const double dt = settings.step_s;
    const int steps = 60 * 200;
    for (int i = 0; i < steps; ++i)
        filter.update(sampled_rate(truth, i * dt, dt), Vector3f(0, 0, -3.0f * kG));
    const float error_deg = angle_between_deg(truth(steps * dt).to_float(), filter.matrix());
    RecordProperty("coning_error_deg", std::to_string(error_deg));
    EXPECT_LT(error_deg, 0.1f);  // today 0.03 deg; with the coning term's sign flipped, 108
}

// The renormalisation leaves R orthonormal to 1e-5 even after a large error. Fast
// turns on a coarse gyro (1.4 rad an integration, near the update series' limit) leave
// each update a few 1e-4 from a rotation; while every step is followed by an output
// line (update's line_due) the renormalisation waits, and the error adds up beyond
// the 2e-3 a single pass leaves at 1e-5. The first step without a line renormalises.
TEST(DcmRegressions, RenormalisationRestoresOrthonormalityAfterALargeError) {
    static const dcm::DcmSettings settings = integration_only();
    float worst_skewed = 0.0f, worst_after = 0.0f;
    for (int counts = 6000; counts <= 9000; counts += 500) {
        dcm::Dcm filter(settings);
        filter.set_sample_scales(0.01f, 0.0024f);
        ASSERT_TRUE(filter.init(Vector3f(0, 0, -kG), earth_field_uT()));
        const linalg::Vector3i turning((int16_t)counts, (int16_t)counts, 0), still(0, 0, 0),
            one_g(0, 0, (int16_t)(-kG / 0.0024f));
        for (int i = 0; i < 2 * 500; ++i) filter.update(turning, one_g, true, true, true);
        const float skewed = orthonormality_error(filter.matrix());
        worst_skewed = skewed > worst_skewed ? skewed : worst_skewed;
        for (int i = 0; i < 8; ++i) filter.update(still, one_g, true, true, false);
        const float after = orthonormality_error(filter.matrix());
        worst_after = after > worst_after ? after : worst_after;
    }
    RecordProperty("worst_skewed", std::to_string(worst_skewed));
    RecordProperty("worst_after", std::to_string(worst_after * 1e6f) + "e-6");
    EXPECT_GT(worst_skewed, 2e-3f);  // the turns did skew R: the test tests something
    EXPECT_LT(worst_after, 1e-5f);
}

// The compass witnesses the rest test only while it delivers: after it falls silent a
// slow steady turn (3 deg/s, beyond the 2 deg/s bound on the mean's distance from the
// bias) must not be taken for rest, nor its rate for a gyro bias.
TEST(DcmRegressions, ASilentCompassDoesNotWitnessRest) {
    dcm::Dcm filter;
    const Matrix3f level = Matrix3f::identity();
    ASSERT_TRUE(filter.init(accel_for(level), mag_for(level)));
    // 5 s with the compass at 75 Hz (the heading known), then it stops.
    for (int i = 0; i < 1000; ++i) {
        if (i % 3 == 0) filter.correct_heading(mag_for(level));
        filter.update(Vector3f(), accel_for(level));
    }
    ASSERT_FALSE(filter.status() & dcm::kStatusNoHeading);
    const float rate_rad_s = 3.0f * linalg::kRadPerDeg;
    int at_rest = 0;
    for (int i = 0; i < 6000; ++i) {
        filter.update(Vector3f(0, 0, rate_rad_s), accel_for(level));
        // (The flag from the rest before is cleared at the next gravity correction.)
        if (i >= dcm::Dcm::kCorrectionDivider && (filter.status() & dcm::kStatusAtRest)) ++at_rest;
    }
    const float bias_z_deg_s = filter.gyro_bias_rad_s().z * linalg::kDegPerRad;
    RecordProperty("bias_z_deg_s", std::to_string(bias_z_deg_s));
    EXPECT_EQ(at_rest, 0);
    EXPECT_LT(std::fabs(bias_z_deg_s), 0.05f);
}

namespace {

// A steady turn at rate_rad_s about a body axis that is horizontal (the earth's down
// turns in body axes all the time), perfect sensors: the worst tilt error over the
// last 10 s of 20. Each accel sample is the attitude at the start of its gyro
// sample's interval (the estimator's convention: sample j meets R_(j-1)).
float tilt_in_a_steady_turn(const Vector3f& axis, float rate_rad_s) {
    dcm::Dcm filter;
    const double dt = filter.settings().step_s;
    const double w[3] = {axis.x * rate_rad_s, axis.y * rate_rad_s, axis.z * rate_rad_s};
    const auto truth = [&](double t) {
        const double theta[3] = {w[0] * t, w[1] * t, w[2] * t};
        return Rot::exp(theta);
    };
    const Matrix3f start = truth(0.0).to_float();
    EXPECT_TRUE(filter.init(accel_for(start), Vector3f()));
    const Vector3f rate = axis * rate_rad_s;
    float worst = 0.0f;
    for (int i = 1; i <= 4000; ++i) {
        filter.update(rate, accel_for(truth((i - 1) * dt).to_float()));
        // matrix() is R at the last integration (every kIntegrationSteps steps).
        if (i > 2000 && i % dcm::Dcm::kIntegrationSteps == 0) {
            const float e = tilt_error_deg(truth(i * dt).to_float(), filter.matrix());
            worst = e > worst ? e : worst;
        }
    }
    return worst;
}

}  // namespace

// The gravity window's samples meet the matrix of their own time, not the window's
// end: in a steady roll each sample is turned back by the rate times its age (the turn
// term), less the steps the matrix itself is behind (the pending-step term). Without
// either the low-passed down direction lags the truth by the rate times a few ms, and
// the tilt with it.
TEST(DcmRegressions, TiltStaysTrueInASteadyRoll) {
    const float roll = tilt_in_a_steady_turn(Vector3f(1, 0, 0), 3.0f);
    const float pitch = tilt_in_a_steady_turn(Vector3f(0, 1, 0), -2.0f);
    const float oblique = tilt_in_a_steady_turn(Vector3f(0.6f, 0.0f, 0.8f), 4.0f);
    RecordProperty("roll_deg", std::to_string(roll));
    RecordProperty("pitch_deg", std::to_string(pitch));
    RecordProperty("oblique_deg", std::to_string(oblique));
    // Today ~0.02-0.03 deg; without the pending-step term 0.6-0.9, without the turn term 0.9-1.3.
    EXPECT_LT(roll, 0.1f);
    EXPECT_LT(pitch, 0.1f);
    EXPECT_LT(oblique, 0.1f);
}
