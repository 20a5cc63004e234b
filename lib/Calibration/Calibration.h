// SPDX-License-Identifier: GPL-3.0-or-later
// Sensor calibration, applied in one place (apply_gyro / apply_mag), and the procedures
// that measure it: gyro bias at rest, the magnetometer's hard and soft iron from a
// least-squares ellipsoid fit on the samples of a rotation (`cal mag`), and its hard
// iron learned in motion (OffsetLearner).
//
// Body frame (x forward, y right, z down), gyro in rad/s, accel in m/s^2 (specific
// force), field in uT. Pure C++: no clock, no bus, no Arduino include; the caller
// feeds samples at the fixed 200 Hz step (gyro) and as they come (mag).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

struct Calibration {
    linalg::Vector3f gyro_bias_rad_s;  // subtracted from every gyro sample
    linalg::Vector3f mag_offset_uT;    // hard iron from `cal mag`, subtracted first
    linalg::Vector3f mag_scale;        // then the soft-iron matrix W: its diagonal
    linalg::Vector3f mag_cross;        //   and its off-diagonal terms (xy, xz, yz); W symmetric
    linalg::Vector3f mag_learned_uT;   // then the offset learned in motion (OffsetLearner)
};

// Zero bias and offset, unit scale.
Calibration default_calibration();

inline linalg::Vector3f apply_gyro(const Calibration& c, const linalg::Vector3f& gyro_rad_s) {
    return gyro_rad_s - c.gyro_bias_rad_s;
}
// f = W (m - offset) - learned. W symmetric: a soft-iron correction that stretches
// the ellipsoid back to a sphere without turning the compass's axes.
linalg::Vector3f apply_mag(const Calibration& c, const linalg::Vector3f& field_uT);

// True when every number is finite and within what a real board could need (bias
// below 30 deg/s per axis, offsets below 200 uT, soft-iron diagonal within 0.5..2,
// cross terms within +-0.5): a record that fails this is treated as corrupt.
bool is_plausible(const Calibration& c);

// ---------------------------------------------------------------------------
// Gyro bias at rest: the mean over kGyroWindow samples (1 s at 200 Hz). The board
// counts as moving, and the window restarts, when a gyro axis spreads by more than
// kGyroSpreadMax_rad_s (min..max), an accel axis spreads by more than
// kAccelSpreadMax_m_s2, or |accel| is off 1 g by more than kAccelNormTol_g. Spreads,
// not thresholds on the value: the MPU6000's zero-rate offset is up to +-20 deg/s.
constexpr uint16_t kGyroWindow = 200;
constexpr float kGyroSpreadMax_rad_s = 0.035f;  // 2 deg/s peak to peak (noise: ~0.3)
constexpr float kAccelSpreadMax_m_s2 = 0.4f;    // 5 deg/s of rotation over 1 s moves g by ~0.85
constexpr float kAccelNormTol_g = 0.1f;
constexpr float kGyroBiasMax_rad_s = 0.5236f;   // 30 deg/s: more is not a bias

class GyroCalibrator {
public:
    enum class Result : uint8_t {
        Collecting,  // keep feeding
        Moved,       // the board moved: the window restarted (say so)
        Done,        // bias() is the mean of a still window
    };

    void restart();
    // Feeds one sample in the MPU6000's counts and their scales (rad/s and m/s^2 per
    // count); returns what happened. In integers, not floats: it runs at every step while
    // it measures, in the background too (its cost: `make bench`).
    Result add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts, float gyro_rad_s_per_count,
               float accel_m_s2_per_count);
    // The same in SI units (tests, tools), held in fine counts (kFloatGyroScale,
    // kFloatAccelScale: +-4 rad/s and +-16 m/s^2, beyond any still board).
    Result add(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2);
    bool done() const { return done_; }
    // Valid once done(), until the next add().
    linalg::Vector3f bias() const { return mean(0, gyro_scale_); }
    // Mean specific force over the still window (gravity for the DCM init); likewise.
    linalg::Vector3f mean_accel_m_s2() const { return mean(3, accel_scale_); }
    uint16_t count() const { return n_; }
    uint16_t restarts() const { return restarts_; }

    static constexpr float kFloatGyroScale = 1.0f / 8192.0f;
    static constexpr float kFloatAccelScale = 1.0f / 2048.0f;

