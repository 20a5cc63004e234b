// SPDX-License-Identifier: GPL-3.0-or-later
// LinAlg against hand-computed values, degenerate inputs included.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "Bytes.h"
#include "LinAlg.h"
#include "ScoreMetric.h"

using linalg::Matrix3f;
using linalg::Vector3f;

static void expect_vec(const Vector3f& v, float x, float y, float z, float tol = 1e-6f) {
    EXPECT_NEAR(v.x, x, tol);
    EXPECT_NEAR(v.y, y, tol);
    EXPECT_NEAR(v.z, z, tol);
}

TEST(Vector3f, ArithmeticMatchesHandValues) {
    const Vector3f a(1.0f, 2.0f, 3.0f), b(-4.0f, 0.5f, 2.0f);
    expect_vec(a + b, -3.0f, 2.5f, 5.0f);
    expect_vec(a - b, 5.0f, 1.5f, 1.0f);
    expect_vec(a * 2.0f, 2.0f, 4.0f, 6.0f);
    expect_vec(2.0f * a, 2.0f, 4.0f, 6.0f);
    expect_vec(-a, -1.0f, -2.0f, -3.0f);
    EXPECT_FLOAT_EQ(a.dot(b), -4.0f + 1.0f + 6.0f);
    // (2*2 - 3*0.5, 3*-4 - 1*2, 1*0.5 - 2*-4)
    expect_vec(a.cross(b), 2.5f, -14.0f, 8.5f);
    EXPECT_FLOAT_EQ(a.length_squared(), 14.0f);
    EXPECT_FLOAT_EQ(Vector3f(3.0f, 4.0f, 12.0f).length(), 13.0f);
    Vector3f c = a;
    c += b;
    expect_vec(c, -3.0f, 2.5f, 5.0f);
    c -= b;
    expect_vec(c, 1.0f, 2.0f, 3.0f);
    c *= -1.0f;
    expect_vec(c, -1.0f, -2.0f, -3.0f);
}

TEST(Vector3f, CrossOfBasisIsRightHanded) {
    expect_vec(Vector3f(1, 0, 0).cross(Vector3f(0, 1, 0)), 0, 0, 1);
    expect_vec(Vector3f(0, 1, 0).cross(Vector3f(0, 0, 1)), 1, 0, 0);
    expect_vec(Vector3f(0, 0, 1).cross(Vector3f(1, 0, 0)), 0, 1, 0);
}

TEST(Vector3f, NormaliseGivesUnitLength) {
    expect_vec(Vector3f(3.0f, 0.0f, 4.0f).normalized(), 0.6f, 0.0f, 0.8f);
    Vector3f v(0.0f, -2.0f, 0.0f);
    EXPECT_TRUE(v.normalize());
    expect_vec(v, 0.0f, -1.0f, 0.0f);
}

TEST(Vector3f, NormaliseOfDegenerateVectorsIsZeroNotNaN) {
    Vector3f zero;
    EXPECT_FALSE(zero.normalize());
    EXPECT_TRUE(zero.is_zero());
    EXPECT_TRUE(Vector3f(1e-20f, 0.0f, 0.0f).normalized().is_zero());
    EXPECT_TRUE(Vector3f(NAN, 1.0f, 0.0f).normalized().is_zero());
    EXPECT_TRUE(Vector3f(INFINITY, 1.0f, 0.0f).normalized().is_zero());
    // Huge but finite still has a direction (length squared overflows float).
    const Vector3f huge = Vector3f(1e30f, 0.0f, 0.0f).normalized();
    EXPECT_TRUE(huge.is_finite());
    EXPECT_EQ(huge.length_squared() == 0.0f || std::fabs(huge.length() - 1.0f) < 1e-6f, true);
    EXPECT_FALSE(Vector3f(NAN, 0, 0).is_finite());
    EXPECT_TRUE(Vector3f(1, 2, 3).is_finite());
}

TEST(Matrix3f, ProductsTransposeAndDeterminant) {
    const Matrix3f m(Vector3f(1, 2, 3), Vector3f(4, 5, 6), Vector3f(7, 8, 10));
    const Vector3f v(1, -1, 2);
    expect_vec(m * v, 1 - 2 + 6, 4 - 5 + 12, 7 - 8 + 20);
    // M^T v = column sums weighted by v.
    expect_vec(m.mul_transpose(v), 1 - 4 + 14, 2 - 5 + 16, 3 - 6 + 20);
    const Matrix3f t = m.transposed();
    expect_vec(t.a, 1, 4, 7);
    expect_vec(t.b, 2, 5, 8);
    expect_vec(t.c, 3, 6, 10);
    const Matrix3f n(Vector3f(0, 1, 0), Vector3f(2, 0, 1), Vector3f(1, 1, 1));
    const Matrix3f mn = m * n;
    // Row 1 of M N: 1*(0,1,0) + 2*(2,0,1) + 3*(1,1,1) = (7, 4, 5)
    expect_vec(mn.a, 7, 4, 5);
    expect_vec(mn.b, 4 * 0 + 5 * 2 + 6, 4 + 6, 5 + 6);
    expect_vec(mn.c, 16 + 10, 7 + 10, 8 + 10);
    EXPECT_FLOAT_EQ(m.determinant(), -3.0f);
    const Matrix3f s = m + n - n * 2.0f;
    expect_vec(s.b, 2, 5, 5);  // m - n
    EXPECT_FLOAT_EQ(Matrix3f::identity().determinant(), 1.0f);
    EXPECT_FLOAT_EQ(Matrix3f::zero().determinant(), 0.0f);
    expect_vec(m.col_y(), 2, 5, 8);
}

