// SPDX-License-Identifier: GPL-3.0-or-later
// The host unit tests' checks, on the ATmega2560: the lib/ routines the firmware runs,
// compiled by avr-gcc (test/e2e/support/avr/build.sh) and run in apm25sim by
// test/e2e/test_selftest.cpp, so that "host-tested" also means "works on the target"
// (float, int and libm behaviour of avr-gcc/avr-libc, not the host's).
//
// One line per check on UART0 (115200):
//   # selftest <name>: ok [metric=value]
//   # selftest <name>: FAIL line <source line of the first failed expectation> (<n> failed) [metric=value]
// then "# selftest done: <checks> checks, <ok> ok, <failed> FAIL".
// Deterministic: a fixed xorshift32 sequence, no sensor, no time dependence.
//
// Also builds on the host (g++ -I lib/* selftest.cpp lib/*/*.cpp), printing to stdout,
// which is how the bounds below were checked against the host's figures.
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "Console.h"
#include "Dcm.h"
#include "Euler.h"
#include "Fixed.h"
#include "Format.h"
#include "Hmc5883Registers.h"
#include "LinAlg.h"
#include "Mpu6000Registers.h"
#include "Settings.h"
#include "Text.h"

#ifdef __AVR__
#include <Arduino.h>
#include <avr/sleep.h>
#else
#include <stdio.h>
#endif

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {

// ---- output ----------------------------------------------------------------------
#ifdef __AVR__
void out_write(void*, const char* data, uint8_t len) { Serial.write(reinterpret_cast<const uint8_t*>(data), len); }
#else
void out_write(void*, const char* data, uint8_t len) { fwrite(data, 1, len, stdout); }
#endif
const text::Sink kOut = {nullptr, out_write};

// ---- expectations ----------------------------------------------------------------
struct State {
    uint16_t failed_expectations;
    uint16_t first_failed_line;
    bool has_metric;
    text::Flash metric_name;
    int32_t metric;
};
State g_state;

#define EXPECT(cond)                                                            \
    do {                                                                        \
        if (!(cond)) {                                                          \
            if (g_state.failed_expectations == 0) g_state.first_failed_line = __LINE__; \
            ++g_state.failed_expectations;                                      \
        }                                                                       \
    } while (0)

// avr-libc's fabsf, asinf, ... are its double functions (double is float there):
// these keep every expression float on both targets (-Wdouble-promotion).
float absf(float x) { return x < 0.0f ? -x : x; }
float asin_f(float x) { return (float)asinf(x); }
float acos_f(float x) { return (float)acosf(x); }
float atan2_f(float y, float x) { return (float)atan2f(y, x); }

// |a - b| <= tol; NaN fails.
bool near(float a, float b, float tol) { return absf(a - b) <= tol; }
bool near(const Vector3f& v, float x, float y, float z, float tol) {
    return near(v.x, x, tol) && near(v.y, y, tol) && near(v.z, z, tol);
}

// A figure shown on the check's line: round(value * scale) as an integer.
void metric(text::Flash name, float value, float scale) {
    g_state.has_metric = true;
    g_state.metric_name = name;
    const float v = value * scale;
    g_state.metric = linalg::is_finite(v) && v < 2e9f && v > -2e9f ? (int32_t)(v + (v >= 0 ? 0.5f : -0.5f)) : INT32_MAX;
}

uint8_t g_checks = 0, g_ok = 0;

void run(text::Flash name, void (*check)()) {
    memset(&g_state, 0, sizeof g_state);
    check();
    ++g_checks;
    text::Writer w(&kOut);
    w.str(TXT("# selftest ")).str(name).str(TXT(": "));
    if (g_state.failed_expectations == 0) {
        ++g_ok;
        w.str(TXT("ok"));
    } else {
        w.str(TXT("FAIL line ")).u32(g_state.first_failed_line).str(TXT(" ("))
            .u32(g_state.failed_expectations).str(TXT(" failed)"));
    }
    if (g_state.has_metric) w.chr(' ').str(g_state.metric_name).chr('=').i32(g_state.metric);
    w.end();
}

// xorshift32: the same sequence on every target.
uint32_t g_rng = 2463534242u;
uint32_t random_u32() {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 17;
    g_rng ^= g_rng << 5;
    return g_rng;
}
float uniform(float lo, float hi) { return lo + (hi - lo) * (float)(random_u32() >> 8) * (1.0f / 16777216.0f); }

float max_abs_diff(const Matrix3f& a, const Matrix3f& b) {
    const Matrix3f d = a - b;
    const float v[9] = {d.a.x, d.a.y, d.a.z, d.b.x, d.b.y, d.b.z, d.c.x, d.c.y, d.c.z};
    float worst = 0.0f;
    for (uint8_t i = 0; i < 9; ++i) worst = absf(v[i]) > worst ? absf(v[i]) : worst;
    return worst;
}

float orthonormality_error(const Matrix3f& r) { return max_abs_diff(r * r.transposed(), Matrix3f::identity()); }

constexpr float kG = 9.80665f;
const Vector3f kEarthField_uT(20.0f, 0.0f, 45.0f);  // NED, Berlin-like

// ---- the checks --------------------------------------------------------------------

// LinAlg: every operation against hand-computed values (test_linalg.cpp).
void check_linalg_ops() {
    const Vector3f a(1, 2, 3), b(4, -5, 6);
    EXPECT(near(a + b, 5, -3, 9, 0));
    EXPECT(near(a - b, -3, 7, -3, 0));
    EXPECT(near(-a, -1, -2, -3, 0));
    EXPECT(near(a * 2.0f, 2, 4, 6, 0));
    EXPECT(near(0.5f * b, 2, -2.5f, 3, 0));
    EXPECT(a.dot(b) == 12.0f);
    EXPECT(near(a.cross(b), 27, 6, -13, 0));
    EXPECT(near(Vector3f(3, 4, 0).length(), 5.0f, 1e-6f));
    EXPECT(near(Vector3f(3, 4, 0).normalized(), 0.6f, 0.8f, 0.0f, 1e-6f));
    Vector3f c = a;
    c += b;
    c -= Vector3f(1, 1, 1);
    c *= 2.0f;
    EXPECT(near(c, 8, -8, 16, 0));
    const Matrix3f m(Vector3f(1, 2, 3), Vector3f(4, 5, 6), Vector3f(7, 8, 10));
    EXPECT(near(m * a, 14, 32, 53, 0));
    EXPECT(near(m.mul_transpose(a), 30, 36, 45, 0));
    EXPECT(near(m.determinant(), -3.0f, 1e-5f));
    EXPECT(near(m.transposed().a, 1, 4, 7, 0) && near(m.transposed().c, 3, 6, 10, 0));
    EXPECT(max_abs_diff(m * Matrix3f::identity(), m) == 0.0f);
    EXPECT(near(Matrix3f::skew(a) * b, 27, 6, -13, 0));
    // (M [b x]) a = M (b x a)
    const Vector3f lhs = (m * Matrix3f::skew(b)) * a, rhs = m * b.cross(a);
    EXPECT(near(lhs, rhs.x, rhs.y, rhs.z, 1e-4f));
    EXPECT(max_abs_diff(m + m, m * 2.0f) == 0.0f && max_abs_diff(m - m, Matrix3f::zero()) == 0.0f);
}

// Degenerate inputs never give NaN (test_linalg.cpp).
void check_linalg_degenerate() {
    const float nan = __builtin_nanf("");
    const float inf = __builtin_inff();
    Vector3f z;
    EXPECT(z.normalized().is_zero() && z.normalized().is_finite());
    EXPECT(!z.normalize());
    EXPECT(Vector3f(1e-30f, 0, 0).normalized().is_finite());
    EXPECT(Vector3f(nan, 1, 1).normalized().is_zero());
    EXPECT(Vector3f(inf, 0, 0).normalized().is_zero());
    EXPECT(!Vector3f(inf, 0, 0).is_finite() && !Vector3f(0, nan, 0).is_finite());
    EXPECT((linalg::constrain)(nan, -1.0f, 1.0f) == -1.0f && (linalg::constrain)(5.0f, -1.0f, 1.0f) == 1.0f);
    EXPECT(linalg::safe_sqrt(-1.0f) == 0.0f && linalg::safe_sqrt(nan) == 0.0f && linalg::safe_sqrt(4.0f) == 2.0f);
    EXPECT(near(linalg::safe_asin(2.0f), linalg::kPi / 2, 1e-6f) && linalg::safe_asin(nan) == 0.0f);
    EXPECT(!linalg::is_finite(inf) && !linalg::is_finite(nan) && linalg::is_finite(-3.0e38f));
}

// fast_atan2 within its stated 1.2e-5 rad of the libm atan2 (test bound 1.3e-5).
void check_fast_atan2() {
    float worst = 0.0f;
    const float scales[] = {1.0f, 1e3f, 1e-3f};
    for (uint8_t s = 0; s < 3; ++s) {
        for (uint16_t i = 0; i < 400; ++i) {
            const float y = uniform(-1, 1) * scales[s], x = uniform(-1, 1) * scales[s];
            const float err = absf(linalg::fast_atan2(y, x) - atan2_f(y, x));
            worst = err > worst ? err : worst;
        }
    }
    EXPECT(worst < 1.3e-5f);
    EXPECT(linalg::fast_atan2(0.0f, 1.0f) == 0.0f);
    EXPECT(near(linalg::fast_atan2(1.0f, 0.0f), linalg::kPi / 2, 2e-5f));
    EXPECT(near(linalg::fast_atan2(0.0f, -1.0f), linalg::kPi, 1e-6f));
    EXPECT(near(linalg::fast_atan2(-1.0f, 0.0f), -linalg::kPi / 2, 2e-5f));
    EXPECT(linalg::fast_atan2(0.0f, 0.0f) == 0.0f);
    EXPECT(linalg::fast_atan2(__builtin_nanf(""), 1.0f) == 0.0f);
    EXPECT(near(linalg::fast_atan2(1e30f, 1e-30f), linalg::kPi / 2, 2e-5f));
    metric(TXT("worst_urad"), worst, 1e6f);
}

// R -> (roll, pitch, yaw) -> R within 1e-4, for random R and at / near pitch +-90 deg
// (test_euler.cpp).
void check_euler_round_trip() {
    float worst = 0.0f;
    const float d = linalg::kRadPerDeg;
    const dcm::EulerAngles known = dcm::euler_from_dcm(dcm::dcm_from_euler(10 * d, -20 * d, 135 * d));
    EXPECT(near(known.roll_rad / d, 10.0f, 1e-3f) && near(known.pitch_rad / d, -20.0f, 1e-3f) &&
           near(known.yaw_rad / d, 135.0f, 1e-3f));
    const float offsets[] = {-1.0f, 0.0f, 1e-6f, -1e-6f, 1e-5f, 1e-3f};  // -1: a random pitch
    for (uint8_t o = 0; o < 6; ++o) {
        for (int8_t sign = -1; sign <= 1; sign += 2) {
            for (uint8_t i = 0; i < 40; ++i) {
                const float pitch = offsets[o] < 0.0f ? asin_f(uniform(-1, 1))
                                                      : (float)sign * (linalg::kPi / 2 - offsets[o]);
                const Matrix3f r = dcm::dcm_from_euler(uniform(-linalg::kPi, linalg::kPi), pitch,
                                                       uniform(-linalg::kPi, linalg::kPi));
                const dcm::EulerAngles e = dcm::euler_from_dcm(r);
                EXPECT(linalg::is_finite(e.roll_rad) && linalg::is_finite(e.pitch_rad) && linalg::is_finite(e.yaw_rad));
                const float err = max_abs_diff(dcm::dcm_from_euler(e.roll_rad, e.pitch_rad, e.yaw_rad), r);
                worst = err > worst ? err : worst;
                EXPECT(near(e.pitch_rad, pitch, 2e-5f));
            }
        }
    }
    EXPECT(worst < 1e-4f);
    // At exactly +90 deg roll folds into yaw: roll 30, yaw 50 -> roll 0, yaw 20.
    const dcm::EulerAngles lock = dcm::euler_from_dcm(dcm::dcm_from_euler(30 * d, 90 * d, 50 * d));
    EXPECT(near(lock.roll_rad, 0.0f, 1e-3f) && near(lock.yaw_rad / d, 20.0f, 0.05f));
    metric(TXT("worst_e6"), worst, 1e6f);
}

// Many random-rate steps keep the matrix orthonormal to 1e-5 (test_dcm.cpp: 100 000
// steps on the host; 1 000 here, ~3 simulated seconds).
void check_dcm_orthonormal() {
    dcm::Dcm filter;
    EXPECT(filter.init(Vector3f(0, 0, -kG), kEarthField_uT));
    float worst = 0.0f;
    for (uint16_t i = 0; i < 1000; ++i) {
        // Accel far from 1 g: only integration and renormalisation act.
        filter.update(Vector3f(uniform(-10, 10), uniform(-10, 10), uniform(-10, 10)), Vector3f(0, 0, -3.0f * kG));
        const float e = orthonormality_error(filter.matrix());
        worst = e > worst ? e : worst;
    }
    EXPECT(worst < 1e-5f);
    EXPECT(filter.recoveries() == 0);
    metric(TXT("worst_e7"), worst, 1e7f);
}

// A 2 deg/s bias on every axis at rest: roll/pitch within 0.5 deg after 30 s and the
// bias learned (test_dcm.cpp). The step is 20 ms instead of 5 ms, a quarter of the
// AVR time: the gains are per second and scaled by the step, so the filter converges
// the same (host: tilt 0.13 deg, bias 2.01 1.97 1.95 deg/s at 30 s at either step).
void check_dcm_bias_at_rest() {
    dcm::DcmSettings settings = dcm::kDefaultDcmSettings;
    settings.step_s = 0.02f;
    dcm::Dcm filter(settings);
    const Matrix3f truth = dcm::dcm_from_euler(0.4f, -0.3f, 2.0f);
    const Vector3f accel = truth.mul_transpose(Vector3f(0, 0, -kG));
    const Vector3f field = truth.mul_transpose(kEarthField_uT);
    EXPECT(filter.init(accel, field));
    const Vector3f bias = Vector3f(1, 1, 1) * (2.0f * linalg::kRadPerDeg);
    float t_s = 0.0f, next_mag_s = 0.0f;
    for (uint16_t i = 0; i < 1500; ++i) {  // 30 s
        t_s += settings.step_s;
        if (t_s >= next_mag_s) {  // the field at 75 Hz, at most one sample a step (as the firmware)
            filter.correct_heading(field);
            next_mag_s += 1.0f / 75.0f;
        }
        filter.update(bias, accel);
    }
    const float tilt_deg = acos_f((linalg::constrain)(truth.c.dot(filter.matrix().c), -1.0f, 1.0f)) * linalg::kDegPerRad;
    EXPECT(tilt_deg < 0.5f);
    const Vector3f learned = filter.gyro_bias_rad_s() * linalg::kDegPerRad;
    EXPECT(near(learned, 2.0f, 2.0f, 2.0f, 0.3f));
    // Uncorrected, yaw would be ~80 deg off by now.
    const float yaw_err = (filter.euler().yaw_rad - dcm::euler_from_dcm(truth).yaw_rad) * linalg::kDegPerRad;
    EXPECT(absf(yaw_err) < 10.0f);
    metric(TXT("tilt_mdeg"), tilt_deg, 1e3f);
}

// No NaN from any input, including zero, huge and NaN sensor values; a NaN gyro
// sample is rejected, not integrated (test_dcm.cpp).
void check_dcm_absurd_inputs() {
    const float nan = __builtin_nanf(""), inf = __builtin_inff(), big = 3.0e38f;
    const Vector3f inputs[] = {
        Vector3f(), Vector3f(nan, nan, nan), Vector3f(inf, 0, 0), Vector3f(big, big, big),
        Vector3f(1e6f, -1e6f, 1e6f), Vector3f(0, 0, -kG),
    };
    const uint8_t n = sizeof inputs / sizeof inputs[0];
    dcm::Dcm filter;
    EXPECT(filter.init(Vector3f(0, 0, -kG), kEarthField_uT));
    float worst = 0.0f;
    for (uint8_t g = 0; g < n; ++g) {
        for (uint8_t a = 0; a < n; ++a) {
            for (uint8_t m = 0; m < n; ++m) {
                filter.update(inputs[g], inputs[a]);
                filter.correct_heading(inputs[m]);
                filter.update(inputs[g], inputs[a]);
                const dcm::EulerAngles e = filter.euler();
                EXPECT(filter.matrix().is_finite() && filter.gyro_bias_rad_s().is_finite());
                EXPECT(linalg::is_finite(e.roll_rad) && linalg::is_finite(e.pitch_rad) && linalg::is_finite(e.yaw_rad));
                const float err = orthonormality_error(filter.matrix());
                worst = err > worst ? err : worst;
            }
        }
    }
    EXPECT(worst < 1e-3f);
    dcm::Dcm fresh;
    EXPECT(!fresh.init(Vector3f(), kEarthField_uT) && !fresh.init(Vector3f(nan, 0, 0), kEarthField_uT));
    EXPECT(fresh.init(Vector3f(0, 0, -kG), kEarthField_uT));
    const Matrix3f before = fresh.matrix();
    fresh.update(Vector3f(nan, 0, 0), Vector3f(0, 0, -kG));
    EXPECT((fresh.status() & dcm::kStatusGyroRejected) != 0);
    EXPECT(max_abs_diff(before, fresh.matrix()) < 1e-4f);
    fresh.update(Vector3f(), Vector3f(0, 0, -kG));
    EXPECT((fresh.status() & dcm::kStatusGyroRejected) == 0);
    metric(TXT("worst_e6"), worst, 1e6f);
}

void burst(uint8_t out[14], const int16_t v[7]) {
    for (uint8_t i = 0; i < 7; ++i) {
        out[2 * i] = (uint8_t)((uint16_t)v[i] >> 8);
        out[2 * i + 1] = (uint8_t)((uint16_t)v[i] & 0xFFu);
    }
}

// MPU6000 bytes -> body-frame SI values per axis and range; absent patterns flagged
// (test/MPU6000/test_mpu6000_registers.cpp).
void check_decode_mpu6000() {
    const float d2r = linalg::kRadPerDeg;
    uint8_t raw[14];
    mpu6000::Sample s{};
    const int16_t x_only[7] = {4096, 0, 0, 0, 1640, 0, 0};
    burst(raw, x_only);
    EXPECT(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s) ==
           mpu6000::BurstStatus::Ok);
    EXPECT(near(s.accel_m_s2(), 0, kG, 0, 1e-4f) && near(s.gyro_rad_s(), 0, 100 * d2r, 0, 1e-5f));
    const int16_t y_only[7] = {0, 4096, 0, 0, 0, -1640, 0};
    burst(raw, y_only);
    mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s);
    EXPECT(near(s.accel_m_s2(), kG, 0, 0, 1e-4f) && near(s.gyro_rad_s(), -100 * d2r, 0, 0, 1e-5f));
    const int16_t z_only[7] = {0, 0, 4096, 0, 0, 0, 164};
    burst(raw, z_only);
    mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s);
    EXPECT(near(s.accel_m_s2(), 0, 0, -kG, 1e-4f) && near(s.gyro_rad_s(), 0, 0, -10 * d2r, 1e-5f));
    struct Range {
        mpu6000::GyroRange g;
        float lsb_dps;
        mpu6000::AccelRange a;
        float lsb_g;
    };
    const Range ranges[] = {
        {mpu6000::GyroRange::Dps250, 131.0f, mpu6000::AccelRange::G2, 16384.0f},
        {mpu6000::GyroRange::Dps500, 65.5f, mpu6000::AccelRange::G4, 8192.0f},
        {mpu6000::GyroRange::Dps1000, 32.8f, mpu6000::AccelRange::G8, 4096.0f},
        {mpu6000::GyroRange::Dps2000, 16.4f, mpu6000::AccelRange::G16, 2048.0f},
    };
    for (uint8_t i = 0; i < 4; ++i) {
        const int16_t v[7] = {0, (int16_t)(ranges[i].lsb_g / 2), 0, 0, (int16_t)(ranges[i].lsb_dps * 20.0f), 0, 0};
        burst(raw, v);
        EXPECT(mpu6000::decode_burst(raw, ranges[i].g, ranges[i].a, s) == mpu6000::BurstStatus::Ok);
        EXPECT(near(s.accel_m_s2().x, 0.5f * kG, 2e-3f) && near(s.gyro_rad_s().y, 20 * d2r, 2e-3f));
        EXPECT(mpu6000::gyro_lsb_per_dps(ranges[i].g) == ranges[i].lsb_dps);
        EXPECT(mpu6000::accel_lsb_per_g(ranges[i].a) == ranges[i].lsb_g);
    }
    const int16_t sat[7] = {32767, 0, 0, -521, 0, -32768, 0};
    burst(raw, sat);
    mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s);
    EXPECT(s.accel_saturated && s.gyro_saturated && near(s.temperature_c(), -521.0f / 340.0f + 36.53f, 1e-4f));
    s.temperature_raw = 1234;
    memset(raw, 0x00, sizeof raw);
    EXPECT(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s) ==
           mpu6000::BurstStatus::NoSensor);
    memset(raw, 0xFF, sizeof raw);
    EXPECT(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G8, s) ==
           mpu6000::BurstStatus::NoSensor);
    EXPECT(s.temperature_raw == 1234);  // untouched
    EXPECT(mpu6000::smplrt_div_for_hz(200) == 4);
}

