// SPDX-License-Identifier: GPL-3.0-or-later
// Rest detection (after VQF, Laidig & Seel 2023, sec. 3.4): the board is still when,
// for rest_min_s, the gyro and the accelerometer stay close to their recent means
// (deviations, so that any bias passes the test), the gyro's mean stays where the rest
// began, and the compass's field stays put in body axes. There the gyro reads its bias
// alone, on every axis (GyroBias follows the rest mean). The MPU6000's rate noise,
// 0.005 deg/s/sqrt(Hz), averages to ~0.004 deg/s over the 0.5 s mean; a hand-held
// board's tremor is below 2 deg/s and 0.5 m/s^2.
//
// Formats: the gyro mean in units, the accel mean in accel units (Coefficients.h); the
// field in uT Q5 (kFieldQ); the low-pass factor Q14.
#pragma once

#include <stdint.h>

#include "Coefficients.h"

namespace dcm {

// How far the gyro's mean may move during a rest (Rest.cpp, update), rad/s.
constexpr float kRestMeanMove_rad_s = 0.5f * linalg::kRadPerDeg;

class RestDetector {
public:
    // At start-up: the accel mean from the first sample, the gyro's from the first
    // window (start_counts_ marks it unknown till then), no rest yet.
    void reset(const linalg::Vector3l& accel_mean_units) {
        accel_mean_ = accel_mean_units;
        corrections_ = 0;
        start_counts_.x = kMeanUnknown;
    }
    // A broken read is no rest.
    void interrupt() { corrections_ = 0; }
    // A field sample (uT Q5, body axes): one that moved by more than kRestFieldMove_uT
    // since the rest began means the board turns (or a magnet moved): no rest.
    void watch_field(const linalg::Vector3i& field_q5);
    // One gravity correction's window means: the gyro's (units, less the calibrated
    // bias) and the accelerometer's (accel units); mean_off_bias: the gyro mean less the
    // bias estimate; whole_window: a full window of samples; compass_watching: a recent
    // field sample watches the turn. True when the board has been still for
    // rest_min_s: the bias may be taken from gyro_mean().
    bool update(const linalg::Vector3l& gyro_mean_units, const linalg::Vector3l& accel_mean_units,
                const linalg::Vector3l& mean_off_bias_units, bool whole_window, bool compass_watching,
                const DcmCoefficients& k);
    // The low-passed gyro mean (units): the bias at rest, the turn that lasts otherwise.
    const linalg::Vector3l& gyro_mean() const { return gyro_mean_; }
    void rescale(float gyro_ratio, float accel_ratio) {
        if (gyro_ratio != 1.0f) gyro_mean_ = rescaled(gyro_mean_, gyro_ratio);
        if (accel_ratio != 1.0f) accel_mean_ = rescaled(accel_mean_, accel_ratio);
        if (gyro_ratio != 1.0f && start_counts_.x != kMeanUnknown) restart_at_mean();
    }

private:
    // The rest begins at the mean now: a new rest, or one at a new calibration's scale
    // (the mean is within the kRestMeanMove_rad_s a rest lets it move of its start).
    void restart_at_mean();
    // The gyro mean moved from where the rest began (and where that is).
    bool mean_moved(const DcmCoefficients& k);
    // start_counts_.x before the first window after reset. A mean's counts read this only
    // when wrapped at full scale (Rest.cpp, counts_of): then the next window is taken as
    // the mean, no harm where there is no rest.
    static constexpr int16_t kMeanUnknown = -32767 - 1;

    linalg::Vector3l gyro_mean_;   // the low-passed gyro mean, units
    linalg::Vector3l accel_mean_;  // the low-passed accel mean, accel units
    uint16_t corrections_ = 0;     // how long the board has been still, in corrections
    linalg::Vector3i field_q5_;    // the field (body axes, uT Q5) when the board last seemed to turn
    linalg::Vector3i start_counts_;  // the gyro mean (counts) when the rest began
};

}  // namespace dcm
