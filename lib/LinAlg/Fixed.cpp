// SPDX-License-Identifier: GPL-3.0-or-later
// The tables of the fixed-point atan2 and hypot (Fixed.h, whose routines are inline).
#include "Fixed.h"

namespace linalg {

// The ordinary (called) forms of the hot list's inline helpers (Fixed.h).
int32_t fixed_from_float(float x, uint8_t frac_bits) { return hot::fixed_from_float(x, frac_bits); }
#ifdef __AVR__
// The called form in the registers the call brings its operands in (a in r22..r25,
// x in r18..r21, the result in r22..r25) and the call-clobbered r26, r27, r30, r31
// for the sum: no register to save, where the inline form's register choice makes a
// called copy save fourteen. The same sums as mul_u32_shr30 in another order: the
// products of a's and x's low bytes first, so that those two registers take the
// sum's two high bytes. The sign of the product waits in the T flag.
int32_t mul_q30(int32_t a, int32_t x) {
    register int32_t ra asm("r22") = a;
    register int32_t rx asm("r18") = x;
    __asm__(
        "mov  r26, %D[a]\n\t" "eor r26, %D[x]\n\t" "bst r26, 7\n\t"       // T: the product's sign
        "sbrs %D[a], 7\n\t" "rjmp 1f\n\t"                                   // a = |a|
        "com  %D[a]\n\t" "com %C[a]\n\t" "com %B[a]\n\t" "neg %A[a]\n\t"
        "sbci %B[a], 0xFF\n\t" "sbci %C[a], 0xFF\n\t" "sbci %D[a], 0xFF\n"
        "1:\n\t"
        "sbrs %D[x], 7\n\t" "rjmp 2f\n\t"                                   // x = |x|
        "com  %D[x]\n\t" "com %C[x]\n\t" "com %B[x]\n\t" "neg %A[x]\n\t"
        "sbci %B[x], 0xFF\n\t" "sbci %C[x], 0xFF\n\t" "sbci %D[x], 0xFF\n"
        "2:\n\t"
        // bytes 3, 4, 5 of the product in r26, r27, r30; r31 zero
        "clr  r26\n\t" "clr r27\n\t" "clr r30\n\t" "clr r31\n\t"
        // i + j = 2: the high bytes into byte 3
        "mul  %A[a], %C[x]\n\t" "add r26, r1\n\t" "adc r27, r31\n\t"
        "mul  %B[a], %B[x]\n\t" "add r26, r1\n\t" "adc r27, r31\n\t"
        "mul  %C[a], %A[x]\n\t" "add r26, r1\n\t" "adc r27, r31\n\t"
        // i + j = 3 at byte 3
        "mul  %A[a], %D[x]\n\t" "add r26, r0\n\t" "adc r27, r1\n\t" "adc r30, r31\n\t"
        "mul  %B[a], %C[x]\n\t" "add r26, r0\n\t" "adc r27, r1\n\t" "adc r30, r31\n\t"
        "mul  %C[a], %B[x]\n\t" "add r26, r0\n\t" "adc r27, r1\n\t" "adc r30, r31\n\t"
        "mul  %D[a], %A[x]\n\t" "add r26, r0\n\t" "adc r27, r1\n\t" "adc r30, r31\n\t"
        // a's and x's low bytes are done with: byte 6 in %A[x], byte 7 in %A[a]
        "clr  %A[x]\n\t" "clr %A[a]\n\t"
        // i + j = 4 at byte 4
        "mul  %B[a], %D[x]\n\t" "add r27, r0\n\t" "adc r30, r1\n\t" "adc %A[x], r31\n\t"
        "mul  %C[a], %C[x]\n\t" "add r27, r0\n\t" "adc r30, r1\n\t" "adc %A[x], r31\n\t"
        "mul  %D[a], %B[x]\n\t" "add r27, r0\n\t" "adc r30, r1\n\t" "adc %A[x], r31\n\t"
        // i + j = 5 at byte 5
        "mul  %C[a], %D[x]\n\t" "add r30, r0\n\t" "adc %A[x], r1\n\t" "adc %A[a], r31\n\t"
        "mul  %D[a], %C[x]\n\t" "add r30, r0\n\t" "adc %A[x], r1\n\t" "adc %A[a], r31\n\t"
        // i + j = 6 at byte 6
        "mul  %D[a], %D[x]\n\t" "add %A[x], r0\n\t" "adc %A[a], r1\n\t"
        // bits 30..61: (bytes 3..7) << 2, bytes 4..7
        "lsl  r26\n\t" "rol r27\n\t" "rol r30\n\t" "rol %A[x]\n\t" "rol %A[a]\n\t"
        "lsl  r26\n\t" "rol r27\n\t" "rol r30\n\t" "rol %A[x]\n\t" "rol %A[a]\n\t"
        "mov  %D[a], %A[a]\n\t" "mov %C[a], %A[x]\n\t" "mov %B[a], r30\n\t" "mov %A[a], r27\n\t"
        "brtc 3f\n\t"                                                         // the sign
        "com  %D[a]\n\t" "com %C[a]\n\t" "com %B[a]\n\t" "neg %A[a]\n\t"
        "sbci %B[a], 0xFF\n\t" "sbci %C[a], 0xFF\n\t" "sbci %D[a], 0xFF\n"
        "3:\n\t"
        "clr  r1"
        : [a] "+r"(ra), [x] "+r"(rx)
        :
        : "r26", "r27", "r30", "r31", "cc");
    return ra;
}
#else
int32_t mul_q30(int32_t a, int32_t x) { return hot::mul_q30(a, x); }
#endif
int32_t mul_q14(int16_t r, int32_t x) { return hot::mul_q14(r, x); }
int32_t mul_q14_unit(int16_t r, int32_t x) { return hot::mul_q14_unit(r, x); }

int32_t dot_q30(const Vector3l& r, const Vector3l& v) { return mul_q30(r.x, v.x) + mul_q30(r.y, v.y) + mul_q30(r.z, v.z); }

Vector3l cross_q30(const Vector3l& r, const Vector3l& v) {
    return Vector3l(mul_q30(r.y, v.z) - mul_q30(r.z, v.y), mul_q30(r.z, v.x) - mul_q30(r.x, v.z),
                    mul_q30(r.x, v.y) - mul_q30(r.y, v.x));
}

Vector3l mul_q30(const Matrix3q30& r, const Vector3l& v) { return Vector3l(dot_q30(r.a, v), dot_q30(r.b, v), dot_q30(r.c, v)); }

Vector3l fixed_from_vector(const Vector3f& v, uint8_t frac_bits) {
    return Vector3l(fixed_from_float(v.x, frac_bits), fixed_from_float(v.y, frac_bits), fixed_from_float(v.z, frac_bits));
}

Vector3f vector_from_fixed(const Vector3l& v, uint8_t frac_bits) {
    return Vector3f(float_from_fixed(v.x, frac_bits), float_from_fixed(v.y, frac_bits), float_from_fixed(v.z, frac_bits));
}

Vector3f vector_from_q30(const Vector3l& v) { return vector_from_fixed(v, kQ30); }

Matrix3q30 q30_from_matrix(const Matrix3f& m) {
    return Matrix3q30{fixed_from_vector(m.a, kQ30), fixed_from_vector(m.b, kQ30), fixed_from_vector(m.c, kQ30)};
}

Matrix3f matrix_from_q30(const Matrix3q30& m) {
    return Matrix3f(vector_from_q30(m.a), vector_from_q30(m.b), vector_from_q30(m.c));
}

// (The formats keep every shift to whole bytes, which are register moves on the AVR.)
uint16_t inverse_sqrt_q15(uint16_t xn) {
    // w = y/2 in Q16. The lines, minimax in relative error on [1/4, 1/2) and [1/2, 1):
    // y = 2.53 - 2.295 t and y = 1.7875 - 0.81 t, as w = a - b t with b t from a 16x16
    // product (b - 1 and t apart where b > 1).
    const bool low = xn < 0x8000u;
    uint32_t w = (low ? 82903u - xn : 58573u) - (mul_u16(low ? 9667u : 26542u, xn) >> 16);
    for (uint8_t i = 0; i < 2; ++i) {
        if (w > 0xFFFFu) w = 0xFFFFu;  // y = 2 is one beyond
        // Newton's step as w <- w + w g with g = (1 - t y^2)/2 = 1/2 - 2 t w^2 in Q16
        // (|g| < 0.03 from the lines): t w^2 in Q32 (< 2^31 then), g from its double.
        const uint32_t t_w2_q32 = mul_u16(xn, (uint16_t)(mul_u16((uint16_t)w, (uint16_t)w) >> 16));
        const int16_t g_q16 = (int16_t)(((int32_t)(0x80000000u - (t_w2_q32 << 1)) + 0x8000) >> 16);
        const uint32_t step = (mul_u16((uint16_t)w, (uint16_t)(g_q16 < 0 ? -g_q16 : g_q16)) + 0x8000u) >> 16;
        w = g_q16 < 0 ? w - step : w + step;
    }
    return (uint16_t)(w < 0x8000u ? 0x8000u : (w > 0xFFFFu ? 0xFFFFu : w));
}

uint32_t inverse_sqrt_q30(uint32_t x) {
    if (x == 0) return 0x7FFFFFFFu;
    // x = xn 2^-2h with xn in [2^14, 2^16): 2^30 / sqrt(x) = y_q15 2^(7 + h).
    int8_t h = 0;
    while (x >= 0x10000u) {
        x >>= 2;
        --h;
    }
    while (x < 0x4000u) {
        x <<= 2;
        ++h;
    }
    const uint32_t y_q15 = inverse_sqrt_q15((uint16_t)x);
    return h >= -7 ? y_q15 << (uint8_t)(7 + h) : y_q15 >> 1;
}

float inverse_sqrt(float x) {
    uint32_t bits;
    memcpy(&bits, &x, sizeof bits);
    const uint8_t biased = fixed_detail::bits_23_to_30(bits);
    if ((bits & 0x80000000u) || biased == 0 || biased == 0xFFu) return 0.0f;
    // x = s 2^e with the significand s in [1, 2); t = s/2 (e odd) or s/4 (e even), in
    // [1/4, 1) in Q16, and x = t 2^k with k = e + 1 or e + 2, even.
    const int16_t e = (int16_t)biased - 127;
    uint16_t xn = (uint16_t)((bits | 0x800000u) >> 8);  // s in Q15: t = s/2 in Q16
    int16_t k = (int16_t)(e + 1);
    if ((e & 1) == 0) {
        xn >>= 1;
        k = (int16_t)(e + 2);
    }
    // 1/sqrt(x) = y 2^(-k/2), y in [1, 2): the float's bits directly (y in Q15 has its
    // leading one at bit 15).
    const uint16_t y = inverse_sqrt_q15(xn);
    const uint32_t result = ((uint32_t)(uint16_t)(127 - k / 2) << 23) | ((uint32_t)(y & 0x7FFFu) << 8);
    float r;
    memcpy(&r, &result, sizeof r);
    return r;
}

namespace fixed_detail {

const uint8_t kPowersOfTwo[8] FIXED_PROGMEM = {1, 2, 4, 8, 16, 32, 64, 128};

// The tables live in flash (1.3 KB of the 256 KB: 1.3 KB of SRAM would be a sixth of
// it). Each entry is round(formula) with the formula beside it; test_fixed.cpp checks
// every entry against it. Linear interpolation between entries h apart errs by at most
// h^2/8 * max|f''|, stated per table.

// 1/d - 1 in Q16 at d = (1 + i/256)/2, i = 0..256, for the reciprocal of a divisor
// normalised into [1/2, 1): g(u) = (1 - u)/(1 + u). |g''| <= 4: interpolation error
// <= 7.6e-6 (half a count). The first entry, 65536, is stored as 65535.
const uint16_t kReciprocalMinusOne[257] FIXED_PROGMEM = {
    65535, 65026, 64520, 64018, 63520, 63025, 62534, 62047, 61564, 61084, 60608, 60136,
    59667, 59202, 58740, 58281, 57826, 57374, 56925, 56480, 56038, 55599, 55163, 54731,
    54301, 53875, 53451, 53031, 52613, 52199, 51787, 51378, 50972, 50569, 50169, 49771,
    49376, 48984, 48595, 48208, 47824, 47442, 47063, 46686, 46312, 45941, 45571, 45205,
    44840, 44479, 44119, 43762, 43407, 43054, 42704, 42356, 42010, 41667, 41325, 40986,
    40649, 40314, 39981, 39650, 39322, 38995, 38670, 38348, 38027, 37708, 37392, 37077,
    36764, 36453, 36144, 35837, 35532, 35228, 34926, 34626, 34328, 34032, 33737, 33445,
    33154, 32864, 32576, 32290, 32006, 31723, 31442, 31163, 30885, 30609, 30334, 30061,
    29789, 29519, 29251, 28984, 28718, 28454, 28191, 27930, 27671, 27413, 27156, 26900,
    26647, 26394, 26143, 25893, 25645, 25397, 25152, 24907, 24664, 24422, 24182, 23942,
    23705, 23468, 23232, 22998, 22765, 22533, 22303, 22073, 21845, 21618, 21393, 21168,
    20944, 20722, 20501, 20281, 20062, 19844, 19628, 19412, 19197, 18984, 18772, 18560,
    18350, 18141, 17933, 17726, 17520, 17314, 17110, 16907, 16705, 16504, 16304, 16105,
    15907, 15710, 15513, 15318, 15124, 14930, 14738, 14546, 14356, 14166, 13977, 13789,
    13602, 13416, 13230, 13046, 12862, 12679, 12498, 12317, 12136, 11957, 11778, 11601,
    11424, 11248, 11072, 10898, 10724, 10551, 10379, 10208, 10037, 9867, 9698, 9530,
    9362, 9195, 9029, 8864, 8699, 8536, 8372, 8210, 8048, 7887, 7727, 7567,
    7408, 7250, 7093, 6936, 6780, 6624, 6469, 6315, 6162, 6009, 5856, 5705,
    5554, 5404, 5254, 5105, 4957, 4809, 4662, 4515, 4369, 4224, 4079, 3935,
    3791, 3648, 3506, 3364, 3223, 3082, 2942, 2803, 2664, 2526, 2388, 2251,
    2114, 1978, 1842, 1707, 1573, 1439, 1305, 1173, 1040, 908, 777, 646,
    516, 386, 257, 128, 0,
};

// t - atan(t) in Q18 at t = j/256, j = 0..256 (max 1 - pi/4 = 0.2146). Storing the
// difference from t keeps atan exact to first order where it is small (pitch near
// +-90 deg: h/|R31| -> 0) and leaves a rounding of 1.9e-6 rad at most; |atan''| <=
// 0.65: interpolation error <= 1.3e-6 rad.
const uint16_t kTMinusAtan[257] FIXED_PROGMEM = {
    0, 0, 0, 0, 0, 1, 1, 2, 3, 4, 5, 7,
    9, 11, 14, 18, 21, 26, 30, 36, 42, 48, 55, 63,
    72, 81, 91, 102, 114, 126, 139, 154, 169, 185, 203, 221,
    240, 261, 282, 305, 329, 354, 380, 407, 436, 466, 497, 530,
    564, 600, 637, 675, 715, 756, 799, 843, 889, 937, 986, 1037,
    1089, 1143, 1199, 1257, 1316, 1377, 1440, 1505, 1572, 1640, 1710, 1783,
    1857, 1933, 2011, 2091, 2173, 2257, 2342, 2430, 2521, 2613, 2707, 2803,
    2902, 3002, 3105, 3210, 3317, 3426, 3538, 3652, 3768, 3886, 4007, 4129,
    4254, 4382, 4512, 4644, 4778, 4915, 5054, 5195, 5339, 5485, 5634, 5785,
    5939, 6095, 6253, 6414, 6577, 6743, 6911, 7082, 7255, 7431, 7609, 7789,
    7973, 8158, 8347, 8537, 8731, 8927, 9125, 9326, 9530, 9736, 9944, 10155,
    10369, 10586, 10805, 11026, 11250, 11477, 11706, 11938, 12172, 12409, 12649, 12891,
    13136, 13384, 13634, 13886, 14141, 14399, 14660, 14923, 15188, 15457, 15727, 16001,
    16277, 16555, 16836, 17120, 17407, 17695, 17987, 18281, 18578, 18877, 19179, 19483,
    19790, 20100, 20412, 20726, 21044, 21363, 21686, 22011, 22338, 22668, 23000, 23335,
    23673, 24013, 24355, 24700, 25048, 25398, 25751, 26106, 26463, 26823, 27186, 27551,
    27918, 28288, 28660, 29035, 29412, 29792, 30174, 30558, 30945, 31335, 31726, 32120,
    32517, 32916, 33317, 33721, 34127, 34535, 34946, 35359, 35774, 36192, 36612, 37035,
    37459, 37886, 38315, 38747, 39181, 39617, 40055, 40496, 40939, 41384, 41832, 42281,
    42733, 43187, 43643, 44102, 44563, 45025, 45490, 45958, 46427, 46898, 47372, 47848,
    48326, 48806, 49288, 49772, 50259, 50747, 51238, 51731, 52225, 52722, 53221, 53722,
    54225, 54730, 55237, 55746, 56257,
};

// sqrt(1 + t^2) - 1 in Q16 at t = j/128, j = 0..128 (max sqrt(2) - 1): |f''| <= 1,
// interpolation error <= 7.6e-6, relative to the hypotenuse.
const uint16_t kHypotMinusOne[129] FIXED_PROGMEM = {
    0, 2, 8, 18, 32, 50, 72, 98, 128, 162, 200, 242,
    287, 337, 391, 448, 510, 575, 645, 718, 795, 876, 961, 1050,
    1142, 1238, 1338, 1442, 1550, 1661, 1776, 1895, 2017, 2143, 2273, 2406,
    2543, 2683, 2827, 2974, 3125, 3280, 3438, 3599, 3764, 3932, 4104, 4278,
    4456, 4638, 4823, 5010, 5202, 5396, 5593, 5794, 5998, 6204, 6414, 6627,
    6843, 7062, 7283, 7508, 7735, 7966, 8199, 8435, 8674, 8916, 9160, 9407,
    9657, 9909, 10164, 10421, 10682, 10944, 11209, 11477, 11747, 12020, 12295, 12572,
    12852, 13134, 13418, 13705, 13994, 14285, 14579, 14874, 15172, 15472, 15774, 16078,
    16384, 16692, 17002, 17315, 17629, 17945, 18263, 18583, 18905, 19229, 19555, 19882,
    20211, 20542, 20875, 21210, 21546, 21884, 22224, 22565, 22908, 23253, 23599, 23947,
    24296, 24647, 25000, 25354, 25709, 26066, 26425, 26785, 27146,
};

}  // namespace fixed_detail

}  // namespace linalg