private:
    linalg::Vector3f mean(uint8_t first, float scale) const;
    // Plain arrays, gyro x y z then accel x y z: one loop does all six channels, and
    // the object needs no constructor code. Valid from the first add() of a window
    // (n_ == 0 starts them); the limits in counts follow the scales (set when they change).
    int32_t sum_[6] = {};
    int16_t lo_[6], hi_[6];
    uint16_t spread_max_[2];     // gyro, accel: the spreads in counts
    uint32_t norm2_min_, norm2_max_;  // |accel|^2 in counts^2 for 1 g -+ kAccelNormTol_g
    float gyro_scale_ = 0.0f, accel_scale_ = 0.0f;
    uint16_t n_ = 0;
    uint16_t restarts_ = 0;
    bool done_ = false;
};

// ---------------------------------------------------------------------------
// Magnetometer calibration (`cal mag`): a least-squares fit on every sample of a
// kMagCalSeconds rotation, first a sphere |m - o| = R (the hard-iron offset o), then
// an ellipsoid |W (m - o)| = R (o, and a symmetric soft-iron W with det W = 1), as
// ArduPilot's CompassCalibrator does, but without storing the samples: the fits are
// linear in their parameters, so their normal equations are sums of the monomials
// x^i y^j z^k (i + j + k <= 4) of the samples, 35 sums accumulated as they come
// (140 B; the fit then works in the same memory, grown to 220 B). The samples are
// centred on a pivot (the centre already in use) and scaled by 1/64 uT, so that the
// float32 sums (AVR's double is 32-bit too) keep their precision. A fit is refused, with
// the reason, when the board did not see enough directions, when the residual is larger
// than a clean compass gives, or when the result is not an Earth-like field or a
// plausible soft iron.
constexpr uint8_t kMagCalSeconds = 30;
constexpr uint16_t kMagCalMinSamples = 200;     // at 75 Hz the 30 s give ~2 250
// Of the 26 direction cells (the cube's faces, edges and corners seen from the
// centre), the share the field must have visited. Turning about one axis only visits
// a ring (~1/3); an ellipsoid fitted to a cap trades its offset along the missing
// direction against scale, so most of the sphere must be seen.
constexpr uint8_t kMagMinCoveragePct = 70;
constexpr uint8_t kMagCellMinSamples = 3;       // a cell counts once seen this often (not one noisy sample)
constexpr uint8_t kCoverageRefitSamples = 75;   // the cells' centre is refitted each second at 75 Hz
// ArduPilot's default fitness (COMPASS_CAL_FIT 16 mGauss): rms distance of the samples
// from the fitted ellipsoid. The HMC5883L's own noise gives ~0.2 uT; 1.6 uT of a 50 uT
// field is at most 1.8 deg of heading: more means a moving magnet or a bad sensor.
constexpr float kMagMaxResidual_uT = 1.6f;
constexpr float kMagMinRadius_uT = 15.0f;       // Earth: 25..65 uT; outside 15..100 is not the Earth's field
constexpr float kMagMaxRadius_uT = 100.0f;
constexpr float kMagMaxOffset_uT = 150.0f;      // the HMC5883L saturates at 130 uT (1.3 Ga): beyond is no fit
// ArduPilot's limits on the soft-iron terms (diagonal 0.8..1.2, off-diagonal +-0.2):
// a board needing more has a magnet next to the compass, not soft iron.
constexpr float kMagMinDiag = 0.8f;
constexpr float kMagMaxDiag = 1.2f;
constexpr float kMagMaxCross = 0.2f;

class MagCalibrator {
public:
    enum class Quality : uint8_t {
        Ok,
        TooFewSamples,
        ThinCoverage,     // coverage_pct() below kMagMinCoveragePct
        FitFailed,        // singular normal equations, or not an ellipsoid
        NotEarthField,    // radius or offset out of range (magnet nearby?)
        SoftIronTooLarge, // soft-iron terms beyond ArduPilot's limits
        PoorFit,          // residual_uT() above kMagMaxResidual_uT
    };

