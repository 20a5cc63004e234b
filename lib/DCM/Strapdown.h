// SPDX-License-Identifier: GPL-3.0-or-later
// Strapdown integration and renormalisation (ArduPilot's matrix_update + normalize):
// R, body to earth, in Q30; its rows are the earth axes in body coordinates.
//
// Multi-rate (Savage, "Strapdown Inertial Navigation Integration Algorithm Design",
// part 1): the corrected rates are summed at every step (add_turn, end_step) and every
// kIntegrationSteps steps the summed rotation vector turns R (integrate), with the
// two-sample coning term of its two halves. Renormalisation (Premerlani & Bizard
// eq. 18-21) every kRenormaliseEvery integrations.
//
// Formats: R Q30; the sums in units (gyro counts * 2^8, Coefficients.h); the turn
// Q30 radians inside integrate; 16-bit factors Q14.
#pragma once

#include <stdint.h>

#include "Coefficients.h"
#include "Fixed.h"

namespace dcm {

class Strapdown {
public:
    const linalg::Matrix3q30& r() const { return r_; }
    linalg::Matrix3q30& r() { return r_; }  // the heading taken at once turns it (Dcm)

    // A new R (start-up, a rebuild): nothing summed waits.
    void reset(const linalg::Matrix3q30& r);
    // A turn in units into the sum not yet integrated: the step's corrected rate, or the
    // heading's correction.
    void add_turn(const linalg::Vector3l& units) { turn_sum_ += units; }
    // Closes a step: at half the integration's steps the sum so far is its first half.
    void end_step();
    // R <- R exp([theta x]) with the summed turn and its coning term; row c <- a x b.
    void integrate(const DcmCoefficients& k);
    // Orthonormalisation, a second pass after a large error; false: the matrix is
    // hopeless (NaN, rows far from unit length) and must be rebuilt.
    bool renormalise();

    uint8_t pending_steps() const { return pending_steps_; }
    // The turn summed since the last integration, units.
    linalg::Vector3l pending_units() const { return first_half_ + turn_sum_; }
    bool renormalisation_due() const { return updates_since_renormalise_ >= kRenormaliseEvery; }

    // One row of R turned: r + r D (D = exp([theta x]) - I, rows as Matrix3q30), in Q30.
    static void turn_row(linalg::Vector3l& r, const linalg::Matrix3q30& d);
    // A row brought to unit length (first-order near it, exact beyond); false: hopeless.
    static bool rescale(const linalg::Vector3l& row, linalg::Vector3l& out);

private:
    bool renormalise_once(int32_t& skew_q30);  // skew: the X.Y it found

    linalg::Matrix3q30 r_;               // body -> earth, Q30
    linalg::Vector3l first_half_;        // corrected rates summed over the integration's first half, units
    linalg::Vector3l turn_sum_;          // ... and since
    uint8_t pending_steps_ = 0;          // steps summed, not yet integrated
    uint8_t updates_since_renormalise_ = 0;  // >= kRenormaliseEvery: renormalisation due
};

}  // namespace dcm
