// SPDX-License-Identifier: GPL-3.0-or-later
#include "Euler.h"

#include "Fixed.h"

// -O2 here (the build is -Os): the output path (Fixed.h's routines inline into
// euler_carried_q24 and angles_centideg) is shorter than at -Os (make bench).
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
// Yaw from R21 and R11, or at the gimbal lock from R12 and R22 (roll := 0, all of the
// heading in yaw: with phi = 0, R12 = -sin(psi) and R22 = cos(psi) exactly). One
// inline copy of atan2: the operands are chosen first.
FIXED_INLINE int32_t yaw(bool away_from_lock, int32_t r11, int32_t r12, int32_t r21, int32_t r22) {
    const int32_t y = away_from_lock ? r21 : r12, x = away_from_lock ? r11 : r22;
    const bool y_negative = away_from_lock ? y < 0 : y > 0;
    return atan2_q24(y_negative, magnitude(y), x < 0, magnitude(x));
}

}  // namespace

EulerQ24 euler_q24_from_q30(int32_t r11, int32_t r12, int32_t r21, int32_t r22, int32_t r31, int32_t r32,
                            int32_t r33) {
    EulerQ24 e;
    e.yaw_q24 = yaw(roll_pitch(r31, r32, r33, e), r11, r12, r21, r22);
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

// The entries rounded to their top 16 bits (linalg::q14_of) for the first-order terms:
// a term moves by 2^-15 * |theta|, ~3e-7 at the output's typical theta (0.01 rad).
using linalg::q14_of;

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
        pp = linalg::opaque(pp >> 8);
        qq = linalg::opaque(qq >> 8);
    }
    return (pp >> 1) - (qq >> 1);
}
// e + the cross term, in unsigned arithmetic: a matrix far from a rotation (|entry|
// near 2) wraps instead of overflowing (its angles are garbage but finite; a
// rotation's entries stay below 1.1 here).
FIXED_INLINE int32_t plus_cross(int32_t e, const Theta& t, int16_t p, int16_t tp, int16_t q, int16_t tq) {
    return (int32_t)((uint32_t)e + (uint32_t)cross_term(t, p, tp, q, tq));
}

// e + p tp - q tq for three Q30 entries of a row.
FIXED_INLINE int32_t carried_entry(const Theta& t, int32_t e, int32_t p, int16_t tp, int32_t q, int16_t tq) {
    return plus_cross(e, t, q14_of(p), tp, q14_of(q), tq);
}

// One conversion per axis (Q26): rounded to Q25 when all three are within 2^-10 rad,
// else to Q17 (a byte and a bit further right) and saturated at +-0.25 rad.
constexpr int32_t kFineLimitQ26 = (int32_t)32767 << 1;  // 2^-10 rad
FIXED_INLINE bool fine(int32_t q26) { return q26 > -kFineLimitQ26 && q26 < kFineLimitQ26; }
FIXED_INLINE int16_t q25_from_q26(int32_t q26) { return (int16_t)((q26 + 1) >> 1); }  // |q26| < 2^16 - 2
FIXED_INLINE int16_t q17_from_q26(int32_t q26) {
    // round(q26 / 2^9) beyond +-32767 from here (whatever q26: no add that overflows).
    constexpr int32_t kSaturationQ26 = (int32_t)32767 * 512 + 256;
    if (q26 >= kSaturationQ26) return 32767;
    if (q26 < -kSaturationQ26) return -32767;
    return (int16_t)(linalg::opaque((q26 + 256) >> 1) >> 8);
}
FIXED_INLINE Theta theta_for(int32_t x, int32_t y, int32_t z) {
    if (fine(x) && fine(y) && fine(z)) return Theta{q25_from_q26(x), q25_from_q26(y), q25_from_q26(z), true};
    return Theta{q17_from_q26(x), q17_from_q26(y), q17_from_q26(z), false};
}

}  // namespace

EulerAngles euler_from_dcm(const Matrix3f& r) {
    return euler_from_entries(r.a.x, r.a.y, r.b.x, r.b.y, r.c.x, r.c.y, r.c.z);
}

EulerAngles euler_from_entries(float r11, float r12, float r21, float r22, float r31, float r32, float r33) {
    return euler_from_q30(q30(r11), q30(r12), q30(r21), q30(r22), q30(r31), q30(r32), q30(r33));
}

