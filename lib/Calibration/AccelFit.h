// SPDX-License-Identifier: GPL-3.0-or-later
// The accelerometer's six-position calibration fit (ArduPilot's AP_AccelCal; the ground
// station's flow asks for the positions LEVEL, LEFT, RIGHT, NOSEDOWN, NOSEUP, BACK):
// from the mean specific force m_k of each still position, the offsets o and the
// diagonal scales s (INS_ACCOFFS_*, INS_ACCSCAL_*: a = (raw - o) .* s, in the board's
// axes) for which every corrected mean has gravity's length:
//
//   F_k(o, s) = sum_i s_i^2 (m_ki - o_i)^2 - g^2 = 0,   k = 1..6
//
// six equations in six unknowns (ArduPilot 3's _calibrate_accel solved the same six by
// Gauss-Newton). Here by sweeps over the axes: each axis's two positions (the one reading
// most along +axis, the one most along -axis) give its o_i and s_i exactly with the other
// axes held, and the sweeps contract in a few to the solution of all six: a sweep is six
// square roots and no matrix kept (a 6x6 Newton step would not fit one estimator step),
// one per call (step()) so that a caller with a time budget spreads them
// (docs/board_frame.md has the costs).
// Units m/s^2. Pure C++: no clock, no bus, no Arduino include.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace calib {

// ArduPilot's ACCELCAL_VEHICLE_POS: the positions in the order asked (1..6).
enum class AccelPosition : uint8_t { kLevel = 1, kLeft, kRight, kNoseDown, kNoseUp, kBack };
constexpr uint8_t kAccelPositions = 6;
// The specific force a still airframe reads in position p, as a unit vector of its axes
// (level: z down reads -g; on its left side the right wing points up: +y ...).
linalg::Vector3f expected_direction(AccelPosition p);
// The airframe is in position p: its mean force (the airframe's axes) within
// kPositionTolerance_deg of expected_direction(p) and within 10 % of 1 g.
bool in_position(AccelPosition p, const linalg::Vector3f& mean_m_s2);
constexpr float kPositionTolerance_deg = 30.0f;

class AccelFit {
public:
    enum class Quality : uint8_t {
        Ok,
        Fitting,      // step() has more to do
        Singular,     // the positions do not span the axes both ways (no unique fit)
        NoConvergence,
        OutOfRange,   // offsets beyond +-3.5 m/s^2 or scales beyond 0.8..1.2 (ArduPilot's)
    };
    static constexpr uint8_t kMaxIterations = 30;
    static constexpr float kMaxResidual_m_s2 = 0.05f;  // |corrected mean| - g, each position

    // Starts a fit of the six means (board axes, m/s^2): o the means' centre, s 1.
    void begin(const linalg::Vector3f means_m_s2[kAccelPositions], float g_m_s2);
    // The same from the means already given one by one (set_mean, no copy of them kept
    // elsewhere: RAM).
    void set_mean(uint8_t k, const linalg::Vector3f& mean_m_s2);
    void begin(float g_m_s2);
    // One Newton iteration; the quality after it (Fitting: call again).
    Quality step();
    Quality quality() const { return quality_; }
    linalg::Vector3f offset_m_s2() const { return linalg::Vector3f(x_[3], x_[4], x_[5]); }
    linalg::Vector3f scale() const { return linalg::Vector3f(x_[0], x_[1], x_[2]); }
    // The largest | |s .* (m_k - o)| - g | over the positions, m/s^2.
    float residual_m_s2() const;

private:
    float m_[kAccelPositions][3];
    float x_[6];  // s x y z, o x y z
    float g2_;
    uint8_t iterations_;
    Quality quality_ = Quality::Fitting;
};

}  // namespace calib