// HMC5883L: X, Z, Y register order, axes, gain scales, -4096 overflow and absent
// patterns (test/HMC5883/test_hmc5883_registers.cpp).
void check_decode_hmc5883() {
    const uint8_t raw[6] = {0x00, 0x64, 0xFF, 0x38, 0x01, 0x2C};  // X 100, Z -200, Y 300
    const hmc5883::Counts c = hmc5883::counts_from_data(raw);
    EXPECT(c.x == 100 && c.y == 300 && c.z == -200);
    Vector3f field;
    EXPECT(hmc5883::decode_data(raw, hmc5883::Gain::Ga1_3, field) == hmc5883::DataStatus::Ok);
    const float uT = 100.0f / 1090.0f;
    EXPECT(near(field, -300 * uT, -100 * uT, 200 * uT, 1e-4f));  // body = (-chip_y, -chip_x, -chip_z)
    const hmc5883::Gain gains[] = {hmc5883::Gain::Ga0_88, hmc5883::Gain::Ga1_3, hmc5883::Gain::Ga1_9,
                                   hmc5883::Gain::Ga2_5,  hmc5883::Gain::Ga4_0, hmc5883::Gain::Ga4_7,
                                   hmc5883::Gain::Ga5_6,  hmc5883::Gain::Ga8_1};
    const float lsb[] = {1370, 1090, 820, 660, 440, 390, 330, 230};
    for (uint8_t i = 0; i < 8; ++i) EXPECT(hmc5883::lsb_per_gauss(gains[i]) == lsb[i]);
    const uint8_t overflow[6] = {0xF0, 0x00, 0x00, 0x10, 0x00, 0x10};  // X = -4096
    Vector3f kept(1, 2, 3);
    EXPECT(hmc5883::decode_data(overflow, hmc5883::Gain::Ga1_3, kept) == hmc5883::DataStatus::Overflow);
    EXPECT(near(kept, 1, 2, 3, 0));
    uint8_t absent[6];
    memset(absent, 0x00, sizeof absent);
    EXPECT(hmc5883::decode_data(absent, hmc5883::Gain::Ga1_3, kept) == hmc5883::DataStatus::NoSensor);
    memset(absent, 0xFF, sizeof absent);
    EXPECT(hmc5883::decode_data(absent, hmc5883::Gain::Ga1_3, kept) == hmc5883::DataStatus::NoSensor);
    EXPECT(near(kept, 1, 2, 3, 0));
    const uint8_t id[3] = {'H', '4', '3'}, bad_id[3] = {'H', '4', '4'};
    EXPECT(hmc5883::id_matches(id) && !hmc5883::id_matches(bad_id));
}

