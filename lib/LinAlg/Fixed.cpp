#include "Fixed.h"

// -O2 here (the build is -Os): at -Os avr-gcc calls its register-saving prologue and
// epilogue routines and keeps the small helpers out of line; -O2 saves ~120 cycles per
// atan2 on the output path for ~1 KB of flash.
#ifdef __AVR__
#pragma GCC optimize("O2")
#endif

#ifdef __AVR__
#include <avr/pgmspace.h>
#define FIXED_PROGMEM PROGMEM
#else
#define FIXED_PROGMEM
#endif

namespace linalg {

using fixed_detail::bits_23_to_30;
using fixed_detail::bits_7_to_22;
using fixed_detail::byte3;

namespace {

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

// 16x16->32 with avr-gcc's widening multiply (__umulhisi3, ~25 cycles). Not inline:
// inlined, gcc sees through (uint16_t)(x >> 16) and calls its 32x32 routine (~105).
__attribute__((noinline)) uint32_t mul16(uint16_t a, uint16_t b) { return (uint32_t)a * (uint32_t)b; }

// (x * g) >> 16 for a 32-bit x and a 16-bit g: two 16x16->32 multiplies (avr-gcc
// would call its 32x32 routine, ~105 cycles, for the plain product, and lose the top).
FIXED_INLINE uint32_t mul_u32_u16_shr16(uint32_t x, uint16_t g) {
    return mul16((uint16_t)(x >> 16), g) + (mul16((uint16_t)x, g) >> 16);
}

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
    return ((uint32_t)lo << 16) + mul16(step, f);
}
FIXED_INLINE uint32_t interpolate_down(const uint16_t* table, uint16_t i, uint16_t f) {
    const uint16_t hi = entry(table, i);
    const uint16_t step = (uint16_t)(hi - entry(table, (uint16_t)(i + 1u)));
    return ((uint32_t)hi << 16) - mul16(step, f);
}

}  // namespace

__attribute__((noinline)) int32_t mul_s16(int16_t a, int16_t b) { return (int32_t)a * (int32_t)b; }

int32_t atan_of_ratio_q24(uint32_t num, uint32_t den, uint32_t* ratio_q31) {
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
    const uint16_t i = bits_23_to_30(den);
    const uint16_t f = bits_7_to_22(den);
    const uint16_t g = (uint16_t)(interpolate_down(kReciprocalMinusOne, i, f) >> 16);
    // t = (num / 2^32) / d = n (1 + g) in Q31.
    const uint32_t n_q31 = num >> 1;
    uint32_t t_q31 = n_q31 + mul_u32_u16_shr16(n_q31, g);
    if (t_q31 >= 0x80000000u) t_q31 = 0x80000000u;  // num = den (interpolation rounding)
    if (ratio_q31) *ratio_q31 = t_q31;
    if (t_q31 == 0x80000000u) return kQuarterPiQ24;
    // atan(t) = t - (t - atan(t)), the table at j = t*256.
    const uint16_t j = bits_23_to_30(t_q31);  // t_q31 < 2^31: j <= 255
    const uint16_t fj = bits_7_to_22(t_q31);
    const uint32_t t_minus_atan_q34 = interpolate_up(kTMinusAtan, j, fj);
    const uint32_t atan_q32 = (t_q31 << 1) - (t_minus_atan_q34 >> 2);
    return (int32_t)((atan_q32 + 0x80u) >> 8);
}

int32_t atan2_q24(bool y_negative, uint32_t y_magnitude, bool x_negative, uint32_t x_magnitude,
                  uint32_t* ratio_q31) {
    // Fold into the first octant, as fast_atan2 does: a = atan(min/max).
    const bool steep = y_magnitude > x_magnitude;
    int32_t a = steep ? atan_of_ratio_q24(x_magnitude, y_magnitude, ratio_q31)
                      : atan_of_ratio_q24(y_magnitude, x_magnitude, ratio_q31);
    if (steep) a = kHalfPiQ24 - a;
    if (x_negative && x_magnitude != 0) a = kPiQ24 - a;
    return y_negative && y_magnitude != 0 ? -a : a;
}

int32_t centideg_from_q24(int32_t angle_q24) {
    // m * K / 2^40 with m = |a| < 2^26 and K = round(18000/pi * 2^16) = 375493621 <
    // 2^29, from 16-bit halves: m K = hi 2^32 + (mid mod 2^16) 2^16 + (lo mod 2^16).
    constexpr uint16_t kHigh = 5729, kLow = 37877;  // K = 5729 * 2^16 + 37877
    const uint32_t m = magnitude(angle_q24);
    const uint16_t m_high = (uint16_t)(m >> 16), m_low = (uint16_t)m;  // m_high < 2^10
    const uint32_t lo = mul16(m_low, kLow);
    // < 2^29 + 2^26 + 2^16: no overflow.
    const uint32_t mid = mul16(m_low, kHigh) + mul16(m_high, kLow) + (lo >> 16);
    const uint32_t hi = mul16(m_high, kHigh) + (mid >> 16);
    // round(m K / 2^40) = (hi + 2^7) >> 8: the bits below hi cannot carry into it.
    const uint16_t c = (uint16_t)((hi + 0x80u) >> 8);
    return angle_q24 < 0 ? -(int32_t)c : (int32_t)c;
}

uint32_t hypot_from_ratio(uint32_t larger, uint32_t ratio_q31) {
    uint16_t s;
    if (ratio_q31 >= 0x80000000u) {
        s = entry(kHypotMinusOne, 128);
    } else {
        const uint16_t j = byte3(ratio_q31);
        const uint16_t fj = (uint16_t)(ratio_q31 >> 8);
        s = (uint16_t)(interpolate_up(kHypotMinusOne, j, fj) >> 16);
    }
    return larger + mul_u32_u16_shr16(larger, s);
}

}  // namespace linalg
