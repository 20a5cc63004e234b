// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-step Direction Cosine Matrix attitude estimator with drift correction,
// after W. Premerlani and P. Bizard, "Direction Cosine Matrix IMU: Theory" (2009): the
// update (eq. 17, here as an exact rotation: Strapdown.h), the renormalisation (eqs.
// 18-21), the roll/pitch error (eq. 27: Gravity.h), the heading error (eqs. 31-33:
// Heading.h) and the centripetal term (eq. 26: Centripetal.h).
//
// Frames: body x forward, y right, z down; earth north-east-down, referenced to
// MAGNETIC north (the declination is added only when a heading is reported, so
// changing it moves the output at once). The matrix R maps body to earth; its rows
// are the earth axes seen in body coordinates.
//
// Units: gyro rad/s, specific force m/s^2 (level at rest reads z = -9.81), field in
// any consistent unit (uT), time in seconds. Gains are per second and scaled by the
// step, so the step rate can change without retuning.
//
// Dcm is the facade; each mechanism is a part with its own file and tests, which owns its
// state and is handed what it reads of the estimator around it in a small context
// (GravityContext, HeadingContext) built for the call:
//   DcmSettings.h    DcmSettings            the tuning values with units (VQF's params)
//   Coefficients.h   DcmCoefficients        what follows from them and the scales (VQF's coefficients)
//   Strapdown.h      Strapdown              integration and renormalisation (AP's matrix_update, normalize)
//   Schedule.h       HeavySchedule          one heavy part a step
//   Gravity.h        GravityCorrection      accel window, earth-frame low-pass, roll/pitch (VQF's updateAcc)
//   Centripetal.h    TurnMean               the turn's centripetal acceleration off the window (AP's DCM, airspeed)
//   GpsAid.h         GpsAccel               gravity from the accelerometer less the GPS's acceleration (AP's DCM, GPS)
//   Rest.h           RestDetector           rest detection (VQF's rest, Fusion's FusionOffset)
//   GyroBias.h       GyroBias               the calibrated bias, the estimate and what may teach it when
//   Heading.h        HeadingCorrection      the heading correction with its gate (VQF's updateMag): the
//                    EarthFieldMean,        field's mean in earth axes, the magnetic disturbance gate
//                    MagneticGate
//   Trace.h          TraceHook              what the corrections did, for the host's replay --trace
//   Euler.h          euler_*                the output angles
// Dcm keeps the samples' checks, the start-up (TRIAD), the rebuild, and the wiring
// between the parts: what the step subtracts from the gyro, the status.
//
// Formats of the integer state (table in Coefficients.h): R Q30; rates and turns in
// units (gyro counts * 2^8 per step); the bias in fine units (units * 2^8); accel in
// accel units (counts * 2^8); turns in radians Q26/Q30; fields uT Q5.
//
// Plain C++ with no Arduino include: the host tests, the host replay tool and the
// firmware run this very code.
#pragma once

#include <stdint.h>

#include "Coefficients.h"
#include "DcmSettings.h"
#include "Euler.h"
#include "GpsAid.h"
#include "Gravity.h"
#include "GyroBias.h"
#include "Heading.h"
#include "Rest.h"
#include "Schedule.h"
#include "Strapdown.h"
#include "Trace.h"
#include "Fixed.h"
#include "LinAlg.h"

namespace dcm {

// Bits of Dcm::status().
enum StatusFlags : uint8_t {
    kStatusInitialised = 0x01,
    kStatusAccelIgnored = 0x02,   // last step gave gravity no weight (NaN or beyond any range)
    kStatusMagIgnored = 0x04,     // last mag sample rejected (disturbed, NaN, or too vertical)
    kStatusBiasHeld = 0x08,       // integrator held: rotating fast, or starting up
    kStatusRecovered = 0x10,      // the matrix was rebuilt since start (sticky)
    kStatusNoHeading = 0x20,      // no magnetometer sample yet: yaw is gyro-only
    kStatusGyroRejected = 0x40,   // last gyro sample non-finite or beyond any range: not integrated
    kStatusAtRest = 0x80,         // still for rest_min_s: the gyro bias is being measured
};

class Dcm {
public:
    // Everything the step needs that depends only on the settings is worked out once
    // here (DcmCoefficients); the settings must outlive the estimator.
    explicit Dcm(const DcmSettings& settings = kDefaultDcmSettings);

    // Start-up attitude from one gravity and one field sample (TRIAD):
    // K = -a/|a| (earth down in body), I = (K x m) x K normalised (north), J = K x I.
    // With a zero or unusable field, yaw starts at 0 and kStatusNoHeading is set.
    // Returns false (and stays uninitialised) when gravity is unusable.
    // gravity_is_mean: accel_m_s2 is a mean over the start's window (a still board's, or
    // one that was never still, carried by the gyro), not one sample: the start-up's fast
    // gravity gain has nothing to pull in (correct_gravity).
    bool init(const linalg::Vector3f& accel_m_s2, const linalg::Vector3f& mag_field, bool gravity_is_mean = false);

