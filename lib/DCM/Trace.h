// SPDX-License-Identifier: GPL-3.0-or-later
// What the estimator's corrections did on a step, for the host's `replay --trace`
// (which corrections ran and why, while the board moves). Host only: the
// trace's code is in `#if DCM_TRACE` blocks, 1 on the host and 0 on the AVR, so the
// firmware's code and RAM are the same with or without it (and `make mutate` builds
// without it: instrumentation, not the estimator). Dcm only writes here, never reads
// back: the estimate is the same whether a trace is attached or not.
#pragma once

#ifndef DCM_TRACE
#ifdef __AVR__
#define DCM_TRACE 0
#else
#define DCM_TRACE 1
#endif
#endif

#include <stdint.h>

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

struct DcmTrace {
    // Cleared by the caller before each step (reset_step); filled by Dcm.
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

    void reset_step() {
        gravity = GravityEvent::kNotDue;
        heading = HeadingEvent::kNotDue;
    }
};

}  // namespace dcm