TEST(Matrix3f, SkewIsTheCrossProduct) {
    const Vector3f w(0.3f, -1.2f, 2.0f), u(1.5f, 0.25f, -0.75f);
    const Vector3f a = Matrix3f::skew(w) * u, b = w.cross(u);
    expect_vec(a, b.x, b.y, b.z);
}

TEST(Scalar, SafeFunctionsNeverReturnNaN) {
    EXPECT_FLOAT_EQ(linalg::safe_asin(2.0f), linalg::kPi / 2);
    EXPECT_FLOAT_EQ(linalg::safe_asin(-1.0000001f), -linalg::kPi / 2);
    EXPECT_EQ(linalg::safe_asin(NAN), 0.0f);
    EXPECT_EQ(linalg::safe_sqrt(-1.0f), 0.0f);
    EXPECT_EQ(linalg::safe_sqrt(NAN), 0.0f);
    EXPECT_FLOAT_EQ(linalg::safe_sqrt(9.0f), 3.0f);
    EXPECT_EQ(linalg::constrain(NAN, -1.0f, 1.0f), -1.0f);
    EXPECT_EQ(linalg::constrain(5.0f, -1.0f, 1.0f), 1.0f);
    EXPECT_FALSE(linalg::is_finite(INFINITY));
    EXPECT_FALSE(linalg::is_finite(NAN));
    EXPECT_TRUE(linalg::is_finite(-3.0e38f));
}

TEST(Scalar, FastAtan2WithinItsStatedError) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    float worst = 0.0f;
    for (int i = 0; i < 200000; ++i) {
        const float y = u(rng), x = u(rng);
        const float err = std::fabs(linalg::fast_atan2(y, x) - std::atan2(y, x));
        worst = err > worst ? err : worst;
    }
    EXPECT_LT(worst, 1.3e-5f);
    // The axes, exactly.
    EXPECT_FLOAT_EQ(linalg::fast_atan2(0.0f, 1.0f), 0.0f);
    EXPECT_NEAR(linalg::fast_atan2(1.0f, 0.0f), linalg::kPi / 2, 2e-5f);
    EXPECT_NEAR(linalg::fast_atan2(0.0f, -1.0f), linalg::kPi, 1e-6f);
    EXPECT_NEAR(linalg::fast_atan2(-1.0f, 0.0f), -linalg::kPi / 2, 2e-5f);
    EXPECT_EQ(linalg::fast_atan2(0.0f, 0.0f), 0.0f);
    EXPECT_EQ(linalg::fast_atan2(NAN, 1.0f), 0.0f);
    EXPECT_NEAR(linalg::fast_atan2(1e30f, 1e-30f), linalg::kPi / 2, 2e-5f);
}

TEST(Scalar, FastAtanIsFastAtan2OverOne) {
    // The same polynomial: within 1 ulp of fast_atan2(x, 1) (the fold's 1 / |x| against
    // 1 / |x| over 1), either side of 1 and far out.
    for (float x = -40.0f; x <= 40.0f; x += 0.0137f) {
        const float want = linalg::fast_atan2(x, 1.0f);
        EXPECT_NEAR(linalg::fast_atan(x), want, 2e-7f * (1.0f + std::fabs(want))) << x;
    }
    EXPECT_EQ(linalg::fast_atan(0.0f), 0.0f);
    EXPECT_FLOAT_EQ(linalg::fast_atan(1.0f), linalg::fast_atan2(1.0f, 1.0f));
    EXPECT_NEAR(linalg::fast_atan(INFINITY), linalg::kPi / 2, 1e-6f);
    EXPECT_NEAR(linalg::fast_atan(-1e30f), -linalg::kPi / 2, 1e-6f);
    EXPECT_EQ(linalg::fast_atan(NAN), 0.0f);
}

TEST(Bytes, BigEndianInt16AndSaturation) {
    EXPECT_EQ(linalg::int16_from_be(0x12, 0x34), 0x1234);
    EXPECT_EQ(linalg::int16_from_be(0xFF, 0xFE), -2);
    EXPECT_EQ(linalg::int16_from_be(0x80, 0x00), -32768);
    EXPECT_EQ(linalg::int16_from_be(0x7F, 0xFF), 32767);
    EXPECT_EQ(linalg::high_byte(-2), 0xFF);
    EXPECT_EQ(linalg::low_byte(-2), 0xFE);
    EXPECT_EQ(linalg::saturate_int16(1e9f), 32767);
    EXPECT_EQ(linalg::saturate_int16(-1e9f), -32768);
    EXPECT_EQ(linalg::saturate_int16(NAN), 0);
    EXPECT_EQ(linalg::saturate_int16(2.5f), 3);
    EXPECT_EQ(linalg::saturate_int16(-2.5f), -3);
}

