// SPDX-License-Identifier: GPL-3.0-or-later
// The gravity correction (VQF's updateAcc with the DCM's PI loop): the specific force
// is low-passed in the estimated earth frame, where a linear acceleration averages out
// (velocity stays bounded) while in body axes it does not; its direction's error
// against earth down (Premerlani & Bizard eq. 27) is the roll/pitch correction, a rate
// applied at every step until the next correction, and its integral the horizontal
// gyro bias (GyroBias).
//
// The samples are summed at every step (add) and low-passed every kCorrectionDivider
// steps (low_pass_window): the low-pass is seconds long, so the window's mean loses
// nothing; each sample is turned to the matrix's time (the window's turn term).
//
// Formats: the sums in counts, the means and the low-pass in accel units (counts *
// 2^8), the correction in units (Coefficients.h); R's entries in 16 bits (Q14) where
// they turn a vector, Q30 factors; the error Q14 radians.
#pragma once

#include <stdint.h>

#include "Centripetal.h"
#include "Coefficients.h"
#include "GyroBias.h"
#include "Trace.h"

namespace dcm {

// What the gravity correction reads of the estimator around it, for one correction
// (built by Dcm; the part keeps no pointer to it).
struct GravityContext {
    const DcmSettings& settings;
    const DcmCoefficients& k;
    const linalg::Matrix3q30& r;           // R, body to earth
    uint8_t pending_steps;                 // steps summed, not yet integrated into R
    const linalg::Vector3l& offset_units;       // what the step subtracts from the gyro (units)
    const linalg::Vector3l& sensor_bias_units;  // the calibrated bias (units)
    bool starting;                         // within the start-up (startup_s)
    float startup_left;                    // the start-up ramp's share still to run (1 at start, 0 after)
    float tilt_startup_left;               // ... for the tilt's gain: 0 after a start from a mean (Dcm::init)
    TraceHook trace;                       // what the correction did, for the host's trace
};

// One window's means, for the rest test.
struct WindowMeans {
    linalg::Vector3l gyro;   // the gyro's less the calibrated bias, units
    linalg::Vector3l accel;  // accel units
    linalg::Vector3l accel_ef;  // the mean in earth axes, each sample turned to R's time (accel units)
    bool whole;              // a whole window: kCorrectionDivider samples
};

class GravityCorrection {
public:
    // At start-up: the low-pass at gravity (accel units, earth down), no correction.
    void reset(int32_t down_accel_units);
    // One step's sample (counts), a usable one.
    void add(const linalg::Vector3l& gyro_counts, const linalg::Vector3l& accel_counts) {
        gyro_sum_ += gyro_counts;
        accel_sum_ += accel_counts;
        accel_sum_of_sums_ += accel_sum_;  // sum of (samples from this one on) a_j
        ++window_samples_;
    }
    // The turn's centripetal acceleration off the window's accel sums (Centripetal.h),
    // from its gyro sums less the calibrated bias (units) and earth down in body axes
    // (R's third row, Q30); during the start-up a_y's bound leaves the tilt out
    // (TurnMean::subtract_from_window).
    void subtract_turn(TurnMean& turn, const GravityContext& c) {
        const uint8_t n = window_samples_;
        if (n == 0) return;
        // The calibrated bias in counts, rounded (units are counts * 2^8).
        const int32_t bias_y = (c.sensor_bias_units.y + 128) >> 8, bias_z = (c.sensor_bias_units.z + 128) >> 8;
        turn.subtract_from_window(gyro_sum_.y - times_n(bias_y, n), gyro_sum_.z - times_n(bias_z, n), c.r.c, n,
                                  accel_sum_, accel_sum_of_sums_, c.starting);
    }
    // The window into the earth-frame low-pass, each sample turned to R's time; its means
    // for the rest test and the GPS's sums. False: no sample. feed_low_pass false: the
    // means only (the GPS's observations feed the low-pass: low_pass_observation).
    bool low_pass_window(const GravityContext& c, WindowMeans& means, bool feed_low_pass = true);
    // The GPS-aided gravity reading (GpsAid.h: earth axes, accel units) into the low-pass
    // with the factor alpha_q30 (its interval against accel_lowpass_s).
    void low_pass_observation(const linalg::Vector3l& observation, int32_t alpha_q30);
    // The low-pass's direction against earth down: the correction (units per step) and,
    // unless held (GyroBias::integrator_held), the bias's integral; the low-pass turns
    // with the correction.
    void correct_tilt(const GravityContext& c, bool hold_integrator, GyroBias& bias) {
        tilt_correction(c.r, c.tilt_startup_left, hold_integrator, c.settings, c.k, bias, c.trace);
    }
    const linalg::Vector3l& correction_units() const { return correction_units_; }
    const linalg::Vector3l& low_pass_ef() const { return lp_ef_; }
    void rescale(float gyro_ratio, float accel_ratio);

private:
    void clear_window();
    // correct_tilt's work, out of line, with the context's fields as arguments (in
    // registers): through the context itself, in memory, every use of a field would
    // first load it through a pointer.
    void tilt_correction(const linalg::Matrix3q30& r, float startup_left, bool hold_integrator,
                         const DcmSettings& settings, const DcmCoefficients& k, GyroBias& bias, TraceHook trace);

    linalg::Vector3l gyro_sum_;           // gyro and accel counts summed over the window
    linalg::Vector3l accel_sum_;
    linalg::Vector3l accel_sum_of_sums_;  // the running sums summed: weights n - j + 1
    uint8_t window_samples_ = 0;          // samples in the sums
    linalg::Vector3l lp_ef_;              // specific force low-passed in earth axes, accel units
    linalg::Vector3l correction_units_;   // roll/pitch correction, units per step, held between corrections
};

}  // namespace dcm