console::Command feed(console::LineReader& r, const char* bytes, uint8_t len) {
    console::Command last{console::CommandId::None, console::Error::None, 0, fmt::OutputMode::Plot};
    for (uint8_t i = 0; i < len; ++i) {
        const console::Command c = r.feed((uint8_t)bytes[i]);
        if (c.id != console::CommandId::None) last = c;
    }
    return last;
}
console::Command feed(console::LineReader& r, const char* s) { return feed(r, s, (uint8_t)strlen(s)); }

void null_write(void*, const char*, uint8_t) {}

// The console's parser and line reader, and the settings commands (test_console.cpp).
void check_console_parse() {
    using console::CommandId;
    using console::Error;
    using console::parse_line;
    EXPECT(parse_line("help").id == CommandId::Help && parse_line("  STATUS\t ").id == CommandId::Status);
    EXPECT(parse_line("").id == CommandId::None && parse_line("cal gyro").id == CommandId::CalGyro);
    const console::Command rate = parse_line("rate 10");
    EXPECT(rate.id == CommandId::Rate && rate.value == 10);
    EXPECT(parse_line("rate 25.0").value == 25);
    EXPECT(parse_line("rate 0").error == Error::RateRange && parse_line("rate 2.5").error == Error::RateRange);
    EXPECT(parse_line("rate 1e2").error == Error::BadNumber && parse_line("rate 99999999999").error == Error::BadNumber);
    EXPECT(parse_line("rate").error == Error::MissingArgument && parse_line("rate 5 6").error == Error::ExtraArgument);
    const console::Command decl = parse_line("decl -12.34");
    EXPECT(decl.id == CommandId::Decl && decl.value == -1234);
    EXPECT(parse_line("decl 1.005").value == 101 && parse_line("decl -1.005").value == -101);
    EXPECT(parse_line("decl 180.01").error == Error::DeclRange && parse_line("decl nan").error == Error::BadNumber);
    EXPECT(parse_line("mode CSV").mode == fmt::OutputMode::Csv && parse_line("mode loud").error == Error::BadMode);
    EXPECT(parse_line("hello").error == Error::Unknown && parse_line("help me").error == Error::ExtraArgument);
    console::LineReader r;
    uint8_t commands = 0;
    const char* two = "rate 5\r\nrate 6\r\n";
    for (const char* p = two; *p != '\0'; ++p)
        if (r.feed((uint8_t)*p).id != CommandId::None) ++commands;
    EXPECT(commands == 2);
    EXPECT(feed(r, "ratx\x08" "e 7\n").value == 7);
    char longline[70];
    memset(longline, '5', sizeof longline);
    memcpy(longline, "rate ", 5);
    longline[sizeof longline - 1] = '\n';
    EXPECT(feed(r, longline, sizeof longline).error == Error::TooLong);
    EXPECT(feed(r, "rate 5\n").value == 5);
    EXPECT(feed(r, "mode csv\xff\n").error == Error::Garbage);
    EXPECT(feed(r, "rate\0 5\n", 8).error == Error::Garbage);
    // Settings commands: a good one changes exactly its setting, an error nothing.
    const text::Sink quiet = {nullptr, null_write};
    settings::Settings s = settings::defaults();
    EXPECT(console::apply_setting(parse_line("rate 10"), s, &quiet) && s.rate_hz == 10);
    EXPECT(console::apply_setting(parse_line("decl 10"), s, &quiet) && s.declination_centideg == 1000);
    const settings::Settings before = s;
    console::apply_setting(parse_line("xyzzy 12 ###"), s, &quiet);
    console::apply_setting(parse_line("rate 500"), s, &quiet);
    EXPECT(s.rate_hz == before.rate_hz && s.declination_centideg == before.declination_centideg &&
           s.mode == before.mode);
}

