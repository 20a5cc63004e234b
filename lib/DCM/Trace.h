// SPDX-License-Identifier: GPL-3.0-or-later
// What the estimator's corrections did on a step, for the host's `replay --trace`
// (which corrections ran and why, while the board moves): the record (DcmTrace) and
// the one hook the estimator writes it through (TraceHook), handed to each part in its
// context. Host only: with DCM_TRACE 0 (the AVR, and `make mutate`: instrumentation, not
// the estimator) the hook holds nothing and every call returns at once, so the
// firmware's code and RAM are the same with or without it. The estimator only writes
// here, never reads back: the estimate is the same whether a trace is attached or not.
#pragma once

#ifndef DCM_TRACE
#ifdef __AVR__
#define DCM_TRACE 0
#else
#define DCM_TRACE 1
#endif
#endif

#include <math.h>
#include <stdint.h>

#include "Coefficients.h"
#include "GyroBias.h"
#include "LinAlg.h"

namespace dcm {

// What the gravity correction did on a step.
enum class GravityEvent : uint8_t {
    kNotDue,        // not a correction step (every kCorrectionDivider): the last one's rate is applied
    kRan,           // worked out: the low-pass's direction against earth down
    kNoDirection,   // the low-pass shorter than g/2: no correction (zero)
};

// Which way the heading correction went on a step.
enum class HeadingEvent : uint8_t {
    kNotDue,        // no complete field mean this step
    kTooVertical,   // the mean field within ~6 deg of vertical: no heading from it
    kDisturbed,     // the gate: strength or dip differ from the learned field
    kNewField,      // the gate: a new steady field, its heading taken at once
    kUsed,          // the learned earth field: the heading corrected from it
};

// What changed the bias estimate.
enum class BiasSource : uint8_t { kGravity, kHeading, kRest };

struct DcmTrace {
    // Cleared by the caller before each step (reset_step); filled through TraceHook.
    GravityEvent gravity = GravityEvent::kNotDue;
    bool integrator_held = false;          // rotating fast or starting: no bias learning
    float gravity_kp_1_s = 0.0f;           // the gain the correction used (start-up ramp)
    float tilt_error_n_rad = 0.0f;         // the low-pass's direction error, estimated earth axes
    float tilt_error_e_rad = 0.0f;         // (kept from the last correction)
    HeadingEvent heading = HeadingEvent::kNotDue;
    float heading_error_deg = 0.0f;        // the last field mean's horizontal angle from north (atan2)
    float field_norm_uT = 0.0f;            // the last mean's strength and dip (deg), and the reference's
    float field_dip_deg = 0.0f;
    float ref_norm_uT = 0.0f;
    float ref_dip_deg = 0.0f;
    // The bias estimate's changes, summed since the start, by source (rad/s, body axes).
    linalg::Vector3f bias_from_gravity_rad_s;  // the tilt integrator (ki_rp)
    linalg::Vector3f bias_from_heading_rad_s;  // the compass integrator (ki_yaw)
    linalg::Vector3f bias_from_rest_rad_s;     // the rest mean
    linalg::Vector3f bias_before_rad_s;        // TraceHook::bias_before's, for the change by source

    void reset_step() {
        gravity = GravityEvent::kNotDue;
        heading = HeadingEvent::kNotDue;
    }
};

// (The casts: avr-libc's float functions are its double ones, 32 bits; the bodies compile
// there too, and return before any of them runs.)
class TraceHook {
public:
#if DCM_TRACE
    TraceHook() : trace_(nullptr) {}
    explicit TraceHook(DcmTrace* trace) : trace_(trace) {}
#endif

    // A gravity correction about to turn the estimate: the low-pass (earth axes, accel
    // units) against earth down, whether the bias integrator is held, and the start-up
    // ramp's share left (the gain).
    void gravity(const linalg::Vector3l& low_pass_ef, bool integrator_held, float startup_left,
                 const DcmSettings& settings, const DcmCoefficients& k) const {
        if (trace_ == nullptr) return;
        const linalg::Vector3f lp = low_pass_ef.scaled(k.accel_m_s2_per_count * (1.0f / 256.0f));
        const float lp_norm = (float)sqrtf(lp.length_squared());
        const bool direction = lp_norm > 0.5f * kGravity_m_s2;
        trace_->gravity = direction ? GravityEvent::kRan : GravityEvent::kNoDirection;
        trace_->integrator_held = integrator_held;
        trace_->gravity_kp_1_s = settings.kp_rp_1_s + (settings.kp_startup_1_s - settings.kp_rp_1_s) * startup_left;
        trace_->tilt_error_n_rad = direction ? -lp.y / lp_norm : 0.0f;
        trace_->tilt_error_e_rad = direction ? lp.x / lp_norm : 0.0f;
    }
    // A complete field mean (earth axes, uT) and its mean squared strength (uT^2), before
    // the gate: no heading from it unless heading() follows.
    void heading_mean(const linalg::Vector3f& field_ef, float norm2) const {
        if (trace_ == nullptr) return;
        trace_->heading = HeadingEvent::kTooVertical;
        trace_->heading_error_deg = (float)atan2f(field_ef.y, field_ef.x) * (1.0f / linalg::kRadPerDeg);
        trace_->field_norm_uT = (float)sqrtf(norm2);
        trace_->field_dip_deg =
            (float)asinf(fminf(1.0f, fmaxf(-1.0f, field_ef.z / (float)sqrtf(norm2)))) * (1.0f / linalg::kRadPerDeg);
    }
    // The gate's verdict on it (MagneticGate's FieldVerdict: a template, as Heading.h
    // includes this file), and the learned field's strength (uT) and dip (its sine).
    template <class Verdict>
    void heading(Verdict verdict, float ref_norm_uT, float ref_down) const {
        if (trace_ == nullptr) return;
        trace_->heading = verdict == Verdict::kDisturbed  ? HeadingEvent::kDisturbed
                          : verdict == Verdict::kNewField ? HeadingEvent::kNewField
                                                          : HeadingEvent::kUsed;
        trace_->ref_norm_uT = ref_norm_uT;
        trace_->ref_dip_deg = (float)asinf(fminf(1.0f, fmaxf(-1.0f, ref_down))) * (1.0f / linalg::kRadPerDeg);
    }
    // Around a change of the bias estimate by `source`: its change, in rad/s.
    void bias_before(const GyroBias& bias, const DcmCoefficients& k) const {
        if (trace_ == nullptr) return;
        trace_->bias_before_rad_s = bias.estimate_rad_s(k);
    }
    void bias_after(BiasSource source, const GyroBias& bias, const DcmCoefficients& k) const {
        if (trace_ == nullptr) return;
        linalg::Vector3f& sum = source == BiasSource::kGravity   ? trace_->bias_from_gravity_rad_s
                                : source == BiasSource::kHeading ? trace_->bias_from_heading_rad_s
                                                                 : trace_->bias_from_rest_rad_s;
        sum += bias.estimate_rad_s(k) - trace_->bias_before_rad_s;
    }

private:
#if DCM_TRACE
    DcmTrace* trace_;
#else
    // The firmware's hook holds nothing: every call returns at once, and compiles to nothing.
    static constexpr DcmTrace* trace_ = nullptr;
#endif
};

}  // namespace dcm
