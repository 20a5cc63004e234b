// SPDX-License-Identifier: GPL-3.0-or-later
#include "LinAlg.h"

namespace linalg {

namespace {

// atan on [0, 1]: odd minimax polynomial, |error| <= 1.15e-5 rad.
float atan_unit(float t) {
    const float t2 = t * t;
    return t * (0.99986631f + t2 * (-0.33030486f + t2 * (0.18015960f + t2 * (-0.08515681f + t2 * 0.02084534f))));
}

}  // namespace

float fast_atan2(float y, float x) {
    const float abs_y = y < 0.0f ? -y : y;
    const float abs_x = x < 0.0f ? -x : x;
    if (!(abs_x > 0.0f || abs_y > 0.0f)) return 0.0f;  // (0, 0) and NaN
    // Fold into the first octant: t = min/max in [0, 1].
    const bool steep = abs_y > abs_x;
    const float t = steep ? abs_x / abs_y : abs_y / abs_x;
    if (!is_finite(t)) return 0.0f;
    float a = atan_unit(t);
    if (steep) a = 0.5f * kPi - a;
    if (x < 0.0f) a = kPi - a;
    return y < 0.0f ? -a : a;
}

float fast_atan(float x) {
    const float abs_x = x < 0.0f ? -x : x;
    float a;
    if (abs_x <= 1.0f) {
        a = atan_unit(abs_x);  // no divide
    } else if (abs_x > 1.0f) {
        a = 0.5f * kPi - atan_unit(1.0f / abs_x);
    } else {
        return 0.0f;  // NaN
    }
    return x < 0.0f ? -a : a;
}

Vector3f Vector3f::operator+(const Vector3f& v) const { return Vector3f(x + v.x, y + v.y, z + v.z); }
Vector3f Vector3f::operator-(const Vector3f& v) const { return Vector3f(x - v.x, y - v.y, z - v.z); }
Vector3f Vector3f::operator-() const { return Vector3f(-x, -y, -z); }
Vector3f Vector3f::operator*(float s) const { return Vector3f(x * s, y * s, z * s); }
Vector3f& Vector3f::operator+=(const Vector3f& v) {
    x += v.x;
    y += v.y;
    z += v.z;
    return *this;
}
Vector3f& Vector3f::operator-=(const Vector3f& v) {
    x -= v.x;
    y -= v.y;
    z -= v.z;
    return *this;
}
Vector3f& Vector3f::operator*=(float s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
}
float Vector3f::dot(const Vector3f& v) const { return x * v.x + y * v.y + z * v.z; }
Vector3f Vector3f::cross(const Vector3f& v) const {
    return Vector3f(y * v.z - z * v.y, z * v.x - x * v.z, x * v.y - y * v.x);
}
bool Vector3f::is_finite() const { return linalg::is_finite(x) && linalg::is_finite(y) && linalg::is_finite(z); }
Vector3f Vector3f::normalized() const {
    const float len_sq = length_squared();
    if (!(len_sq > 1e-30f) || !linalg::is_finite(len_sq)) return Vector3f();
    return *this * (1.0f / sqrtf(len_sq));
}

Vector3f Matrix3f::operator*(const Vector3f& v) const { return Vector3f(a.dot(v), b.dot(v), c.dot(v)); }
Vector3f Matrix3f::mul_transpose(const Vector3f& v) const { return a * v.x + b * v.y + c * v.z; }

Quaternion quat_from_rotation(const Matrix3f& m) {
    const float trace = m.a.x + m.b.y + m.c.z;
    // 4 q_i^2 for each component: the largest has the best-conditioned square root.
    float q[4];
    if (trace >= m.a.x && trace >= m.b.y && trace >= m.c.z) {
        const float s = 2.0f * safe_sqrt(1.0f + trace);  // 4 w
        const float inv = s > 0.0f ? 1.0f / s : 0.0f;
        q[0] = 0.25f * s;
        q[1] = (m.c.y - m.b.z) * inv;
        q[2] = (m.a.z - m.c.x) * inv;
        q[3] = (m.b.x - m.a.y) * inv;
    } else if (m.a.x >= m.b.y && m.a.x >= m.c.z) {
        const float s = 2.0f * safe_sqrt(1.0f + m.a.x - m.b.y - m.c.z);  // 4 x
        const float inv = s > 0.0f ? 1.0f / s : 0.0f;
        q[0] = (m.c.y - m.b.z) * inv;
        q[1] = 0.25f * s;
        q[2] = (m.a.y + m.b.x) * inv;
        q[3] = (m.a.z + m.c.x) * inv;
    } else if (m.b.y >= m.c.z) {
        const float s = 2.0f * safe_sqrt(1.0f - m.a.x + m.b.y - m.c.z);  // 4 y
        const float inv = s > 0.0f ? 1.0f / s : 0.0f;
        q[0] = (m.a.z - m.c.x) * inv;
        q[1] = (m.a.y + m.b.x) * inv;
        q[2] = 0.25f * s;
        q[3] = (m.b.z + m.c.y) * inv;
    } else {
        const float s = 2.0f * safe_sqrt(1.0f - m.a.x - m.b.y + m.c.z);  // 4 z
        const float inv = s > 0.0f ? 1.0f / s : 0.0f;
        q[0] = (m.b.x - m.a.y) * inv;
        q[1] = (m.a.z + m.c.x) * inv;
        q[2] = (m.b.z + m.c.y) * inv;
        q[3] = 0.25f * s;
    }
    const float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    if (!(n2 > 0.0f) || !is_finite(n2)) return Quaternion{1.0f, 0.0f, 0.0f, 0.0f};
    float inv_n = 1.0f / sqrtf(n2);
    if (q[0] < 0.0f) inv_n = -inv_n;  // w >= 0
    return Quaternion{q[0] * inv_n, q[1] * inv_n, q[2] * inv_n, q[3] * inv_n};
}

Quaternion quat_turned_about_down(const Quaternion& q, float cos_half, float sin_half) {
    // (c, 0, 0, s) * (w, x, y, z), Hamilton product.
    return Quaternion{cos_half * q.w - sin_half * q.z, cos_half * q.x - sin_half * q.y,
                      cos_half * q.y + sin_half * q.x, cos_half * q.z + sin_half * q.w};
}

}  // namespace linalg