// Settings record: CRC-16/CCITT-FALSE check value, round trip, corruption caught
// (test_settings.cpp).
void check_settings_crc() {
    const char* check = "123456789";
    EXPECT(settings::crc16(reinterpret_cast<const uint8_t*>(check), 9) == 0x29B1);
    settings::Settings in = settings::defaults();
    in.rate_hz = 25;
    settings::set_declination_centideg(in, -1234);
    in.mode = fmt::OutputMode::Csv;
    in.flags = settings::kFlagGyroCalibrated;
    in.cal.gyro_bias_rad_s = Vector3f(0.01f, -0.02f, 0.003f);
    in.cal.mag_offset_uT = Vector3f(-3.5f, 12.25f, 0.5f);
    in.cal.mag_scale = Vector3f(1.01f, 0.98f, 1.0f);
    uint8_t rec[settings::kRecordSize];
    settings::encode(in, rec);
    EXPECT(rec[0] == 'A' && rec[1] == 'T' && rec[3] == settings::kPayloadLength && rec[4] == 25);
    EXPECT(rec[5] == (uint8_t)(-1234 & 0xFF) && rec[6] == (uint8_t)((uint16_t)-1234 >> 8));
    settings::Settings out;
    EXPECT(settings::decode(rec, out) == settings::LoadResult::Ok);
    EXPECT(out.rate_hz == 25 && out.declination_centideg == -1234 && out.mode == fmt::OutputMode::Csv &&
           out.flags == in.flags);
    EXPECT(out.cal.gyro_bias_rad_s == in.cal.gyro_bias_rad_s && out.cal.mag_offset_uT == in.cal.mag_offset_uT &&
           out.cal.mag_scale == in.cal.mag_scale);
    uint8_t flips = 0;
    for (uint8_t byte = 0; byte < settings::kRecordSize; byte += 5) {
        rec[byte] ^= 0x10;
        if (settings::decode(rec, out) != settings::LoadResult::Ok && out.rate_hz == settings::kRateDefaultHz) ++flips;
        rec[byte] ^= 0x10;
    }
    EXPECT(flips == (settings::kRecordSize + 4) / 5);
    memset(rec, 0xFF, sizeof rec);
    EXPECT(settings::decode(rec, out) == settings::LoadResult::Blank && out.rate_hz == settings::kRateDefaultHz);
}

