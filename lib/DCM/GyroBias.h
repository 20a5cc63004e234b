// SPDX-License-Identifier: GPL-3.0-or-later
// The gyro bias (Fusion's FusionOffset, with the DCM's integrator): the calibrated
// sensor bias (the start-up calibration) and the estimator's own estimate, learned from
// gravity (the tilt error's integral, ki_rp) and at rest (RestDetector: the gyro reads
// its bias alone). What the step subtracts from every sample is offset_units().
//
// Formats: units (gyro counts * 2^8, Coefficients.h); the estimate in fine units
// (units * 2^8: the rest's slow steps are kept), bounded by bias_limit_rad_s.
#pragma once

#include <stdint.h>

#include "Coefficients.h"

namespace dcm {

class GyroBias {
public:
    // The estimate rounded to units, and the calibrated bias.
    linalg::Vector3l units() const {
        return linalg::Vector3l((fine_.x + 128) >> 8, (fine_.y + 128) >> 8, (fine_.z + 128) >> 8);
    }
    const linalg::Vector3l& sensor_units() const { return sensor_units_; }
    // sensor + estimate - the gravity correction (units per step): what the step subtracts.
    linalg::Vector3l offset_units(const linalg::Vector3l& correction_units) const {
        return sensor_units_ + units() - correction_units;
    }

    linalg::Vector3f estimate_rad_s(const DcmCoefficients& k) const;
    void set_estimate_rad_s(const linalg::Vector3f& bias, const DcmCoefficients& k);
    void set_sensor_rad_s(const linalg::Vector3f& bias, const DcmCoefficients& k);
    // New sensor scales: the state in the old units carried over (ratio old/new).
    void rescale(float gyro_ratio) {
        fine_ = rescaled(fine_, gyro_ratio);
        sensor_units_ = rescaled(sensor_units_, gyro_ratio);
    }

    // At rest: estimate += alpha (rest mean - estimate), alpha = rest_bias_alpha_q30.
    void follow_rest_mean(const linalg::Vector3l& rest_mean_units, const DcmCoefficients& k);
    // The bias was measured on a still board (the start-up calibration, a rest): from now
    // the gravity integrator uses ki_rp_measured (DcmSettings.h).
    void set_measured() { measured_ = true; }
    bool measured() const { return measured_; }
    // The gravity correction's integral: estimate -= ki error (the error in Q14 radians).
    void integrate_tilt_error(int16_t ex_q14, int16_t ey_q14, int16_t ez_q14, const DcmCoefficients& k);
    // A change in fine units (the compass integrator, ki_yaw), then bounded.
    void subtract_fine(const linalg::Vector3l& change_fine, const DcmCoefficients& k) {
        fine_ -= change_fine;
        clamp(k);
    }

private:
    void clamp(const DcmCoefficients& k);

    linalg::Vector3l fine_;          // the estimate, fine units
    linalg::Vector3l sensor_units_;  // the calibrated bias (set_sensor_rad_s), units
    bool measured_ = false;          // set_measured() since the start
};

}  // namespace dcm
