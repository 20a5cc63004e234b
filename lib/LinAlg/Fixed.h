// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-point helpers: integer arithmetic on the 2560's hardware multiplier instead of
// float calls (a float multiply or division is a library call; a 16x16->32 integer
// multiply is four MUL instructions), with bit-identical results on the board and on the host (replay).
// The estimator (lib/DCM) and the Euler output run on them.
//
// Formats: Qn is value * 2^n in an int32_t (or int16_t where it says so).
//   Q30   rotation-matrix entries and factors, |v| < 2 (1 = 2^30)      mul_q30, q30_of
//   Q26   turns in radians, |theta| < 32 (the DCM's integration)
//   Q24   angles in radians (6e-8 rad steps), kPiQ24 ...             atan2_q24, centideg_from_q24
//   Q14   a Q30 entry rounded to 16 bits (int16_t)                   q14_of, mul_q14
//   Q31   ratios in [0, 1] (unsigned)                                atan_of_ratio_q24, hypot_from_ratio
//   Q0    whole units: fixed_from_float(x, 0)
// Whole bytes of a shift are register moves on the AVR, other constant shifts of a
// 32-bit word a loop, one bit a turn: the formats are chosen for byte shifts.
//
// Inlining is decided per call site, by the profile (`make bench`'s step parts):
//   - FIXED_INLINE helpers are a few instructions (mul_s16, mul_u16, q14_of ...): forced
//     inline everywhere, cheaper than a call.
//   - mul_q30, mul_q14, mul_q14_unit and fixed_from_float are ordinary calls
//     (linalg::mul_q30 ...); the hot list takes the forced-inline copies of mul_q14,
//     mul_q14_unit and fixed_from_float from namespace linalg::hot, one
//     `using linalg::hot::...` at the top of the function: the integration's coning term
//     (Strapdown), the gravity window's products, the rest means and the field sample's
//     latency turn (each runs at 50 to 200 Hz). Cold code (start-up, the float paths,
//     renormalisation, a new field's heading, the learner's solve) calls.
//   - mul_q30 is called even on the hot list: its called form keeps to the
//     call-clobbered registers (Fixed.cpp), while a function with many inline copies
//     (the integration) runs out of registers and spills to a deep frame, slower and
//     larger than the calls. hot::mul_q30 is the host's form and the reference.
//   - The Euler output (atan2_q24 ...) runs once a line, all inline (its own target).
#pragma once

#include <stdint.h>
#include <string.h>

#include "LinAlg.h"

// FIXED_INLINE: forced inline on the AVR (out of line, -mcall-prologues gives each call
// the register-saving routines). FIXED_COLD: never inline (one copy of cold code that
// would otherwise be copied into each caller, or cold code whose locals would grow a hot
// caller's frame). FIXED_OWN_FRAME: never inline either, for a large part of a hot step
// called from one place: inlined, its locals join the caller's, and a frame beyond the 63
// bytes ldd/std reach from Y makes every access beyond them five instructions (subi,
// sbci, the access, subi, sbci) in the caller's whole body.
#ifdef __AVR__
#define FIXED_INLINE __attribute__((always_inline)) inline
#define FIXED_COLD __attribute__((noinline))
#define FIXED_OWN_FRAME __attribute__((noinline))
#include <avr/pgmspace.h>
#define FIXED_PROGMEM PROGMEM
#else
#define FIXED_INLINE inline
#define FIXED_COLD
#define FIXED_OWN_FRAME
#define FIXED_PROGMEM
#endif

