// SPDX-License-Identifier: GPL-3.0-or-later
// The gyro bias (Fusion's FusionOffset, with the DCM's integrators): the calibrated
// sensor bias (the start-up calibration) and the estimator's own estimate, with the rules
// of what may teach it and when:
//   gravity   the tilt error's integral (ki_rp, the two horizontal axes), held while the
//             board turns lastingly or a broken gyro read is in the window, and through a
//             still start's start-up;
//   rest      the rest mean (RestDetector: the gyro reads its bias alone, every axis);
//   compass   the heading error's integral (ki_yaw, the vertical axis), only until a rest
//             or the calibration has measured the bias, and neither while turning nor
//             starting (DcmSettings.h says why).
// What the step subtracts from every sample is offset_units().
//
// Formats: units (gyro counts * 2^8, Coefficients.h); the estimate in fine units
// (units * 2^8: the rest's slow steps are kept), bounded by bias_limit_rad_s (a quarter
// of it once calibrated).
#pragma once

#include <stdint.h>

#include "Coefficients.h"

namespace dcm {

// Once the calibration at this start has measured the bias, the estimate holds what the
// gyro drifts with temperature: the MPU-6000's zero-rate output moves by 20 deg/s over
// its 125 degC range (product specification 6.1), 0.16 deg/s a degree, so a quarter of
// the 10 deg/s limit (2.5 deg/s) covers a board 15 degC warmer than at power-on (the
// warm-up is 0.2 deg/s a minute). More is a tilt error that a sustained acceleration
// left, not the gyro: a turn flown without an airspeed below the integrator's hold rate
// (30 deg of bank at 36 m/s) teaches 3.8 deg/s. VQF bounds its moving bias estimate at
// 2 deg/s. Never measured, a bias is the chip's whole zero-rate output: bias_limit_rad_s
// itself.
constexpr uint8_t kCalibratedLimitShift = 2;

class GyroBias {
public:
    static constexpr uint8_t kByRest = 1, kByCalibration = 2;
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
    // A start value for the estimate, and the calibrated bias (rad/s); a non-finite one is
    // ignored.
    void set_estimate_rad_s(const linalg::Vector3f& bias, const DcmCoefficients& k);
    void set_sensor_rad_s(const linalg::Vector3f& bias, const DcmCoefficients& k);
    // New sensor scales: the state in the old units carried over (ratio old/new).
    void rescale(float gyro_ratio) {
        fine_ = rescaled(fine_, gyro_ratio);
        sensor_units_ = rescaled(sensor_units_, gyro_ratio);
    }

    // The integrator's holds. No learning from gravity while rotating fast: gyro scale
    // errors look like bias there (ArduPilot's rule), and a vehicle's turn holds a
    // centripetal acceleration the accelerometer reads as tilt (integrator_hold_rate).
    // What counts is the turn that lasts, the rest test's 0.5 s mean rate less the
    // estimate (mean_off_bias, units): a vibration's rates average out, while a hand's or
    // a vehicle's turn does not. Judged at each gravity correction; a broken gyro read in
    // the window holds it too (gyro_rejected), and so does one before the next judgement.
    void judge_rotation(const linalg::Vector3l& mean_off_bias, bool gyro_rejected, const DcmCoefficients& k) {
        rotating_fast_ = gyro_rejected || exceeds(mean_off_bias, k.hold_rate);
    }
    void hold_for_broken_sample() { rotating_fast_ = true; }
    // The gravity integrator is held: rotating fast, or within the start-up (starting),
    // whose tilt error is not a gyro bias (a wrong first sample, a launch off the stand).
    // Except after a start from a mean that was never still (start_from_mean, with no
    // bias measured): the bias nothing measured (the saved calibration's, or none: the
    // chip's +-20 deg/s) is what gravity has to learn first; while it waits, the
    // proportional loop holds b / kp of tilt and the dip turns it into 2.5 times as much
    // heading.
    bool integrator_held(bool starting, bool start_from_mean) const {
        return rotating_fast_ || (starting && !(start_from_mean && !measured()));
    }

    // At rest: the estimate follows the rest mean (follow_rest_mean), and the bias counts
    // as measured.
    void learn_at_rest(const linalg::Vector3l& rest_mean_units, const DcmCoefficients& k) {
        follow_rest_mean(rest_mean_units, k);
        set_measured();
    }
    // The compass's integral (ki_yaw): the heading error (the sine, saturated) about earth
    // down (R's third row, Q30), over interval_steps steps; only while nothing else has
    // measured the bias, neither rotating fast nor starting. True when it learned.
    bool learn_from_heading(const linalg::Vector3l& down_q30, float heading_error, uint16_t interval_steps,
                            bool starting, const DcmSettings& settings, const DcmCoefficients& k);
    // At rest: estimate += alpha (rest mean - estimate), alpha = rest_bias_alpha_q30.
    void follow_rest_mean(const linalg::Vector3l& rest_mean_units, const DcmCoefficients& k);
    // The bias was measured on a still board: from now the gravity integrator uses
    // ki_rp_measured (DcmSettings.h). set_measured: a rest measured the estimate;
    // set_calibrated: the sensor's calibration did, at this start (the pipeline's still
    // second), so the estimate is only what the gyro drifts after it: bounded by a
    // quarter of bias_limit_rad_s from then on (kCalibratedLimitShift).
    void set_measured() { measured_ |= kByRest; }
    void set_calibrated() { measured_ |= kByRest | kByCalibration; }
    bool measured() const { return measured_ != 0; }
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
    uint8_t measured_ = 0;           // kByRest, kByCalibration: what measured the bias
    bool rotating_fast_ = false;     // judge_rotation: the integrator held
};

}  // namespace dcm