    // One fixed step: the corrected rate and the accel sample are summed; every
    // kIntegrationSteps steps the summed turn rotates R (R <- R exp([theta x]), with
    // coning) and R is renormalised; every kCorrectionDivider steps the gravity
    // correction is worked out (applied at every step); never both in one step. A
    // non-finite gyro sample is rejected (not summed); a non-finite or absurd accel
    // sample gets no weight.
    // line_due: an output line follows this step; the matrix is brought up to date for it
    // (Strapdown::integrate when two or more steps wait; one is carried by euler_now()).
    // The sample in the sensor's counts (the firmware's path: integer sums at 200 Hz and
    // fixed point in the parts that use them), scaled by set_sample_scales; the gyro
    // counts carry the sensor bias set by set_sensor_bias_rad_s. gyro_valid false: the
    // rate is beyond any MEMS gyro (kMaxCredibleRate_rad_s: every axis at full scale, a
    // stuck or broken read) and is not integrated, nor is the accel sample used.
    // accel_valid false: the sample gives gravity no weight (a stuck accelerometer).
    void update(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts, bool gyro_valid,
                bool accel_valid, bool line_due = false);
    // The same in SI units (host tests, tools): rad/s and m/s^2, held in fine integer
    // units (kFloatGyroScale, kFloatAccelScale). Not to be mixed with the counts form.
    void update(const linalg::Vector3f& gyro_rad_s, const linalg::Vector3f& accel_m_s2, bool line_due = false);
    // The scales of the counts update() takes: rad/s and m/s^2 per count.
    void set_sample_scales(float gyro_rad_s_per_count, float accel_m_s2_per_count);
    // The calibrated bias the gyro counts carry (rad/s; the start-up calibration): the
    // step subtracts it with the estimator's own bias estimate.
    void set_sensor_bias_rad_s(const linalg::Vector3f& bias);
    // The bias was just measured on a still board (the start-up calibration): the gravity
    // integrator slows to ki_rp_measured (a rest does the same by itself), and the
    // estimate stays within a quarter of bias_limit_rad_s (GyroBias.h).
    void set_gyro_bias_measured() { bias_.set_calibrated(); }
    bool gyro_bias_measured() const { return bias_.measured(); }

    // A new magnetometer sample (call when one arrives, e.g. 75 Hz): turned into earth
    // axes and averaged; every kHeadingSteps the mean's tilt-compensated heading error,
    // projected on earth down, goes into the turn not yet integrated (the yaw drift
    // correction). A mean whose strength or dip differs from the learned earth field is
    // rejected (kStatusMagIgnored).
    // age_steps: steps the sample waited before this call (its latency grows by as much).
    void correct_heading(const linalg::Vector3f& mag_field, uint8_t age_steps = 0);
    // The same for a sample already in the integer form (field_q5_of, where it arrived).
    void correct_heading(const linalg::Vector3i& field_q5, uint8_t age_steps = 0);
    // The next update (without a line) integrates or corrects gravity: a caller with
    // deferrable work puts it on another step.
    bool heavy_due() const { return initialised() && HeavySchedule::blocks(next_heavy_part(false)); }
    // A field sample given to correct_heading after the next update completes the
    // average of kHeadingSteps and corrects the heading, or is the first heading after a
    // start without one (the costly parts): a caller with
    // deferrable work (the compass learner) puts it on another step.
    bool heading_due_next() const {
        return initialised() && ((status_ & kStatusNoHeading) || heading_.due_after_next_step());
    }

    // The gyro's own turn over `steps` steps from its `counts` summed meanwhile, less the
    // calibrated bias and the estimator's (no drift correction in it: what the compass
    // learner composes), in Q30 radians, each axis saturated at 1.5 rad (2 kMaxTurnAxisQ26).
    linalg::Vector3l gyro_turn_q30(const linalg::Vector3l& counts, uint16_t steps) const;

    // Forgets the learned earth field (strength and dip): the next field sample is
    // taken as the reference. take_heading: its heading too, at once, as a new steady
    // field's is after mag_recover_s (a new compass calibration, whose fields the old
    // reference would reject as disturbed); false: the heading is corrected at the usual
    // rate (a learned offset that moved by a few uT: a small, uncertain change that
    // must not turn the heading in one step).
    void reset_mag_reference(bool take_heading = true) { heading_.forget_field(take_heading, steps_); }
    // The compass's calibration moved (a learned offset): during the start the heading's
    // mean begins again from the next sample (HeadingCorrection::restart_mean).
    void restart_heading_mean() { heading_.restart_mean(steps_); }

