// SPDX-License-Identifier: GPL-3.0-or-later
// The heavy-part schedule: one heavy part a step at most, so that no step runs long
// (the firmware's loop has 5 ms a step, and the compass learner fills the light ones).
// The integration when kIntegrationSteps are summed with this step (or two or more
// before an output line), else the gravity correction when one is due or falls due with
// this step (a step later costs nothing: it follows a 3 s low-pass), else the
// renormalisation when due, on a step without a line (a few steps later: eight
// integrations leave R orthonormal to ~3e-6, nine no worse).
#pragma once

#include <stdint.h>

#include "Coefficients.h"

namespace dcm {

enum class HeavyPart : uint8_t { kNone, kIntegration, kGravity, kRenormalisation };

class HeavySchedule {
public:
    // The heavy part of the next step, from the counters before it (the strapdown's
    // pending steps and whether its renormalisation is due).
    HeavyPart next(uint8_t pending_steps, bool renormalisation_due, bool line_due) const {
        const uint8_t pending = (uint8_t)(pending_steps + 1u);
        if (pending >= kIntegrationSteps || (line_due && pending >= 2)) return HeavyPart::kIntegration;
        if (gravity_due_ || correction_phase_ + 1u >= kCorrectionDivider) return HeavyPart::kGravity;
        if (renormalisation_due && !line_due) return HeavyPart::kRenormalisation;
        return HeavyPart::kNone;
    }
    // The integration and the gravity correction take a step to themselves (what a
    // caller with deferrable work avoids); the renormalisation only keeps off the line's.
    static bool blocks(HeavyPart p) { return p == HeavyPart::kIntegration || p == HeavyPart::kGravity; }
    // A step counted: every kCorrectionDivider steps a gravity correction falls due.
    void count_step() {
        if (++correction_phase_ >= kCorrectionDivider) {
            correction_phase_ = 0;
            gravity_due_ = true;
        }
    }
    void gravity_done() { gravity_due_ = false; }

private:
    uint8_t correction_phase_ = 0;  // steps since the last gravity correction fell due
    bool gravity_due_ = false;      // a gravity correction waits for a step without an integration
};

}  // namespace dcm
