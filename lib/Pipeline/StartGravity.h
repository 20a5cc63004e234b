// SPDX-License-Identifier: GPL-3.0-or-later
// Gravity for the estimator's start (TRIAD) when the board never kept still through the
// start-up: flown, carried, in a car. One accelerometer sample then carries whatever the
// motion adds at that instant (a gust's 2-3 m/s^2 is 10-15 deg of tilt, and through the
// field's dip 2.5 times as much heading); the mean over the start-up window keeps only
// the mean acceleration, which a gust, a vibration or a hand's stroke hardly has. The
// board turns meanwhile, so the sum is kept in the current body frame: a vector fixed in
// the earth frame, seen from a body turning at w, changes as dv/dt = -w x v (Premerlani
// and Bizard eq. 17, the other way round), one first-order step a sample.
#pragma once

#include <stdint.h>

#include "LinAlg.h"

namespace pipeline {

class StartGravity {
public:
    void restart() {
        sum_m_s2_ = linalg::Vector3f();
        n_ = 0;
    }
    // gyro_rad_s with the known bias taken out; dt_s the sample period.
    void add(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2, float dt_s) {
        sum_m_s2_ = sum_m_s2_ - gyro_rad_s.cross(sum_m_s2_) * dt_s + accel_m_s2;
        if (n_ < 0xFFFFu) ++n_;
    }
    uint16_t count() const { return n_; }
    // The mean specific force in the current body frame; zero before the first sample.
    linalg::Vector3f mean_m_s2() const { return n_ ? sum_m_s2_ * (1.0f / n_) : linalg::Vector3f(); }

private:
    linalg::Vector3f sum_m_s2_;
    uint16_t n_ = 0;
};

}  // namespace pipeline