    bool initialised() const { return (status_ & kStatusInitialised) != 0; }
    // The last update turned the matrix or worked out the gravity correction (the
    // step's two heavy parts, each on its own step): a caller with deferrable work (the
    // compass learner) puts only a short piece of it on this step, so that the step stays
    // within its budget (the estimator step's maximum in `make bench`).
    bool heavy_step() const { return heavy_; }
    uint8_t status() const { return status_; }
    uint16_t recoveries() const { return recoveries_; }
    // R in float (tests, tools, the quaternion output): the estimator keeps it in Q30.
    linalg::Matrix3f matrix() const { return linalg::matrix_from_q30(strapdown_.r()); }
    // R's last entry, earth down's body z component: cos(roll) cos(pitch), the cosine of
    // the tilt (one entry, where matrix() converts nine).
    float cos_tilt() const { return linalg::float_from_fixed(strapdown_.r().c.z, linalg::kQ30); }
    // The turn's centripetal correction (Centripetal.h): its gain and means, kept by the
    // caller (the pipeline: it knows the airspeed); nullptr: none.
    void set_turn(TurnMean* turn) { turn_ = turn; }
    // A usable GPS fix's velocity (m/s, north-east-down with north the MAGNETIC one, as
    // the estimator's earth axes), interval_s after the one before (s, the receiver's
    // time; 0: none), gain AHRS_GPS_GAIN: the accelerometer's earth-frame sums less the
    // GPS's acceleration become the gravity correction's reference (GpsAid.h) in place of
    // the accelerometer alone and the turn's term, until kGpsTimeoutWindows pass without
    // one or gps_unusable(). Not during the start-up (its low-pass ramps on its own).
    void on_gps_velocity(const linalg::Vector3f& vel_ned_m_s, float interval_s, float gain);
    // A fix that cannot be used (no 3D fix, too few satellites, AHRS_GPS_USE 0): the
    // accelerometer's own reference at once.
    void gps_unusable() { gps_.stop(); }
    bool gps_aiding() const { return gps_.aiding(); }
    // The GPS course over ground as the heading reference, for a board without a compass
    // or with a failed one (AP_AHRS_DCM: yaw error sin(course - yaw), above 3 m/s: the
    // caller's test): course_rad from the MAGNETIC north, interval_steps since the last
    // course given (the correction's rate stands for it). The first one after a start
    // without a heading is taken at once, as a compass's first field is.
    void correct_heading_from_course(float course_rad, uint16_t interval_steps);
    // Current gyro-bias estimate, rad/s (what the integrator has learned).
    linalg::Vector3f gyro_bias_rad_s() const;
    // A start value for the bias estimate, e.g. from a start-up calibration at rest.
    void set_gyro_bias_rad_s(const linalg::Vector3f& bias);
    const DcmSettings& settings() const { return *settings_; }
#if DCM_TRACE
    // What the corrections do, step by step, into *trace (null: none): host tools only
    // (Trace.h); the firmware has no trace and the estimate does not depend on one.
    void set_trace(DcmTrace* trace) { trace_ = TraceHook(trace); }
#endif
    // Euler angles of R (yaw relative to magnetic north); see Euler.h.
    EulerAngles euler() const {
        return euler_in_rad(euler_q24_from_q30(strapdown_.r().a.x, strapdown_.r().a.y, strapdown_.r().b.x, strapdown_.r().b.y, strapdown_.r().c.x, strapdown_.r().c.y, strapdown_.r().c.z));
    }
    // Euler angles of R carried forward by output_lead_s at the last corrected rate:
    // the attitude now rather than when the (low-passed, hence delayed) gyro sample
    // was taken. R (I + [w lead x]), first order: the lead is a few ms. What the
    // firmware prints.
    EulerAngles euler_now() const { return euler_in_rad(euler_now_q24()); }
    // The same in Q24 radians, for the integer output path; with trim_q14 (rows of a Q14
    // rotation T, Euler.h), the angles of R T^T: the airframe's for a board trimmed by T.
    EulerQ24 euler_now_q24(const int16_t (*trim_q14)[3] = nullptr) const;

