// SPDX-License-Identifier: GPL-3.0-or-later
#include "AccelFit.h"

#include <math.h>

#include "BoardFrame.h"
#include "CalibMath.h"

namespace calib {

using linalg::Vector3f;

Vector3f expected_direction(AccelPosition p) {
    switch (p) {
        case AccelPosition::kLevel: return Vector3f(0.0f, 0.0f, -1.0f);
        case AccelPosition::kLeft: return Vector3f(0.0f, 1.0f, 0.0f);
        case AccelPosition::kRight: return Vector3f(0.0f, -1.0f, 0.0f);
        case AccelPosition::kNoseDown: return Vector3f(-1.0f, 0.0f, 0.0f);
        case AccelPosition::kNoseUp: return Vector3f(1.0f, 0.0f, 0.0f);
        default: return Vector3f(0.0f, 0.0f, 1.0f);  // kBack: upside down
    }
}

bool in_position(AccelPosition p, const Vector3f& m) {
    const float n = m.length();
    if (!within(n, 0.9f * linalg::kGravity_m_s2, 1.1f * linalg::kGravity_m_s2)) return false;
    const float cos_tol = 0.8660254f;  // cos(kPositionTolerance_deg)
    return expected_direction(p).dot(m) >= cos_tol * n;
}

void AccelFit::set_mean(uint8_t k, const Vector3f& m) {
    if (k >= kAccelPositions) return;
    m_[k][0] = m.x;
    m_[k][1] = m.y;
    m_[k][2] = m.z;
}

void AccelFit::begin(const Vector3f means[kAccelPositions], float g) {
    for (uint8_t k = 0; k < kAccelPositions; ++k) set_mean(k, means[k]);
    begin(g);
}

void AccelFit::begin(float g) {
    Vector3f c;
    for (uint8_t k = 0; k < kAccelPositions; ++k) c += Vector3f(m_[k][0], m_[k][1], m_[k][2]);
    c *= 1.0f / (float)kAccelPositions;  // opposite positions: the offset, roughly
    x_[0] = x_[1] = x_[2] = 1.0f;
    x_[3] = c.x;
    x_[4] = c.y;
    x_[5] = c.z;
    g2_ = g * g;
    iterations_ = 0;
    quality_ = Quality::Fitting;
}

float AccelFit::residual_m_s2() const {
    float worst = 0.0f;
    const float g = sqrtf(g2_);
    for (uint8_t k = 0; k < kAccelPositions; ++k) {
        float n2 = 0.0f;
        for (uint8_t i = 0; i < 3; ++i) {
            const float d = x_[i] * (m_[k][i] - x_[3 + i]);
            n2 += d * d;
        }
        const float r = absf(sqrtf(n2) - g);
        if (r > worst) worst = r;
    }
    return worst;
}

AccelFit::Quality AccelFit::step() {
    if (quality_ != Quality::Fitting) return quality_;
    // J delta = -F: rows the positions, columns d/ds_i then d/do_i.
    float a[6][7];
    for (uint8_t k = 0; k < kAccelPositions; ++k) {
        float f = -g2_;
        for (uint8_t i = 0; i < 3; ++i) {
            const float d = m_[k][i] - x_[3 + i], s = x_[i];
            f += s * s * d * d;
            a[k][i] = 2.0f * s * d * d;
            a[k][3 + i] = -2.0f * s * s * d;
        }
        a[k][6] = -f;
    }
    // Gaussian elimination with partial pivoting.
    for (uint8_t c = 0; c < 6; ++c) {
        uint8_t p = c;
        for (uint8_t r = (uint8_t)(c + 1); r < 6; ++r)
            if (absf(a[r][c]) > absf(a[p][c])) p = r;
        // A pivot this small against g^2 per unit: positions that leave an axis unseen.
        if (!(absf(a[p][c]) > 1e-3f)) return quality_ = Quality::Singular;
        if (p != c)
            for (uint8_t j = 0; j < 7; ++j) {
                const float t = a[c][j];
                a[c][j] = a[p][j];
                a[p][j] = t;
            }
        const float inv = 1.0f / a[c][c];
        for (uint8_t r = (uint8_t)(c + 1); r < 6; ++r) {
            const float q = a[r][c] * inv;
            for (uint8_t j = c; j < 7; ++j) a[r][j] -= q * a[c][j];
        }
    }
    float step2 = 0.0f;
    for (int8_t r = 5; r >= 0; --r) {
        float v = a[r][6];
        for (uint8_t j = (uint8_t)(r + 1); j < 6; ++j) v -= a[r][j] * a[j][6];
        a[r][6] = v / a[r][r];
        x_[r] += a[r][6];
        step2 += a[r][6] * a[r][6];
    }
    ++iterations_;
    const bool finite = x_[0] == x_[0] && x_[1] == x_[1] && x_[2] == x_[2] && x_[3] == x_[3] && x_[4] == x_[4] &&
                        x_[5] == x_[5];
    if (!finite) return quality_ = Quality::NoConvergence;
    // Converged: the last step moved nothing that matters (1e-5 of a scale or m/s^2).
    if (step2 > 1e-10f) {
        if (iterations_ >= kMaxIterations) quality_ = Quality::NoConvergence;
        return quality_;
    }
    for (uint8_t i = 0; i < 3; ++i)
        if (!within(x_[i], kAccelScaleMin, kAccelScaleMax) ||
            !within(x_[3 + i], -kAccelOffsetMax_m_s2, kAccelOffsetMax_m_s2))
            return quality_ = Quality::OutOfRange;
    return quality_ = residual_m_s2() <= kMaxResidual_m_s2 ? Quality::Ok : Quality::NoConvergence;
}

}  // namespace calib
