#include "Euler.h"

#include "Fixed.h"

// -O2 here (the build is -Os), as in Fixed.cpp: ~100 cycles less per output line.
#ifdef __AVR__
#pragma GCC optimize("O2")
#endif

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {

// kGimbalLockCos in Q30.
constexpr uint32_t kGimbalLockCosQ30 = (uint32_t)(kGimbalLockCos * 1073741824.0f);

}  // namespace

EulerAngles euler_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32,
                           int32_t r33) {
    using linalg::atan2_q24;
    using linalg::magnitude;
    // Roll and cos(pitch) share one ratio, min/max of |R32| and |R33|.
    const uint32_t m32 = magnitude(r32), m33 = magnitude(r33);
    uint32_t ratio_q31;
    int32_t roll = atan2_q24(r32 < 0, m32, r33 < 0, m33, &ratio_q31);
    // cos(theta) = sqrt(R32^2 + R33^2): pitch by atan2 is accurate near +-90 deg,
    // where asin(R31) loses all its digits.
    const uint32_t cos_pitch_q30 = linalg::hypot_from_ratio(m32 > m33 ? m32 : m33, ratio_q31);
    const int32_t pitch = atan2_q24(r31 > 0, magnitude(r31), false, cos_pitch_q30);
    int32_t yaw;
    if (cos_pitch_q30 > kGimbalLockCosQ30) {
        yaw = atan2_q24(r21 < 0, magnitude(r21), r11 < 0, magnitude(r11));
    } else {
        // Gimbal lock: roll := 0, all of the heading in yaw. With phi = 0,
        // R12 = -sin(psi) and R22 = cos(psi) exactly.
        roll = 0;
        yaw = atan2_q24(r12 > 0, magnitude(r12), r22 < 0, magnitude(r22));
    }
    EulerAngles e;
    e.roll_rad = linalg::float_from_fixed(roll, linalg::kAngleQ);
    e.pitch_rad = linalg::float_from_fixed(pitch, linalg::kAngleQ);
    e.yaw_rad = linalg::float_from_fixed(yaw, linalg::kAngleQ);
    return e;
}

namespace {

FIXED_INLINE int32_t q30(float entry) { return linalg::fixed_from_float(entry, linalg::kQ30); }

// A Q30 entry rounded to its top 16 bits (Q14) for the first-order terms: moves a
// term by 2^-15 * |theta|, ~3e-7 at the output's typical theta (0.01 rad).
// (In unsigned arithmetic: the rounding add wraps for an entry saturated at 2^31 - 1,
// a garbage matrix, instead of overflowing.)
FIXED_INLINE int16_t q14(int32_t e_q30) { return (int16_t)(uint16_t)(((uint32_t)e_q30 + 0x8000u) >> 16); }

// theta in int16: Q17 covers +-0.25 rad in steps of 7.6e-6 rad; below 2^-10 rad
// (0.33 rad/s over the 3 ms lead: a slow turn, a board at rest) Q25 steps of 3e-8 rad.
// The step is a rotation error, which roll and yaw divide by cos(pitch): near +-90 deg
// pitch the fine step keeps them within a count.
struct Theta {
    int16_t x, y, z;
    bool fine;  // Q25, else Q17
};

// p*tp - q*tq (Q14 * theta) in Q30: Q31 >> 1 for a Q17 theta, Q39 >> 9 for Q25 (a
// byte shift first: a whole byte is register moves on the AVR).
FIXED_INLINE int32_t cross_term(const Theta& t, int16_t p, int16_t tp, int16_t q, int16_t tq) {
    int32_t pp = linalg::mul_s16(p, tp), qq = linalg::mul_s16(q, tq);
    if (t.fine) {
        pp >>= 8;
        qq >>= 8;
    }
    return (pp >> 1) - (qq >> 1);
}
// e + the cross term, in unsigned arithmetic: a matrix far from a rotation (|entry|
// near 2) wraps instead of overflowing (its angles are garbage but finite; a
// rotation's entries stay below 1.1 here).
FIXED_INLINE int32_t plus_cross(int32_t e, const Theta& t, int16_t p, int16_t tp, int16_t q, int16_t tq) {
    return (int32_t)((uint32_t)e + (uint32_t)cross_term(t, p, tp, q, tq));
}

// One conversion per axis (Q26), rounded to Q25, or when any axis is past the fine
// range to Q17 (a byte and a bit further right), saturated at +-0.25 rad.
FIXED_INLINE int16_t round_shift(int32_t q26, uint8_t right) {
    // Limited to +-2^30 first (32 rad, far past the saturation) so that the rounding
    // add cannot overflow.
    constexpr int32_t kLimit = (int32_t)1 << 30;
    q26 = q26 > kLimit ? kLimit : q26 < -kLimit ? -kLimit : q26;
    const int32_t r = (q26 + ((int32_t)1 << (right - 1u))) >> right;
    return (int16_t)(r > 32767 ? 32767 : r < -32767 ? -32767 : r);
}
Theta theta_for(const Vector3f& theta_rad) {
    const int32_t x = linalg::fixed_from_float(theta_rad.x, 26), y = linalg::fixed_from_float(theta_rad.y, 26),
                  z = linalg::fixed_from_float(theta_rad.z, 26);
    constexpr int32_t kFineLimitQ26 = (int32_t)32767 << 1;  // 2^-10 rad
    if (x > -kFineLimitQ26 && x < kFineLimitQ26 && y > -kFineLimitQ26 && y < kFineLimitQ26 &&
        z > -kFineLimitQ26 && z < kFineLimitQ26)
        return Theta{round_shift(x, 1), round_shift(y, 1), round_shift(z, 1), true};
    return Theta{round_shift(x, 9), round_shift(y, 9), round_shift(z, 9), false};
}

}  // namespace

EulerAngles euler_from_dcm(const Matrix3f& r) {
    return euler_from_entries(r.a.x, r.a.y, r.b.x, r.b.y, r.c.x, r.c.y, r.c.z);
}

EulerAngles euler_from_entries(float r11, float r12, float r21, float r22, float r31, float r32, float r33) {
    return euler_from_q30(q30(r11), q30(r12), q30(r21), q30(r22), q30(r31), q30(r32), q30(r33));
}

EulerAngles euler_carried(const Matrix3f& r, const Vector3f& theta_rad) {
    const Theta t = theta_for(theta_rad);
    const int32_t a[3] = {q30(r.a.x), q30(r.a.y), q30(r.a.z)};
    const int32_t b[3] = {q30(r.b.x), q30(r.b.y), q30(r.b.z)};
    const int32_t c[3] = {q30(r.c.x), q30(r.c.y), q30(r.c.z)};
    // r' = r + r x theta = r + (r_y t_z - r_z t_y, r_z t_x - r_x t_z, r_x t_y - r_y t_x),
    // the seven entries the angles read.
    return euler_from_q30(plus_cross(a[0], t, q14(a[1]), t.z, q14(a[2]), t.y),   // R11
                          plus_cross(a[1], t, q14(a[2]), t.x, q14(a[0]), t.z),   // R12
                          plus_cross(b[0], t, q14(b[1]), t.z, q14(b[2]), t.y),   // R21
                          plus_cross(b[1], t, q14(b[2]), t.x, q14(b[0]), t.z),   // R22
                          plus_cross(c[0], t, q14(c[1]), t.z, q14(c[2]), t.y),   // R31
                          plus_cross(c[1], t, q14(c[2]), t.x, q14(c[0]), t.z),   // R32
                          plus_cross(c[2], t, q14(c[0]), t.y, q14(c[1]), t.x));  // R33
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
