// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the calibration tests: the level board and a gyro bias, deterministic noise,
// random directions, and a compass with hard and soft iron turned through them.
#pragma once

#include <gtest/gtest.h>

#include <cmath>

#include "Calibration.h"

namespace calib_test {

using calib::MagCalibrator;
using linalg::Matrix3f;
using linalg::Vector3f;

const Vector3f kLevel(0.0f, 0.0f, -9.80665f);
const Vector3f kBias(0.02f, -0.01f, 0.005f);

// Small deterministic noise in [-a, a].
inline float noise(uint32_t& s, float a) {
    s = s * 1664525u + 1013904223u;
    return a * ((float)(s >> 8) / 8388608.0f - 1.0f);
}

// Gaussian noise from a fixed seed (Box-Muller on the LCG above).
inline float gauss(uint32_t& s) {
    const float u1 = 0.5f * (noise(s, 1.0f) + 1.0f) + 1e-7f, u2 = 0.5f * (noise(s, 1.0f) + 1.0f);
    return sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
}

// A uniformly random direction.
inline Vector3f random_direction(uint32_t& s) {
    for (;;) {
        const Vector3f v(noise(s, 1.0f), noise(s, 1.0f), noise(s, 1.0f));
        const float n2 = v.length_squared();
        if (n2 > 0.01f && n2 <= 1.0f) return v * (1.0f / sqrtf(n2));
    }
}

// A compass with hard iron `offset` and a symmetric soft-iron distortion `s` (raw =
// s b + offset) turned through `n` random orientations of a `b_uT` field, noise_uT rms.
inline void feed_random(MagCalibrator& m, int n, const Vector3f& offset, const Matrix3f& s, float b_uT,
                        float noise_uT, uint32_t seed = 1) {
    for (int i = 0; i < n; ++i) {
        const Vector3f b = random_direction(seed) * b_uT;
        m.add(s * b + offset + Vector3f(gauss(seed), gauss(seed), gauss(seed)) * noise_uT);
    }
}

const Matrix3f kSoftIron(Vector3f(1.03f, 0.02f, -0.015f), Vector3f(0.02f, 0.98f, 0.01f),
                         Vector3f(-0.015f, 0.01f, 1.0f));

// W s must be a multiple of I: the calibrated field is a scaled copy of the true one,
// neither stretched nor turned.
inline void expect_undistorted(const calib::Calibration& c, const Matrix3f& s, float tol) {
    const Matrix3f w(Vector3f(c.mag_scale.x, c.mag_cross.x, c.mag_cross.y),
                     Vector3f(c.mag_cross.x, c.mag_scale.y, c.mag_cross.z),
                     Vector3f(c.mag_cross.y, c.mag_cross.z, c.mag_scale.z));
    const Matrix3f ws = w * s;
    const float k = (ws.a.x + ws.b.y + ws.c.z) / 3.0f;
    const Matrix3f e = ws * (1.0f / k) - Matrix3f::identity();
    for (const Vector3f& row : {e.a, e.b, e.c}) {
        EXPECT_NEAR(row.x, 0.0f, tol);
        EXPECT_NEAR(row.y, 0.0f, tol);
        EXPECT_NEAR(row.z, 0.0f, tol);
    }
}

}  // namespace calib_test
