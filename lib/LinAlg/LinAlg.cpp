#include "LinAlg.h"

namespace linalg {

float fast_atan2(float y, float x) {
    const float abs_y = y < 0.0f ? -y : y;
    const float abs_x = x < 0.0f ? -x : x;
    if (!(abs_x > 0.0f || abs_y > 0.0f)) return 0.0f;  // (0, 0) and NaN
    // Fold into the first octant: t = min/max in [0, 1].
    const bool steep = abs_y > abs_x;
    const float t = steep ? abs_x / abs_y : abs_y / abs_x;
    if (!is_finite(t)) return 0.0f;
    const float t2 = t * t;
    // Odd minimax polynomial, |error| <= 1.15e-5 rad on [0, 1].
    float a = t * (0.99986631f +
                   t2 * (-0.33030486f + t2 * (0.18015960f + t2 * (-0.08515681f + t2 * 0.02084534f))));
    if (steep) a = 0.5f * kPi - a;
    if (x < 0.0f) a = kPi - a;
    return y < 0.0f ? -a : a;
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

}  // namespace linalg
