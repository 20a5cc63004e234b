// SPDX-License-Identifier: GPL-3.0-or-later
// LinAlg: small float value types for 3-vectors and 3x3 matrices.
//
// Plain C++11, no Arduino include: the same code builds for the host tests and the
// ATmega2560 (where float and double are both 32-bit; we use float everywhere so
// both targets compute the same thing). No heap, no virtuals, no exceptions.
//
// Matrix3f stores ROWS: m.a is row 1, m.b row 2, m.c row 3. For the DCM the rows are
// the earth axes (north, east, down) expressed in body coordinates, so
// m * v_body = v_earth and m.mul_transpose(v_earth) = v_body.
#pragma once

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "Constants.h"

namespace linalg {

// True if x is neither NaN nor infinite: the exponent bits are not all ones (IEEE
// 754 single, on the host and on the AVR alike). A bit test, not float arithmetic:
// a few instructions where x == x && x - x == 0 is two float calls.
inline bool is_finite(float x) {
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    return (bits & 0x7F800000u) != 0x7F800000u;
}

// Clamp x to [lo, hi]; a NaN becomes lo so that it never propagates.
inline float constrain(float x, float lo, float hi) {
    if (!(x >= lo)) return lo;
    if (x > hi) return hi;
    return x;
}

// asin defined for every input: |x| > 1 (rounding) is clamped, NaN gives 0.
inline float safe_asin(float x) {
    if (!is_finite(x)) return 0.0f;
    return asinf(constrain(x, -1.0f, 1.0f));
}

// sqrt defined for every input: negatives and NaN give 0.
inline float safe_sqrt(float x) { return (x > 0.0f && is_finite(x)) ? sqrtf(x) : 0.0f; }

// atan2 to within 1.2e-5 rad (0.0007 deg) for any finite input, cheaper than
// avr-libc's atan2f: one division and an odd degree-9 polynomial fitted (least maximum
// error) to atan on [0, 1], with the octant folded in by symmetry. atan2(0, 0) = 0; NaN
// in gives 0 out.
float fast_atan2(float y, float x);
// atan(x) with the same polynomial, for any x: fast_atan2(x, 1) without its divide when
// |x| <= 1 (a bank within 45 degrees from a_lat / g). NaN gives 0.
float fast_atan(float x);

// Operations are out of line (LinAlg.cpp): inlined, each float operation is a call
// with its own register shuffling, copied into every caller's flash.
struct Vector3f {
    float x, y, z;

    constexpr Vector3f() : x(0.0f), y(0.0f), z(0.0f) {}
    constexpr Vector3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

    Vector3f operator+(const Vector3f& v) const;
    Vector3f operator-(const Vector3f& v) const;
    Vector3f operator-() const;
    Vector3f operator*(float s) const;
    Vector3f& operator+=(const Vector3f& v);
    Vector3f& operator-=(const Vector3f& v);
    Vector3f& operator*=(float s);
    bool operator==(const Vector3f& v) const { return x == v.x && y == v.y && z == v.z; }

    float dot(const Vector3f& v) const;
    Vector3f cross(const Vector3f& v) const;
    float length_squared() const { return dot(*this); }
    float length() const { return safe_sqrt(length_squared()); }
    bool is_finite() const;
    bool is_zero() const { return x == 0.0f && y == 0.0f && z == 0.0f; }

    // Unit vector in the same direction; a zero, tiny or non-finite vector has no
    // direction and gives the zero vector (never NaN). Callers test is_zero().
    Vector3f normalized() const;
    // In-place form of normalized(); returns false (and leaves zero) when impossible.
    bool normalize() {
        *this = normalized();
        return !is_zero();
    }
};

inline Vector3f operator*(float s, const Vector3f& v) { return v * s; }

// The integer vectors' few-instruction members, forced inline on the AVR: out of line
// (avr-gcc at -Os does that for code used often), each call costs more than its work.
#ifdef __AVR__
#define LINALG_INLINE __attribute__((always_inline)) inline
#else
#define LINALG_INLINE inline
#endif

// Integer vectors for the estimator's 200 Hz path: a sensor's samples in its own
// counts, and their sums (a 32-bit add is a few instructions on the AVR, a float add a
// library call).
struct Vector3i {
    int16_t x, y, z;

    LINALG_INLINE constexpr Vector3i() : x(0), y(0), z(0) {}
    LINALG_INLINE constexpr Vector3i(int16_t x_, int16_t y_, int16_t z_) : x(x_), y(y_), z(z_) {}
};
struct Vector3l {
    int32_t x, y, z;

    LINALG_INLINE constexpr Vector3l() : x(0), y(0), z(0) {}
    LINALG_INLINE constexpr Vector3l(int32_t x_, int32_t y_, int32_t z_) : x(x_), y(y_), z(z_) {}

