// SPDX-License-Identifier: GPL-3.0-or-later
#include "Heading.h"

#include <math.h>

#include "Fixed.h"

namespace dcm {

using linalg::Vector3f;
using linalg::Vector3l;

namespace {
// A mag correction stands for the time since the previous sample, but never more
// than this many steps (after an outage the first sample must not make a jump).
constexpr uint16_t kMaxMagIntervalSteps = 20;
// A field sample's wait before it is used, counted in its latency up to this (steps).
constexpr uint8_t kMaxMagAgeSteps = 2;

// Q26 radians in Q16 (2^-10, rounded), saturated at +-0.5 rad.
int16_t q16_of(int32_t x_q26) {
    const int32_t q16 = linalg::opaque((x_q26 + 512) >> 8) >> 2;  // a byte, then two bits
    return (int16_t)(q16 > 32767 ? 32767 : (q16 < -32767 ? -32767 : q16));
}
// A Q21 change of a Q5 field in Q5 (rounded): the two high bytes.
int16_t q5_of(int32_t x_q21) { return (int16_t)((x_q21 + 0x8000) >> 16); }
int32_t row_times(const Vector3l& row, const linalg::Vector3i& v) {
    using linalg::q14_of;
    return linalg::mul_s16(q14_of(row.x), v.x) + linalg::mul_s16(q14_of(row.y), v.y) + linalg::mul_s16(q14_of(row.z), v.z);
}

// The recent disturbed field, for the new-field test, follows the samples with 53 ms
// (a fifth of the way at each 75 Hz sample); the learned field tracks slow changes
// (temperature, location) with 1.3 s.
constexpr float kCandidateTau_s = 0.053f;
constexpr float kReferenceTau_s = 1.32f;
constexpr int32_t kMaxFieldQ = (int32_t)(kMaxField_uT * (float)(1 << kFieldQ));
// The sums' units in uT.
constexpr float kEarthFieldPerUnit = 1.0f / (float)(1L << (kFieldQ + 14 - kEarthFieldShift));

// 1/n for the few window lengths there are, without a float division.
float inverse(uint8_t n) {
    switch (n) {
        case 1: return 1.0f;
        case 2: return 0.5f;
        case 3: return 1.0f / 3.0f;
        case 4: return 0.25f;
        case 5: return 0.2f;
        case 6: return 1.0f / 6.0f;
        default: return 1.0f / (float)n;
    }
}
}  // namespace

bool field_q5_of(const linalg::Vector3f& field_uT, linalg::Vector3i& field_q5) {
    if (!field_uT.is_finite()) return false;
    const float* in[3] = {&field_uT.x, &field_uT.y, &field_uT.z};
    int16_t* out[3] = {&field_q5.x, &field_q5.y, &field_q5.z};
    for (uint8_t i = 0; i < 3; ++i) {
        const int32_t q = linalg::fixed_from_float(*in[i], kFieldQ);
        if (q >= kMaxFieldQ || q <= -kMaxFieldQ) return false;
        *out[i] = (int16_t)q;
    }
    return true;
}

uint32_t field_norm2(const linalg::Vector3i& q5) {
    const int16_t* axis = &q5.x;
    uint32_t sum = 0;
    for (uint8_t i = 0; i < 3; ++i) sum += (uint32_t)linalg::mul_s16(axis[i], axis[i]) >> kNorm2Shift;
    return sum;
}

linalg::Vector3f field_uT_of(const linalg::Vector3i& field_q5) {
    return linalg::scaled(field_q5, 1.0f / (float)(1 << kFieldQ));
}

void EarthFieldMean::take(linalg::Vector3f& field_ef_uT, float& norm2_uT2) {
    const float inv_samples = inverse(samples_);
    field_ef_uT = field_sum_.scaled(inv_samples * kEarthFieldPerUnit);
    norm2_uT2 = (float)norm2_sum_ * (inv_samples * kFieldNorm2PerUnit_uT2);
    clear();
}

void MagneticGate::learn(float norm, float down_component) {
    ref_norm_ = candidate_norm_ = norm;
    ref_down_ = candidate_down_ = down_component;
}

bool MagneticGate::matches(float norm, float down_component, float ref_norm, float ref_down, float tolerance_scale,
                           const DcmSettings& settings) const {
    const float norm_tolerance = settings.mag_norm_tolerance * tolerance_scale * ref_norm;
    const float dip_tolerance = settings.mag_dip_tolerance * tolerance_scale;
    const float norm_error = norm - ref_norm;
    const float dip_error = down_component - ref_down;
    return norm_error < norm_tolerance && norm_error > -norm_tolerance && dip_error < dip_tolerance &&
           dip_error > -dip_tolerance;
}

FieldVerdict MagneticGate::judge(float norm, float down_component, uint16_t interval_steps, float sample_dt_s,
                                 const linalg::Vector3l& rate_units, const DcmSettings& settings, const DcmCoefficients& k) {
    bool forgotten = !(ref_norm_ > 0.0f);  // forget(): adopt this one
    if (forgotten && !take_heading_) {
        learn(norm, down_component);  // the strength and dip only; the heading as usual
        take_heading_ = true;
        forgotten = false;
    }
    if (forgotten || !matches(norm, down_component, ref_norm_, ref_down_, 1.0f, settings)) {
        // Only a field that stays the same while the board turns is shown to be fixed
        // in the earth frame: at rest any disturbance (a magnet on the desk, one fixed to
        // the board) is steady too. VQF's rule: a mean rate of 20 deg/s over the window.
        if (matches(norm, down_component, candidate_norm_, candidate_down_, 0.5f, settings)) {
            const linalg::Vector3f rate_rad_s = rate_units.scaled(k.gyro_rad_s_per_count * (1.0f / (float)kTurnScale));
            steady_steps_ += interval_steps;
            steady_turn_rad_ += sqrtf(rate_rad_s.length_squared()) * settings.step_s * (float)interval_steps;
        } else {
            steady_steps_ = 0;
            steady_turn_rad_ = 0.0f;
        }
        // candidate += alpha (field - candidate), alpha = dt / (tau + dt)
        const float candidate_alpha = sample_dt_s / (kCandidateTau_s + sample_dt_s);
        candidate_norm_ += candidate_alpha * (norm - candidate_norm_);
        candidate_down_ += candidate_alpha * (down_component - candidate_down_);
        if (!forgotten && (steady_steps_ < k.mag_recover_steps || steady_turn_rad_ < k.mag_new_min_turn_rad))
            return FieldVerdict::kDisturbed;
        learn(norm, down_component);
        steady_steps_ = 0;
        steady_turn_rad_ = 0.0f;
        return FieldVerdict::kNewField;
    }
    steady_steps_ = 0;
    steady_turn_rad_ = 0.0f;
    candidate_norm_ = norm;
    candidate_down_ = down_component;
    // Track slow changes of the local field (temperature, location): ~1.3 s at 75 Hz.
    // ref += alpha (field - ref), alpha = dt / tau (<= 0.08: first order)
    const float reference_alpha = sample_dt_s * (1.0f / kReferenceTau_s);
    ref_norm_ += reference_alpha * (norm - ref_norm_);
    ref_down_ += reference_alpha * (down_component - ref_down_);
    return FieldVerdict::kEarthField;
}

// In integers from here to the mean (~75 Hz): 16 bits, uT * 2^kFieldQ.
bool HeadingCorrection::add_sample(const linalg::Vector3i& field, uint32_t norm2, uint16_t interval_steps,
                                   uint8_t age_steps, const HeadingContext& ctx) {
    // The sample is older than the gyro-propagated attitude (the chip's averaging
    // and the wait for the next step): turn it forward by the rotation since, as a
    // fixed earth vector seen from the body moves, dm/dt = m x w.
    // The matrix itself is behind the last sample by the turn not yet integrated: the
    // field is brought back by that much (a fixed earth vector seen from the body
    // after a turn p reads v - p x v = v + v x p, so before it v x -p).
    // Both in the turn sums' units (the rate per step times the latency in steps, Q12,
    // less the pending turn), then in radians as the integration takes them.
    const uint8_t age = age_steps < kMaxMagAgeSteps ? age_steps : kMaxMagAgeSteps;
    const int16_t latency_q12 = (int16_t)(ctx.k.mag_latency_steps_q12 + (int16_t)((uint16_t)age << 12));
    const Vector3l& rate = ctx.rate_units;
    const Vector3l pending = ctx.strapdown.pending_units();
    const Vector3l turn(linalg::hot::mul_q14(latency_q12, rate.x) * 4 - pending.x, linalg::hot::mul_q14(latency_q12, rate.y) * 4 - pending.y,
                        linalg::hot::mul_q14(latency_q12, rate.z) * 4 - pending.z);
    // field + field x turn, the turn in Q16 radians (saturated at 0.5): Q21, then Q5 again.
    const Vector3l t = ctx.k.theta_q26_coarse(turn);
    const int16_t tx = q16_of(t.x), ty = q16_of(t.y), tz = q16_of(t.z);
    using linalg::mul_s16;
    // The change (Q21) in Q5, then added (a field within 1 000 uT and a turn within
    // 0.5 rad stay within 16 bits).
    const linalg::Vector3i field_now(
        (int16_t)(field.x + q5_of(mul_s16(field.y, tz) - mul_s16(field.z, ty))),
        (int16_t)(field.y + q5_of(mul_s16(field.z, tx) - mul_s16(field.x, tz))),
        (int16_t)(field.z + q5_of(mul_s16(field.x, ty) - mul_s16(field.y, tx))));
    // Tilt compensation: the field in earth axes; its horizontal part points to
    // magnetic north when the heading is right (eq. 31-33 in vector form).
    // The samples are averaged in earth axes over kHeadingSteps (a fixed earth field is
    // the same vector there whatever the board did meanwhile), and the heading is
    // corrected from their mean: each sample costs the rotation into earth axes, the
    // correction (correct) runs at 12.5 Hz.
    const linalg::Matrix3q30& r = ctx.strapdown.r();
    mean_.add(Vector3l(row_times(r.a, field_now) >> kEarthFieldShift, row_times(r.b, field_now) >> kEarthFieldShift,
                       row_times(r.c, field_now) >> kEarthFieldShift),
              norm2, interval_steps);
    return mean_.complete();
}

void turn_heading_at_once(linalg::Matrix3q30& r, float cos_error, float sin_error) {
    using linalg::mul_q30;
    const int32_t c = linalg::fixed_from_float(cos_error, linalg::kQ30);
    const int32_t sn = linalg::fixed_from_float(sin_error, linalg::kQ30);
    const Vector3l north(mul_q30(c, r.a.x) + mul_q30(sn, r.b.x), mul_q30(c, r.a.y) + mul_q30(sn, r.b.y),
                         mul_q30(c, r.a.z) + mul_q30(sn, r.b.z));
    r.b = Vector3l(mul_q30(c, r.b.x) - mul_q30(sn, r.a.x), mul_q30(c, r.b.y) - mul_q30(sn, r.a.y),
                   mul_q30(c, r.b.z) - mul_q30(sn, r.a.z));
    r.a = north;
}

void turn_heading(Strapdown& strapdown, float heading_error, float gain_1_s, float steps, const DcmCoefficients& k) {
    // Into the turn not yet integrated (applied with the next integration): the row in
    // 16 bits times the turn's size in units (kp error steps, at most 5 * 20 rad/s steps
    // = 2.4e7 units: within 31 bits).
    const int32_t size_units = linalg::fixed_from_float(-heading_error * gain_1_s * steps * k.units_per_rad_s, 0);
    using linalg::q14_of;
    const Vector3l& down = strapdown.r().c;
    strapdown.add_turn(Vector3l(linalg::mul_q14(q14_of(down.x), size_units), linalg::mul_q14(q14_of(down.y), size_units),
                                linalg::mul_q14(q14_of(down.z), size_units)));
}

// The heading's correction from a complete mean (kHeadingSteps steps, 12.5 Hz): out of
// line (FIXED_OWN_FRAME), so that its float locals stay out of the 75 Hz part's frame.
FIXED_OWN_FRAME HeadingResult HeadingCorrection::correct(const HeadingContext& ctx) {
    const DcmSettings& settings = ctx.settings;
    uint16_t interval_steps = mean_.steps();
    Vector3f field_ef;
    float norm2;
    mean_.take(field_ef, norm2);
    const float horizontal2 = field_ef.x * field_ef.x + field_ef.y * field_ef.y;
    ctx.trace.heading_mean(field_ef, norm2);
    // A field within ~6 deg of vertical: no heading.
    if (!(horizontal2 > 0.01f * norm2)) return HeadingResult{false, false};
    // (The integer inverse square root, to 1e-4: no sqrtf and no division, the float
    // library's dearest calls on the AVR.)
    const float inv_norm = linalg::inverse_sqrt(norm2);
    const float norm = norm2 * inv_norm;
    const float down_component = field_ef.z * inv_norm;
    const float inv_horizontal = linalg::inverse_sqrt(horizontal2);
    const float sin_error = field_ef.y * inv_horizontal;
    // The time this sample stands for (the low-passes below are in time, not samples).
    const float sample_dt = settings.step_s * (float)(interval_steps < kMaxMagIntervalSteps ? interval_steps : kMaxMagIntervalSteps);

    // Disturbance rejection (as VQF does): a field whose strength or dip differs
    // from the learned earth field is a magnet or iron nearby, not north, and is not
    // used; the heading then runs on the gyro. A different field that stays the same
    // for mag_recover_s is a new environment (the board was moved): it becomes the
    // reference, and its heading is taken at once. A magnet fixed to a rotating
    // board never looks the same twice, so it never gets in.
    const FieldVerdict verdict =
        gate_.judge(norm, down_component, interval_steps, sample_dt, ctx.rate_units, settings, ctx.k);
    ctx.trace.heading(verdict, gate_.ref_norm(), gate_.ref_down());
    if (verdict == FieldVerdict::kDisturbed) return HeadingResult{false, false};
    if (verdict == FieldVerdict::kNewField) {
        // Its heading at once (the rotation that puts the field's horizontal part on north).
        turn_heading_at_once(ctx.strapdown.r(), field_ef.x * inv_horizontal, sin_error);
        return HeadingResult{true, false};
    }

    // sin of the heading error, saturated to +-1 beyond 90 deg so it stays monotonic.
    const float heading_error = field_ef.x >= 0.0f ? sin_error : (sin_error >= 0.0f ? 1.0f : -1.0f);
    // The correction is a rotation about earth down by -error: in body axes that
    // is the third row of R. It stands for the whole interval since the last
    // correction, so its rate is scaled by interval / step.
    if (interval_steps > kMaxMagIntervalSteps) interval_steps = kMaxMagIntervalSteps;
    const float steps = (float)interval_steps;
    const bool starting = ctx.steps < ctx.k.startup_steps;
    // At start, while the board moves, the heading is a constant to find from means that
    // each carry their moment's tilt error through the dip: the mean of them all since the
    // start (or since the compass's calibration last moved) is its least-squares estimate,
    // the gain 1/t (VQF's kMagInit), within the start's kp_startup and the steady kp_yaw.
    // At rest there is no motion's error to average out, and a gyro bias not yet learned
    // would make a long mean lag: the start's gain.
    float gain_1_s = settings.kp_yaw_1_s;
    if (starting && ctx.at_rest) {
        gain_1_s = settings.kp_startup_1_s;
    } else if (starting) {
        const float since_s = (float)(uint16_t)(ctx.steps - mean_from_) * settings.step_s;
        float mean_gain_1_s = 1.0f / (since_s > sample_dt ? since_s : sample_dt);
        if (mean_gain_1_s > settings.kp_startup_1_s) mean_gain_1_s = settings.kp_startup_1_s;
        if (mean_gain_1_s > gain_1_s) gain_1_s = mean_gain_1_s;
    }
    turn_heading(ctx.strapdown, heading_error, gain_1_s, steps, ctx.k);
    const Vector3l& down = ctx.strapdown.r().c;
    // The compass's integral, while nothing else has measured the bias (GyroBias).
    ctx.trace.bias_before(ctx.bias, ctx.k);
    const bool learned = ctx.bias.learn_from_heading(down, heading_error, interval_steps, starting, settings, ctx.k);
    ctx.trace.bias_after(BiasSource::kHeading, ctx.bias, ctx.k);
    return HeadingResult{true, learned};
}

}  // namespace dcm