namespace linalg {

constexpr uint8_t kQ30 = 30;
constexpr int32_t kOneQ30 = 1L << 30;
// Constants written as the ratio they are: round(num / den) in Q30 or Q14, in integers
// (the AVR's double is a float: a ratio in double would round differently there).
constexpr int32_t q30_ratio(int32_t num, int32_t den) {
    return (int32_t)((((int64_t)num << 30) + den / 2) / den);
}
constexpr int16_t q14_ratio(int32_t num, int32_t den) { return (int16_t)((((int32_t)num << 14) + den / 2) / den); }
constexpr uint8_t kAngleQ = 24;              // angles: radians * 2^24
constexpr int32_t kQuarterPiQ24 = 13176795;  // round(pi/4 * 2^24)
constexpr int32_t kHalfPiQ24 = 26353589;     // round(pi/2 * 2^24)
constexpr int32_t kPiQ24 = 52707179;         // round(pi * 2^24)

namespace fixed_detail {
// Bit fields of a 32-bit word from its bytes: at -Os avr-gcc shifts a 32-bit word by
// a constant that is not a multiple of 8 in a loop, one bit per turn; whole bytes are
// only register moves.
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

// 2^n for n = 0..7, from a table in flash (avr-gcc computes 1 << n in a loop).
extern const uint8_t kPowersOfTwo[8] FIXED_PROGMEM;
FIXED_INLINE uint8_t power_of_two(uint8_t n) {
#ifdef __AVR__
    return pgm_read_byte(kPowersOfTwo + n);
#else
    return kPowersOfTwo[n];
#endif
}

}  // namespace fixed_detail

// m * p for a 24-bit m and an 8-bit p (< 2^32): on the AVR three MUL instructions, a
// shift by 0..7 bits with p = 2^n, where avr-gcc shifts a 32-bit word by a variable
// count in a loop, one bit a turn.
FIXED_INLINE uint32_t mul_u24_u8(uint32_t m, uint8_t p) {
#ifdef __AVR__
    uint32_t r;
    __asm__("mul  %A1, %2\n\t"
            "movw %A0, r0\n\t"
            "mul  %C1, %2\n\t"
            "movw %C0, r0\n\t"
            "mul  %B1, %2\n\t"
            "add  %B0, r0\n\t"
            "adc  %C0, r1\n\t"
            "clr  r1\n\t"  // eor leaves the carry
            "adc  %D0, r1"
            : "=&r"(r)
            : "r"(m), "r"(p));
    return r;
#else
    return (m & 0xFFFFFFu) * (uint32_t)p;
#endif
}

// x * 2^frac_bits, truncated toward zero, read from the float's bits (no float call:
// whole bytes are register moves, the remaining 0..7
// bits one mul_u24_u8): saturates at +-(2^31 - 1) (infinities too); NaN gives 0.
namespace hot {
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
    } else if (shift >= 0) {
        m = mul_u24_u8(m, fixed_detail::power_of_two((uint8_t)shift));
    } else {
        uint8_t right = (uint8_t)-shift;
        if (right >= 24) return 0;
        // Whole bytes first (register moves), then the rest as a shift left by
        // 8 - right and a byte right: m < 2^24 before, so m * 2^(8 - right) fits.
        if (right >= 16) { m >>= 16; right = (uint8_t)(right - 16u); }
        if (right >= 8) { m >>= 8; right = (uint8_t)(right - 8u); }
        if (right != 0) m = mul_u24_u8(m, fixed_detail::power_of_two((uint8_t)(8u - right))) >> 8;
    }
    return (bits & 0x80000000u) ? -(int32_t)m : (int32_t)m;
}
}  // namespace hot
// The same as an ordinary call (Fixed.cpp): where no cycle matters.
int32_t fixed_from_float(float x, uint8_t frac_bits);

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


// x unchanged, but opaque to the optimiser: avr-gcc folds (x >> 8) >> 1 into x >> 9,
// a loop of nine 4-byte shifts, where a shift by a whole byte is register
// moves and one more bit four instructions.
FIXED_INLINE int32_t opaque(int32_t x) {
#ifdef __AVR__
    __asm__("" : "+r"(x));
#endif
    return x;
}

// |q| as an unsigned magnitude (|-2^31| fits).
inline uint32_t magnitude(int32_t q) { return q < 0 ? (uint32_t)0 - (uint32_t)q : (uint32_t)q; }