bool line_is(const char* buf, uint8_t len, const char* expected) {
    return len == strlen(expected) && memcmp(buf, expected, len) == 0;
}

// The integer-only output formatting (test_format.cpp).
void check_format() {
    const float nan = __builtin_nanf("");
    char buf[fmt::kLineMax];
    EXPECT(line_is(buf, fmt::format_plot_line(buf, -1.23f, 4.56f, 271.8f), "roll:-1.23 pitch:4.56 yaw:271.80\n"));
    EXPECT(line_is(buf, fmt::format_plot_line(buf, -180.0f, -90.0f, 359.99f), "roll:-180.00 pitch:-90.00 yaw:359.99\n"));
    EXPECT(line_is(buf, fmt::format_plot_line(buf, 0.004f, -0.004f, 1.006f), "roll:0.00 pitch:0.00 yaw:1.01\n"));
    EXPECT(line_is(buf, fmt::format_plot_line(buf, -0.006f, 0.996f, 10.0f), "roll:-0.01 pitch:1.00 yaw:10.00\n"));
    EXPECT(line_is(buf, fmt::format_plot_line(buf, 0.0f, 0.0f, 359.996f), "roll:0.00 pitch:0.00 yaw:0.00\n"));
    EXPECT(fmt::format_plot_line(buf, nan, 0.0f, 0.0f) == 0 && fmt::format_plot_line(buf, 1000.0f, 0.0f, 0.0f) == 0);
    EXPECT(line_is(buf, fmt::format_csv_line(buf, 0, 1.0f, -2.5f, 90.125f), "0,1.00,-2.50,90.13\n"));
    EXPECT(line_is(buf, fmt::format_csv_line(buf, 4294967295u, 0.0f, 0.0f, 0.0f), "4294967295,0.00,0.00,0.00\n"));
    EXPECT(fmt::format_csv_line(buf, 5, 0.0f, 0.0f, nan) == 0);
    EXPECT(line_is(buf, text::format_centi(buf, -123456), "-1234.56") && line_is(buf, text::format_centi(buf, 5), "0.05"));
    EXPECT(line_is(buf, text::format_centi(buf, INT32_MIN), "-21474836.48"));
    EXPECT(line_is(buf, text::format_int(buf, INT32_MIN), "-2147483648"));
    int32_t centi = 42;
    EXPECT(!text::to_centi(nan, centi) && !text::to_centi(3e7f, centi) && centi == 42);
    EXPECT(text::to_centi(-2.345f, centi) && centi == -235);
}

