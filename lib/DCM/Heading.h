// SPDX-License-Identifier: GPL-3.0-or-later
// The heading correction (VQF's updateMag; Premerlani & Bizard eqs. 31-33), a part of
// the estimator with its gate. Each field sample is brought up to date (its latency
// turn), turned into earth axes (tilt compensation) and summed (EarthFieldMean); every
// kHeadingSteps the mean's horizontal part gives the heading error, which goes into the
// turn not yet integrated, or teaches the bias (GyroBias: the compass's integral) while
// nothing else has measured it. The magnetic disturbance gate (MagneticGate) comes
// first: a field whose strength or dip differs from the learned earth field is a magnet
// or iron nearby, not north, and is not used; a different field that stays the same for
// mag_recover_s while the board turns is a new environment and becomes the reference,
// its heading taken at once.
//
// Formats: a field sample in 16 bits, uT * 2^kFieldQ (Q5); the latency turn in Q16
// radians; R in 16 bits (Q14) where it turns the field into earth axes; the sums in
// integers (the earth-frame field in uT * 2^(kFieldQ + 14 - kEarthFieldShift), the
// squared strengths in uT^2 * 2^(2 kFieldQ - kNorm2Shift)); the mean, the gate and the
// heading error in float (uT; the dip as a sine): they run at 12.5 Hz.
#pragma once

#include <stdint.h>

#include "Coefficients.h"
#include "GyroBias.h"
#include "Strapdown.h"
#include "Trace.h"

namespace dcm {

// The sums' shifts: eight samples' sums within 32 bits.
constexpr uint8_t kNorm2Shift = 4;
constexpr uint8_t kEarthFieldShift = 2;

// A field sample in the heading's integer form, uT * 2^kFieldQ in 16 bits: false for
// NaN or an axis at or beyond kMaxField_uT (no compass reads that: garbage). Made once
// where a sample arrives: the range check, the DCM and the rest test all take this form.
bool field_q5_of(const linalg::Vector3f& field_uT, linalg::Vector3i& field_q5);
// Its squared strength in the sums' units (uT^2 * 2^(2 kFieldQ - kNorm2Shift)).
uint32_t field_norm2(const linalg::Vector3i& field_q5);
// The integer form in uT.
linalg::Vector3f field_uT_of(const linalg::Vector3i& field_q5);
// ... in uT^2.
constexpr float kFieldNorm2PerUnit_uT2 = (float)(1L << kNorm2Shift) / (float)(1L << (2 * kFieldQ));

class EarthFieldMean {
public:
    // One sample: the field in earth axes (sum units), its squared strength (sum units),
    // and the steps since the previous sample.
    void add(const linalg::Vector3l& earth_field, uint32_t norm2, uint16_t steps) {
        field_sum_ += earth_field;
        norm2_sum_ += norm2;
        ++samples_;
        steps_ = (uint16_t)(steps_ + steps);
    }
    // The samples stand for kHeadingSteps or more: the mean is due.
    bool complete() const { return steps_ >= kHeadingSteps; }
    // ... after `steps` more steps and one more sample.
    bool complete_after(uint16_t steps) const { return (uint16_t)(steps_ + steps + 1u) >= kHeadingSteps; }
    uint16_t steps() const { return steps_; }
    // The mean field in earth axes (uT) and the samples' mean squared strength (uT^2:
    // the field's strength is the same in every frame; the mean vector's is shorter where
    // the samples differ); the sums start again.
    void take(linalg::Vector3f& field_ef_uT, float& norm2_uT2);
    // Forgets the sums; the next sample closes a mean alone.
    void restart_with_one_sample() {
        clear();
        steps_ = kHeadingSteps - 1;
    }
    void clear() {
        field_sum_ = linalg::Vector3l();
        norm2_sum_ = 0;
        samples_ = 0;
        steps_ = 0;
    }

private:
    linalg::Vector3l field_sum_;  // field samples in earth axes (sum units)
    uint32_t norm2_sum_ = 0;      // ... and their squared strengths (sum units)
    uint8_t samples_ = 0;
    uint16_t steps_ = 0;          // steps the summed samples stand for
};

enum class FieldVerdict : uint8_t {
    kDisturbed,   // not the earth's field: the heading runs on the gyro
    kNewField,    // a new steady field, now the reference: take its heading at once
    kEarthField,  // the learned earth field (tracked): correct the heading from it
};

class MagneticGate {
public:
    // Forgets the learned strength and dip: the next field is the reference. take_heading:
    // its heading at once too (a new compass calibration), else at the usual rate.
    void forget(bool take_heading) {
        ref_norm_ = 0.0f;
        take_heading_ = take_heading;
    }
    // A start: a new field's steadiness is counted again (the turn meanwhile is kept).
    void restart_steady_count() { steady_steps_ = 0; }
    // A field's strength (uT) and dip (its down component over its strength) as the
    // reference.
    void learn(float norm, float down_component);
    // The learned strength (uT, 0: forgotten) and sine of the dip (host tools: the trace).
    float ref_norm() const { return ref_norm_; }
    float ref_down() const { return ref_down_; }
    // One mean field: its strength, dip, the steps it stands for and the time they take
    // (s, capped), and the gyro's rate meanwhile (units per step).
    FieldVerdict judge(float norm, float down_component, uint16_t interval_steps, float sample_dt_s,
                       const linalg::Vector3l& rate_units, const DcmSettings& settings, const DcmCoefficients& k);

private:
    bool matches(float norm, float down_component, float ref_norm, float ref_down, float tolerance_scale,
                 const DcmSettings& settings) const;

