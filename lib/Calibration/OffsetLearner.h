// SPDX-License-Identifier: GPL-3.0-or-later
// Hard-iron learning in motion (Premerlani, "Magnetometer Offset Nulling Revisited",
// eq. 11; ArduPilot's Compass::null_offsets on the APM2). The earth field is fixed, so
// two samples f1, f2 (calibrated, the learned offset not yet removed) with the board
// turned by P between them (P: body 2 to body 1, integrated from the gyro) satisfy
// P (f2 - e) = f1 - e for the right offset e; for the estimate x the innovation is
//   r = P f2 - f1 - (P - I) x = H (e - x).
// A pair measures the two components of e across the rotation axis, with information
// H^T H / sigma^2 (H^T H = 2 (1 - cos theta) (I - n n^T)). The learner is recursive
// least squares in information form: x += (I / prior^2 + L)^-1 H^T r / sigma^2, L the
// sum of the pairs' information fading by 1/kLearnMemoryPairs a pair (a hard iron that
// changes, a battery moved, is followed); the step is kept across the pair's axis.
// The turn comes from the gyro alone, not from the estimator's attitude: the
// estimator's drift corrections turn its matrix by up to a degree a second (1 uT of a
// 50 uT field over a pair), which is not a turn of the board.
// Pairs are taken at least 20 deg apart and at most kLearnMaxPairSteps apart (gyro
// drift over a longer span is no longer small against the signal).
//
// The estimate x is not the offset in use: a wrong offset costs heading (0.3 uT of a
// 15 uT horizontal field is 1.1 deg), and the pairs carry errors that do not average
// out (below). The offset in use moves from where it started (the saved one, zero after
// `cal mag`) to x once x has differed from that start by more than kLearnSignificance
// times its uncertainty on some axis for kLearnConfirmPairs pairs, the uncertainty being
// the posterior's (the inverse information) and the pairs' systematic error in
// quadrature; from then on it follows x. Except while x is at (or a step from)
// kLearnMaxOffset_uT, or more than kLearnMaxRejectShare of the recent pairs disagree
// with x: both are a magnet at the compass, which no fixed offset describes (the
// estimator's disturbance rejection deals with it); then the start is in use.
//
// Body frame (x forward, y right, z down), field in uT, turns in rad. Pure C++: no clock,
// no bus, no Arduino include; the caller feeds field samples as they come, with the
// gyro's turn since the previous one.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

constexpr float kLearnMinCos = 0.94f;           // pairs at least 20 deg apart: cos 20 deg
// Noise of one pair's innovation, each of its two components: the HMC5883L's 0.2 uT,
// the gyro's scale error over the turn (0.5 % of 60 deg of a 45 uT field: 0.25 uT), the
// sample's timing against the gyro (a few ms of a 200 deg/s turn: 1.5 uT) and the
// field's change as the hand moves the board through a room's gradients (a few uT/m
// over tens of cm). Recorded pairs with a calibrated compass agree (docs/estimator.md).
constexpr float kLearnPairNoise_uT = 1.5f;
// The part of the pairs' error that does not average out over a session (gradients
// along the path, soft iron left after calibration): about 1 uT an axis, as recorded
// sessions' pairs solved for one offset show (docs/estimator.md).
constexpr float kLearnSystematic_uT = 1.0f;
// Sigmas from the start before x is put in use: the test is made on 3 axes at every
// pair, ~10 independent looks a session (1 000 pairs over a memory of 100): 3.6 sigmas
// (two-sided 3e-4 a look) keeps a false start below ~1 % a session.
constexpr float kLearnSignificance = 3.6f;
// ... on this many pairs in a row (~1 s of turning): one pair can carry x over the line
// by its own error; a hard iron stays there, the next pairs confirm it.
constexpr uint8_t kLearnConfirmPairs = 2;
// A pair whose innovation is beyond this many sigmas of its covariance (the pair noise
// and the estimate's uncertainty; 3 components: chi-square 99.9 % = 16.3 = 4.0^2) is
// not explained by any offset near x: it is dropped.
constexpr float kLearnGate = 4.0f;
// The dropped share (averaged over ~kLearnMemoryPairs pairs) beyond which the field is
// not a hard iron at all: the pair noise's tails drop ~1 % of the pairs of a calibrated
// compass.
constexpr float kLearnMaxRejectShare = 0.1f;
constexpr uint16_t kLearnMaxPairSteps = 400;    // 2 s at 200 Hz
// ~2 pairs a second while turning: a minute of turning to follow a change, and one
// pair's noise averaged down by ~10.
constexpr float kLearnMemoryPairs = 100.0f;
constexpr float kLearnMaxStep_uT = 5.0f;        // one pair moves no axis of x further (a passing magnet)
// ArduPilot's "compass offsets too high" limit (500 mGauss): beyond, calibrate.
constexpr float kLearnMaxOffset_uT = 50.0f;
// Prior uncertainty: an uncalibrated APM 2.5 compass is tens of uT off; after `cal mag`
// the fit's own error is a fraction of a uT.
constexpr float kLearnPriorUncalibrated_uT = 30.0f;
constexpr float kLearnPriorCalibrated_uT = 1.0f;