// The integer output path's own AVR code (inline MUL sequences, Fixed.h; test_fixed.cpp):
// the 16x16 products against the compiler's, the hundredths against a 64-bit
// reference, and the integer lines against the float path on carried rotations.
void check_fixed_output() {
    EXPECT(linalg::mul_s16(-32768, -32768) == 1073741824L && linalg::mul_s16(-32768, 32767) == -1073709056L);
    EXPECT(linalg::mul_u16(65535u, 65535u) == 4294836225UL && linalg::mul_s16(-1, 1) == -1);
    for (uint16_t i = 0; i < 2000; ++i) {
        const uint32_t a = random_u32(), b = random_u32();
        const uint16_t ua = (uint16_t)a, ub = (uint16_t)b;
        const int16_t sa = (int16_t)(uint16_t)(a >> 16), sb = (int16_t)(uint16_t)(b >> 16);
        EXPECT(linalg::mul_u16(ua, ub) == (uint32_t)ua * (uint32_t)ub);
        EXPECT(linalg::mul_s16(sa, sb) == (int32_t)sa * (int32_t)sb);
        const int32_t q = (b & 1u) ? -(int32_t)(a >> 6) : (int32_t)(a >> 6);  // |q| < 2^26
        const uint64_t m = (uint64_t)(a >> 6);
        const int32_t c = (int32_t)((m * 375493621ULL + (1ULL << 39)) >> 40);  // round(m 18000/pi / 2^24)
        EXPECT(linalg::centideg_from_q24(q) == ((b & 1u) ? -c : c));
    }
    // mul_q30's assembly against the sum it implements, and its signs.
    for (uint16_t i = 0; i < 500; ++i) {
        const uint32_t a = random_u32() >> (i % 3), x = random_u32() >> (i % 29);
        EXPECT(linalg::mul_u32_shr30(a, x) == linalg::fixed_detail::mul_u32_shr30_by_bytes(a, x));
        const int32_t sa = (int32_t)(a >> 2) * ((i & 1) ? -1 : 1), sx = (int32_t)(x >> 1) * ((i & 2) ? -1 : 1);
        const int32_t m = (int32_t)linalg::fixed_detail::mul_u32_shr30_by_bytes(a >> 2, x >> 1);
        EXPECT(linalg::mul_q30(sa, sx) == (((i & 1) != 0) != ((i & 2) != 0) ? -m : m));
    }
    // fixed_from_float's shifts by MUL against a float scaling by 2^q (exact) and the
    // cast's truncation, from 2^-24 to 2 in magnitude.
    for (uint16_t i = 0; i < 500; ++i) {
        const float x = uniform(-1.99f, 1.99f) / (float)(1UL << (i % 24));  // power-of-two division: exact
        EXPECT(linalg::fixed_from_float(x, 30) == (int32_t)(x * 1073741824.0f));
        EXPECT(linalg::fixed_from_float(x, 26) == (int32_t)(x * 67108864.0f));
    }
    EXPECT(linalg::fixed_from_float(-2.5f, 30) == -0x7FFFFFFFL && linalg::fixed_from_float(1e-12f, 30) == 0);
    const float d = linalg::kPi / 180.0f;
    const Matrix3f r = dcm::dcm_from_euler(10 * d, -20 * d, 135 * d);
    const dcm::AnglesCentideg c = dcm::angles_centideg(dcm::euler_carried_q24(r, 0, 0, 0), 1000);
    EXPECT(c.roll_centideg == 1000 && c.pitch_centideg == -2000 && c.heading_centideg == 14500);
    for (uint16_t i = 0; i < 100; ++i) {
        const Matrix3f s = dcm::dcm_from_euler(uniform(-3.1f, 3.1f), uniform(-1.4f, 1.4f), uniform(-3.1f, 3.1f));
        const int32_t tx = (int32_t)(random_u32() >> 12) - (1L << 19), ty = (int32_t)(random_u32() >> 12) - (1L << 19);
        const dcm::EulerQ24 e = dcm::euler_carried_q24(s, tx, ty, 0);
        const dcm::EulerAngles f = dcm::euler_carried(s, Vector3f((float)tx / 67108864.0f, (float)ty / 67108864.0f, 0.0f));
        const dcm::AnglesCentideg h = dcm::angles_centideg(e, 0);
        EXPECT(near((float)h.roll_centideg, f.roll_rad * (18000.0f / linalg::kPi), 0.52f));
        EXPECT(near((float)h.pitch_centideg, f.pitch_rad * (18000.0f / linalg::kPi), 0.52f));
    }
}