// quat_from_rotation: checked against sim/ScoreMetric.h's Euler quaternion (double,
// independent code) and by rotating vectors with the quaternion.

namespace {

// R = Rz(yaw) Ry(pitch) Rx(roll), body -> earth (APM25.md).
linalg::Matrix3f matrix_from_euler_deg(float roll, float pitch, float yaw) {
    const float r = roll * linalg::kRadPerDeg, p = pitch * linalg::kRadPerDeg, y = yaw * linalg::kRadPerDeg;
    const float cr = std::cos(r), sr = std::sin(r), cp = std::cos(p), sp = std::sin(p), cy = std::cos(y),
                sy = std::sin(y);
    return linalg::Matrix3f(linalg::Vector3f(cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
                            linalg::Vector3f(sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
                            linalg::Vector3f(-sp, cp * sr, cp * cr));
}

// v' = q v q*
linalg::Vector3f rotate(const linalg::Quaternion& q, const linalg::Vector3f& v) {
    const linalg::Vector3f u(q.x, q.y, q.z);
    const linalg::Vector3f t = u.cross(v) * 2.0f;
    return v + t * q.w + u.cross(t);
}

}  // namespace

TEST(LinAlg, QuatFromRotationMatchesEulerQuaternionsEverywhere) {
    // Every branch of Shepperd's method: near identity, and 180-degree turns about x, y, z
    // (trace -1, one diagonal element +1).
    const float cases[][3] = {{0, 0, 0},     {10, -20, 30},  {180, 0, 0},  {0, 0, 180},  {179, 1, 90},
                              {0, 89.9f, 0}, {-90, 45, 270}, {170, -5, 10}, {0, 180, 0}, {-179.5f, -30, 359}};
    for (const auto& c : cases) {
        const linalg::Quaternion q = linalg::quat_from_rotation(matrix_from_euler_deg(c[0], c[1], c[2]));
        score::Quat e = score::quat_from_euler_deg(c[0], c[1], c[2]);
        if (e.w < 0.0) e = score::Quat{-e.w, -e.x, -e.y, -e.z};
        const double dot = q.w * e.w + q.x * e.x + q.y * e.y + q.z * e.z;
        EXPECT_NEAR(std::fabs(dot), 1.0, 1e-6) << c[0] << " " << c[1] << " " << c[2];
        EXPECT_GE(q.w, 0.0f);
        EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0f, 1e-6f);
    }
}

TEST(LinAlg, QuatFromRotationRotatesVectorsAsTheMatrixDoes) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int i = 0; i < 500; ++i) {
        const linalg::Matrix3f m = matrix_from_euler_deg(180.0f * u(rng), 90.0f * u(rng), 180.0f * u(rng));
        const linalg::Quaternion q = linalg::quat_from_rotation(m);
        const linalg::Vector3f v(u(rng), u(rng), u(rng));
        const linalg::Vector3f a = m * v, b = rotate(q, v);
        EXPECT_NEAR(a.x, b.x, 2e-6f);
        EXPECT_NEAR(a.y, b.y, 2e-6f);
        EXPECT_NEAR(a.z, b.z, 2e-6f);
    }
}

TEST(LinAlg, QuatFromRotationIsUnitForAScaledMatrixAndIdentityForNaN) {
    const linalg::Quaternion q = linalg::quat_from_rotation(matrix_from_euler_deg(30, 20, 10) * 1.001f);
    EXPECT_NEAR(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z, 1.0f, 1e-6f);
    linalg::Matrix3f bad;
    bad.b.y = std::nanf("");
    const linalg::Quaternion i = linalg::quat_from_rotation(bad);
    EXPECT_EQ(i.w, 1.0f);
    EXPECT_EQ(i.x, 0.0f);
    EXPECT_EQ(i.y, 0.0f);
    EXPECT_EQ(i.z, 0.0f);
}

TEST(LinAlg, QuatTurnedAboutDownAddsTheDeclinationToTheHeading) {
    // A board at roll 10, pitch -20, magnetic heading 30; declination +12 (east): the
    // true-north quaternion is the one of heading 42 with the same roll and pitch.
    const linalg::Quaternion q = linalg::quat_from_rotation(matrix_from_euler_deg(10, -20, 30));
    const float half = 0.5f * 12.0f * linalg::kRadPerDeg;
    const linalg::Quaternion t = linalg::quat_turned_about_down(q, std::cos(half), std::sin(half));
    const linalg::Quaternion want = linalg::quat_from_rotation(matrix_from_euler_deg(10, -20, 42));
    EXPECT_NEAR(std::fabs(t.w * want.w + t.x * want.x + t.y * want.y + t.z * want.z), 1.0f, 1e-6f);
}
