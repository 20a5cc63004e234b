// Gyro-bias and magnetometer calibration (lib/Calibration).
#include <gtest/gtest.h>

#include <cmath>

#include "Calibration.h"

using calib::GyroCalibrator;
using calib::MagCalibrator;
using linalg::Vector3f;

namespace {
const Vector3f kLevel(0.0f, 0.0f, -9.80665f);
const Vector3f kBias(0.02f, -0.01f, 0.005f);

// Small deterministic noise in [-a, a].
float noise(uint32_t& s, float a) {
    s = s * 1664525u + 1013904223u;
    return a * ((float)(s >> 8) / 8388608.0f - 1.0f);
}
}  // namespace

TEST(Calibration, ApplyInOnePlace) {
    calib::Calibration c = calib::default_calibration();
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == kBias);
    c.gyro_bias_rad_s = kBias;
    EXPECT_TRUE(calib::apply_gyro(c, kBias) == Vector3f());
    c.mag_offset_uT = Vector3f(10.0f, 0.0f, -5.0f);
    c.mag_scale = Vector3f(2.0f, 1.0f, 0.5f);
    EXPECT_TRUE(calib::apply_mag(c, Vector3f(11.0f, 3.0f, -1.0f)) == Vector3f(2.0f, 3.0f, 2.0f));
    EXPECT_TRUE(calib::is_plausible(c));
    c.mag_scale.x = 5.0f;
    EXPECT_FALSE(calib::is_plausible(c));
}

TEST(Calibration, GyroBiasAtRestTakesOneSecond) {
    GyroCalibrator g;
    uint32_t s = 1;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    int n = 0;
    while (r != GyroCalibrator::Result::Done && n < 1000) {
        const Vector3f gyro = kBias + Vector3f(noise(s, 0.004f), noise(s, 0.004f), noise(s, 0.004f));
        const Vector3f acc = kLevel + Vector3f(noise(s, 0.05f), noise(s, 0.05f), noise(s, 0.05f));
        r = g.add(gyro, acc);
        ASSERT_NE(r, GyroCalibrator::Result::Moved);
        ++n;
    }
    EXPECT_EQ(n, calib::kGyroWindow);
    EXPECT_NEAR(g.bias().x, kBias.x, 0.001f);
    EXPECT_NEAR(g.bias().y, kBias.y, 0.001f);
    EXPECT_NEAR(g.bias().z, kBias.z, 0.001f);
    EXPECT_NEAR(g.mean_accel_m_s2().z, -9.80665f, 0.02f);
    EXPECT_EQ(g.restarts(), 0);
}

TEST(Calibration, GyroRestartsWhenTheBoardMoves) {
    GyroCalibrator g;
    for (int i = 0; i < 100; ++i) ASSERT_EQ(g.add(kBias, kLevel), GyroCalibrator::Result::Collecting);
    // A 10 deg/s twitch.
    EXPECT_EQ(g.add(kBias + Vector3f(0.0f, 0.0f, 0.17f), kLevel), GyroCalibrator::Result::Moved);
    EXPECT_EQ(g.restarts(), 1);
    EXPECT_EQ(g.count(), 0);
    // Then a full still second completes.
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(kBias, kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Done);
}

TEST(Calibration, GyroRestartsOnAccelChange) {
    GyroCalibrator g;
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Shaken: |a| 1.3 g.
    EXPECT_EQ(g.add(kBias, kLevel * 1.3f), GyroCalibrator::Result::Moved);
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    // Slowly tilting: |a| stays 1 g but an axis moves by 0.5 m/s^2.
    EXPECT_EQ(g.add(kBias, Vector3f(0.5f, 0.0f, -9.79f)), GyroCalibrator::Result::Moved);
    // NaN counts as movement, never as data.
    for (int i = 0; i < 50; ++i) g.add(kBias, kLevel);
    EXPECT_EQ(g.add(Vector3f(std::nanf(""), 0.0f, 0.0f), kLevel), GyroCalibrator::Result::Moved);
}

TEST(Calibration, SteadySpinIsNotABias) {
    GyroCalibrator g;
    GyroCalibrator::Result r = GyroCalibrator::Result::Collecting;
    for (int i = 0; i < calib::kGyroWindow; ++i) r = g.add(Vector3f(0.0f, 0.0f, 1.0f), kLevel);
    EXPECT_EQ(r, GyroCalibrator::Result::Moved);
    EXPECT_FALSE(g.done());
}