// quat and raw lines, fixed point at 1..4 decimals (test_format.cpp), and the DCM's
// quaternion (test_linalg.cpp): 16-bit int arithmetic on this target.
void check_quat_raw() {
    char buf[fmt::kRawLineMax];
    EXPECT(line_is(buf, fmt::format_quat_line(buf, linalg::Quaternion{0.70710678f, 0.0f, -0.70710678f, 0.00004f}),
                   "qw:0.7071 qx:0.0000 qy:-0.7071 qz:0.0000\n"));
    EXPECT(fmt::format_quat_line(buf, linalg::Quaternion{1.01f, 0.0f, 0.0f, 0.0f}) == 0);
    EXPECT(line_is(buf,
                   fmt::format_raw_line(buf, linalg::Vector3f(-2000.0f, 1999.99f, 5.0f), linalg::Vector3f(8.0f, -8.0f, 0.5f),
                                        linalg::Vector3f(-810.0f, 0.0f, 1.0f)),
                   "gx:-2000.00 gy:1999.99 gz:5.00 ax:8.000 ay:-8.000 az:0.500 mx:-810.0 my:0.0 mz:1.0\n"));
    EXPECT(line_is(buf, text::format_fixed(buf, INT32_MIN, 4), "-214748.3648"));
    // 90 degrees of yaw: R rows (0 -1 0), (1 0 0), (0 0 1); q = (cos 45, 0, 0, sin 45).
    const linalg::Quaternion q = linalg::quat_from_rotation(linalg::Matrix3f(
        linalg::Vector3f(0.0f, -1.0f, 0.0f), linalg::Vector3f(1.0f, 0.0f, 0.0f), linalg::Vector3f(0.0f, 0.0f, 1.0f)));
    EXPECT(fabsf(q.w - 0.70710678f) < 1e-6f && fabsf(q.z - 0.70710678f) < 1e-6f && q.x == 0.0f && q.y == 0.0f);
    // 180 degrees about x (trace -1): q = (0, 1, 0, 0).
    const linalg::Quaternion r = linalg::quat_from_rotation(linalg::Matrix3f(
        linalg::Vector3f(1.0f, 0.0f, 0.0f), linalg::Vector3f(0.0f, -1.0f, 0.0f), linalg::Vector3f(0.0f, 0.0f, -1.0f)));
    EXPECT(fabsf(r.x - 1.0f) < 1e-6f && r.w == 0.0f && r.y == 0.0f && r.z == 0.0f);
}

}  // namespace

