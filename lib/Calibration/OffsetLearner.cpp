// SPDX-License-Identifier: GPL-3.0-or-later
#include "OffsetLearner.h"

#include "CalibMath.h"
#include "Fixed.h"

namespace calib {

using linalg::Vector3f;

void OffsetLearner::restart(float prior_uT, const Vector3f& in_use_uT) {
    have_ref_ = false;
    solve_part_ = 0;  // a completed pair not yet solved goes too
    prior_info_ = 1.0f / (prior_uT * prior_uT);
    for (uint8_t i = 0; i < 6; ++i) info_[i] = 0.0f;
    estimate_uT_ = start_uT_ = in_use_uT;
    reject_share_ = 0.0f;
    significant_run_ = 0;
}

bool OffsetLearner::add(const Vector3f& field_uT, const Vector3f& turn_rad, uint16_t steps, Vector3f& in_use_uT) {
    // The turn in Q30 (saturated beyond 2 rad an axis: no pair survives such a turn).
    const float limit = 1.99f;
    const Vector3f t(linalg::constrain(turn_rad.x, -limit, limit), linalg::constrain(turn_rad.y, -limit, limit),
                     linalg::constrain(turn_rad.z, -limit, limit));
    if (!turn_rad.is_finite()) {
        bool changed = false;
        while (solving()) changed = solve_part(in_use_uT) || changed;
        return changed;
    }
    return add(field_uT, linalg::fixed_from_vector(t, linalg::kQ30), steps, in_use_uT);
}

bool OffsetLearner::add(const Vector3f& field_uT, const linalg::Vector3l& turn_q30, uint16_t steps,
                        Vector3f& in_use_uT) {
    bool changed = false;
    while (solving()) changed = solve_part(in_use_uT) || changed;
    if (!field_uT.is_finite()) return changed;
    int32_t* q = turn_.q30;
    age_steps_ = (uint16_t)(age_steps_ + steps < kLearnMaxPairSteps ? age_steps_ + steps : kLearnMaxPairSteps);
    if (!have_ref_ || age_steps_ >= kLearnMaxPairSteps) {
        end_solve();  // q = 1: this sample starts the next pair
        field_ref_ = field_uT;
        age_steps_ = 0;
        have_ref_ = true;
        return changed;
    }
    // q <- q dq, dq = (cos(a/2), sin(a/2) t / a) for the turn t, a = |t|: cos(a/2) = 1 -
    // a^2/8 + a^4/384 and sin(a/2)/a = 1/2 - a^2/48 leave dq unit to 1e-6 and its angle
    // right to 1e-6 rad up to a = 0.43 rad (each axis within 0.25 rad). A longer turn (a
    // fast spin, or a sample that waited for a step with room for the learner) is halved
    // k times to that and dq squared k times, (w, v)^2 = (w^2 - v.v, 2 w v). In Q30
    // (mul_q30: ~1e-9 a product), so q stays a unit quaternion without renormalising.
    using linalg::mul_q30;
    constexpr int32_t kOne = 1073741824L, kHalf = 536870912L, kEighth = 134217728L;
    constexpr int32_t kOver48 = 22369621L, kOver384 = 2796203L;  // 2^30/48, 2^30/384
    constexpr int32_t kMaxAxis = 268435456L;                      // 0.25 rad
    linalg::Vector3l t = turn_q30;
    uint8_t halvings = 0;
    while (linalg::magnitude(t.x) > (uint32_t)kMaxAxis || linalg::magnitude(t.y) > (uint32_t)kMaxAxis ||
           linalg::magnitude(t.z) > (uint32_t)kMaxAxis) {
        t = linalg::Vector3l(t.x / 2, t.y / 2, t.z / 2);
        ++halvings;
    }
    const int32_t a2 = linalg::dot_q30(t, t);
    int32_t dw = kOne - mul_q30(a2, kEighth - mul_q30(a2, kOver384));
    const int32_t ratio = kHalf - mul_q30(a2, kOver48);
    int32_t dx = mul_q30(ratio, t.x), dy = mul_q30(ratio, t.y), dz = mul_q30(ratio, t.z);
    for (; halvings > 0; --halvings) {
        const int32_t w2 = mul_q30(dw, dw) - mul_q30(dx, dx) - mul_q30(dy, dy) - mul_q30(dz, dz);
        dx = mul_q30(dw, dx) * 2;
        dy = mul_q30(dw, dy) * 2;
        dz = mul_q30(dw, dz) * 2;
        dw = w2;
    }
    const int32_t w = q[0], x = q[1], y = q[2], z = q[3];
    q[0] = mul_q30(w, dw) - mul_q30(x, dx) - mul_q30(y, dy) - mul_q30(z, dz);
    q[1] = mul_q30(w, dx) + mul_q30(x, dw) + mul_q30(y, dz) - mul_q30(z, dy);
    q[2] = mul_q30(w, dy) - mul_q30(x, dz) + mul_q30(y, dw) + mul_q30(z, dx);
    q[3] = mul_q30(w, dz) + mul_q30(x, dy) - mul_q30(y, dx) + mul_q30(z, dw);
    // cos theta = 2 w^2 - 1 > kLearnMinCos: not turned enough yet, the pair stays open.
    constexpr int32_t kMinW2 = (int32_t)((1.0 + (double)kLearnMinCos) * 0.5 * 1073741824.0);
    if (mul_q30(q[0], q[0]) > kMinW2) return changed;
    // The sample that closes this pair opens the next, once the pair is solved.
    field_next_ = field_uT;
    age_steps_ = 0;
    solve_part_ = 1;
    return changed;
}

bool OffsetLearner::solve_part(Vector3f& in_use_uT) {
    switch (solve_part_) {
        case 1:
            solve_part_ = solve_residual() ? 2 : kSolveParts + 1;
            return false;
        case 2:
            solve_part_ = solve_step() ? 3 : kSolveParts + 1;
            return false;
        case 3: return solve_estimate(in_use_uT);
        default:  // the pair was dropped by the second part: its third only closes the solve
            end_solve();
            return false;
    }
}

void OffsetLearner::end_solve() {
    field_ref_ = field_next_;
    turn_.q30[0] = 1073741824L;  // the identity, Q30
    turn_.q30[1] = turn_.q30[2] = turn_.q30[3] = 0;
    solve_part_ = 0;
}

// First part (in fixed point, not float: short enough for a step that also corrects
// gravity): the innovation r = P f2 - f1 - (P - I) x = P (f2 - x) - (f1 - x) =
// H (e - x) and H^T r = P^T r - r, P = R(q) the pair's turn, in fixed point: P in Q30
// from q's products (mul_q30, ~1e-9 each), the fields less the estimate in Q16 uT (steps
// of 1.5e-5 uT; fields within 2^15 uT). Leaves r . r in turn_.f[0] (q is not needed
// again), H^T r in field_ref_ (f1 is not either), and the rotation's axis for the second
// part: m = 2 u / sigma in turn_.f[1..3] (the pair's information H^T H / sigma^2 =
// |m|^2 I - m m^T) and 1 / |m|^2 in inv_axis2_.
FIXED_COLD bool OffsetLearner::solve_residual() {
    using linalg::mul_q30;
    using linalg::Vector3l;
    const int32_t w = turn_.q30[0], x = turn_.q30[1], y = turn_.q30[2], z = turn_.q30[3];
    const int32_t xx = mul_q30(x, x), yy = mul_q30(y, y), zz = mul_q30(z, z);
    const int32_t xy = mul_q30(x, y), xz = mul_q30(x, z), yz = mul_q30(y, z);
    const int32_t wx = mul_q30(w, x), wy = mul_q30(w, y), wz = mul_q30(w, z);
    // R(q) = I + 2 w [u x] + 2 [u x]^2; each entry within 1 (the sums doubled by adding
    // twice: 2 (y^2 + z^2) reaches 2^31 for a half turn).
    constexpr int32_t kOne = 1073741824L;
    const linalg::Matrix3q30 p{Vector3l(kOne - (yy + zz) - (yy + zz), (xy - wz) * 2, (xz + wy) * 2),
                               Vector3l((xy + wz) * 2, kOne - (xx + zz) - (xx + zz), (yz - wx) * 2),
                               Vector3l((xz - wy) * 2, (yz + wx) * 2, kOne - (xx + yy) - (xx + yy))};
    const linalg::Matrix3q30 p_transposed{Vector3l(p.a.x, p.b.x, p.c.x), Vector3l(p.a.y, p.b.y, p.c.y),
                                          Vector3l(p.a.z, p.b.z, p.c.z)};
    constexpr uint8_t kFieldQ = 16;
    const Vector3l e = linalg::fixed_from_vector(estimate_uT_, kFieldQ);
    const Vector3l r = mul_q30(p, linalg::fixed_from_vector(field_next_, kFieldQ) - e) -
                       (linalg::fixed_from_vector(field_ref_, kFieldQ) - e);
    field_ref_ = linalg::vector_from_fixed(mul_q30(p_transposed, r) - r, kFieldQ);
    turn_.f[0] = linalg::vector_from_fixed(r, kFieldQ).length_squared();
    const float k = 2.0f / kLearnPairNoise_uT;
    turn_.f[1] = linalg::float_from_fixed(x, linalg::kQ30) * k;
    turn_.f[2] = linalg::float_from_fixed(y, linalg::kQ30) * k;
    turn_.f[3] = linalg::float_from_fixed(z, linalg::kQ30) * k;
    // |u|^2 = sin^2(theta/2) >= 0.03 once the pair is turned by 20 deg.
    const float m2 = turn_.f[1] * turn_.f[1] + turn_.f[2] * turn_.f[2] + turn_.f[3] * turn_.f[3];
    if (!(m2 > 0.0f)) return false;
    inv_axis2_ = 1.0f / m2;
    return true;
}

// Second part (the long one): the information, the step, the gate. A = I / prior^2 + L (L
// faded, this pair's H^T H / sigma^2 added) and its inverse C (symmetric: cofactors
// over the determinant), the posterior covariance, uT^2. H^T H = 2 I - P - P^T =
// 4 (|u|^2 I - u u^T) for the unit q = (w, u). info_ holds L already faded (the third
// part fades what it takes in). Leaves the step in field_ref_, 1 / det A in turn_.f[0]
// and C's diagonal cofactors in turn_.f[1..3]; false when the pair is dropped.
FIXED_COLD bool OffsetLearner::solve_step() {
    const Vector3f m(turn_.f[1], turn_.f[2], turn_.f[3]);
    const Vector3f across = field_ref_;
    const float rr = turn_.f[0];
    const float fade = 1.0f - 1.0f / kLearnMemoryPairs;
    const float inv_noise = 1.0f / (kLearnPairNoise_uT * kLearnPairNoise_uT);
    const float xx = m.x * m.x, yy = m.y * m.y, zz = m.z * m.z;
    const float hth[6] = {yy + zz, xx + zz, xx + yy, -(m.x * m.y), -(m.x * m.z), -(m.y * m.z)};
    float info[6];
    for (uint8_t e = 0; e < 6; ++e) info[e] = info_[e] + hth[e];
    const float axx = info[0] + prior_info_, ayy = info[1] + prior_info_, azz = info[2] + prior_info_;
    const float axy = info[3], axz = info[4], ayz = info[5];
    const float cxx = ayy * azz - ayz * ayz, cyy = axx * azz - axz * axz, czz = axx * ayy - axy * axy;
    const float cxy = axz * ayz - axy * azz, cxz = axy * ayz - axz * ayy, cyz = axy * axz - axx * ayz;
    const float det = axx * cxx + axy * cxy + axz * cxz;
    if (!(det > 0.0f)) return false;
    const float inv_det = 1.0f / det;
    const Vector3f b = across * (inv_noise * inv_det);
    Vector3f step(cxx * b.x + cxy * b.y + cxz * b.z, cxy * b.x + cyy * b.y + cyz * b.z,
                  cxz * b.x + cyz * b.y + czz * b.z);
    // A pair says nothing along its rotation axis, m: what the solve puts there is the
    // weak prior amplifying the pair's error: taken out (no square root).
    step -= m * (m.dot(step) * inv_axis2_);
    // The innovation's covariance is S = H C0 H^T + sigma^2 I (C0: the covariance before
    // this pair), and what the step leaves of it is sigma^2 S^-1 r: r^T S^-1 r, the
    // innovation in sigmas squared, is r . (r - H step) / sigma^2 = (r . r - H^T r . step)
    // / sigma^2. Beyond kLearnGate^2 no offset near x explains the pair (a magnet passing,
    // the board carried through a gradient): dropped, x and L unchanged.
    const bool consistent =
        rr - across.dot(step) < kLearnGate * kLearnGate * kLearnPairNoise_uT * kLearnPairNoise_uT;
    reject_share_ = reject_share_ * fade + (consistent ? 0.0f : 1.0f / kLearnMemoryPairs);
    if (!consistent) {
        if (rejected_ < 0xFFFFu) ++rejected_;
        return false;
    }
    // A step cut short has not taken the pair in: its information is not counted, or the
    // next pairs would be judged against an estimate that is not there.
    const float* s = &step.x;
    step_cut_ = false;
    for (uint8_t i = 0; i < 3; ++i) step_cut_ = step_cut_ || !(s[i] > -kLearnMaxStep_uT && s[i] < kLearnMaxStep_uT);
    if (!step_cut_)
        for (uint8_t e = 0; e < 6; ++e) info_[e] = info[e];
    field_ref_ = step;
    turn_.f[0] = inv_det;
    turn_.f[1] = cxx;
    turn_.f[2] = cyy;
    turn_.f[3] = czz;
    return true;
}

// Third part: the estimate moves by the step, and the offset in use follows it
// once it is significant; the information taken in fades for the next pair.
FIXED_COLD bool OffsetLearner::solve_estimate(Vector3f& in_use_uT) {
    const Vector3f step = field_ref_;
    const float inv_det = turn_.f[0];
    const float var[3] = {turn_.f[1] * inv_det, turn_.f[2] * inv_det, turn_.f[3] * inv_det};
    end_solve();
    if (!step_cut_)
        for (uint8_t e = 0; e < 6; ++e) info_[e] *= 1.0f - 1.0f / kLearnMemoryPairs;
    const float* s = &step.x;
    float* o = &estimate_uT_.x;
    const float* start = &start_uT_.x;
    bool at_bound = false, significant = false;
    for (uint8_t i = 0; i < 3; ++i) {
        o[i] += linalg::constrain(s[i], -kLearnMaxStep_uT, kLearnMaxStep_uT);
        o[i] = linalg::constrain(o[i], -kLearnMaxOffset_uT, kLearnMaxOffset_uT);
        // At the bound, or one pair's step from it: a magnet (it hovers there).
        at_bound = at_bound || !(absf(o[i]) < kLearnMaxOffset_uT - kLearnMaxStep_uT);
        const float dev = o[i] - start[i];
        significant = significant || dev * dev > kLearnSignificance * kLearnSignificance *
                                                     (var[i] + kLearnSystematic_uT * kLearnSystematic_uT);
    }
    if (updates_ < 0xFFFFu) ++updates_;
    // Once put in use, the offset follows the estimate (no toggling about the threshold:
    // each change makes the estimator learn the field again); an estimate still on its
    // way (a step cut short) changes nothing.
    if (step_cut_) return false;
    const bool following = !(in_use_uT == start_uT_);
    const bool hard_iron = !at_bound && reject_share_ <= kLearnMaxRejectShare;
    significant_run_ = significant ? (uint8_t)(significant_run_ < 255 ? significant_run_ + 1 : 255) : 0;
    const bool confirmed = significant_run_ >= kLearnConfirmPairs;
    const Vector3f use = hard_iron && (confirmed || following) ? estimate_uT_ : start_uT_;
    if (use == in_use_uT) return false;
    in_use_uT = use;
    return true;
}

}  // namespace calib
