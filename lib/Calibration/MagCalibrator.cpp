// SPDX-License-Identifier: GPL-3.0-or-later
#include "MagCalibrator.h"

#include "CalibMath.h"
#include "Fixed.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define CALIB_PROGMEM PROGMEM
#else
#define CALIB_PROGMEM
#endif

namespace calib {

using linalg::Matrix3f;
using linalg::Vector3f;
using linalg::safe_sqrt;

namespace {

// The samples are centred on the pivot and scaled by this (a power of two: exact), so
// that the sums are of numbers near 1.
constexpr float kFitScale_uT = 64.0f;
constexpr float kFitInvScale = 1.0f / kFitScale_uT;

// Index of the monomial x^i y^j z^k in MagCalibrator's sums: by degree d = i + j + k,
// then by r = j + k, then by k (1, x, y, z, x^2, xy, xz, y^2, yz, z^2, x^3, ...).
// Tables, not d (d + 1) (d + 2) / 6 and r (r + 1) / 2: a division is a library call on
// the AVR, and add() looks up 34 indices a sample. The small tables are in flash on the
// AVR (a const array is copied to SRAM at start otherwise): table_byte reads them.
const uint8_t kTetrahedral[5] CALIB_PROGMEM = {0, 1, 4, 10, 20};  // monomials of degree < d
const uint8_t kTriangular[5] CALIB_PROGMEM = {0, 1, 3, 6, 10};
uint8_t table_byte(const uint8_t* table, uint8_t i) {
#ifdef __AVR__
    return pgm_read_byte(table + i);
#else
    return table[i];
#endif
}
uint8_t tetrahedral(uint8_t d) { return table_byte(kTetrahedral, d); }
uint8_t triangular(uint8_t r) { return table_byte(kTriangular, r); }
uint8_t moment_index(uint8_t i, uint8_t j, uint8_t k) {
    const uint8_t r = (uint8_t)(j + k);
    return (uint8_t)(tetrahedral((uint8_t)(i + r)) + triangular(r) + k);
}

// Exponents packed two bits each (i | j << 2 | k << 4).
uint8_t moment_of(uint8_t packed) { return moment_index(packed & 3u, (packed >> 2) & 3u, (packed >> 4) & 3u); }
uint8_t moment_of_sum(uint8_t a, uint8_t b) {
    return moment_index((uint8_t)((a & 3u) + (b & 3u)), (uint8_t)(((a >> 2) & 3u) + ((b >> 2) & 3u)),
                        (uint8_t)(((a >> 4) & 3u) + ((b >> 4) & 3u)));
}
constexpr uint8_t kX = 1, kY = 4, kZ = 16, kOne = 0;

// Solves the n x n system held as an augmented matrix a[n][n+1] (Gaussian elimination
// with partial pivoting); the solution replaces column n. False when a pivot is below
// 1e-6 of the largest diagonal term: the fit is not determined.
constexpr uint8_t kMaxUnknowns = 4;
bool solve(float a[][kMaxUnknowns + 1], uint8_t n) {
    float scale = 0.0f;
    for (uint8_t i = 0; i < n; ++i) scale = a[i][i] > scale ? a[i][i] : scale;
    const float tiny = scale * 1e-6f;
    for (uint8_t col = 0; col < n; ++col) {
        uint8_t best = col;
        for (uint8_t row = (uint8_t)(col + 1); row < n; ++row)
            if (absf(a[row][col]) > absf(a[best][col])) best = row;
        if (!(absf(a[best][col]) > tiny)) return false;
        if (best != col)
            for (uint8_t k = col; k <= n; ++k) {
                const float t = a[col][k];
                a[col][k] = a[best][k];
                a[best][k] = t;
            }
        const float inv = 1.0f / a[col][col];
        for (uint8_t row = 0; row < n; ++row) {
            if (row == col) continue;
            const float f = a[row][col] * inv;
            for (uint8_t k = col; k <= n; ++k) a[row][k] -= f * a[col][k];
        }
    }
    for (uint8_t i = 0; i < n; ++i) a[i][n] /= a[i][i];
    return true;
}

// Newton-Schulz's T = (3I - Z Y) / 2 from the product Z Y (root_start, root_part).
Matrix3f newton_schulz_t(const Matrix3f& zy) {
    return Matrix3f(Vector3f(1.5f - 0.5f * zy.a.x, -0.5f * zy.a.y, -0.5f * zy.a.z),
                    Vector3f(-0.5f * zy.b.x, 1.5f - 0.5f * zy.b.y, -0.5f * zy.b.z),
                    Vector3f(-0.5f * zy.c.x, -0.5f * zy.c.y, 1.5f - 0.5f * zy.c.z));
}
// A 3x3 matrix kept as nine floats, row by row (the fit's working memory is a union).
Matrix3f matrix_of(const float* m) {
    return Matrix3f(Vector3f(m[0], m[1], m[2]), Vector3f(m[3], m[4], m[5]), Vector3f(m[6], m[7], m[8]));
}
void store(const Matrix3f& x, float* m) {
    const Vector3f rows[3] = {x.a, x.b, x.c};
    for (uint8_t r = 0; r < 3; ++r) {
        m[3 * r] = rows[r].x;
        m[3 * r + 1] = rows[r].y;
        m[3 * r + 2] = rows[r].z;
    }
}

// Row i's first entry in a packed lower triangle.
uint8_t row_start(uint8_t i) { return (uint8_t)((i * (i + 1u)) >> 1); }

}  // namespace

void MagCalibrator::restart(const Vector3f& pivot_uT) {
    for (uint8_t i = 0; i < kMoments; ++i) work_.sums[i] = 0.0f;
    count_ = 0;
    stage_ = kStageDone;
    quality_ = Quality::TooFewSamples;
    for (uint8_t& b : cell_samples_) b = 0;
    pivot_uT_ = cover_centre_uT_ = pivot_uT.is_finite() ? pivot_uT : Vector3f();
    residual_uT_ = sphere_residual_uT_ = radius_uT_ = 0.0f;
}

void MagCalibrator::add(const Vector3f& field_uT) {
    if (!field_uT.is_finite() || count_ == 0xFFFFu || stage_ != kStageDone) return;
    ++count_;
    // The monomials in index order, each one a product of a lower one: 31 multiplies.
    const Vector3f u = (field_uT - pivot_uT_) * kFitInvScale;
    const float var[3] = {u.x, u.y, u.z};
    float m[kMoments];
    m[0] = 1.0f;
    uint8_t n = 1;
    for (uint8_t d = 1; d <= 4; ++d) {
        for (uint8_t r = 0; r <= d; ++r) {
            for (uint8_t k = 0; k <= r; ++k, ++n) {
                // Parent: x^(i-1) y^j z^k (same r) times x while i > 0, else y, else z.
                const uint8_t below = (uint8_t)(tetrahedral((uint8_t)(d - 1)) + k);
                if (r < d) m[n] = m[below + triangular(r)] * var[0];
                else if (k < r) m[n] = m[below + triangular((uint8_t)(r - 1))] * var[1];
                else m[n] = m[below - 1 + triangular((uint8_t)(r - 1))] * var[2];
            }
        }
    }
    for (uint8_t i = 0; i < kMoments; ++i) work_.sums[i] += m[i];

    // Coverage: the direction from the centre (the sphere fit so far, refreshed each
    // kCoverageRefitSamples; the pivot before), quantised to one of 26 cells by the
    // sign of each component that is at least tan 22.5 deg of the largest one (faces,
    // edges and corners of a cube).
    if (count() % kCoverageRefitSamples == 0) fit_sphere();
    const Vector3f d = field_uT - cover_centre_uT_;
    const float c[3] = {d.x, d.y, d.z};
    float big = 0.0f;
    for (uint8_t a = 0; a < 3; ++a) {
        const float m_abs = absf(c[a]);
        if (m_abs > big) big = m_abs;
    }
    if (!(big > 0.0f)) return;
    uint8_t cell = 0;
    for (uint8_t a = 0; a < 3; ++a) {
        const uint8_t q = absf(c[a]) < 0.4142f * big ? 1 : (c[a] > 0.0f ? 2 : 0);
        cell = (uint8_t)(cell * 3u + q);
    }
    if (cell > 13) --cell;  // 13 (all components small) cannot happen
    if (cell_samples(cell) < kMagCellMinSamples)
        cell_samples_[cell >> 2] = (uint8_t)(cell_samples_[cell >> 2] + (1u << ((cell & 3u) * 2u)));
}

static_assert(kMagCellMinSamples <= 3, "a cell's count has 2 bits");
uint8_t MagCalibrator::cell_samples(uint8_t cell) const {
    return (uint8_t)((cell_samples_[cell >> 2] >> ((cell & 3u) * 2u)) & 3u);
}

uint32_t MagCalibrator::cells_seen() const {
    uint32_t bits = 0;
    for (uint8_t i = 0; i < kCells; ++i)
        if (cell_samples(i) >= kMagCellMinSamples) bits |= (uint32_t)1u << i;
    return bits;
}

uint8_t MagCalibrator::coverage_pct() const {
    uint8_t seen = 0;
    for (uint8_t i = 0; i < kCells; ++i) seen = (uint8_t)(seen + (cell_samples(i) >= kMagCellMinSamples));
    return (uint8_t)((seen * 100u + kCells / 2u) / kCells);
}

// Sphere: |u|^2 = a x + b y + c z + d, linear in (a, b, c, d); centre (a, b, c) / 2,
// radius^2 = d + |centre|^2. Residual: |u - c|^2 - R^2 ~ 2 R (|u - c| - R).
bool MagCalibrator::fit_sphere() {
    static const uint8_t kReg[4] CALIB_PROGMEM = {kX, kY, kZ, kOne};
    float a[4][kMaxUnknowns + 1];
    float tt;  // sum |u|^4
    for (uint8_t p = 0; p < 4; ++p) {
        const uint8_t rp = table_byte(kReg, p);
        for (uint8_t q = 0; q < 4; ++q) a[p][q] = work_.sums[moment_of_sum(rp, table_byte(kReg, q))];
        a[p][4] = work_.sums[moment_of_sum(rp, 2 * kX)] + work_.sums[moment_of_sum(rp, 2 * kY)] +
                  work_.sums[moment_of_sum(rp, 2 * kZ)];
    }
    tt = work_.sums[moment_index(4, 0, 0)] + work_.sums[moment_index(0, 4, 0)] + work_.sums[moment_index(0, 0, 4)] +
         2.0f * (work_.sums[moment_index(2, 2, 0)] + work_.sums[moment_index(2, 0, 2)] + work_.sums[moment_index(0, 2, 2)]);
    float rhs[4];
    for (uint8_t p = 0; p < 4; ++p) rhs[p] = a[p][4];
    if (!solve(a, 4)) return false;
    const Vector3f centre(a[0][4] * 0.5f, a[1][4] * 0.5f, a[2][4] * 0.5f);
    const float r2 = a[3][4] + centre.length_squared();
    if (!(r2 > 0.0f)) return false;
    float sse = tt;
    for (uint8_t p = 0; p < 4; ++p) sse -= a[p][4] * rhs[p];
    const float r = sqrtf(r2);
    cover_centre_uT_ = pivot_uT_ + centre * kFitScale_uT;
    sphere_residual_uT_ = safe_sqrt(sse / work_.sums[0]) / (2.0f * r) * kFitScale_uT;
    radius_uT_ = r * kFitScale_uT;
    return true;
}

// Ellipsoid: u^T Q u + g.u = 1 with Q symmetric, linear in its nine terms
// (A x^2 + B y^2 + C z^2 + D yz + E xz + F xy + G x + H y + I z = 1; a pivot near the
// centre keeps the constant term away from zero). Centre c = -Q^-1 g / 2; then
// (u - c)^T Q (u - c) = k = 1 + c^T Q c. W = sqrt(Q / det(Q)^(1/3)) has det 1 and
// maps the ellipsoid onto a sphere of radius sqrt(k / det(Q)^(1/3)).
// The least-squares normal equations A t = b (A = sum r r^T over the regressors r, b =
// sum r) are symmetric positive definite when the fit is determined: solved by Cholesky
// (A = L L^T) in the sums' memory, a few columns a part. Then the sum of squares left is
// count - b^T t = count - |L^-1 b|^2.
static const uint8_t kEllipsoidRegressors[MagCalibrator::kUnknowns] CALIB_PROGMEM = {
    2 * kX, 2 * kY, 2 * kZ, kY + kZ, kX + kZ, kX + kY, kX, kY, kZ};
FIXED_COLD void MagCalibrator::normal_equations() {
    Work::Normal n;  // built apart: the sums are read while it is written
    float largest = 0.0f;
    for (uint8_t p = 0; p < kUnknowns; ++p) {
        const uint8_t rp = table_byte(kEllipsoidRegressors, p);
        for (uint8_t q = 0; q <= p; ++q)
            n.l[row_start(p) + q] = work_.sums[moment_of_sum(rp, table_byte(kEllipsoidRegressors, q))];
        n.b[p] = work_.sums[moment_of(rp)];
        if (n.l[row_start(p) + p] > largest) largest = n.l[row_start(p) + p];
    }
    n.tiny = largest * 1e-6f;
    work_.normal = n;
}

// Columns first_column .. first_column + kCholeskyColumns - 1 of L (Cholesky-Banachiewicz
// by columns: each needs the ones before it). False when a pivot is not above tiny.
FIXED_COLD bool MagCalibrator::cholesky_part(uint8_t first_column) {
    float* l = work_.normal.l;
    for (uint8_t j = first_column; j < first_column + kCholeskyColumns && j < kUnknowns; ++j) {
        float d = l[row_start(j) + j];
        for (uint8_t k = 0; k < j; ++k) d -= l[row_start(j) + k] * l[row_start(j) + k];
        if (!(d > work_.normal.tiny)) return false;
        const float ljj = sqrtf(d);
        l[row_start(j) + j] = ljj;
        const float inv = 1.0f / ljj;
        for (uint8_t i = (uint8_t)(j + 1); i < kUnknowns; ++i) {
            float v = l[row_start(i) + j];
            for (uint8_t k = 0; k < j; ++k) v -= l[row_start(i) + k] * l[row_start(j) + k];
            l[row_start(i) + j] = v * inv;
        }
    }
    return true;
}

// b <- L^-1 b, and |L^-1 b|^2.
FIXED_COLD void MagCalibrator::forward_substitution() {
    const float* l = work_.normal.l;
    float* b = work_.normal.b;
    fit_yy_ = 0.0f;
    for (uint8_t i = 0; i < kUnknowns; ++i) {
        float v = b[i];
        for (uint8_t k = 0; k < i; ++k) v -= l[row_start(i) + k] * b[k];
        b[i] = v / l[row_start(i) + i];
        fit_yy_ += b[i] * b[i];
    }
}

// b <- L^-T b: the solution t.
FIXED_COLD void MagCalibrator::back_substitution() {
    const float* l = work_.normal.l;
    float* b = work_.normal.b;
    for (uint8_t i = kUnknowns; i-- > 0;) {
        float v = b[i];
        for (uint8_t k = (uint8_t)(i + 1); k < kUnknowns; ++k) v -= l[row_start(k) + i] * b[k];
        b[i] = v / l[row_start(i) + i];
    }
}

// The quadric's centre, k and det(Q)^(1/3); Q / det(Q)^(1/3) for the root. False when it
// is not an ellipsoid.
bool MagCalibrator::quadric() {
    // A pivot outside the ellipsoid flips the sign of the whole quadric: then
    // -u^T Q u - g.u = -1, with -Q positive.
    const float side = work_.normal.b[0] < 0.0f ? -1.0f : 1.0f;
    float t[kUnknowns];
    for (uint8_t p = 0; p < kUnknowns; ++p) t[p] = work_.normal.b[p] * side;  // read before root is written
    const Matrix3f q(Vector3f(t[0], 0.5f * t[5], 0.5f * t[4]), Vector3f(0.5f * t[5], t[1], 0.5f * t[3]),
                     Vector3f(0.5f * t[4], 0.5f * t[3], t[2]));
    const float det = q.determinant();
    if (!(det > 0.0f) || !(t[0] > 0.0f)) return false;  // not an ellipsoid
    float c3[3][kMaxUnknowns + 1] = {{q.a.x, q.a.y, q.a.z, -0.5f * t[6]},
                                     {q.b.x, q.b.y, q.b.z, -0.5f * t[7]},
                                     {q.c.x, q.c.y, q.c.z, -0.5f * t[8]}};
    if (!solve(c3, 3)) return false;
    const Vector3f centre(c3[0][3], c3[1][3], c3[2][3]);
    const float k = side + centre.dot(q * centre);
    if (!(k > 0.0f)) return false;
    Work::Root& r = work_.root;
    r.cube_root_det = cbrtf(det);
    r.k = k;
    r.centre[0] = centre.x;
    r.centre[1] = centre.y;
    r.centre[2] = centre.z;
    store(q * (1.0f / r.cube_root_det), r.a);
    return true;
}

// Symmetric square root of a symmetric positive matrix near I (Newton-Schulz:
// Y -> Y T, Z -> T Z, T = (3I - Z Y) / 2; quadratic convergence while |I - A| < 1). The
// first step, from Z = I, written out: T = (3I - A) / 2 and Z = T (an identity matrix
// object would be a 36-byte constant in the AVR's SRAM).
FIXED_COLD void MagCalibrator::root_start() {
    Work::Root& r = work_.root;
    const Matrix3f a = matrix_of(r.a);
    const Matrix3f z = newton_schulz_t(a);
    store(z, r.z);
    store(a * z, r.y);
}

// One Newton-Schulz step in two halves: T and Y, then Z.
void MagCalibrator::root_part(bool second_half) {
    Work::Root& r = work_.root;
    if (!second_half) {
        const Matrix3f t = newton_schulz_t(matrix_of(r.z) * matrix_of(r.y));
        store(t, r.t);
        store(matrix_of(r.y) * t, r.y);
    } else {
        store(matrix_of(r.t) * matrix_of(r.z), r.z);
    }
}

static bool within_box(const Vector3f& v, float limit) {
    return within(v.x, -limit, limit) && within(v.y, -limit, limit) && within(v.z, -limit, limit);
}

FIXED_COLD MagCalibrator::Quality MagCalibrator::final_checks() {
    const Work::Root& r = work_.root;
    // The root has not converged: A too far from I, soft iron beyond any limit.
    const Matrix3f y = matrix_of(r.y);
    const Matrix3f d = y * y - matrix_of(r.a);
    const float err = d.a.length_squared() + d.b.length_squared() + d.c.length_squared();
    if (!(err < 1e-8f && y.is_finite())) return Quality::FitFailed;
    const float sse = (float)count_ - fit_yy_;
    const float radius = sqrtf(r.k / r.cube_root_det);
    radius_uT_ = radius * kFitScale_uT;
    residual_uT_ = radius * safe_sqrt(sse / (float)count_) / (2.0f * r.k) * kFitScale_uT;
    Calibration c;
    result(c);
    if (!within(radius_uT_, kMagMinRadius_uT, kMagMaxRadius_uT) || !within_box(c.mag_offset_uT, kMagMaxOffset_uT))
        return Quality::NotEarthField;
    if (!within(c.mag_scale.x, kMagMinDiag, kMagMaxDiag) || !within(c.mag_scale.y, kMagMinDiag, kMagMaxDiag) ||
        !within(c.mag_scale.z, kMagMinDiag, kMagMaxDiag) || !within_box(c.mag_cross, kMagMaxCross))
        return Quality::SoftIronTooLarge;
    if (!(residual_uT_ <= kMagMaxResidual_uT)) return Quality::PoorFit;
    return Quality::Ok;
}

Vector3f MagCalibrator::offset_uT() const {
    const Work::Root& r = work_.root;
    return pivot_uT_ + Vector3f(r.centre[0], r.centre[1], r.centre[2]) * kFitScale_uT;
}
Vector3f MagCalibrator::scale() const { return Vector3f(work_.root.y[0], work_.root.y[4], work_.root.y[8]); }
Vector3f MagCalibrator::cross() const { return Vector3f(work_.root.y[1], work_.root.y[2], work_.root.y[5]); }

void MagCalibrator::result(Calibration& cal) const {
    cal.mag_offset_uT = offset_uT();
    cal.mag_scale = scale();
    cal.mag_cross = cross();
    cal.mag_learned_uT = Vector3f();
}

void MagCalibrator::end_fit(Quality q) {
    quality_ = q;
    stage_ = kStageDone;
}

void MagCalibrator::begin_fit() {
    stage_ = kStageCheck;
    quality_ = Quality::FitFailed;
}

void MagCalibrator::fit_part() {
    const uint8_t stage = stage_;
    if (stage == kStageCheck) {
        if (count_ < kMagCalMinSamples) return end_fit(Quality::TooFewSamples);
        if (coverage_pct() < kMagMinCoveragePct) return end_fit(Quality::ThinCoverage);
        if (!fit_sphere()) return end_fit(Quality::FitFailed);
        if (!within(radius_uT_, kMagMinRadius_uT, kMagMaxRadius_uT)) return end_fit(Quality::NotEarthField);
    } else if (stage == kStageNormal) {
        normal_equations();
    } else if (stage < kStageForward) {
        if (!cholesky_part((uint8_t)((stage - kStageCholesky) * kCholeskyColumns))) return end_fit(Quality::FitFailed);
    } else if (stage == kStageForward) {
        forward_substitution();
    } else if (stage == kStageBack) {
        back_substitution();
    } else if (stage == kStageQuadric) {
        if (!quadric()) return end_fit(Quality::FitFailed);
    } else if (stage == kStageRootStart) {
        root_start();
    } else if (stage < kStageFinal) {
        root_part(((stage - kStageRoot) & 1u) != 0);
    } else if (stage == kStageFinal) {
        return end_fit(final_checks());
    } else {
        return;
    }
    ++stage_;
}

MagCalibrator::Quality MagCalibrator::finish(Calibration& cal) {
    begin_fit();
    while (fitting()) fit_part();
    if (quality_ == Quality::Ok) result(cal);
    return quality_;
}

}  // namespace calib