// Cost on the AVR (figures: `make bench`, docs/performance.md): a pair's update in float
// is more than a 5 ms step can carry beside the estimator's own work; so a sample only
// composes the turn (a quaternion product in Q30) and stores a pair that completes, and
// the pair is worked out by solve_part() in kSolveParts parts (the residual in fixed
// point, the 3x3 solve in float, the estimate), on the caller's next steps with room for
// them (the Pipeline: the long one on a step without the DCM's heavy parts, none with a
// heading correction or a line), before the next sample: the same arithmetic as one
// update.
class OffsetLearner {
public:
    // Starts afresh from the offset in use (in_use_uT: the estimate's start and the
    // offset kept until a significant one is learned); prior_uT: how far off it may be.
    void restart(float prior_uT, const linalg::Vector3f& in_use_uT);
    // Drops the pair in progress (not one already complete and being solved).
    void forget_pair() { have_ref_ = false; }
    // One field sample (uT, body frame, calibrated but with no learned offset removed),
    // the board's turn since the previous sample (rad, body frame: the gyro's rate
    // integrated) and the estimator steps since. A pair being solved is finished first
    // (all its parts at once: a caller that minds the cost calls solve_part() until
    // solving() is false before the next sample). When a pair completes it is stored for
    // solve_part(). Returns true when `in_use_uT` (the offset that calibration
    // subtracts) changed.
    bool add(const linalg::Vector3f& field_uT, const linalg::Vector3l& turn_q30, uint16_t steps,
             linalg::Vector3f& in_use_uT);
    // The same with the turn in float radians (tools, tests).
    bool add(const linalg::Vector3f& field_uT, const linalg::Vector3f& turn_rad, uint16_t steps,
             linalg::Vector3f& in_use_uT);
    // A completed pair waits for solve_part().
    bool solving() const { return solve_part_ != 0; }
    // The next solve_part() is the second, the long one (the 3x3 solve in float); the
    // others are shorter.
    bool long_part_next() const { return solve_part_ == 2; }
    // The next part of the pending pair's update (nothing when none): the estimate, and
    // `in_use_uT` as add() describes; returns true when that changed.
    bool solve_part(linalg::Vector3f& in_use_uT);
    const linalg::Vector3f& estimate_uT() const { return estimate_uT_; }
    uint16_t updates() const { return updates_; }
    uint16_t rejected() const { return rejected_; }

    static constexpr uint8_t kSolveParts = 3;

private:
    bool solve_residual();
    bool solve_step();
    bool solve_estimate(linalg::Vector3f& in_use_uT);
    void end_solve();

    // The board's turn since the pair's first sample as a quaternion (w, x, y, z) in Q30:
    // P = R(q), composed by q <- q dq at each sample (16 products where the 3x3 product
    // took 27). While a completed pair is solved no sample is composed, and the same 16
    // bytes carry the solve from part to part as floats: w the innovation's r . r after
    // the first part, then 1 / det A; (x, y, z) the rotation's axis until the second,
    // then the posterior's diagonal cofactors.
    union {
        int32_t q30[4];
        float f[4];
    } turn_;
    linalg::Vector3f field_ref_;     // f1; while solving, the pair's H^T r, then its step
    linalg::Vector3f field_next_;    // while solving, f2: the next pair's first sample
    float inv_axis2_;                // while solving, 1 / |m|^2 (solve_residual)
    linalg::Vector3f estimate_uT_;   // x
    linalg::Vector3f start_uT_;      // the offset in use at restart
    float info_[6] = {};             // L faded for the next pair, 1/uT^2: xx yy zz, then xy xz yz
    float prior_info_ = 1.0f / (kLearnPriorUncalibrated_uT * kLearnPriorUncalibrated_uT);
    float reject_share_ = 0.0f;      // dropped pairs, averaged over ~kLearnMemoryPairs
    uint16_t age_steps_ = 0;
    uint16_t updates_ = 0;
    uint16_t rejected_ = 0;
    uint8_t significant_run_ = 0;    // pairs in a row with x significant
    uint8_t solve_part_ = 0;         // the next part of a completed pair (1..kSolveParts), 0: none
    bool have_ref_ = false;
    bool step_cut_ = false;          // the solve's step was cut to kLearnMaxStep_uT
};

}  // namespace calib
