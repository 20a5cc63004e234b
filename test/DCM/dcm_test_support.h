// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the estimator tests: a true attitude and the ideal sensor readings
// it produces (body frame: x forward, y right, z down; earth NED).
#pragma once

#include <cmath>
#include <random>

#include "Dcm.h"
#include "Euler.h"
#include "LinAlg.h"

namespace dcm_test {

using linalg::Matrix3f;
using linalg::Vector3f;

constexpr float kG = 9.80665f;
// A Berlin-like earth field, NED, uT: 20 north, 45 down.
inline Vector3f earth_field_uT() { return Vector3f(20.0f, 0.0f, 45.0f); }

inline Vector3f accel_for(const Matrix3f& r_true) { return r_true.mul_transpose(Vector3f(0.0f, 0.0f, -kG)); }
inline Vector3f mag_for(const Matrix3f& r_true) { return r_true.mul_transpose(earth_field_uT()); }

// Angle of the rotation R_a^T R_b, degrees.
inline float angle_between_deg(const Matrix3f& a, const Matrix3f& b) {
    const Matrix3f e = a.transposed() * b;
    const float c = 0.5f * (e.a.x + e.b.y + e.c.z - 1.0f);
    return std::acos(linalg::constrain(c, -1.0f, 1.0f)) * linalg::kDegPerRad;
}

// Angle between the true and estimated down directions (roll/pitch error), degrees.
inline float tilt_error_deg(const Matrix3f& truth, const Matrix3f& est) {
    return std::acos(linalg::constrain(truth.c.dot(est.c), -1.0f, 1.0f)) * linalg::kDegPerRad;
}

inline float wrap_deg(float a) {
    while (a > 180.0f) a -= 360.0f;
    while (a < -180.0f) a += 360.0f;
    return a;
}

inline Matrix3f random_rotation(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_real_distribution<float> angle(-linalg::kPi, linalg::kPi);
    std::uniform_real_distribution<float> half(-linalg::kPi / 2, linalg::kPi / 2);
    // Uniform pitch in asin space so all orientations are covered.
    return dcm::dcm_from_euler(angle(rng), std::asin(u(rng)), angle(rng));
}

// The coefficients of the default settings at the float form's scales (the parts'
// tests: DcmSettings' units through kFloatGyroScale and kFloatAccelScale).
inline dcm::DcmCoefficients float_form_coefficients() {
    dcm::DcmCoefficients k;
    k.from_settings(dcm::kDefaultDcmSettings);
    k.derive_from_scales(dcm::kDefaultDcmSettings);
    return k;
}

inline float orthonormality_error(const Matrix3f& r) {
    const Matrix3f p = r * r.transposed();
    const Matrix3f d = p - Matrix3f::identity();
    float worst = 0.0f;
    const float v[9] = {d.a.x, d.a.y, d.a.z, d.b.x, d.b.y, d.b.z, d.c.x, d.c.y, d.c.z};
    for (float x : v) worst = std::fabs(x) > worst ? std::fabs(x) : worst;
    return worst;
}

}  // namespace dcm_test