namespace {
// Feeds a rotation through every orientation of a field `b` seen through an offset and
// per-axis gains.
void feed_sphere(MagCalibrator& m, const Vector3f& offset, const Vector3f& gain, float b_uT) {
    for (int i = 0; i < 36; ++i) {
        for (int j = 0; j < 18; ++j) {
            const float az = (float)i * 10.0f * linalg::kRadPerDeg;
            const float el = ((float)j * 10.0f - 85.0f) * linalg::kRadPerDeg;
            const Vector3f f(b_uT * cosf(el) * cosf(az), b_uT * cosf(el) * sinf(az), b_uT * sinf(el));
            m.add(Vector3f(f.x * gain.x, f.y * gain.y, f.z * gain.z) + offset);
        }
    }
}
}  // namespace

TEST(Calibration, MagHardIronAndScale) {
    MagCalibrator m;
    const Vector3f offset(20.0f, -15.0f, 40.0f);
    const Vector3f gain(1.1f, 0.9f, 1.0f);
    feed_sphere(m, offset, gain, 50.0f);
    calib::Calibration c = calib::default_calibration();
    c.gyro_bias_rad_s = kBias;
    ASSERT_EQ(m.finish(c), MagCalibrator::Quality::Ok);
    EXPECT_NEAR(c.mag_offset_uT.x, 20.0f, 0.5f);
    EXPECT_NEAR(c.mag_offset_uT.y, -15.0f, 0.5f);
    EXPECT_NEAR(c.mag_offset_uT.z, 40.0f, 0.5f);
    // After calibration the axes have equal spans.
    EXPECT_NEAR(c.mag_scale.x * 1.1f, c.mag_scale.y * 0.9f, 0.02f);
    EXPECT_NEAR(c.mag_scale.y * 0.9f, c.mag_scale.z * 1.0f, 0.02f);
    EXPECT_TRUE(c.gyro_bias_rad_s == kBias);  // untouched
    const Vector3f corrected = calib::apply_mag(c, Vector3f(50.0f * 1.1f, 0.0f, 0.0f) + offset);
    EXPECT_NEAR(corrected.length(), 50.0f, 1.5f);
}

TEST(Calibration, MagQualityChecks) {
    calib::Calibration c = calib::default_calibration();
    const calib::Calibration before = c;
    MagCalibrator m;
    for (int i = 0; i < 10; ++i) m.add(Vector3f((float)i, 0.0f, 0.0f));
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::TooFewSamples);

    // Only turned about z: the z axis never changes.
    m.restart();
    for (int i = 0; i < 360; ++i) {
        const float a = (float)i * linalg::kRadPerDeg;
        m.add(Vector3f(30.0f * cosf(a), 30.0f * sinf(a), 40.0f));
    }
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::AxisNotTurned);
    EXPECT_EQ(m.axis(), 2);

    // A magnet nearby.
    m.restart();
    feed_sphere(m, Vector3f(), Vector3f(1.0f, 1.0f, 1.0f), 400.0f);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::SpanTooLarge);

    // Axes that disagree by 2x.
    m.restart();
    feed_sphere(m, Vector3f(), Vector3f(2.0f, 1.0f, 1.0f), 30.0f);
    EXPECT_EQ(m.finish(c), MagCalibrator::Quality::AxesDisagree);

    EXPECT_TRUE(c.mag_offset_uT == before.mag_offset_uT);
    EXPECT_TRUE(c.mag_scale == before.mag_scale);

    // Non-finite samples are ignored.
    m.restart();
    m.add(Vector3f(std::nanf(""), 0.0f, 0.0f));
    EXPECT_EQ(m.count(), 0);
}

// ---------------------------------------------------------------------------
// The start-up calibration as the firmware and the replay tool run it (lib/Pipeline).
#include <string>

#include "Pipeline.h"

namespace {

void sink_write(void* ctx, const char* d, uint8_t n) { static_cast<std::string*>(ctx)->append(d, n); }

mpu6000::Sample imu(const Vector3f& gyro, const Vector3f& accel) {
    return mpu6000::Sample{gyro, accel, 25.0f, false, false};
}

// North-facing level board: field north and down (dip ~60 deg).
const Vector3f kFieldNorthDown(20.0f, 0.0f, 40.0f);

}  // namespace