    // Starts a new collection; pivot_uT: the centre in use (raw field, uT), which the
    // samples are centred on (any value works; closer is more precise).
    void restart(const linalg::Vector3f& pivot_uT);
    // Feeds one field sample (uT, body frame, BEFORE calibration); non-finite ignored.
    // Not between begin_fit() and the next restart().
    void add(const linalg::Vector3f& field_uT);
    uint16_t count() const { return count_; }
    // Share of the 26 direction cells seen at least kMagCellMinSamples times, percent.
    uint8_t coverage_pct() const;
    // Fits all at once (tools, tests: the parts below, one after the other); on Ok writes
    // result() into cal. The figures below are valid after any fit that got as far as
    // the ellipsoid (Ok, NotEarthField, SoftIronTooLarge, PoorFit).
    Quality finish(Calibration& cal);
    // The same fit in kFitParts (25) parts for a caller with part of a step to spare (the
    // whole is longer than a 5 ms step on the AVR): begin_fit() once the
    // samples are in, then fit_part() while fitting(); then quality() and, on Ok,
    // result(). The fit works in the sums' memory: no add() until restart().
    void begin_fit();
    void fit_part();
    bool fitting() const { return stage_ < kStageDone; }
    Quality quality() const { return quality_; }
    // The offset, the soft-iron terms and a zero learned offset into cal (gyro bias
    // untouched); valid when quality() is Ok.
    void result(Calibration& cal) const;
    float residual_uT() const { return residual_uT_; }
    float radius_uT() const { return radius_uT_; }
    // The sphere fit's offset and residual (the first stage).
    linalg::Vector3f sphere_offset_uT() const { return cover_centre_uT_; }
    float sphere_residual_uT() const { return sphere_residual_uT_; }

    static constexpr uint8_t kMoments = 35;  // monomials of degree <= 4 in x, y, z
    static constexpr uint8_t kCells = 26;
    static constexpr uint8_t kUnknowns = 9;  // the ellipsoid's terms
    static constexpr uint8_t kPacked = kUnknowns * (kUnknowns + 1) / 2;
    static constexpr uint8_t kRootIterations = 7;  // Newton-Schulz steps after the first
    static constexpr uint8_t kCholeskyColumns = 2;  // of the factor, a part

private:
    // The parts: checks and sphere, normal equations, Cholesky, the two substitutions,
    // the quadric, the root's first step, its iterations (two parts each), final checks.
    enum Stage : uint8_t {
        kStageCheck,
        kStageNormal,
        kStageCholesky,
        kStageForward = kStageCholesky + (kUnknowns + kCholeskyColumns - 1) / kCholeskyColumns,
        kStageBack,
        kStageQuadric,
        kStageRootStart,
        kStageRoot,      // 2 kRootIterations parts
        kStageFinal = kStageRoot + 2 * kRootIterations,
        kStageDone,
    };

public:
    static constexpr uint8_t kFitParts = kStageDone;

private:
    // On success the centre goes to cover_centre_uT_ (it is sphere_offset_uT()).
    bool fit_sphere();
    void normal_equations();
    bool cholesky_part(uint8_t first_column);
    void forward_substitution();
    void back_substitution();
    bool quadric();
    void root_start();
    void root_part(bool second_half);
    Quality final_checks();
    void end_fit(Quality q);
    uint8_t cell_samples(uint8_t cell) const;

    // The sums while collecting; the fit's working memory after begin_fit() (restart()
    // clears it).
    union Work {
        float sums[kMoments];  // sums of x^i y^j z^k of the centred, scaled samples; [0] = count
        struct Normal {        // the ellipsoid's normal equations A t = b
            float l[kPacked];  // A's lower triangle row by row, then its Cholesky factor L
            float b[kUnknowns];  // b, then L^-1 b, then the solution t
            float tiny;          // a pivot below this: the fit is not determined
        } normal;
        struct Root {          // W = sqrt(Q / det(Q)^(1/3)) by Newton-Schulz, 3x3 row by row
            float a[9], y[9], z[9], t[9];
            float centre[3];
            float k, cube_root_det;
        } root;
    } work_;
    linalg::Vector3f pivot_uT_;
    linalg::Vector3f cover_centre_uT_;  // the coverage cells' centre: the latest sphere fit
    // Each cell's samples, counted up to kMagCellMinSamples (all coverage needs): 2 bits
    // a cell, four cells a byte.
    uint8_t cell_samples_[(kCells + 3u) / 4u];
    float sphere_residual_uT_ = 0.0f;
    float residual_uT_ = 0.0f;
    float radius_uT_ = 0.0f;
    float fit_yy_ = 0.0f;   // b^T A^-1 b = |L^-1 b|^2: the fit's residual is count - this
    uint16_t count_ = 0;
    uint8_t stage_ = kStageDone;
    Quality quality_ = Quality::TooFewSamples;
};

// ---------------------------------------------------------------------------
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
