#include "Euler.h"

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;
using linalg::fast_atan2;

EulerAngles euler_from_dcm(const Matrix3f& r) {
    return euler_from_entries(r.a.x, r.a.y, r.b.x, r.b.y, r.c.x, r.c.y, r.c.z);
}

EulerAngles euler_from_entries(float r11, float r12, float r21, float r22, float r31, float r32, float r33) {
    EulerAngles e;
    // cos(theta) from the other two entries of the last row: pitch by atan2 is
    // accurate near +-90 deg, where asin(R31) loses all its digits.
    const float cos_pitch = linalg::safe_sqrt(r32 * r32 + r33 * r33);
    e.pitch_rad = fast_atan2(-r31, cos_pitch);
    if (cos_pitch > kGimbalLockCos) {
        e.roll_rad = fast_atan2(r32, r33);
        e.yaw_rad = fast_atan2(r21, r11);
    } else {
        // Gimbal lock: roll := 0, all of the heading in yaw. With phi = 0,
        // R12 = -sin(psi) and R22 = cos(psi) exactly.
        e.roll_rad = 0.0f;
        e.yaw_rad = fast_atan2(-r12, r22);
    }
    return e;
}

Matrix3f dcm_from_euler(float roll_rad, float pitch_rad, float yaw_rad) {
    const float cr = cosf(roll_rad), sr = sinf(roll_rad);
    const float cp = cosf(pitch_rad), sp = sinf(pitch_rad);
    const float cy = cosf(yaw_rad), sy = sinf(yaw_rad);
    // R = Rz(yaw) Ry(pitch) Rx(roll), body -> earth (NED).
    return Matrix3f(Vector3f(cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy),
                    Vector3f(cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy),
                    Vector3f(-sp, sr * cp, cr * cp));
}

float heading_deg(float yaw_rad, float declination_deg) {
    // yaw within +-180 deg and the declination within +-180 give -360 < h < 360: two
    // folds, where fmodf would cost ~300 B of AVR flash.
    float h = yaw_rad * linalg::kDegPerRad + declination_deg;
    if (h < 0.0f) h += 360.0f;
    if (h < 0.0f) h += 360.0f;
    if (h >= 360.0f) h -= 360.0f;
    // NaN, or beyond the documented ranges, or -1e-9 + 360 rounding to 360: 0.
    if (!(h >= 0.0f && h < 360.0f)) h = 0.0f;
    return h;
}

}  // namespace dcm
