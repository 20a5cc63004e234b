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
    // The position reading most along +axis and most along -axis, for each axis: the six
    // must be six different positions (each axis seen both ways), else no unique fit.
    uint8_t plus[3], minus[3], used = 0;
    for (uint8_t i = 0; i < 3; ++i) {
        plus[i] = minus[i] = 0;
        for (uint8_t k = 1; k < kAccelPositions; ++k) {
            if (m_[k][i] > m_[plus[i]][i]) plus[i] = k;
            if (m_[k][i] < m_[minus[i]][i]) minus[i] = k;
        }
        used = (uint8_t)(used | (1u << plus[i]) | (1u << minus[i]));
        if (!(m_[plus[i]][i] - m_[minus[i]][i] > 1.0f * sqrtf(g2_))) return quality_ = Quality::Singular;
    }
    if (used != (1u << kAccelPositions) - 1u) return quality_ = Quality::Singular;
    // One sweep: for each axis, its two positions' equations solved for (o_i, s_i) with
    // the other axes as they stand: s_i (m+ - o_i) = c+, s_i (m- - o_i) = -c-, with
    // c = sqrt(g^2 - the other axes' corrected squares). The other axes read little in
    // those positions, so the sweeps contract fast (a few) to F_k = 0 for all six.
    float change = 0.0f;
    for (uint8_t i = 0; i < 3; ++i) {
        float c[2];
        const uint8_t ks[2] = {plus[i], minus[i]};
        for (uint8_t n = 0; n < 2; ++n) {
            float rest = 0.0f;
            for (uint8_t j = 0; j < 3; ++j) {
                if (j == i) continue;
                const float d = x_[j] * (m_[ks[n]][j] - x_[3 + j]);
                rest += d * d;
            }
            const float c2 = g2_ - rest;
            if (!(c2 > 0.25f * g2_)) return quality_ = Quality::NoConvergence;  // NaN too
            c[n] = sqrtf(c2);
        }
        const float s = (c[0] + c[1]) / (m_[plus[i]][i] - m_[minus[i]][i]);
        const float o = m_[plus[i]][i] - c[0] / s;
        change += absf(s - x_[i]) + absf(o - x_[3 + i]);
        x_[i] = s;
        x_[3 + i] = o;
    }
    ++iterations_;
    // Converged: the last sweep moved nothing that matters (1e-5 of a scale or m/s^2).
    if (change > 1e-5f) {
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