EulerQ24 euler_carried_q24(const linalg::Matrix3q30& r, int32_t theta_x_q26, int32_t theta_y_q26,
                           int32_t theta_z_q26) {
    const Theta t = theta_for(theta_x_q26, theta_y_q26, theta_z_q26);
    // r' = r + r x theta = r + (r_y t_z - r_z t_y, r_z t_x - r_x t_z, r_x t_y - r_y t_x),
    // only the entries the angles read: the third row, then R11 and R21, or at the
    // lock R12 and R22.
    const int32_t c0 = r.c.x, c1 = r.c.y, c2 = r.c.z;
    const int16_t c0h = q14_of(c0), c1h = q14_of(c1), c2h = q14_of(c2);
    EulerQ24 e;
    const bool away_from_lock = roll_pitch(plus_cross(c0, t, c1h, t.z, c2h, t.y),  // R31
                                           plus_cross(c1, t, c2h, t.x, c0h, t.z),  // R32
                                           plus_cross(c2, t, c0h, t.y, c1h, t.x),  // R33
                                           e);
    // Column 1 (R11 = r_x + r_y t_z - r_z t_y) of the first two rows, or at the lock
    // column 2 (R12 = r_y + r_z t_x - r_x t_z): the entries are chosen first, so that
    // each row is one inline copy.
    const int16_t tp = away_from_lock ? t.z : t.x, tq = away_from_lock ? t.y : t.z;
    const int32_t r_1 = away_from_lock ? carried_entry(t, r.a.x, r.a.y, tp, r.a.z, tq)
                                       : carried_entry(t, r.a.y, r.a.z, tp, r.a.x, tq);
    const int32_t r_2 = away_from_lock ? carried_entry(t, r.b.x, r.b.y, tp, r.b.z, tq)
                                       : carried_entry(t, r.b.y, r.b.z, tp, r.b.x, tq);
    e.yaw_q24 = yaw(away_from_lock, r_1, r_1, r_2, r_2);
    return e;
}

// One carried row (r + r x theta), all three entries.
static linalg::Vector3l carried_row(const Theta& t, const linalg::Vector3l& p) {
    return linalg::Vector3l(carried_entry(t, p.x, p.y, t.z, p.z, t.y), carried_entry(t, p.y, p.z, t.x, p.x, t.z),
                            carried_entry(t, p.z, p.x, t.y, p.y, t.x));
}
// Row p of R' times row j of T (Q14): entry (., j) of R' T^T, Q30.
static int32_t times_trim_row(const linalg::Vector3l& p, const int16_t* tj) {
    return linalg::hot::mul_q14(tj[0], p.x) + linalg::hot::mul_q14(tj[1], p.y) + linalg::hot::mul_q14(tj[2], p.z);
}

EulerQ24 euler_carried_trimmed_q24(const linalg::Matrix3q30& r, int32_t theta_x_q26, int32_t theta_y_q26,
                                   int32_t theta_z_q26, const int16_t trim_q14[3][3]) {
    const Theta t = theta_for(theta_x_q26, theta_y_q26, theta_z_q26);
    const linalg::Vector3l a = carried_row(t, r.a), b = carried_row(t, r.b), c = carried_row(t, r.c);
    // R' T^T: the entries the angles read (the third row, the first two columns of the
    // first two rows), then the one extraction with no further turn (one copy of it in
    // flash: this path adds 21 products, not another atan2).
    linalg::Matrix3q30 v;
    v.a = linalg::Vector3l(times_trim_row(a, trim_q14[0]), times_trim_row(a, trim_q14[1]), 0);
    v.b = linalg::Vector3l(times_trim_row(b, trim_q14[0]), times_trim_row(b, trim_q14[1]), 0);
    v.c = linalg::Vector3l(times_trim_row(c, trim_q14[0]), times_trim_row(c, trim_q14[1]), times_trim_row(c, trim_q14[2]));
    return euler_carried_q24(v, 0, 0, 0);
}

EulerQ24 euler_carried_q24(const Matrix3f& r, int32_t theta_x_q26, int32_t theta_y_q26, int32_t theta_z_q26) {
    return euler_carried_q24(linalg::q30_from_matrix(r), theta_x_q26, theta_y_q26, theta_z_q26);
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
    // folds, where fmodf would bring avr-libc's routine into the flash.
    float h = yaw_rad * linalg::kDegPerRad + declination_deg;
    if (h < 0.0f) h += 360.0f;
    if (h < 0.0f) h += 360.0f;
    if (h >= 360.0f) h -= 360.0f;
    // NaN, or beyond the documented ranges, or -1e-9 + 360 rounding to 360: 0.
    if (!(h >= 0.0f && h < 360.0f)) h = 0.0f;
    return h;
}

AnglesCentideg angles_centideg(const EulerQ24& e, int16_t declination_centideg) {
    return AnglesCentideg{linalg::centideg_from_q24(e.roll_q24), linalg::centideg_from_q24(e.pitch_q24),
                          heading_centideg(e.yaw_q24, declination_centideg)};
}

int32_t heading_centideg(int32_t yaw_q24, int16_t declination_centideg) {
    // -36000 <= h <= 36000 in the documented ranges: one fold each way.
    int32_t h = linalg::centideg_from_q24(yaw_q24) + declination_centideg;
    if (h < 0) h += 36000;
    if (h >= 36000) h -= 36000;
    return h;
}

}  // namespace dcm