// a * b, 16 x 16 -> 32 bits. On the AVR four MUL instructions inline:
// avr-gcc calls a library routine for a widening multiply (and for a product of casts
// often its 32 x 32 one, __mulsi3), and a call makes the caller save
// registers. Signed as in Atmel's AVR201 (MULS/MULSU need r16..r23: constraint "a").
FIXED_INLINE uint32_t mul_u16(uint16_t a, uint16_t b) {
#ifdef __AVR__
    uint32_t r;
    __asm__("mul  %A1, %A2\n\t"
            "movw %A0, r0\n\t"
            "mul  %B1, %B2\n\t"
            "movw %C0, r0\n\t"
            "mul  %B1, %A2\n\t"
            "add  %B0, r0\n\t"
            "adc  %C0, r1\n\t"
            "clr  r1\n\t"  // eor leaves the carry
            "adc  %D0, r1\n\t"
            "mul  %A1, %B2\n\t"
            "add  %B0, r0\n\t"
            "adc  %C0, r1\n\t"
            "clr  r1\n\t"
            "adc  %D0, r1"
            : "=&r"(r)
            : "r"(a), "r"(b));
    return r;
#else
    return (uint32_t)a * (uint32_t)b;
#endif
}
FIXED_INLINE int32_t mul_s16(int16_t a, int16_t b) {
#ifdef __AVR__
    int32_t r;
    uint8_t zero;
    __asm__("clr   %[z]\n\t"
            "muls  %B[a], %B[b]\n\t"
            "movw  %C[r], r0\n\t"
            "mul   %A[a], %A[b]\n\t"
            "movw  %A[r], r0\n\t"
            "mulsu %B[a], %A[b]\n\t"  // carry = sign of the partial product
            "sbc   %D[r], %[z]\n\t"
            "add   %B[r], r0\n\t"
            "adc   %C[r], r1\n\t"
            "adc   %D[r], %[z]\n\t"
            "mulsu %B[b], %A[a]\n\t"
            "sbc   %D[r], %[z]\n\t"
            "add   %B[r], r0\n\t"
            "adc   %C[r], r1\n\t"
            "adc   %D[r], %[z]\n\t"
            "clr   r1"
            : [r] "=&r"(r), [z] "=&r"(zero)
            : [a] "a"(a), [b] "a"(b));
    return r;
#else
    return (int32_t)a * (int32_t)b;
#endif
}

namespace fixed_detail {
// mul_u32_shr30's sum written out (the host's; the AVR self test checks its assembly
// against it).
inline uint32_t mul_u32_shr30_by_bytes(uint32_t a, uint32_t x) {
    uint64_t sum = 0;
    for (uint8_t i = 0; i < 4; ++i)
        for (uint8_t j = 0; j < 4; ++j) {
            const uint64_t p = (uint64_t)((a >> (8 * i)) & 0xFFu) * ((x >> (8 * j)) & 0xFFu);
            if (i + j == 2) sum += p >> 8;
            if (i + j >= 3) sum += p << (8 * (i + j - 3));
        }
    return (uint32_t)(sum >> 6);
}
}  // namespace fixed_detail

// The bits 30..61 of a * x for magnitudes a, x (< 2^32): the partial products of their
// bytes a_i x_j with i + j >= 3, and the high bytes of those with i + j = 2 (the rest
// is below 2^24 of the 2^30 unit: the result is at most 1 below the exact floor).
// On the AVR 13 MULs in one accumulator; the host computes the same sum.
FIXED_INLINE uint32_t mul_u32_shr30(uint32_t a, uint32_t x) {
#ifdef __AVR__
    // acc: bytes 3..7 of the product, in %A..%D[hi] (3..6) and %[b7] (7).
    uint32_t acc;
    uint8_t b7, zero;
    __asm__(
        "clr  %[z]\n\t"
        "clr  %A[acc]\n\t" "clr %B[acc]\n\t" "clr %C[acc]\n\t" "clr %D[acc]\n\t" "clr %[b7]\n\t"
        // i + j = 2: the high bytes into byte 3 (their sum < 2^10: bytes 3, 4)
        "mul  %A[a], %C[x]\n\t" "add %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
        "mul  %B[a], %B[x]\n\t" "add %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
        "mul  %C[a], %A[x]\n\t" "add %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
        // i + j = 3 at byte 3 (the sum < 2^19: bytes 3..5)
        "mul  %A[a], %D[x]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t" "adc %C[acc], %[z]\n\t"
        "mul  %B[a], %C[x]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t" "adc %C[acc], %[z]\n\t"
        "mul  %C[a], %B[x]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t" "adc %C[acc], %[z]\n\t"
        "mul  %D[a], %A[x]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t" "adc %C[acc], %[z]\n\t"
        // i + j = 4 at byte 4 (< 2^26: bytes 3..6)
        "mul  %B[a], %D[x]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t" "adc %D[acc], %[z]\n\t"
        "mul  %C[a], %C[x]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t" "adc %D[acc], %[z]\n\t"
        "mul  %D[a], %B[x]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t" "adc %D[acc], %[z]\n\t"
        // i + j = 5 at byte 5 (bytes 3..7)
        "mul  %C[a], %D[x]\n\t" "add %C[acc], r0\n\t" "adc %D[acc], r1\n\t" "adc %[b7], %[z]\n\t"
        "mul  %D[a], %C[x]\n\t" "add %C[acc], r0\n\t" "adc %D[acc], r1\n\t" "adc %[b7], %[z]\n\t"
        // i + j = 6 at byte 6
        "mul  %D[a], %D[x]\n\t" "add %D[acc], r0\n\t" "adc %[b7], r1\n\t"
        // bits 30..61 = (bytes 3..7) >> 6 = ((bytes 3..7) << 2), bytes 4..7
        "lsl  %A[acc]\n\t" "rol %B[acc]\n\t" "rol %C[acc]\n\t" "rol %D[acc]\n\t" "rol %[b7]\n\t"
        "lsl  %A[acc]\n\t" "rol %B[acc]\n\t" "rol %C[acc]\n\t" "rol %D[acc]\n\t" "rol %[b7]\n\t"
        "mov  %A[acc], %B[acc]\n\t" "mov %B[acc], %C[acc]\n\t" "mov %C[acc], %D[acc]\n\t" "mov %D[acc], %[b7]\n\t"
        "clr  r1"
        : [acc] "=&r"(acc), [b7] "=&r"(b7), [z] "=&r"(zero)
        : [a] "r"(a), [x] "r"(x));
    return acc;
#else
    return fixed_detail::mul_u32_shr30_by_bytes(a, x);
#endif
}