    // The step's fixed constants (Coefficients.h), here too for the callers and tests
    // that name them as Dcm's.
    static constexpr uint8_t kCorrectionDivider = dcm::kCorrectionDivider;
    static constexpr uint8_t kIntegrationSteps = dcm::kIntegrationSteps;
    static constexpr uint8_t kRenormaliseEvery = dcm::kRenormaliseEvery;
    static constexpr int32_t kMaxTurnAxisQ26 = dcm::kMaxTurnAxisQ26;
    static constexpr uint8_t kHeadingSteps = dcm::kHeadingSteps;
    static constexpr float kRestMeanTau_s = dcm::kRestMeanTau_s;
    static constexpr float kStartupAccelTau_s = dcm::kStartupAccelTau_s;
    static constexpr uint8_t kTurnFraction = dcm::kTurnFraction;
    static constexpr int32_t kTurnScale = dcm::kTurnScale;
    static constexpr float kFloatGyroScale = dcm::kFloatGyroScale;
    static constexpr float kFloatAccelScale = dcm::kFloatAccelScale;
    static constexpr float kFloatUnitsPerRad_s = dcm::kFloatUnitsPerRad_s;

private:
    // The heavy part of the next step (HeavySchedule): step() does what this says,
    // heavy_due() tells the caller.
    HeavyPart next_heavy_part(bool line_due) const {
        return schedule_.next(strapdown_.pending_steps(), strapdown_.renormalisation_due(), line_due);
    }
    void step(const linalg::Vector3l& gyro, const linalg::Vector3l& accel, bool gyro_ok, bool accel_ok, bool line_due);
    void take_sample(const linalg::Vector3l& gyro, const linalg::Vector3l& accel, bool gyro_ok, bool accel_ok);
    void correct_gravity();
    linalg::Vector3l earth_of_counts(const linalg::Vector3i& counts) const;
    // What the gravity correction reads (Gravity.h).
    GravityContext gravity_context();
    void update_offset();
    // What the heading correction reads and turns (Heading.h).
    HeadingContext heading_context() {
        return HeadingContext{*settings_, k_, strapdown_, bias_, last_rate_units(), steps_,
                              (status_ & kStatusAtRest) != 0, trace()};
    }
    // Counts to the turn sums' units: a byte shift (a multiply by 256 may become avr-gcc's
    // 32x32 routine).
    static int32_t in_turn_units(int32_t counts) {
        static_assert(kTurnFraction == 8, "a byte shift");
        return (int32_t)((uint32_t)counts << 8);
    }
    linalg::Vector3l pending_turn_units() const;  // summed since the last integration (turn sums' units)
    linalg::Vector3f pending_turn_rad() const;
    linalg::Vector3l last_rate_units() const;     // the last sample, corrected (turn sums' units per step)
    linalg::Vector3f last_rate_rad_s() const;
    // mean_off_bias: the rest test's gyro mean less the bias estimate (the hold test's too).
    void detect_rest(const WindowMeans& window, const linalg::Vector3l& mean_off_bias);
    linalg::Vector3f last_mag_field() const;
    void recover();
    bool accel_plausible(const linalg::Vector3f& a) const;

    // The settings (not a copy: 84 bytes of RAM; they must outlive the estimator, as
    // kDefaultDcmSettings and a tool's own set do) and what follows from them, once.
    const DcmSettings* settings_;
    DcmCoefficients k_;

    Strapdown strapdown_;                // R and the turn summed for it
    HeavySchedule schedule_;             // which heavy part a step runs
    GyroBias bias_;                      // the calibrated bias and the estimate
    GravityCorrection gravity_;          // the accel window, its low-pass and the roll/pitch correction
    TurnMean* turn_ = nullptr;           // the turn's centripetal correction, if flying (set_turn)
    GpsAccel gps_;                       // the GPS-aided gravity reference
    RestDetector rest_;                  // rest, when the gyro reads its bias alone
    HeadingCorrection heading_;          // the field's mean, the disturbance gate, the heading's correction
    // The rates in the turn sums' units per step ("units": gyro counts * 2^8).
    linalg::Vector3l offset_units_;      // sensor bias + bias - correction: what the step subtracts
    linalg::Vector3l last_accel_;        // for a rebuild if the matrix degenerates (counts)
    linalg::Vector3l last_gyro_;         // the last sample's rate (counts)
    linalg::Vector3i last_field_q5_;     // for a rebuild if the matrix degenerates (uT * 2^5)
    bool heavy_ = false;                 // the last update integrated or corrected gravity
    uint16_t steps_ = 0;                 // since init, saturated (the start-up ramp's clock)
    uint16_t recoveries_ = 0;
    uint8_t status_ = kStatusNoHeading;
    bool start_from_mean_ = false;       // init's gravity_is_mean
    bool course_taken_ = false;          // a GPS course gave the heading since the start
    // The trace's one hook (Trace.h), handed to the parts in their context: set_trace's
    // on the host; on the AVR an empty one, which takes no byte of Dcm.
#if DCM_TRACE
    TraceHook trace() const { return trace_; }
    TraceHook trace_;
#else
    static TraceHook trace() { return TraceHook(); }
#endif
};

}  // namespace dcm
