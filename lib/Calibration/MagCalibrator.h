// SPDX-License-Identifier: GPL-3.0-or-later
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
//
// Body frame (x forward, y right, z down), field in uT. Pure C++: no clock, no bus, no
// Arduino include; the caller feeds field samples as they come.
#pragma once

#include <stdint.h>

#include "LinAlg.h"
#include "SensorCalibration.h"

namespace calib {

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
    // The same cells as bits (bit i: cell i seen kMagCellMinSamples times): the ground
    // station's MAG_CAL_PROGRESS completion_mask.
    uint32_t cells_seen() const;
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
    // untouched); valid when quality() is Ok, until restart(): a result may wait there
    // for a ground station's accept without a copy.
    void result(Calibration& cal) const;
    // The same terms one at a time (Calibration's mag_offset_uT, mag_scale, mag_cross).
    linalg::Vector3f offset_uT() const;
    linalg::Vector3f scale() const;
    linalg::Vector3f cross() const;
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

}  // namespace calib