// a * x / 2^30: a Q30 factor (|a| < 2) times any x, in x's own units (the result must
// fit in 31 bits), within 1 unit of the exact product (toward zero): mul_u32_shr30 on the
// magnitudes, a fraction of a float multiply's cost on the AVR; the same bits on the host.
namespace hot {
FIXED_INLINE int32_t mul_q30(int32_t a, int32_t x) {
    const uint32_t m = mul_u32_shr30(magnitude(a), magnitude(x));
    return (a < 0) != (x < 0) ? -(int32_t)m : (int32_t)m;
}
}  // namespace hot
int32_t mul_q30(int32_t a, int32_t x);  // Fixed.cpp: an ordinary call

// r * x / 2^14 for a Q14 factor r (a Q30 matrix entry rounded to 16 bits: q14_of) and
// any x: two 16x16 products, half of mul_q30's cost, within 4 units of x's scale plus
// r's rounding (6e-5 of |x|): for the terms of an update, x small (a turn).
// (In unsigned arithmetic: the rounding add wraps for an entry saturated at 2^31 - 1, a
// garbage matrix, instead of overflowing.)
FIXED_INLINE int16_t q14_of(int32_t e_q30) { return (int16_t)(uint16_t)(((uint32_t)e_q30 + 0x8000u) >> 16); }
// r * x / 2^16 rounded, from two 16x16 products (x = xh 2^16 + xl, xl signed).
namespace hot {
FIXED_INLINE int32_t mul_s16_shr16(int16_t r, int32_t x) {
    const int16_t xl = (int16_t)(uint16_t)x;
    const int16_t xh = (int16_t)(uint16_t)(((uint32_t)x - (uint32_t)(int32_t)xl) >> 16);
    return mul_s16(r, xh) + ((mul_s16(r, xl) + 0x8000) >> 16);
}
FIXED_INLINE int32_t mul_q14(int16_t r, int32_t x) { return (int32_t)((uint32_t)mul_s16_shr16(r, x) << 2); }
// mul_q14 rounded to the unit instead of to 4 units, for |x| < 2^29 (the shift moves to
// x): where the product is a low-pass's step. A step of 0.04 that comes in 4-unit
// multiples stops 50 units short of the mean it follows (RestDetector::update's rest
// means: their offset would become the gyro bias at rest).
FIXED_INLINE int32_t mul_q14_unit(int16_t r, int32_t x) { return mul_s16_shr16(r, (int32_t)((uint32_t)x << 2)); }
}  // namespace hot
// The same as ordinary calls (Fixed.cpp).
int32_t mul_q14(int16_t r, int32_t x);
int32_t mul_q14_unit(int16_t r, int32_t x);