TEST(Pipeline, StartsAfterOneStillSecondLevelAndNorth) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    pipeline::AttitudePipeline p(&sink);
    p.set_mag_present(true);
    int first_output = -1;
    for (int i = 0; i < 400; ++i) {
        if (i % 3 == 0) p.on_mag_sample(kFieldNorthDown);
        p.on_imu_sample(imu(kBias, kLevel));
        if (p.output_due() && first_output < 0) first_output = i;
    }
    EXPECT_EQ(first_output, calib::kGyroWindow - 1);  // the step that finished the calibration
    EXPECT_EQ(p.phase(), pipeline::Phase::Running);
    EXPECT_NEAR(p.settings().cal.gyro_bias_rad_s.x, kBias.x, 1e-6f);
    const pipeline::Angles a = p.angles();
    EXPECT_NEAR(a.roll_deg, 0.0f, 0.1f);
    EXPECT_NEAR(a.pitch_deg, 0.0f, 0.1f);
    EXPECT_TRUE(a.heading_deg < 0.5f || a.heading_deg > 359.5f) << a.heading_deg;
    EXPECT_NE(log.find("# gyro bias: "), std::string::npos) << log;
    p.settings().declination_centideg = 250;
    EXPECT_NEAR(p.angles().heading_deg, 2.5f, 0.5f);
}

TEST(Pipeline, RolledAndPitchedBoardFromGravity) {
    // 90 deg roll right: body y points down, the accelerometer reads -g on body y.
    pipeline::AttitudePipeline p;
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(Vector3f(), Vector3f(0.0f, -9.80665f, 0.0f)));
    EXPECT_NEAR(p.angles().roll_deg, 90.0f, 0.5f);
    // 30 deg nose up: body x tilts up, specific force along +x is g sin 30.
    pipeline::AttitudePipeline q;
    for (int i = 0; i < 300; ++i) q.on_imu_sample(imu(Vector3f(), Vector3f(4.903f, 0.0f, -8.4926f)));
    EXPECT_NEAR(q.angles().pitch_deg, 30.0f, 0.5f);
}

TEST(Pipeline, MovingBoardStillStartsBeforeTheDeadline) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    pipeline::AttitudePipeline p(&sink);
    int first_output = -1;
    for (int i = 0; i < 400 && first_output < 0; ++i) {
        const float wobble = (i % 20 < 10) ? 0.2f : -0.2f;  // +-11 deg/s
        p.on_imu_sample(imu(Vector3f(0.0f, 0.0f, wobble), kLevel));
        if (p.output_due()) first_output = i;
    }
    EXPECT_EQ(first_output, pipeline::kStartupDeadlineSteps - 1);
    EXPECT_NE(log.find("# calibrating gyro: board moved, retrying"), std::string::npos);
    EXPECT_NE(log.find("# warn: board not still"), std::string::npos);
    EXPECT_TRUE(p.gyro_calibrating());  // measuring on in the background
}

TEST(Pipeline, OutputRateFollowsTheSetting) {
    pipeline::AttitudePipeline p;
    for (int i = 0; i < calib::kGyroWindow; ++i) p.on_imu_sample(imu(kBias, kLevel));
    for (uint8_t rate : {50, 1, 7, 100}) {
        p.settings().rate_hz = rate;
        int lines = 0;
        for (int i = 0; i < 2000; ++i) {  // 10 s
            p.on_imu_sample(imu(kBias, kLevel));
            if (p.output_due()) ++lines;
        }
        EXPECT_NEAR(lines, rate * 10, 1) << int(rate);
    }
}

TEST(Pipeline, SpikeIsReplacedAndWarnedOnce) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    pipeline::AttitudePipeline p(&sink);
    for (int i = 0; i < 300; ++i) p.on_imu_sample(imu(kBias, kLevel));
    log.clear();
    p.on_imu_sample(imu(Vector3f(30.0f, -30.0f, 30.0f), kLevel * 6.0f));
    p.on_imu_sample(imu(Vector3f(30.0f, -30.0f, 30.0f), kLevel * 6.0f));
    for (int i = 0; i < 10; ++i) p.on_imu_sample(imu(kBias, kLevel));
    EXPECT_EQ(p.spikes(), 2u);
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.2f);  // the spike never reached the estimator
    size_t first = log.find("# warn: MPU6000 spike");
    EXPECT_NE(first, std::string::npos) << log;
    EXPECT_EQ(log.find("# warn: MPU6000 spike", first + 1), std::string::npos) << "rate-limited";
}