    float ref_norm_ = 0.0f;           // learned field strength, uT (0: forgotten)
    bool take_heading_ = true;        // forget()'s take_heading
    float ref_down_ = 0.0f;           // learned sine of the dip (field . down / |field|)
    float candidate_norm_ = 0.0f;     // the recent disturbed field, for the new-field test
    float candidate_down_ = 0.0f;
    uint16_t steady_steps_ = 0;       // how long a different field has stayed the same
    float steady_turn_rad_ = 0.0f;    // how far the board turned meanwhile
};

// What the heading correction reads and turns of the estimator around it, for one
// field sample (built by Dcm; the part keeps no pointer to it).
struct HeadingContext {
    const DcmSettings& settings;
    const DcmCoefficients& k;
    Strapdown& strapdown;         // R (a new field's heading turns it at once) and the turn not yet integrated
    GyroBias& bias;               // the compass's integral
    linalg::Vector3l rate_units;  // the last sample's corrected rate (units per step)
    uint16_t steps;               // steps since the start (the start-up's clock)
    bool at_rest;                 // RestDetector's verdict: the start's gain
    TraceHook trace;              // what the correction did, for the host's trace
};

// What a heading correction did, for the estimator's status and what its step subtracts.
struct HeadingResult {
    bool field_used;    // the mean was the earth field (tracked or new): the heading follows it
    bool bias_learned;  // the compass's integral changed the bias estimate
};

// The heading turned at once by an error (the estimate's heading less the reference's,
// by its cosine and sine): R <- Rz(-error) R (a new field's, the first GPS course).
void turn_heading_at_once(linalg::Matrix3q30& r, float cos_error, float sin_error);
// A heading error (its sine, saturated at +-1 beyond 90 deg) corrected at gain_1_s over
// `steps` steps: the rotation about earth down by -error gain steps dt, into the turn not
// yet integrated (in body axes earth down is R's third row).
void turn_heading(Strapdown& strapdown, float heading_error, float gain_1_s, float steps, const DcmCoefficients& k);

// A compass sample at least this recent (steps) watches the rest (75 Hz: 2-3 steps).
constexpr uint16_t kRestCompassSteps = 20;

class HeadingCorrection {
public:
    // A start (Dcm::init): no sample in the mean, a new field's steadiness counted again,
    // the start's heading mean from step 0.
    void restart() {
        gate_.restart_steady_count();
        mean_.clear();
        mean_from_ = 0;
    }
    // The start's field: its strength (uT) and dip (its down component over its strength)
    // become the reference.
    void learn_field(float norm, float down_component) { gate_.learn(norm, down_component); }
    // Forgets the learned earth field (strength and dip): the next field sample is taken
    // as the reference; take_heading: its heading too, at once (MagneticGate::forget).
    // The samples waiting for the heading's mean were calibrated the old way: the next
    // sample closes the mean alone (the heading has run on the gyro meanwhile, and one
    // sample gives the new reference and the heading's error at once, a whole mean
    // sooner), and the start's mean begins again at `steps`.
    void forget_field(bool take_heading, uint16_t steps) {
        gate_.forget(take_heading);
        mean_.restart_with_one_sample();
        restart_mean(steps);
    }
    // The compass's calibration moved: during the start-up the heading's mean (its gain
    // 1/t) begins again at `steps`.
    void restart_mean(uint16_t steps) { mean_from_ = steps; }

    // A step: the time since the last sample, saturated.
    void count_step() {
        if (steps_since_sample_ < 0xFFFF) ++steps_since_sample_;
    }
    // A sample arrived, usable or not: the steps since the previous one, and the count
    // starts again.
    uint16_t take_interval() {
        const uint16_t steps = steps_since_sample_;
        steps_since_sample_ = 0;
        return steps;
    }
    // A sample came within kRestCompassSteps: the compass watches the rest (Rest.h).
    bool sample_recent() const { return steps_since_sample_ < kRestCompassSteps; }
    // The next sample, one step from now, completes the mean: the costly part is due.
    bool due_after_next_step() const { return mean_.complete_after(steps_since_sample_); }

    // One field sample (uT Q5, body axes; norm2 its squared strength, field_norm2), which
    // arrived interval_steps after the previous one and waited age_steps before this
    // call: brought up to date (its latency turn), into earth axes and the mean (75 Hz).
    // True when the mean is complete: correct() is due.
    bool add_sample(const linalg::Vector3i& field_q5, uint32_t norm2, uint16_t interval_steps, uint8_t age_steps,
                    const HeadingContext& ctx);
    // The complete mean through the gate, and the heading corrected from it (12.5 Hz).
    HeadingResult correct(const HeadingContext& ctx);

private:
    EarthFieldMean mean_;              // the field samples in earth axes
    MagneticGate gate_;                // which means are the earth field
    uint16_t steps_since_sample_ = 0;  // since the last field sample, saturated
    uint16_t mean_from_ = 0;           // the step the start's heading mean began at
};

}  // namespace dcm