// The rows' dot product and cross product, each term by mul_q30: Q30 rows give a Q30
// result; a Q30 row with a vector in other units gives that vector's units.
int32_t dot_q30(const Vector3l& r, const Vector3l& v);
Vector3l cross_q30(const Vector3l& r, const Vector3l& v);
// R v for a Q30 matrix (earth axes from body ones for a DCM), in v's units.
Vector3l mul_q30(const Matrix3q30& r, const Vector3l& v);
// Between float and Q30 (fixed_from_float saturates; float_from_fixed is exact to
// float's 24 bits).
Matrix3q30 q30_from_matrix(const Matrix3f& m);
Matrix3f matrix_from_q30(const Matrix3q30& m);
// Each axis by fixed_from_float (Q frac_bits: 0 for whole units, kQ30 for a row of R).
Vector3l fixed_from_vector(const Vector3f& v, uint8_t frac_bits);
Vector3f vector_from_fixed(const Vector3l& v, uint8_t frac_bits);
Vector3f vector_from_q30(const Vector3l& v);

// (x * g) >> 16 for a 32-bit x and a 16-bit g, from two 16 x 16 products (the bits
// below 2^16 of the low product are dropped: at most 1 below the exact floor).
FIXED_INLINE uint32_t mul_u32_u16_shr16(uint32_t x, uint16_t g) {
    return mul_u16((uint16_t)(x >> 16), g) + (mul_u16((uint16_t)x, g) >> 16);
}

// The tables (Fixed.cpp), in flash on the AVR; what follows is inline so that the
// output path is one function without calls (each call with -mcall-prologues saves
// and restores the registers it uses).
namespace fixed_detail {
extern const uint16_t kReciprocalMinusOne[257] FIXED_PROGMEM;
extern const uint16_t kTMinusAtan[257] FIXED_PROGMEM;
extern const uint16_t kHypotMinusOne[129] FIXED_PROGMEM;

FIXED_INLINE uint16_t entry(const uint16_t* table, uint16_t i) {
#ifdef __AVR__
    return pgm_read_word(table + i);
#else
    return table[i];
#endif
}

// Linear interpolation at index i + f/2^16 of an increasing (sign +1) or decreasing
// table, in the table's Q plus 16 bits.
FIXED_INLINE uint32_t interpolate_up(const uint16_t* table, uint16_t i, uint16_t f) {
    const uint16_t lo = entry(table, i);
    const uint16_t step = (uint16_t)(entry(table, (uint16_t)(i + 1u)) - lo);
    return ((uint32_t)lo << 16) + mul_u16(step, f);
}
FIXED_INLINE uint32_t interpolate_down(const uint16_t* table, uint16_t i, uint16_t f) {
    const uint16_t hi = entry(table, i);
    const uint16_t step = (uint16_t)(hi - entry(table, (uint16_t)(i + 1u)));
    return ((uint32_t)hi << 16) - mul_u16(step, f);
}

}  // namespace fixed_detail

// atan(num / den) in Q24 radians for 0 <= num <= den, den > 0 (0 for den = 0), and
// the ratio num/den in Q31 (2^31 = 1) when ratio_q31 is not null. Error below
// 1.2e-5 rad (0.0007 deg) over the whole range, test_fixed.cpp: tables of 1/d and
// t - atan(t) with linear interpolation, no division.
inline int32_t atan_of_ratio_q24(uint32_t num, uint32_t den, uint32_t* ratio_q31) {
    if (den == 0) {
        if (ratio_q31) *ratio_q31 = 0;
        return 0;
    }
    // Normalise den into [2^31, 2^32) (num <= den follows it without overflow).
    while ((den & 0xFF000000u) == 0) {
        den <<= 8;
        num <<= 8;
    }
    while ((den & 0x80000000u) == 0) {
        den <<= 1;
        num <<= 1;
    }
    // d = den / 2^32 = (1 + u)/2 with u = i/256 + f/2^24: 1/d = 1 + g(u).
    const uint16_t i = fixed_detail::bits_23_to_30(den);
    const uint16_t f = fixed_detail::bits_7_to_22(den);
    const uint16_t g = (uint16_t)(fixed_detail::interpolate_down(fixed_detail::kReciprocalMinusOne, i, f) >> 16);
    // t = (num / 2^32) / d = n (1 + g) in Q31.
    const uint32_t n_q31 = num >> 1;
    uint32_t t_q31 = n_q31 + mul_u32_u16_shr16(n_q31, g);
    if (t_q31 >= 0x80000000u) t_q31 = 0x80000000u;  // num = den (interpolation rounding)
    if (ratio_q31) *ratio_q31 = t_q31;
    if (t_q31 == 0x80000000u) return kQuarterPiQ24;
    // atan(t) = t - (t - atan(t)), the table at j = t*256.
    const uint16_t j = fixed_detail::bits_23_to_30(t_q31);  // t_q31 < 2^31: j <= 255
    const uint16_t fj = fixed_detail::bits_7_to_22(t_q31);
    const uint32_t t_minus_atan_q34 = fixed_detail::interpolate_up(fixed_detail::kTMinusAtan, j, fj);
    const uint32_t atan_q32 = (t_q31 << 1) - (t_minus_atan_q34 >> 2);
    return (int32_t)((atan_q32 + 0x80u) >> 8);
}

