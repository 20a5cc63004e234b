// SPDX-License-Identifier: GPL-3.0-or-later
// Truths in double for the estimator's tests: a rotation (rows as Matrix3f: m * v_body
// = v_earth), its exponential, and the rate a gyro integrating over its sample interval
// reads on a trajectory.
#pragma once

#include <cmath>

#include "LinAlg.h"

namespace dcm_truth {

using linalg::Matrix3f;
using linalg::Vector3f;

struct Rot {
    double m[3][3];
    static Rot identity() { return Rot{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }
    // exp([theta x]) by Rodrigues' formula.
    static Rot exp(const double t[3]) {
        const double a = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        Rot r = identity();
        if (a == 0.0) return r;
        const double k[3] = {t[0] / a, t[1] / a, t[2] / a};
        const double s = std::sin(a), c = 1.0 - std::cos(a);
        const double kx[3][3] = {{0, -k[2], k[1]}, {k[2], 0, -k[0]}, {-k[1], k[0], 0}};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double kk = 0.0;
                for (int l = 0; l < 3; ++l) kk += kx[i][l] * kx[l][j];
                r.m[i][j] += s * kx[i][j] + c * kk;
            }
        return r;
    }
    Rot operator*(const Rot& o) const {
        Rot r{};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                for (int l = 0; l < 3; ++l) r.m[i][j] += m[i][l] * o.m[l][j];
        return r;
    }
    Rot transposed() const {
        Rot r{};
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) r.m[i][j] = m[j][i];
        return r;
    }
    // The rotation vector of a small rotation (the skew part; exact to a^3).
    void log_small(double out[3]) const {
        const double c = 0.5 * (m[0][0] + m[1][1] + m[2][2] - 1.0);
        const double a = std::acos(c > 1.0 ? 1.0 : (c < -1.0 ? -1.0 : c));
        const double f = a < 1e-12 ? 0.5 : 0.5 * a / std::sin(a);
        out[0] = f * (m[2][1] - m[1][2]);
        out[1] = f * (m[0][2] - m[2][0]);
        out[2] = f * (m[1][0] - m[0][1]);
    }
    Matrix3f to_float() const {
        return Matrix3f(Vector3f((float)m[0][0], (float)m[0][1], (float)m[0][2]),
                        Vector3f((float)m[1][0], (float)m[1][1], (float)m[1][2]),
                        Vector3f((float)m[2][0], (float)m[2][1], (float)m[2][2]));
    }
};

// The body rate that carries `from` to `to` over dt, as a gyro integrating over its
// sample interval reads it: the sum of many small increments' rotation vectors.
template <typename Truth>
Vector3f sampled_rate(const Truth& truth, double t0_s, double dt_s) {
    constexpr int kSub = 32;
    double sum[3] = {0, 0, 0};
    Rot prev = truth(t0_s);
    for (int i = 1; i <= kSub; ++i) {
        const Rot next = truth(t0_s + dt_s * i / kSub);
        double inc[3];
        (prev.transposed() * next).log_small(inc);
        for (int k = 0; k < 3; ++k) sum[k] += inc[k];
        prev = next;
    }
    return Vector3f((float)(sum[0] / dt_s), (float)(sum[1] / dt_s), (float)(sum[2] / dt_s));
}

inline Matrix3f rotation_of(const Vector3f& theta_rad) {
    const double t[3] = {theta_rad.x, theta_rad.y, theta_rad.z};
    return Rot::exp(t).to_float();
}

}  // namespace dcm_truth