    LINALG_INLINE Vector3l& operator+=(const Vector3i& v) {
        x += v.x;
        y += v.y;
        z += v.z;
        return *this;
    }
    LINALG_INLINE Vector3l& operator+=(const Vector3l& v) {
        x += v.x;
        y += v.y;
        z += v.z;
        return *this;
    }
    LINALG_INLINE Vector3l& operator-=(const Vector3l& v) {
        x -= v.x;
        y -= v.y;
        z -= v.z;
        return *this;
    }
    LINALG_INLINE Vector3l operator+(const Vector3l& v) const { return Vector3l(x + v.x, y + v.y, z + v.z); }
    LINALG_INLINE Vector3l operator-(const Vector3l& v) const { return Vector3l(x - v.x, y - v.y, z - v.z); }
    Vector3f to_float() const { return Vector3f((float)x, (float)y, (float)z); }
    // The vector times a scale, in float (three conversions and three multiplies).
    Vector3f scaled(float s) const { return Vector3f((float)x * s, (float)y * s, (float)z * s); }
};
// A rotation matrix in fixed point, rows as in Matrix3f, each entry Q30 (2^30 = 1:
// steps of 9.3e-10, headroom to 2): the estimator's R, turned with the 2560's hardware
// multiplier (Fixed.h's mul_q30) instead of float calls.
struct Matrix3q30 {
    Vector3l a, b, c;  // rows
};

inline Vector3f scaled(const Vector3i& v, float s) { return Vector3f((float)v.x * s, (float)v.y * s, (float)v.z * s); }

struct Matrix3f {
    Vector3f a, b, c;  // rows

    constexpr Matrix3f() : a(1.0f, 0.0f, 0.0f), b(0.0f, 1.0f, 0.0f), c(0.0f, 0.0f, 1.0f) {}
    constexpr Matrix3f(const Vector3f& row1, const Vector3f& row2, const Vector3f& row3)
        : a(row1), b(row2), c(row3) {}

    static Matrix3f identity() { return Matrix3f(); }
    static Matrix3f zero() { return Matrix3f(Vector3f(), Vector3f(), Vector3f()); }
    // The matrix [v x] such that [v x] * u = v x u.
    static Matrix3f skew(const Vector3f& v) {
        return Matrix3f(Vector3f(0.0f, -v.z, v.y), Vector3f(v.z, 0.0f, -v.x), Vector3f(-v.y, v.x, 0.0f));
    }

    Vector3f col_x() const { return Vector3f(a.x, b.x, c.x); }
    Vector3f col_y() const { return Vector3f(a.y, b.y, c.y); }
    Vector3f col_z() const { return Vector3f(a.z, b.z, c.z); }

    Matrix3f operator+(const Matrix3f& m) const { return Matrix3f(a + m.a, b + m.b, c + m.c); }
    Matrix3f operator-(const Matrix3f& m) const { return Matrix3f(a - m.a, b - m.b, c - m.c); }
    Matrix3f operator*(float s) const { return Matrix3f(a * s, b * s, c * s); }

    // M v
    Vector3f operator*(const Vector3f& v) const;
    // M^T v, without forming the transpose (earth -> body for a DCM).
    Vector3f mul_transpose(const Vector3f& v) const;
    // M N
    Matrix3f operator*(const Matrix3f& n) const {
        return Matrix3f(n.mul_transpose(a), n.mul_transpose(b), n.mul_transpose(c));
    }
    Matrix3f transposed() const { return Matrix3f(col_x(), col_y(), col_z()); }
    float determinant() const { return a.dot(b.cross(c)); }
    bool is_finite() const { return a.is_finite() && b.is_finite() && c.is_finite(); }
};

// A rotation as a unit quaternion, scalar first (w, x, y, z), in the trajectory files'
// sense: it rotates body to earth, like the DCM it is made from.
struct Quaternion {
    float w, x, y, z;
};

// The quaternion of a rotation matrix m (body -> earth: m * v_body = v_earth), with
// w >= 0 (q and -q are one rotation). Shepperd's method: the square root is taken of
// the largest of 1 + trace and 1 + 2 m_ii - trace, so it never divides by a small
// number, whatever the attitude. The result is normalised (a DCM between
// renormalisations is orthonormal only to ~1e-6). Two sqrtf, two divisions and ~20
// multiplies, paid only in `mode quat`. A non-finite matrix gives the identity.
Quaternion quat_from_rotation(const Matrix3f& m);

// q turned about the earth's down axis by an angle a given as cos(a/2), sin(a/2)
// (computed once when the angle changes): qz(a) * q. The DCM's earth frame is magnetic
// north-east-down; a = the declination makes q's earth frame true north, as the heading
// in the angle lines is. 16 multiplies, no trigonometry.
Quaternion quat_turned_about_down(const Quaternion& q, float cos_half, float sin_half);

}  // namespace linalg
