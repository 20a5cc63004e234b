// SPDX-License-Identifier: GPL-3.0-or-later
#include "Strapdown.h"

#include "Profile.h"

namespace dcm {

using linalg::Vector3l;

void Strapdown::reset(const linalg::Matrix3q30& r) {
    r_ = r;
    first_half_ = Vector3l();
    turn_sum_ = Vector3l();
    pending_steps_ = 0;
}

void Strapdown::end_step() {
    ++pending_steps_;
    if (pending_steps_ == kIntegrationSteps / 2) {
        first_half_ = turn_sum_;
        turn_sum_ = Vector3l();
    }
}

// R <- R exp([theta x]) with theta the summed turn and its coning term. For a row r
// and a = |theta|, Rodrigues' formula is
//   r exp([theta x]) = cos(a) r + (sin(a)/a) (r x theta) + ((1 - cos a)/a^2) theta (r . theta),
// with the three factors from their series to a^6 (sin(a)/a, cos a) and a^4 ((1 - cos a)
// /a^2): below 4e-7 an update up to a = 0.5 rad (1 430 deg/s at 50 Hz). The update is
// then a rotation to that order and keeps R orthonormal by itself: rounding leaves
// ~1e-7 an update, so renormalisation runs only every kRenormaliseEvery updates, and row
// c is rebuilt as a x b at each (rows a and b are what the update turns). The paper's
// first-order R (I + [theta x]) (eq. 17) is not a rotation: it stretches each row by
// a^2/2 an update, which renormalising at every update hides.
FIXED_OWN_FRAME void Strapdown::integrate(const DcmCoefficients& k) {
    profile::begin(profile::kIntegration);
    using linalg::hot::mul_q14;
    using linalg::mul_q30;
    using linalg::q14_of;
    // In Q30 integers (R's entries and the turn, radians): mul_q30 (13 MULs) where the
    // update's orthonormality depends on the product; mul_q14 (two 16x16 products) in the
    // coning term, whose rounding only turns the update a little more or less (a rotation
    // of a few 1e-7 rad at most, below the gyro's own resolution over the 20 ms).
    const Vector3l first = k.theta_q30(first_half_), second = k.theta_q30(turn_sum_);
    first_half_ = Vector3l();
    turn_sum_ = Vector3l();
    pending_steps_ = 0;
    // The coning term (2/3) A x B, with A in 16 bits and 2/3 in Q14.
    const int16_t ax = q14_of(first.x), ay = q14_of(first.y), az = q14_of(first.z);
    constexpr int16_t kTwoThirdsQ14 = linalg::q14_ratio(2, 3);
    const Vector3l theta(
        first.x + second.x + mul_q14(kTwoThirdsQ14, mul_q14(ay, second.z) - mul_q14(az, second.y)),
        first.y + second.y + mul_q14(kTwoThirdsQ14, mul_q14(az, second.x) - mul_q14(ax, second.z)),
        first.z + second.z + mul_q14(kTwoThirdsQ14, mul_q14(ax, second.y) - mul_q14(ay, second.x)));
    // The three factors' series; below a = 0.03 rad (1.6 rad/s) the terms beyond a^2
    // are below 2e-9 and left out.
    using linalg::q30_ratio;
    constexpr int32_t kOne = linalg::kOneQ30, kHalf = q30_ratio(1, 2), kSmallA2 = q30_ratio(1, 1024);
    constexpr int32_t k1_6 = q30_ratio(1, 6), k1_24 = q30_ratio(1, 24), k1_120 = q30_ratio(1, 120),
                      k1_720 = q30_ratio(1, 720), k1_5040 = q30_ratio(1, 5040);
    const int32_t a2 = linalg::dot_q30(theta, theta);
    int32_t versine_ratio, sin_ratio;  // (1 - cos a)/a^2 and sin(a)/a
    if (a2 < kSmallA2) {
        // (1 - cos a)/a^2 = 1/2 - a^2/24, sin(a)/a = 1 - a^2/6
        versine_ratio = kHalf - mul_q30(a2, k1_24);
        sin_ratio = kOne - mul_q30(a2, k1_6);
    } else {
        // (1 - cos a)/a^2 = 1/2 - a^2 (1/24 - a^2/720), sin(a)/a = 1 - a^2 (1/6 - a^2 (1/120 - a^2/5040))
        versine_ratio = kHalf - mul_q30(a2, k1_24 - mul_q30(a2, k1_720));
        sin_ratio = kOne - mul_q30(a2, k1_6 - mul_q30(a2, k1_120 - mul_q30(a2, k1_5040)));
    }
    const int32_t one_minus_cos = mul_q30(a2, versine_ratio);
    const Vector3l s(mul_q30(sin_ratio, theta.x), mul_q30(sin_ratio, theta.y), mul_q30(sin_ratio, theta.z));
    const Vector3l v(mul_q30(versine_ratio, theta.x), mul_q30(versine_ratio, theta.y), mul_q30(versine_ratio, theta.z));
    // exp([theta x]) - I for a row vector r (r' = r M): D_ij = -(1 - cos a) [i = j] +
    // v_i theta_j + (s x)_ij, with (r (s x))_j = (r x s)_j; v_i theta_j is symmetric.
    const int32_t xx = mul_q30(v.x, theta.x) - one_minus_cos, yy = mul_q30(v.y, theta.y) - one_minus_cos,
                  zz = mul_q30(v.z, theta.z) - one_minus_cos;
    const int32_t xy = mul_q30(v.x, theta.y), xz = mul_q30(v.x, theta.z), yz = mul_q30(v.y, theta.z);
    const linalg::Matrix3q30 d{Vector3l(xx, xy - s.z, xz + s.y), Vector3l(xy + s.z, yy, yz - s.x),
                               Vector3l(xz - s.y, yz + s.x, zz)};
    turn_row(r_.a, d);
    turn_row(r_.b, d);
    profile::end(profile::kIntegration);
    // Row c follows as a x b; the renormalisation, when due, takes a step of its own
    // (next_heavy_part): on this one the output line may follow.
    profile::begin(profile::kRenormalisation);
    r_.c = linalg::cross_q30(r_.a, r_.b);
    if (updates_since_renormalise_ < 0xFF) ++updates_since_renormalise_;
    profile::end(profile::kRenormalisation);
}

bool Strapdown::renormalise() {
    profile::begin(profile::kRenormalisation);
    updates_since_renormalise_ = 0;
    // One pass leaves ~(X.Y)^2: a second one, needed only after a large error (a
    // heading taken at once, a rebuilt matrix), keeps it orthonormal to 1e-5.
    constexpr int32_t kSecondPassSkew = linalg::q30_ratio(2, 1000);
    int32_t skew = 0;
    bool ok = renormalise_once(skew);
    if (ok && (skew > kSecondPassSkew || skew < -kSecondPassSkew)) ok = renormalise_once(skew);
    profile::end(profile::kRenormalisation);
    return ok;
}

// One row of R turned: r + r D (D = exp([theta x]) - I, rows as Matrix3q30), in Q30.
void Strapdown::turn_row(Vector3l& r, const linalg::Matrix3q30& d) {
    using linalg::mul_q30;
    r = Vector3l(r.x + mul_q30(r.x, d.a.x) + mul_q30(r.y, d.b.x) + mul_q30(r.z, d.c.x),
                 r.y + mul_q30(r.x, d.a.y) + mul_q30(r.y, d.b.y) + mul_q30(r.z, d.c.y),
                 r.z + mul_q30(r.x, d.a.z) + mul_q30(r.y, d.b.z) + mul_q30(r.z, d.c.z));
}

// Orthonormalisation (eq. 18-21): share the X.Y error between the two rows, bring
// each to unit length, and make Z their cross product (unit to within the square
// of the remaining error, so it needs no scaling of its own). In Q30.
bool Strapdown::renormalise_once(int32_t& skew_q30) {
    using linalg::mul_q30;
    skew_q30 = linalg::dot_q30(r_.a, r_.b);
    const int32_t half_error = skew_q30 / 2;
    const Vector3l x(r_.a.x - mul_q30(half_error, r_.b.x), r_.a.y - mul_q30(half_error, r_.b.y),
                     r_.a.z - mul_q30(half_error, r_.b.z));
    const Vector3l y(r_.b.x - mul_q30(half_error, r_.a.x), r_.b.y - mul_q30(half_error, r_.a.y),
                     r_.b.z - mul_q30(half_error, r_.a.z));
    if (!rescale(x, r_.a) || !rescale(y, r_.b)) return false;
    r_.c = linalg::cross_q30(r_.a, r_.b);
    return true;
}

// Near unit length the first-order Taylor factor (3 - r.r)/2 replaces a square root
// and a division; its residual is 3/8 (r.r - 1)^2, below 2e-6 in this window.
bool Strapdown::rescale(const Vector3l& row, Vector3l& out) {
    constexpr int32_t kOne = linalg::kOneQ30;
    constexpr int32_t kWindow = linalg::q30_ratio(2, 1000);
    // Each entry within +-1.4 (its square within Q30's 2); beyond, the matrix is hopeless.
    constexpr int32_t kMaxEntry = 1518500249L;  // floor(sqrt(2) 2^30): sqrt(2) in Q30
    const int32_t* entry[3] = {&row.x, &row.y, &row.z};
    for (uint8_t i = 0; i < 3; ++i)
        if (*entry[i] >= kMaxEntry || *entry[i] <= -kMaxEntry) return false;
    // |r|^2 in unsigned Q30, which holds up to 4: a row twice a unit long or more wraps
    // (a sum below one of its terms) and is hopeless.
    const uint32_t xx = (uint32_t)linalg::mul_q30(row.x, row.x), yy = (uint32_t)linalg::mul_q30(row.y, row.y),
                   zz = (uint32_t)linalg::mul_q30(row.z, row.z);
    const uint32_t xy = xx + yy, length2 = xy + zz;
    if (xy < xx || length2 < zz) return false;
    if (length2 > (uint32_t)(kOne - kWindow) && length2 < (uint32_t)(kOne + kWindow)) {
        const int32_t factor = kOne + kOne / 2 - (int32_t)(length2 / 2);
        out = Vector3l(linalg::mul_q30(factor, row.x), linalg::mul_q30(factor, row.y), linalg::mul_q30(factor, row.z));
        return true;
    }
    // Far from unit length (a rebuilt matrix, a heading taken at once): the exact factor,
    // in float, unless the matrix is hopeless.
    const float length2_f = linalg::float_from_fixed((int32_t)(length2 / 2), 29);
    if (!(length2_f > 0.25f)) return false;
    out = linalg::fixed_from_vector(linalg::vector_from_q30(row) * (1.0f / sqrtf(length2_f)), linalg::kQ30);
    return true;
}

}  // namespace dcm
