// Fixed-point helpers for the output path (Euler angles): integer arithmetic on the
// 2560's hardware multiplier instead of float calls (a float multiply is ~170 cycles,
// a division ~510, a 16x16->32 integer multiply ~25), and bit-identical results on the
// board and on the host (the replay tool).
//
// Formats: Qn means value * 2^n in an int32_t. Rotation-matrix entries are Q30
// (|entry| <= 1, headroom to 2); angles are Q24 radians (6e-8 rad steps; a whole
// number of bytes from the Q32 the tables give: shifts by 8 are register moves on
// the AVR, other constant shifts of 32-bit words a loop of ~6 cycles per bit).
#pragma once

#include <stdint.h>
#include <string.h>

// Small helpers on the output path forced inline on the AVR: out of line, -mcall-prologues
// gives each one the register-saving routines (~40 cycles a call) whatever the
// optimisation level.
#ifdef __AVR__
#define FIXED_INLINE __attribute__((always_inline)) inline
#else
#define FIXED_INLINE inline
#endif

namespace linalg {

constexpr uint8_t kQ30 = 30;
constexpr uint8_t kAngleQ = 24;              // angles: radians * 2^24
constexpr int32_t kQuarterPiQ24 = 13176795;  // round(pi/4 * 2^24)
constexpr int32_t kHalfPiQ24 = 26353589;     // round(pi/2 * 2^24)
constexpr int32_t kPiQ24 = 52707179;         // round(pi * 2^24)

namespace fixed_detail {
// Bit fields of a 32-bit word from its bytes: at -Os avr-gcc shifts a 32-bit word by
// a constant that is not a multiple of 8 in a loop, one bit (~6 cycles) per turn
// (x >> 23 was ~150 cycles); whole bytes are only register moves.
inline uint8_t byte3(uint32_t x) { return (uint8_t)(x >> 24); }
inline uint8_t byte2(uint32_t x) { return (uint8_t)(x >> 16); }
// (x >> 23) & 0xFF
inline uint8_t bits_23_to_30(uint32_t x) {
    return (uint8_t)((uint8_t)(byte3(x) << 1) | (uint8_t)(byte2(x) >> 7));
}
// (uint16_t)(x >> 7)
inline uint16_t bits_7_to_22(uint32_t x) {
    return (uint16_t)((uint16_t)((uint16_t)(x >> 8) << 1) | (uint8_t)((uint8_t)x >> 7));
}

}  // namespace fixed_detail

// x * 2^frac_bits, truncated toward zero, read from the float's bits (no float call;
// inline: ~60 cycles on the AVR where a call with its register saving took ~140):
// saturates at +-(2^31 - 1) (infinities too); NaN gives 0.
FIXED_INLINE int32_t fixed_from_float(float x, uint8_t frac_bits) {
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    const uint8_t exponent = fixed_detail::bits_23_to_30(bits);
    const uint32_t fraction = bits & 0x7FFFFFu;
    if (exponent == 0) return 0;                          // zero, subnormal (< 1.2e-38)
    if (exponent == 0xFFu && fraction != 0) return 0;     // NaN
    // |x| = m * 2^(exponent - 150) with the 24-bit significand m.
    uint32_t m = fraction | 0x800000u;
    const int16_t shift = (int16_t)((int16_t)exponent - 150 + (int16_t)frac_bits);
    if (shift >= 8) {
        m = 0x7FFFFFFFu;  // >= 2^31 (and infinity)
    } else if (shift >= 4) {
        // A byte left, then back right: 8 - shift <= 4 turns of the bit loop instead of
        // shift <= 7 (matrix entries in [0.5, 1) have shift 6).
        m = (m << 8) >> (uint8_t)(8 - shift);
    } else if (shift >= 0) {
        m <<= shift;
    } else {
        uint8_t right = (uint8_t)-shift;
        if (right >= 24) return 0;
        // Whole bytes first: avr-gcc moves bytes for a constant 8, but shifts bit by
        // bit in a loop for a variable count.
        if (right >= 16) { m >>= 16; right = (uint8_t)(right - 16u); }
        if (right >= 8) { m >>= 8; right = (uint8_t)(right - 8u); }
        m >>= right;
    }
    return (bits & 0x80000000u) ? -(int32_t)m : (int32_t)m;
}

// q * 2^-frac_bits (frac_bits <= 100), rounded to float's 24 bits.
inline float float_from_fixed(int32_t q, uint8_t frac_bits) {
    if (q == 0) return 0.0f;
    float f = (float)q;  // |q| >= 1: a normal float, exponent field >= 127
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    bits -= (uint32_t)(uint16_t)((uint16_t)frac_bits << 7) << 16;  // exponent - frac_bits: exact
    memcpy(&f, &bits, sizeof f);
    return f;
}


// atan(num / den) in Q24 radians for 0 <= num <= den, den > 0 (0 for den = 0), and
// the ratio num/den in Q31 (2^31 = 1) when ratio_q31 is not null. Error below
// 1.2e-5 rad (0.0007 deg) over the whole range, test_fixed.cpp: tables of 1/d and
// t - atan(t) with linear interpolation, no division.
int32_t atan_of_ratio_q24(uint32_t num, uint32_t den, uint32_t* ratio_q31);

// atan2(y, x) in Q24 radians, -pi < a <= pi, for magnitudes and signs given apart (so
// that a magnitude may use all 32 bits); atan2(0, 0) = 0. As fast_atan2: the sign of
// a zero y is +, so atan2(0, -x) = +pi. ratio_q31, when not null, receives
// min/max of the magnitudes (for hypot_from_ratio).
int32_t atan2_q24(bool y_negative, uint32_t y_magnitude, bool x_negative, uint32_t x_magnitude,
                  uint32_t* ratio_q31 = nullptr);

// sqrt(a^2 + b^2) for magnitudes a, b < 2^31 (in their common scale), to within a
// relative 2.5e-5 (and 1 unit), from the ratio t = min/max that atan_of_ratio_q24 gives:
// max * sqrt(1 + t^2), the square root from a table. No overflow: < 1.42 * 2^31.
uint32_t hypot_from_ratio(uint32_t larger, uint32_t ratio_q31);

// An angle in Q24 radians in hundredths of a degree, rounded to nearest (half away
// from zero): round(|a| * 18000/pi / 2^24) from four 16x16 multiplies, no float. The
// constant is 18000/pi in Q16 rounded (relative error 1.3e-9): the result is the
// exact rounding of the Q24 value except within 2^-15 of a count of a half. For
// |a| < 2^26 (4 rad; atan2_q24 gives at most pi).
int32_t centideg_from_q24(int32_t angle_q24);

// a * b for int16 factors, with avr-gcc's widening multiply (__mulhisi3, ~25 cycles):
// out of line because inlined, gcc often turns (int32_t)a * b into its 32x32 routine
// (__mulsi3, ~105 cycles).
int32_t mul_s16(int16_t a, int16_t b);

// |q| as an unsigned magnitude (|-2^31| fits).
inline uint32_t magnitude(int32_t q) { return q < 0 ? (uint32_t)0 - (uint32_t)q : (uint32_t)q; }

}  // namespace linalg
