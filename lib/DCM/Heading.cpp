// SPDX-License-Identifier: GPL-3.0-or-later
#include "Heading.h"

#include <math.h>

#include "Fixed.h"

namespace dcm {

namespace {
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

}  // namespace dcm