// atan2(y, x) in Q24 radians, -pi < a <= pi, for magnitudes and signs given apart (so
// that a magnitude may use all 32 bits); atan2(0, 0) = 0. As fast_atan2: the sign of
// a zero y is +, so atan2(0, -x) = +pi. ratio_q31, when not null, receives
// min/max of the magnitudes (for hypot_from_ratio).
FIXED_INLINE int32_t atan2_q24(bool y_negative, uint32_t y_magnitude, bool x_negative, uint32_t x_magnitude,
                               uint32_t* ratio_q31 = nullptr) {
    // Fold into the first octant, as fast_atan2 does: a = atan(min/max).
    // (One inline copy of atan_of_ratio_q24: the operands are chosen first.)
    const bool steep = y_magnitude > x_magnitude;
    int32_t a = atan_of_ratio_q24(steep ? x_magnitude : y_magnitude, steep ? y_magnitude : x_magnitude, ratio_q31);
    if (steep) a = kHalfPiQ24 - a;
    if (x_negative && x_magnitude != 0) a = kPiQ24 - a;
    return y_negative && y_magnitude != 0 ? -a : a;
}

// Inverse square roots without a float call (sqrtf and a division are the float
// library's dearest calls on the AVR), from 16x16 multiplies (Fixed.cpp). The core:
// 1/sqrt(t) in Q15 for t = xn / 2^16 in [1/4, 1) (2 at t = 1/4 read as 65535), a line
// on each half of the range (2.3 % at most), then two of Newton's steps
// y <- y (3 - t y^2) / 2, each leaving 1.5 times the square of the relative error:
// within 6e-5 of 1/sqrt(t) for every xn (test_fixed.cpp).
uint16_t inverse_sqrt_q15(uint16_t xn);
// 2^30 / sqrt(x) for x >= 1 (x in steps of four bits brought into [2^14, 2^16)):
// within 1e-4 of itself. x = 0 gives 2^31 - 1.
uint32_t inverse_sqrt_q30(uint32_t x);
// 1/sqrt(x) for a positive normal float (its exponent halved, its significand by
// inverse_sqrt_q15): within 1e-4 of itself; 0 for zero, negatives, subnormals,
// infinity and NaN.
float inverse_sqrt(float x);

// sqrt(a^2 + b^2) for magnitudes a, b < 2^31 (in their common scale), to within a
// relative 2.5e-5 (and 1 unit), from the ratio t = min/max that atan_of_ratio_q24 gives:
// max * sqrt(1 + t^2), the square root from a table. No overflow: < 1.42 * 2^31.
FIXED_INLINE uint32_t hypot_from_ratio(uint32_t larger, uint32_t ratio_q31) {
    uint16_t s;
    if (ratio_q31 >= 0x80000000u) {
        s = fixed_detail::entry(fixed_detail::kHypotMinusOne, 128);
    } else {
        const uint16_t j = fixed_detail::byte3(ratio_q31);
        const uint16_t fj = (uint16_t)(ratio_q31 >> 8);
        s = (uint16_t)(fixed_detail::interpolate_up(fixed_detail::kHypotMinusOne, j, fj) >> 16);
    }
    return larger + mul_u32_u16_shr16(larger, s);
}

