// SPDX-License-Identifier: GPL-3.0-or-later
// Gravity for the estimator's start (TRIAD) when the board never kept still through the
// start-up: flown, carried, in a car. One accelerometer sample then carries whatever the
// motion adds at that instant (a gust's 2-3 m/s^2 is 10-15 deg of tilt, and through the
// field's dip 2.5 times as much heading); the mean over the start-up window keeps only
// the mean acceleration, which a gust, a vibration or a hand's stroke hardly has. The
// board turns meanwhile, so the sum is kept in the current body frame: a vector fixed in
// the earth frame, seen from a body turning at w, changes as dv/dt = -w x v (Premerlani
// and Bizard eq. 17, the other way round), one first-order step per kFoldSamples.
//
// The samples are summed in counts (integer adds: the step's budget) and folded into the
// float sum every kFoldSamples with their summed turn: a quarter of the float work, and
// within a fold the turn is a few degrees at most (the sum's direction moves by its
// square, 1e-3 rad at 200 deg/s).
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace pipeline {

class StartGravity {
public:
    static constexpr uint8_t kFoldSamples = 4;  // samples a float fold takes

    void restart() {
        sum_m_s2_ = linalg::Vector3f();
        gyro_counts_ = accel_counts_ = linalg::Vector3l();
        folded_ = 0;
        pending_ = 0;
    }
    // One sample in the MPU6000's counts and their scales; gyro_bias_rad_s the known bias,
    // dt_s the sample period.
    void add(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts, float gyro_rad_s_per_count,
             float accel_m_s2_per_count, const linalg::Vector3f& gyro_bias_rad_s, float dt_s);
    // Samples in the mean.
    uint16_t count() const { return folded_; }
    // The mean specific force of the folded samples in the current body frame (those of
    // a fold not complete yet wait for it); zero before the first fold.
    linalg::Vector3f mean_m_s2() const { return folded_ ? sum_m_s2_ * (1.0f / folded_) : linalg::Vector3f(); }

private:
    linalg::Vector3f sum_m_s2_;
    linalg::Vector3l gyro_counts_, accel_counts_;  // the fold not complete yet
    uint16_t folded_ = 0;
    uint8_t pending_ = 0;
};

}  // namespace pipeline
