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

using linalg::atan2_q24;
using linalg::magnitude;

// kGimbalLockCos in Q30.
constexpr uint32_t kGimbalLockCosQ30 = (uint32_t)(kGimbalLockCos * 1073741824.0f);

// Roll and pitch from the third row; false at the gimbal lock (roll is then 0 and yaw
// comes from R12 and R22, yaw_locked).
FIXED_INLINE bool roll_pitch(int32_t r31, int32_t r32, int32_t r33, EulerQ24& e) {
    // Roll and cos(pitch) share one ratio, min/max of |R32| and |R33|.
    const uint32_t m32 = magnitude(r32), m33 = magnitude(r33);
    uint32_t ratio_q31;
    e.roll_q24 = atan2_q24(r32 < 0, m32, r33 < 0, m33, &ratio_q31);
    // cos(theta) = sqrt(R32^2 + R33^2): pitch by atan2 is accurate near +-90 deg,
    // where asin(R31) loses all its digits.
    const uint32_t cos_pitch_q30 = linalg::hypot_from_ratio(m32 > m33 ? m32 : m33, ratio_q31);
    e.pitch_q24 = atan2_q24(r31 > 0, magnitude(r31), false, cos_pitch_q30);
    if (cos_pitch_q30 > kGimbalLockCosQ30) return true;
    e.roll_q24 = 0;
    return false;
}
FIXED_INLINE int32_t yaw_free(int32_t r11, int32_t r21) {
    return atan2_q24(r21 < 0, magnitude(r21), r11 < 0, magnitude(r11));
}
// Gimbal lock: roll := 0, all of the heading in yaw. With phi = 0, R12 = -sin(psi)
// and R22 = cos(psi) exactly.
FIXED_INLINE int32_t yaw_locked(int32_t r12, int32_t r22) {
    return atan2_q24(r12 > 0, magnitude(r12), r22 < 0, magnitude(r22));
}

}  // namespace

EulerQ24 euler_q24_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32,
                            int32_t r33) {
    EulerQ24 e;
    e.yaw_q24 = roll_pitch(r31, r32, r33, e) ? yaw_free(r11, r21) : yaw_locked(r12, r22);
    return e;
}

EulerAngles euler_in_rad(const EulerQ24& e) {
    EulerAngles a;
    a.roll_rad = linalg::float_from_fixed(e.roll_q24, linalg::kAngleQ);
    a.pitch_rad = linalg::float_from_fixed(e.pitch_q24, linalg::kAngleQ);
    a.yaw_rad = linalg::float_from_fixed(e.yaw_q24, linalg::kAngleQ);
    return a;
}

EulerAngles euler_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32,
                           int32_t r33) {
    return euler_in_rad(euler_q24_from_q30(r11, r12, r21, r22, r31, r32, r33));
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
FIXED_INLINE Theta theta_for(int32_t x, int32_t y, int32_t z) {
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

EulerQ24 euler_carried_q24(const Matrix3f& r, int32_t theta_x_q26, int32_t theta_y_q26, int32_t theta_z_q26) {
    const Theta t = theta_for(theta_x_q26, theta_y_q26, theta_z_q26);
    // r' = r + r x theta = r + (r_y t_z - r_z t_y, r_z t_x - r_x t_z, r_x t_y - r_y t_x),
    // only the entries the angles read: the third row, then R11 and R21, or at the
    // lock R12 and R22.
    const int32_t c0 = q30(r.c.x), c1 = q30(r.c.y), c2 = q30(r.c.z);
    const int16_t c0h = q14(c0), c1h = q14(c1), c2h = q14(c2);
    EulerQ24 e;
    const bool away_from_lock = roll_pitch(plus_cross(c0, t, c1h, t.z, c2h, t.y),   // R31
                                 plus_cross(c1, t, c2h, t.x, c0h, t.z),   // R32
                                 plus_cross(c2, t, c0h, t.y, c1h, t.x),   // R33
                                 e);
    const int32_t a0 = q30(r.a.x), a1 = q30(r.a.y), a2 = q30(r.a.z);
    const int32_t b0 = q30(r.b.x), b1 = q30(r.b.y), b2 = q30(r.b.z);
    if (away_from_lock) {
        e.yaw_q24 = yaw_free(plus_cross(a0, t, q14(a1), t.z, q14(a2), t.y),   // R11
                             plus_cross(b0, t, q14(b1), t.z, q14(b2), t.y));  // R21
    } else {
        e.yaw_q24 = yaw_locked(plus_cross(a1, t, q14(a2), t.x, q14(a0), t.z),   // R12
                               plus_cross(b1, t, q14(b2), t.x, q14(b0), t.z));  // R22
    }
    return e;
}

EulerAngles euler_carried(const Matrix3f& r, int32_t theta_x_q26, int32_t theta_y_q26, int32_t theta_z_q26) {
    return euler_in_rad(euler_carried_q24(r, theta_x_q26, theta_y_q26, theta_z_q26));
}

EulerAngles euler_carried(const Matrix3f& r, const Vector3f& theta_rad) {
    return euler_carried(r, linalg::fixed_from_float(theta_rad.x, 26), linalg::fixed_from_float(theta_rad.y, 26),
                         linalg::fixed_from_float(theta_rad.z, 26));
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

int32_t heading_centideg(int32_t yaw_q24, int16_t declination_centideg) {
    // -36000 <= h <= 36000 in the documented ranges: one fold each way.
    int32_t h = linalg::centideg_from_q24(yaw_q24) + declination_centideg;
    if (h < 0) h += 36000;
    if (h >= 36000) h -= 36000;
    return h;
}

}  // namespace dcm