TEST(Pipeline, StuckAccelIsNotGravityButGyroIsIntegrated) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    pipeline::AttitudePipeline p(&sink);
    for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));  // past the start-up ramp
    log.clear();
    // 1 s of accel stuck at full scale on every axis (a broken sensor, 14 g): it must
    // not tilt the estimate.
    const float fs = 8.0f * 9.80665f;
    mpu6000::Sample clipped = imu(kBias, Vector3f(fs, fs, -fs));
    clipped.accel_saturated = true;
    for (int i = 0; i < 200; ++i) p.on_imu_sample(clipped);
    EXPECT_NEAR(p.angles().roll_deg, 0.0f, 0.05f);
    EXPECT_NEAR(p.angles().pitch_deg, 0.0f, 0.05f);
    EXPECT_NE(log.find("# warn: MPU6000 accel saturated"), std::string::npos) << log;
    // The gyro still counts: 0.5 s at 20 deg/s about x with a stuck accel rolls 10 deg.
    mpu6000::Sample turning = clipped;
    turning.gyro_rad_s = kBias + Vector3f(20.0f * linalg::kRadPerDeg, 0.0f, 0.0f);
    for (int i = 0; i < 100; ++i) p.on_imu_sample(turning);
    EXPECT_NEAR(p.angles().roll_deg, 10.0f, 0.3f);
}

TEST(Pipeline, BriefOneAxisClippingInAShakeIsStillUsed) {
    // A shake that clips one axis for 40 ms at each swing: the clipped samples are
    // used, so the shake averages out as it does unclipped (withholding the clipped
    // half of each swing would leave the other half and tilt the estimate).
    pipeline::AttitudePipeline p(nullptr);
    for (int i = 0; i < 1200; ++i) p.on_imu_sample(imu(kBias, kLevel));
    const float fs = 8.0f * 9.80665f;
    for (int cycle = 0; cycle < 20; ++cycle) {
        for (int i = 0; i < 8; ++i) {  // 40 ms of +x clipped
            mpu6000::Sample s = imu(kBias, Vector3f(fs, 0.0f, -9.80665f));
            s.accel_saturated = true;
            p.on_imu_sample(s);
        }
        for (int i = 0; i < 8; ++i) p.on_imu_sample(imu(kBias, Vector3f(-fs + 0.5f, 0.0f, -9.80665f)));
    }
    for (int i = 0; i < 20; ++i) p.on_imu_sample(imu(kBias, kLevel));
    EXPECT_LT(std::fabs(p.angles().pitch_deg), 1.0f);
}

TEST(Pipeline, MagCalibrationCommand) {
    std::string log;
    const text::Sink sink{&log, sink_write};
    pipeline::AttitudePipeline p(&sink);
    p.set_mag_present(true);
    for (int i = 0; i < 250; ++i) p.on_imu_sample(imu(kBias, kLevel));
    p.start_mag_calibration();
    EXPECT_TRUE(p.mag_calibrating());
    // Only turned about z: the check must fail and keep the old calibration.
    for (int i = 0; i < calib::kMagCalSeconds * 200; ++i) {
        const float a = (float)i * 0.01f;
        if (i % 3 == 0) p.on_mag_sample(Vector3f(30.0f * cosf(a), 30.0f * sinf(a), 40.0f));
        p.on_imu_sample(imu(kBias, kLevel));
    }
    EXPECT_FALSE(p.mag_calibrating());
    EXPECT_NE(log.find("# error: cal mag failed: z axis not turned enough"), std::string::npos) << log;
    EXPECT_TRUE(p.settings().cal.mag_scale == Vector3f(1.0f, 1.0f, 1.0f));
    // Defaults keep the gyro bias measured at this start.
    p.restore_defaults();
    EXPECT_NEAR(p.settings().cal.gyro_bias_rad_s.x, kBias.x, 1e-6f);
}