static void run_all() {
    text::Writer(&kOut).str(TXT("# selftest: lib/ checks on this target")).end();
    run(TXT("linalg_ops"), check_linalg_ops);
    run(TXT("linalg_degenerate"), check_linalg_degenerate);
    run(TXT("fast_atan2"), check_fast_atan2);
    run(TXT("euler_round_trip"), check_euler_round_trip);
    run(TXT("dcm_orthonormal"), check_dcm_orthonormal);
    run(TXT("dcm_bias_at_rest"), check_dcm_bias_at_rest);
    run(TXT("dcm_absurd_inputs"), check_dcm_absurd_inputs);
    run(TXT("decode_mpu6000"), check_decode_mpu6000);
    run(TXT("decode_hmc5883"), check_decode_hmc5883);
    run(TXT("console_parse"), check_console_parse);
    run(TXT("settings_crc"), check_settings_crc);
    run(TXT("format"), check_format);
    run(TXT("quat_raw"), check_quat_raw);
    run(TXT("fixed_output"), check_fixed_output);
    text::Writer(&kOut).str(TXT("# selftest done: ")).u32(g_checks).str(TXT(" checks, ")).u32(g_ok)
        .str(TXT(" ok, ")).u32((uint32_t)(g_checks - g_ok)).str(TXT(" FAIL")).end();
}

#ifdef __AVR__
// RAM: the space between the static data and the stack is painted at start; after the
// checks, the painted bytes the stack never reached are the RAM that was never needed.
extern char __bss_end;
static const uint8_t kPaint = 0xA5;

static void paint_free_ram() {
    char here;
    for (char* p = &__bss_end; p < &here - 32; ++p) *p = (char)kPaint;
}

static uint16_t untouched_ram() {
    uint16_t n = 0;
    for (const char* p = &__bss_end; (uint8_t)*p == kPaint && p < (const char*)RAMEND; ++p) ++n;
    return n;
}

void setup() {
    paint_free_ram();
    Serial.begin(115200);
    run_all();
    text::Writer(&kOut).str(TXT("# selftest ram: static ")).u32((uint32_t)((uintptr_t)&__bss_end - RAMSTART))
        .str(TXT(" bytes, never reached by the stack ")).u32(untouched_ram()).str(TXT(" bytes, of 8192")).end();
    Serial.flush();
}

// Done: idle (apm25sim skips the sleeping core's time cheaply) until the run ends.
void loop() {
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sleep_cpu();
}
#else
int main() {
    run_all();
    return 0;
}
#endif