// An angle in Q24 radians in hundredths of a degree, rounded to nearest (half away
// from zero): round(|a| * 18000/pi / 2^24) from four 16x16 multiplies, no float
// (a fraction of the float path's cost). The
// constant is 18000/pi in Q16 rounded (relative error 1.3e-9): the result is the
// exact rounding of the Q24 value except within 2^-15 of a count of a half. For
// |a| < 2^26 (4 rad; atan2_q24 gives at most pi).
FIXED_INLINE int32_t centideg_from_q24(int32_t angle_q24) {
    // m * K / 2^40 with m = |a| < 2^26 and K = round(18000/pi * 2^16) = 375493621 <
    // 2^29, from 16-bit halves: m K = hi 2^32 + (mid mod 2^16) 2^16 + (lo mod 2^16).
    constexpr uint16_t kHigh = 5729, kLow = 37877;  // K = 5729 * 2^16 + 37877
    const uint32_t m = magnitude(angle_q24);
    uint16_t c;
#ifdef __AVR__
    // The same sums byte by byte in one accumulator (16 MULs, shorter than the four
    // mul_u16 with avr-gcc's moves between them): acc = lo, then its top half
    // plus the two middle products (mid), then mid's top half plus the high product (hi).
    uint32_t acc;
    uint8_t zero;
    __asm__("clr  %[z]\n\t"
            // lo = m_low * kLow: acc = [A B C D]
            "mul  %A[m], %A[kl]\n\t" "movw %A[acc], r0\n\t"
            "mul  %B[m], %B[kl]\n\t" "movw %C[acc], r0\n\t"
            "mul  %B[m], %A[kl]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t" "adc %D[acc], %[z]\n\t"
            "mul  %A[m], %B[kl]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t" "adc %D[acc], %[z]\n\t"
            // mid = lo >> 16 + m_low * kHigh + m_high * kLow, bytes [C D A B]
            "clr  %A[acc]\n\t" "clr %B[acc]\n\t"
            "mul  %A[m], %A[kh]\n\t" "add %C[acc], r0\n\t" "adc %D[acc], r1\n\t" "adc %A[acc], %[z]\n\t" "adc %B[acc], %[z]\n\t"
            "mul  %B[m], %B[kh]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t"
            "mul  %B[m], %A[kh]\n\t" "add %D[acc], r0\n\t" "adc %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
            "mul  %A[m], %B[kh]\n\t" "add %D[acc], r0\n\t" "adc %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
            "mul  %C[m], %A[kl]\n\t" "add %C[acc], r0\n\t" "adc %D[acc], r1\n\t" "adc %A[acc], %[z]\n\t" "adc %B[acc], %[z]\n\t"
            "mul  %D[m], %B[kl]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t"
            "mul  %D[m], %A[kl]\n\t" "add %D[acc], r0\n\t" "adc %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
            "mul  %C[m], %B[kl]\n\t" "add %D[acc], r0\n\t" "adc %A[acc], r1\n\t" "adc %B[acc], %[z]\n\t"
            // hi = mid >> 16 + m_high * kHigh (< 2^24), bytes [A B C]
            "clr  %C[acc]\n\t"
            "mul  %C[m], %A[kh]\n\t" "add %A[acc], r0\n\t" "adc %B[acc], r1\n\t" "adc %C[acc], %[z]\n\t"
            "mul  %D[m], %B[kh]\n\t" "add %C[acc], r0\n\t"
            "mul  %D[m], %A[kh]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t"
            "mul  %C[m], %B[kh]\n\t" "add %B[acc], r0\n\t" "adc %C[acc], r1\n\t"
            // (hi + 2^7) >> 8 in bytes [B C]
            "lsl  %A[acc]\n\t" "adc %B[acc], %[z]\n\t" "adc %C[acc], %[z]\n\t"
            "clr  r1"
            : [acc] "=&r"(acc), [z] "=&r"(zero)
            : [m] "r"(m), [kl] "r"(kLow), [kh] "r"(kHigh));
    c = (uint16_t)(acc >> 8);
#else
    const uint16_t m_high = (uint16_t)(m >> 16), m_low = (uint16_t)m;  // m_high < 2^10
    const uint32_t lo = mul_u16(m_low, kLow);
    // < 2^29 + 2^26 + 2^16: no overflow.
    const uint32_t mid = mul_u16(m_low, kHigh) + mul_u16(m_high, kLow) + (lo >> 16);
    const uint32_t hi = mul_u16(m_high, kHigh) + (mid >> 16);
    // round(m K / 2^40) = (hi + 2^7) >> 8: the bits below hi cannot carry into it.
    c = (uint16_t)((hi + 0x80u) >> 8);
#endif
    return angle_q24 < 0 ? -(int32_t)c : (int32_t)c;
}

}  // namespace linalg
