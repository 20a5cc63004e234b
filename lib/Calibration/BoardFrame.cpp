// SPDX-License-Identifier: GPL-3.0-or-later
#include "BoardFrame.h"

#include <math.h>

#include "Fixed.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define ROTATION_TABLE PROGMEM
#define READ_ROTATION(p) pgm_read_word(p)
#else
#define ROTATION_TABLE
#define READ_ROTATION(p) (*(p))
#endif

namespace calib {

using linalg::Vector3f;
using linalg::Vector3i;

namespace {

// One rotation: out[i] = (neg_i ? -1 : 1) * in[src_i], then, with yaw45, a turn of +45 deg
// about z (x' = (x - y)/sqrt2, y' = (x + y)/sqrt2): ArduPilot's names are "roll, then
// pitch, then yaw", and every 45 deg one is Rz(45) times a signed permutation.
// Bits: src_x 0-1, src_y 2-3, src_z 4-5, neg x 6, neg y 7, neg z 8, yaw45 9.
constexpr uint16_t R(uint8_t sx, uint8_t sy, uint8_t sz, uint8_t nx, uint8_t ny, uint8_t nz, uint8_t yaw45) {
    return (uint16_t)(sx | sy << 2 | sz << 4 | nx << 6 | ny << 7 | nz << 8 | yaw45 << 9);
}
// Worked out from R = Rz(yaw) Ry(pitch) Rx(roll) of each name (test_board_frame.cpp
// checks every row against that matrix).
const uint16_t kRotations[kRotationCount] ROTATION_TABLE = {
    R(0, 1, 2, 0, 0, 0, 0),  //  0 NONE
    R(0, 1, 2, 0, 0, 0, 1),  //  1 YAW_45
    R(1, 0, 2, 1, 0, 0, 0),  //  2 YAW_90
    R(1, 0, 2, 1, 0, 0, 1),  //  3 YAW_135
    R(0, 1, 2, 1, 1, 0, 0),  //  4 YAW_180
    R(0, 1, 2, 1, 1, 0, 1),  //  5 YAW_225
    R(1, 0, 2, 0, 1, 0, 0),  //  6 YAW_270
    R(1, 0, 2, 0, 1, 0, 1),  //  7 YAW_315
    R(0, 1, 2, 0, 1, 1, 0),  //  8 ROLL_180
    R(0, 1, 2, 0, 1, 1, 1),  //  9 ROLL_180_YAW_45
    R(1, 0, 2, 0, 0, 1, 0),  // 10 ROLL_180_YAW_90
    R(1, 0, 2, 0, 0, 1, 1),  // 11 ROLL_180_YAW_135
    R(0, 1, 2, 1, 0, 1, 0),  // 12 PITCH_180
    R(0, 1, 2, 1, 0, 1, 1),  // 13 ROLL_180_YAW_225
    R(1, 0, 2, 1, 1, 1, 0),  // 14 ROLL_180_YAW_270
    R(1, 0, 2, 1, 1, 1, 1),  // 15 ROLL_180_YAW_315
    R(0, 2, 1, 0, 1, 0, 0),  // 16 ROLL_90
    R(0, 2, 1, 0, 1, 0, 1),  // 17 ROLL_90_YAW_45
    R(2, 0, 1, 0, 0, 0, 0),  // 18 ROLL_90_YAW_90
    R(2, 0, 1, 0, 0, 0, 1),  // 19 ROLL_90_YAW_135
    R(0, 2, 1, 0, 0, 1, 0),  // 20 ROLL_270
    R(0, 2, 1, 0, 0, 1, 1),  // 21 ROLL_270_YAW_45
    R(2, 0, 1, 1, 0, 1, 0),  // 22 ROLL_270_YAW_90
    R(2, 0, 1, 1, 0, 1, 1),  // 23 ROLL_270_YAW_135
    R(2, 1, 0, 0, 0, 1, 0),  // 24 PITCH_90
    R(2, 1, 0, 1, 0, 0, 0),  // 25 PITCH_270
    R(1, 0, 2, 1, 1, 1, 0),  // 26 PITCH_180_YAW_90
    R(1, 0, 2, 0, 0, 1, 0),  // 27 PITCH_180_YAW_270
    R(1, 2, 0, 0, 1, 1, 0),  // 28 ROLL_90_PITCH_90
    R(2, 1, 0, 1, 1, 1, 0),  // 29 ROLL_180_PITCH_90
    R(1, 2, 0, 1, 0, 1, 0),  // 30 ROLL_270_PITCH_90
    R(0, 2, 1, 1, 1, 1, 0),  // 31 ROLL_90_PITCH_180
    R(0, 2, 1, 1, 0, 0, 0),  // 32 ROLL_270_PITCH_180
    R(1, 2, 0, 1, 1, 0, 0),  // 33 ROLL_90_PITCH_270
    R(2, 1, 0, 0, 1, 0, 0),  // 34 ROLL_180_PITCH_270
    R(1, 2, 0, 0, 0, 0, 0),  // 35 ROLL_270_PITCH_270
    R(2, 0, 1, 0, 1, 1, 0),  // 36 ROLL_90_PITCH_180_YAW_90
    R(2, 0, 1, 1, 1, 0, 0),  // 37 ROLL_90_YAW_270
};
constexpr uint16_t kYaw45 = 1u << 9;
constexpr int16_t kHalfSqrt2Q15 = 23170;  // round(2^15 / sqrt(2))

// |x| <= limit (avr-libc's fabsf is a double function: no promotion here; NaN fails).
bool within(float x, float limit) { return x <= limit && x >= -limit; }
int16_t saturate(int32_t v) { return v > 32767 ? 32767 : (v < -32767 ? -32767 : (int16_t)v); }
int16_t negate(int16_t v) { return v == -32768 ? 32767 : (int16_t)-v; }
template <typename T>
T pick(const T* in, uint16_t code, uint8_t axis) {
    return in[(code >> (2 * axis)) & 3u];
}

// The row's fields (no variable shift per sample: a loop of single shifts on the AVR).
void decode(uint16_t code, uint8_t src[3], uint8_t& signs) {
    src[0] = (uint8_t)(code & 3u);
    src[1] = (uint8_t)((code >> 2) & 3u);
    src[2] = (uint8_t)((code >> 4) & 3u);
    signs = (uint8_t)((code >> 6) & 15u);
}

void turn(const uint8_t src[3], uint8_t signs, Vector3i& v) {
    const int16_t in[3] = {v.x, v.y, v.z};
    int16_t x = in[src[0]], y = in[src[1]], z = in[src[2]];
    if (signs & 1u) x = negate(x);
    if (signs & 2u) y = negate(y);
    if (signs & 4u) z = negate(z);
    if (signs & 8u) {
        // Q15 products, rounded (16x16 multiplies: four MULs each on the AVR).
        const int32_t xh = linalg::mul_s16(x, kHalfSqrt2Q15), yh = linalg::mul_s16(y, kHalfSqrt2Q15);
        const int16_t x2 = saturate((xh - yh + 16384) >> 15);
        y = saturate((xh + yh + 16384) >> 15);
        x = x2;
    }
    v = Vector3i(x, y, z);
}

}  // namespace

void rotate(uint8_t r, Vector3i& v) {
    if (r == 0 || r >= kRotationCount) return;
    uint8_t src[3], signs;
    decode(READ_ROTATION(&kRotations[r]), src, signs);
    turn(src, signs, v);
}

void apply_gyro(const BoardFrame& f, Vector3i& g) {
    if (f.rotation != 0) turn(f.src, f.signs, g);
}

void rotate(uint8_t r, Vector3f& v) {
    if (r == 0 || r >= kRotationCount) return;
    const uint16_t code = READ_ROTATION(&kRotations[r]);
    const float in[3] = {v.x, v.y, v.z};
    float x = pick(in, code, 0), y = pick(in, code, 1), z = pick(in, code, 2);
    if (code & (1u << 6)) x = -x;
    if (code & (1u << 7)) y = -y;
    if (code & (1u << 8)) z = -z;
    if (code & kYaw45) {
        constexpr float kHalfSqrt2 = 0.70710678f;
        const float x2 = (x - y) * kHalfSqrt2;
        y = (x + y) * kHalfSqrt2;
        x = x2;
    }
    v = Vector3f(x, y, z);
}

void small_sin_cos(float x, float& s, float& c) {
    // Taylor to x^7 and x^8: at 0.1745 rad the next terms are below 1e-9.
    const float x2 = x * x;
    s = x * (1.0f - x2 * (1.0f / 6.0f) * (1.0f - x2 * (1.0f / 20.0f) * (1.0f - x2 * (1.0f / 42.0f))));
    c = 1.0f - x2 * 0.5f * (1.0f - x2 * (1.0f / 12.0f) * (1.0f - x2 * (1.0f / 30.0f)));
}

TrimQ14 trim_q14(float trim_x_rad, float trim_y_rad) {
    float sa, ca, sb, cb;
    small_sin_cos(trim_x_rad, sa, ca);
    small_sin_cos(trim_y_rad, sb, cb);
    // T = Ry(b) Rx(a) = [[cb, sb sa, sb ca], [0, ca, -sa], [-sb, cb sa, cb ca]].
    const float t[3][3] = {{cb, sb * sa, sb * ca}, {0.0f, ca, -sa}, {-sb, cb * sa, cb * ca}};
    TrimQ14 out;
    for (uint8_t i = 0; i < 3; ++i)
        for (uint8_t j = 0; j < 3; ++j) out.t[i][j] = (int16_t)lroundf(t[i][j] * 16384.0f);
    out.active = trim_x_rad != 0.0f || trim_y_rad != 0.0f;
    return out;
}

bool level_trim(const Vector3f& a, float& trim_x_rad, float& trim_y_rad) {
    const float yz = sqrtf(a.y * a.y + a.z * a.z);
    if (!(yz > 0.5f * linalg::kGravity_m_s2)) return false;  // NaN too; a level board reads -9.8 on z
    const float pitch = atan2f(a.x, yz), roll = atan2f(-a.y, -a.z);
    if (!(within(pitch, kTrimMax_rad) && within(roll, kTrimMax_rad))) return false;
    trim_x_rad = roll;
    trim_y_rad = pitch;
    return true;
}

BoardFrame make_board_frame(const Vector3f& offset_m_s2, const Vector3f& scale, uint8_t rotation,
                            float accel_m_s2_per_count) {
    BoardFrame f;
    const float o[3] = {offset_m_s2.x, offset_m_s2.y, offset_m_s2.z}, s[3] = {scale.x, scale.y, scale.z};
    f.accel_corrected = false;
    for (uint8_t i = 0; i < 3; ++i) {
        // Out of range (a corrupt setting): none of it.
        const bool ok = within(o[i], kAccelOffsetMax_m_s2) && s[i] >= kAccelScaleMin && s[i] <= kAccelScaleMax;
        f.accel_offset_counts[i] = ok ? (int16_t)lroundf(o[i] / accel_m_s2_per_count) : 0;
        f.accel_scale_q14[i] = ok ? (int16_t)lroundf(s[i] * 16384.0f) : 16384;
        f.accel_corrected = f.accel_corrected || f.accel_offset_counts[i] != 0 || f.accel_scale_q14[i] != 16384;
    }
    f.rotation = rotation < kRotationCount ? rotation : 0;
    decode(READ_ROTATION(&kRotations[f.rotation]), f.src, f.signs);
    return f;
}

void apply_accel(const BoardFrame& f, Vector3i& a) {
    if (f.accel_corrected) {
        int16_t* axes[3] = {&a.x, &a.y, &a.z};
        for (uint8_t i = 0; i < 3; ++i) {
            // (raw - offset) * scale, Q14 rounded: 16x16 products.
            const int16_t d = saturate((int32_t)*axes[i] - f.accel_offset_counts[i]);
            *axes[i] = saturate((linalg::mul_s16(d, f.accel_scale_q14[i]) + 8192) >> 14);
        }
    }
    if (f.rotation != 0) turn(f.src, f.signs, a);
}

}  // namespace calib
