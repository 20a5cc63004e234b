// SPDX-License-Identifier: GPL-3.0-or-later
#include "Calibration.h"
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

Calibration default_calibration() {
    Calibration c;
    c.gyro_bias_rad_s = Vector3f();
    c.mag_offset_uT = Vector3f();
    c.mag_scale = Vector3f(1.0f, 1.0f, 1.0f);
    c.mag_cross = Vector3f();
    c.mag_learned_uT = Vector3f();
    return c;
}

// W rows: (sx, xy, xz), (xy, sy, yz), (xz, yz, sz).
static Matrix3f soft_iron(const Calibration& c) {
    return Matrix3f(Vector3f(c.mag_scale.x, c.mag_cross.x, c.mag_cross.y),
                    Vector3f(c.mag_cross.x, c.mag_scale.y, c.mag_cross.z),
                    Vector3f(c.mag_cross.y, c.mag_cross.z, c.mag_scale.z));
}

Vector3f apply_mag(const Calibration& c, const Vector3f& field_uT) {
    return soft_iron(c) * (field_uT - c.mag_offset_uT) - c.mag_learned_uT;
}

static bool within(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN

bool is_plausible(const Calibration& c) {
    // Bias, offset, diagonal, cross terms, learned offset: fifteen packed floats.
    static_assert(sizeof(Calibration) == 15 * sizeof(float), "Calibration is fifteen floats");
    const float* v = &c.gyro_bias_rad_s.x;
    for (uint8_t i = 0; i < 15; ++i) {
        const uint8_t k = (uint8_t)(i / 3u);
        const float lo = k == 0 ? -kGyroBiasMax_rad_s : k == 2 ? 0.5f : k == 3 ? -0.5f : -200.0f;
        const float hi = k == 0 ? kGyroBiasMax_rad_s : k == 2 ? 2.0f : k == 3 ? 0.5f : 200.0f;
        if (!within(v[i], lo, hi)) return false;
    }
    return true;
}

// ---------------------------------------------------------------------------
void GyroCalibrator::restart() {
    n_ = 0;  // add() starts the sums and extremes afresh at n_ == 0
    done_ = false;
}

GyroCalibrator::Result GyroCalibrator::add(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    // NaN or beyond the fine counts' range: not still (a count at the range's end fails
    // the spread or the 1 g test).
    const float g[3] = {gyro_rad_s.x, gyro_rad_s.y, gyro_rad_s.z}, a[3] = {accel_m_s2.x, accel_m_s2.y, accel_m_s2.z};
    int16_t gc[3], ac[3];
    for (uint8_t i = 0; i < 3; ++i) {
        const float gi = g[i] * (1.0f / kFloatGyroScale), ai = a[i] * (1.0f / kFloatAccelScale);
        gc[i] = linalg::is_finite(gi) ? (int16_t)linalg::constrain(gi, -32767.0f, 32767.0f) : 32767;
        ac[i] = linalg::is_finite(ai) ? (int16_t)linalg::constrain(ai, -32767.0f, 32767.0f) : 32767;
    }
    return add(linalg::Vector3i(gc[0], gc[1], gc[2]), linalg::Vector3i(ac[0], ac[1], ac[2]), kFloatGyroScale,
               kFloatAccelScale);
}

GyroCalibrator::Result GyroCalibrator::add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts,
                                           float gyro_rad_s_per_count, float accel_m_s2_per_count) {
    if (done_) restart();
    if (gyro_rad_s_per_count != gyro_scale_ || accel_m_s2_per_count != accel_scale_) {
        // New scales (the first sample): the limits in counts (a few float operations,
        // once: a board that keeps moving restarts the window every few samples).
        restart();
        gyro_scale_ = gyro_rad_s_per_count;
        accel_scale_ = accel_m_s2_per_count;
        spread_max_[0] = (uint16_t)linalg::constrain(kGyroSpreadMax_rad_s / gyro_rad_s_per_count, 0.0f, 65535.0f);
        spread_max_[1] = (uint16_t)linalg::constrain(kAccelSpreadMax_m_s2 / accel_m_s2_per_count, 0.0f, 65535.0f);
        const float g_counts = 9.80665f / accel_m_s2_per_count;
        const float lo = g_counts * (1.0f - kAccelNormTol_g), hi = g_counts * (1.0f + kAccelNormTol_g);
        norm2_min_ = (uint32_t)linalg::constrain(lo * lo, 0.0f, 4.0e9f);
        norm2_max_ = (uint32_t)linalg::constrain(hi * hi, 0.0f, 4.0e9f);
    }
    const int16_t v[6] = {gyro_counts.x, gyro_counts.y, gyro_counts.z, accel_counts.x, accel_counts.y, accel_counts.z};
    const uint32_t norm2 = (uint32_t)linalg::mul_s16(v[3], v[3]) + (uint32_t)linalg::mul_s16(v[4], v[4]) +
                           (uint32_t)linalg::mul_s16(v[5], v[5]);
    bool still = norm2 > norm2_min_ && norm2 < norm2_max_;
    // The spread (max - min) of every channel over the window so far.
    for (uint8_t i = 0; i < 6 && still; ++i) {
        if (n_ == 0 || v[i] < lo_[i]) lo_[i] = v[i];
        if (n_ == 0 || v[i] > hi_[i]) hi_[i] = v[i];
        still = (uint16_t)(hi_[i] - lo_[i]) <= spread_max_[i < 3 ? 0 : 1];
    }
    if (!still) {
        const bool had_samples = n_ > 0;
        restart();
        if (had_samples) ++restarts_;
        return had_samples ? Result::Moved : Result::Collecting;
    }
    for (uint8_t i = 0; i < 6; ++i) sum_[i] = (n_ == 0 ? 0 : sum_[i]) + v[i];
    ++n_;
    if (n_ < kGyroWindow) return Result::Collecting;
    const Vector3f b = bias();
    if (!(b.length_squared() <= 3.0f * kGyroBiasMax_rad_s * kGyroBiasMax_rad_s)) {  // steady spin: not a bias
        restart();
        ++restarts_;
        return Result::Moved;
    }
    done_ = true;
    return Result::Done;
}

Vector3f GyroCalibrator::mean(uint8_t first, float scale) const {
    const float k = n_ > 0 ? scale / (float)n_ : 0.0f;
    return Vector3f((float)sum_[first] * k, (float)sum_[first + 1] * k, (float)sum_[first + 2] * k);
}

// ---------------------------------------------------------------------------
namespace {

// The samples are centred on the pivot and scaled by this (a power of two: exact), so
// that the sums are of numbers near 1.
constexpr float kFitScale_uT = 64.0f;

// Not fabsf: avr-libc's is fabs on double (a promotion warning, though both are 32-bit).
float absf(float v) { return v < 0.0f ? -v : v; }
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

void MagCalibrator::result(Calibration& cal) const {
    const Work::Root& r = work_.root;
    cal.mag_offset_uT = pivot_uT_ + Vector3f(r.centre[0], r.centre[1], r.centre[2]) * kFitScale_uT;
    cal.mag_scale = Vector3f(r.y[0], r.y[4], r.y[8]);
    cal.mag_cross = Vector3f(r.y[1], r.y[2], r.y[5]);
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

// ---------------------------------------------------------------------------
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
