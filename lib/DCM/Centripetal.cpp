// SPDX-License-Identifier: GPL-3.0-or-later
#include "Centripetal.h"

#include "Fixed.h"

namespace dcm {

namespace {

int32_t within(int32_t x, LateralBounds b) { return x < b.lo ? b.lo : (x > b.hi ? b.hi : x); }
int32_t within(int32_t x, int32_t limit) { return x < -limit ? -limit : (x > limit ? limit : x); }

// A window's omega V (counts): the rate's mean over the window (rounded to a count:
// 0.06 deg of bank at 18 m/s) times the gain, in 16 bits (below 2^13 up to 60 m/s),
// times n.
int32_t times_gain(int32_t rate_sum, uint8_t n, int16_t gain_q8) {
    return times_n(linalg::mul_s16((int16_t)within(per_sample(rate_sum, n), 32767), gain_q8) >> 8, n);
}

// A mean's step, (sum - mean) / 32 (TurnMean::kMeanShift): the high three bytes times
// 8, not a loop of five shifts (the step's lowest bits, 1/32 of a count, are dropped).
int32_t step_of_mean(int32_t difference_q8) {
    static_assert(TurnMean::kMeanShift == 5, "a byte's shift less five");
    return (difference_q8 >> 8) * 8;
}

}  // namespace

LateralBounds lateral_bounds(int32_t a_y, int32_t margin) {
    return LateralBounds{(a_y < 0 ? a_y : 0) - margin, (a_y > 0 ? a_y : 0) + margin};
}

// g sin(kTurnBankMargin_deg): sin(0.5 deg) = 143 / 2^14.
static_assert(kTurnBankMargin_deg == 0.5f, "143 / 2^14 is sin(kTurnBankMargin_deg)");
constexpr int16_t kSinMarginQ14 = 143;
// g sin(kTurnMinBank_deg): sin(5 deg) = 1428 / 2^14.
static_assert(kTurnMinBank_deg == 5.0f, "1428 / 2^14 is sin(kTurnMinBank_deg)");
constexpr int16_t kSinTurnQ14 = 1428;

void TurnMean::configure(int16_t gain_q8, int16_t gravity_counts, int16_t dv_dt_counts) {
    gain_q8_ = gain_q8;
    dv_dt_counts_ = dv_dt_counts;
    gravity_counts_x4_ = (int16_t)(gravity_counts * 4);
}

int16_t TurnMean::gravity_times(int16_t sin_q14) const {
    // (4 g sin 2^14) / 2^16 rounded: g sin, as (g sin 2^14 + 2^13) >> 14.
    return (int16_t)((linalg::mul_s16(gravity_counts_x4_, sin_q14) + 32768) >> 16);
}

TurnMean::AxisBound TurnMean::axis_bound(int32_t f_sum, int32_t down_q30, uint8_t n) const {
    // a = f + g down, and the margin with the scale error's share, g |down| / 32 (3.1 %:
    // at least g cos(roll) 0.03 roll).
    static_assert(kTurnBankScaleError <= 1.0f / 32.0f, "g |down| / 32 covers kTurnBankScaleError");
    // (down Q14 times 4 g, >> 16: the high bytes, no shift loop.)
    const int16_t gravity = (int16_t)(linalg::mul_s16((int16_t)(down_q30 >> 16), gravity_counts_x4_) >> 16);
    return AxisBound{f_sum + times_n(gravity, n),
                     times_n(gravity_times(kSinMarginQ14) + ((gravity < 0 ? -gravity : gravity) >> 5), n)};
}

int32_t TurnMean::lateral_sum(int32_t raw_sum, int32_t f_y_sum, int32_t down_y_q30, uint8_t n) {
    // Beyond 2^21 counts a window (500 g) is no turn: held, so the means stay in 32 bits.
    const int32_t raw = within(raw_sum, 1L << 21);
    const AxisBound y = axis_bound(f_y_sum, down_y_q30, n);
    const int32_t clipped = within(raw, lateral_bounds(y.a, y.margin));
    // mean += (sum - mean) / 32, Q8; the first window is the means.
    if (!started_) {
        started_ = true;
        raw_q8_ = raw * 256;
        a_y_q8_ = y.a * 256;
        clipped_q8_ = clipped * 256;
    }
    raw_q8_ += step_of_mean(raw * 256 - raw_q8_);
    a_y_q8_ += step_of_mean(y.a * 256 - a_y_q8_);
    clipped_q8_ += step_of_mean(clipped * 256 - clipped_q8_);
    // Straight flight (a_y's mean within the least turn's): no turn to give back to.
    const int32_t turn_q8 = times_n(gravity_times(kSinTurnQ14), n) * 256;
    if (a_y_q8_ < turn_q8 && a_y_q8_ > -turn_q8) return clipped;
    const int32_t mean_bounded_q8 = within(raw_q8_, lateral_bounds(a_y_q8_, y.margin * 256));
    return clipped + ((mean_bounded_q8 - clipped_q8_) >> 8);
}

FIXED_COLD void TurnMean::update(const linalg::Vector3l& down_q30, uint8_t n, const linalg::Vector3l& f_sum,
                                 uint8_t window, bool start_tilt) {
    if ((window & 7u) == 0u) update_longitudinal(down_q30.x, n, f_sum.x);
    // Four samples' worth of the means since the last update: kUpdateEvery windows'
    // (times 2), or the first window's alone (times 4).
    static_assert(kUpdateEvery == 2, "two windows' means a sample are two samples' worth");
    const uint8_t shift = started_ ? 1 : 2;
    // (Shifted unsigned: a left shift of a negative value is undefined.)
    const int32_t rate_y = (int32_t)((uint32_t)rate_y_means_ << shift), rate_z = (int32_t)((uint32_t)rate_z_means_ << shift),
                  f_y = (int32_t)((uint32_t)f_y_means_ << shift);
    rate_y_means_ = rate_z_means_ = f_y_means_ = 0;
    // Each held within the accelerometer's full scale a sample.
    const int32_t full_scale = 4L * 32767;
    // The start's tilt is no witness of bank (Centripetal.h): a_y is f_y alone then.
    const int32_t down_y_q30 = start_tilt ? 0 : down_q30.y;
    const int32_t lateral = within(lateral_sum(times_gain(rate_z, 4, gain_q8_), f_y, down_y_q30, 4), full_scale);
    const int32_t normal = within(times_gain(rate_y, 4, gain_q8_), full_scale);
    term_.y = (int16_t)per_sample(lateral, 4);
    term_.z = (int16_t)-per_sample(normal, 4);
}

FIXED_COLD void TurnMean::update_longitudinal(int32_t down_x_q30, uint8_t n, int32_t f_x_sum) {
    const AxisBound x = axis_bound(f_x_sum, down_x_q30, n);
    // dV/dt in 16 bits: within the full scale a sample as it is.
    term_.x = (int16_t)per_sample(within(times_n(dv_dt_counts_, n), lateral_bounds(x.a, x.margin)), n);
}

}  // namespace dcm
