// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-step Direction Cosine Matrix attitude estimator with drift correction,
// after W. Premerlani and P. Bizard, "Direction Cosine Matrix IMU: Theory" (2009).
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
// Plain C++ with no Arduino include: the host tests, the host replay tool and the
// firmware run this very code.
#pragma once

#include <stdint.h>

#include "Euler.h"
#include "Fixed.h"
#include "LinAlg.h"

namespace dcm {

struct DcmSettings {
    float step_s;                    // fixed update step, s (200 Hz: 0.005)
    float kp_rp_1_s;                 // roll/pitch proportional gain, 1/s
    float ki_rp_1_s2;                // roll/pitch integral gain (gyro-bias estimate), 1/s^2
    float kp_yaw_1_s;                // yaw proportional gain, 1/s
    float ki_yaw_1_s2;               // yaw integral gain, 1/s^2
    float kp_startup_1_s;            // roll/pitch/yaw P gain at start, ramping down to the steady ones, 1/s
    float startup_s;                 // length of the start-up ramp (also speeds up the accel low-pass), s
    float accel_max_g;               // beyond any accelerometer's range: such a sample is garbage, g
    float accel_lowpass_s;           // time constant of the earth-frame accel low-pass, s
    float integrator_hold_rate_rad_s;// mean rate (0.5 s) above which the bias integrator is held, rad/s
    float bias_limit_rad_s;          // bound on each axis of the gyro-bias estimate, rad/s
    float mag_norm_tolerance;        // |field| may differ from the learned one by this fraction
    float mag_dip_tolerance;         // field.down/|field| may differ from the learned one by this
    float mag_recover_s;             // a different field steady this long becomes the reference, s
    float mag_new_min_rate_rad_s;    // ... while the board turned at least this fast on average, rad/s
    float mag_latency_s;             // age of a field sample against the gyro-propagated attitude, s (<= 5.9 steps)
    float rest_gyro_deviation_rad_s; // at rest the gyro stays this close to its recent mean, rad/s
    float rest_accel_deviation_m_s2; // ... and the accelerometer this close to its own, m/s^2
    float rest_min_s;                // rest must last this long before the bias is taken from it, s
    float rest_bias_s;               // time constant of the bias estimate at rest (0: none), s
    float output_lead_s;             // the output is R carried forward by this, s
};

// One set for everything, each value with its physical reason; `make tune`
// (bench/tune.py) cross-validates them on the BROAD recordings (tuned on one half,
// scored on the other) and scores them on the scenarios with a real board's errors.
// The gyro bias is learned from gravity (the two horizontal axes, ki_rp) and at rest
// (every axis, rest_*), never from the compass (ki_yaw 0): the compass's errors (a
// residual hard iron, a nearby magnet) are degrees and turn with the heading, so an
// integrator on them learns a false bias that makes the heading drift whenever the
// compass is disturbed (mag_disturbance with an uncalibrated compass: 9.6 -> 5.9 deg;
// VQF makes the same choice). Rest: a hand-held board's tremor stays below 2 deg/s and
// 0.5 m/s^2 (VQF's thresholds); 1.5 s of it is rest.
// The two latencies: the MPU6000's 42 Hz DLPF delays the gyro by 4.8 ms (Register
// Map 4.3), of which the step's end-point integration takes back 2.5 ms: the output
// leads by 3 ms. A field sample is ~5 ms old when the step uses it (the HMC5883L's
// 8-sample average, the wait for the next step), and BROAD's own magnetometer lags
// its gyro by ~10 ms more: 8 ms serves both (BROAD 1.83 -> 1.56 deg mean total,
// scenarios 0.50 -> 0.40 deg, against 12 ms and no lead).
constexpr DcmSettings kDefaultDcmSettings = {
    0.005f,                         // step_s: 200 Hz
    1.0f,                           // kp_rp_1_s
    0.1f,                           // ki_rp_1_s2
    0.1f,                           // kp_yaw_1_s
    0.0f,                           // ki_yaw_1_s2: no bias from the compass (see above)
    5.0f,                           // kp_startup_1_s
    3.0f,                           // startup_s
    16.0f,                          // accel_max_g
    3.0f,                           // accel_lowpass_s
    20.0f * linalg::kRadPerDeg,     // integrator_hold_rate_rad_s (ArduPilot's 20 deg/s)
    10.0f * linalg::kRadPerDeg,     // bias_limit_rad_s
    0.1f,                           // mag_norm_tolerance
    0.1f,                           // mag_dip_tolerance
    20.0f,                          // mag_recover_s
    20.0f * linalg::kRadPerDeg,     // mag_new_min_rate_rad_s (VQF's magNewMinGyr)
    0.008f,                         // mag_latency_s
    2.0f * linalg::kRadPerDeg,      // rest_gyro_deviation_rad_s
    0.5f,                           // rest_accel_deviation_m_s2
    1.5f,                           // rest_min_s
    1.0f,                           // rest_bias_s
    0.003f,                         // output_lead_s
};

constexpr float kGravity_m_s2 = 9.80665f;
// Beyond any MEMS gyro's range (the MPU6000 stops at 2000 deg/s = 35 rad/s): such a
// sample is garbage, not a rotation, and is not integrated.
constexpr float kMaxCredibleRate_rad_s = 50.0f;

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
    // A rate or specific-force limit for a squared comparison in 16x16 products: the
    // vector shifted right by `shift`, its squared length against limit2 (limit_of).
    struct Limit {
        uint32_t limit2;
        uint8_t shift;
    };

    // Everything the step needs that depends only on the settings is worked out once
    // here (at compile time for constant settings: no start-up code, and a float
    // division costs ~480 cycles on the 2560).
    explicit constexpr Dcm(const DcmSettings& settings = kDefaultDcmSettings)
        : settings_(&settings),
          startup_steps_((uint16_t)(settings.startup_s / settings.step_s)),
          inv_startup_steps_(settings.step_s / settings.startup_s),
          accel_alpha_q30_(q30_of(settings.step_s * (float)kCorrectionDivider /
                                  (settings.accel_lowpass_s + settings.step_s * (float)kCorrectionDivider))),
          tilt_turn_q30_(q30_of(settings.kp_rp_1_s * settings.step_s * (float)kCorrectionDivider)),
          mag_recover_steps_((uint16_t)(settings.mag_recover_s / settings.step_s)),
          rest_min_corrections_((uint16_t)(settings.rest_min_s / (settings.step_s * (float)kCorrectionDivider))),
          rest_alpha_q14_((int16_t)(16384.0f * settings.step_s * (float)kCorrectionDivider /
                                        (kRestMeanTau_s + settings.step_s * (float)kCorrectionDivider) + 0.5f)),
          rest_bias_alpha_q30_(settings.rest_bias_s > 0.0f
                                   ? q30_of(settings.step_s * (float)kCorrectionDivider /
                                            (settings.rest_bias_s + settings.step_s * (float)kCorrectionDivider))
                                   : 0),
          startup_accel_alpha_(settings.step_s * (float)kCorrectionDivider /
                               (kStartupAccelTau_s + settings.step_s * (float)kCorrectionDivider)),
          mag_new_min_turn_rad_(settings.mag_recover_s * settings.mag_new_min_rate_rad_s),
          // For the float form's scales until set_sample_scales (set_output_factors).
          hold_rate_(limit_of(settings.integrator_hold_rate_rad_s * kFloatUnitsPerRad_s)),
          rest_gyro_dev_(limit_of(settings.rest_gyro_deviation_rad_s * kFloatUnitsPerRad_s)),
          rest_accel_dev_(limit_of(settings.rest_accel_deviation_m_s2 * ((float)kTurnScale / kFloatAccelScale))),
          bias_limit_fine_((int32_t)(settings.bias_limit_rad_s * kFloatUnitsPerRad_s * (float)kTurnScale)),
          ki_fine_((int32_t)(settings.ki_rp_1_s2 * settings.step_s * (float)kCorrectionDivider * kFloatUnitsPerRad_s *
                             (float)kTurnScale)) {}

    // Start-up attitude from one gravity and one field sample (TRIAD):
    // K = -a/|a| (earth down in body), I = (K x m) x K normalised (north), J = K x I.
    // With a zero or unusable field, yaw starts at 0 and kStatusNoHeading is set.
    // Returns false (and stays uninitialised) when gravity is unusable.
    bool init(const linalg::Vector3f& accel_m_s2, const linalg::Vector3f& mag_field);

    // One fixed step: the corrected rate and the accel sample are summed; every
    // kIntegrationSteps steps the summed turn rotates R (R <- R exp([theta x]), with
    // coning) and R is renormalised; every kCorrectionDivider steps the gravity
    // correction is worked out (applied at every step); never both in one step. A
    // non-finite gyro sample is rejected (not summed); a non-finite or absurd accel
    // sample gets no weight.
    // line_due: an output line follows this step; the matrix is brought up to date for it
    // (Dcm::integrate when two or more steps wait; one is carried by euler_now()).
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

    // A new magnetometer sample (call when one arrives, e.g. 75 Hz): turned into earth
    // axes and averaged; every kHeadingSteps the mean's tilt-compensated heading error,
    // projected on earth down, goes into the turn not yet integrated (the yaw drift
    // correction). A mean whose strength or dip differs from the learned earth field is
    // rejected (kStatusMagIgnored).
    // age_steps: steps the sample waited before this call (its latency grows by as much).
    void correct_heading(const linalg::Vector3f& mag_field, uint8_t age_steps = 0);
    // The next update (without a line) integrates or corrects gravity: a caller with
    // deferrable work puts it on another step.
    bool heavy_due() const { return initialised() && blocks(next_heavy_part(false)); }
    // A field sample given to correct_heading after the next update completes the
    // average of kHeadingSteps and corrects the heading, or is the first heading after a
    // start without one (the costly parts, up to ~11 k and ~20 k): a caller with
    // deferrable work (the compass learner) puts it on another step.
    bool heading_due_next() const {
        return initialised() && ((status_ & kStatusNoHeading) ||
                                 (uint16_t)(heading_steps_ + steps_since_mag_ + 1u) >= kHeadingSteps);
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
    void reset_mag_reference(bool take_heading = true) {
        mag_ref_norm_ = 0.0f;
        mag_take_heading_ = take_heading;
        // The samples waiting for the heading's mean were calibrated the old way. The next
        // sample closes the mean alone: the heading has run on the gyro meanwhile (the
        // field was rejected, or the mean dropped), and one sample gives the new reference
        // and the heading's error at once, a whole mean (40 ms) sooner.
        heading_field_sum_ = linalg::Vector3l();
        heading_norm2_sum_ = 0;
        heading_samples_ = 0;
        heading_steps_ = kHeadingSteps - 1;
    }

    bool initialised() const { return (status_ & kStatusInitialised) != 0; }
    // The last update turned the matrix or worked out the gravity correction (the
    // step's two heavy parts, ~8.5 k and ~12-15 k cycles on the AVR, each on its own
    // step): a caller with deferrable work (the compass learner) puts only a short piece
    // of it on this step, so that the step stays under 30 k.
    bool heavy_step() const { return heavy_; }
    uint8_t status() const { return status_; }
    uint16_t recoveries() const { return recoveries_; }
    // R in float (tests, tools, the quaternion output): the estimator keeps it in Q30.
    linalg::Matrix3f matrix() const { return linalg::matrix_from_q30(r_); }
    // Current gyro-bias estimate, rad/s (what the integrator has learned).
    linalg::Vector3f gyro_bias_rad_s() const;
    // Seed for the bias estimate, e.g. from a start-up calibration at rest.
    void set_gyro_bias_rad_s(const linalg::Vector3f& bias);
    const DcmSettings& settings() const { return *settings_; }
    // Euler angles of R (yaw relative to magnetic north); see Euler.h.
    EulerAngles euler() const {
        return euler_in_rad(euler_q24_from_q30(r_.a.x, r_.a.y, r_.b.x, r_.b.y, r_.c.x, r_.c.y, r_.c.z));
    }
    // Euler angles of R carried forward by output_lead_s at the last corrected rate:
    // the attitude now rather than when the (low-passed, hence delayed) gyro sample
    // was taken. R (I + [w lead x]), first order: the lead is a few ms. What the
    // firmware prints.
    EulerAngles euler_now() const { return euler_in_rad(euler_now_q24()); }
    // The same in Q24 radians, for the integer output path.
    EulerQ24 euler_now_q24() const;

    // The roll/pitch correction is worked out every this many steps (50 Hz at the
    // default 200 Hz step) and applied at every step: it moves at the 3 s pace of
    // the accel low-pass, and the work saved is a quarter of the step.
    static constexpr uint8_t kCorrectionDivider = 4;
    // The matrix is turned every this many steps (50 Hz at the 200 Hz step) by the
    // rates summed meanwhile (Dcm::integrate). Even: the coning term needs two halves.
    static constexpr uint8_t kIntegrationSteps = 4;
    // Renormalisation every this many integrations (6 Hz): each integration is a
    // rotation to 4e-7 (Dcm::integrate), so eight leave R orthonormal to ~3e-6, below
    // what a 0.01 deg output shows (1.7e-4).
    static constexpr uint8_t kRenormaliseEvery = 8;
    // The turn of one integration saturates at 0.75 rad an axis (Q26): beyond any gyro
    // (2000 deg/s over 20 ms is 0.7 rad), and |theta|^2 < 2 stays within Q30.
    static constexpr int32_t kMaxTurnAxisQ26 = 50331648L;
    // The heading is corrected from the mean of the field samples over at least this
    // many steps (25 Hz; the HMC5883L's 75 Hz samples in threes): the correction is
    // slow (1/kp_yaw = 10 s), and the mean keeps every sample's information.
    static constexpr uint8_t kHeadingSteps = 8;
    // The means the rest test compares the samples against (VQF's 0.5 s).
    static constexpr float kRestMeanTau_s = 0.5f;
    // The accel low-pass's time constant at start (startup_s ramps it to accel_lowpass_s).
    static constexpr float kStartupAccelTau_s = 0.25f;
    // The turn sums hold gyro counts * kTurnScale (2^kTurnFraction): the offset the step
    // subtracts is resolved to 1/256 of a count (0.0002 deg/s on the 2000 deg/s range).
    static constexpr uint8_t kTurnFraction = 8;
    static constexpr int32_t kTurnScale = 1L << kTurnFraction;
    // The float form's units: 2^-14 rad/s (50 rad/s * 2^8 * 4 steps fits in 32 bits)
    // and 2^-12 m/s^2.
    static constexpr float kFloatGyroScale = 1.0f / 16384.0f;
    static constexpr float kFloatAccelScale = 1.0f / 4096.0f;
    static constexpr float kFloatUnitsPerRad_s = (float)kTurnScale / kFloatGyroScale;

private:
    // The heavy part of the next step, from the counters before it: step() does what this
    // says, heavy_due() tells the caller.
    enum class HeavyPart : uint8_t { kNone, kIntegration, kGravity, kRenormalisation };
    HeavyPart next_heavy_part(bool line_due) const;
    // The integration and the gravity correction take a step to themselves (heavy_due,
    // heavy_step); the renormalisation (~5 k) only keeps off the line's step.
    static bool blocks(HeavyPart p) { return p == HeavyPart::kIntegration || p == HeavyPart::kGravity; }
    void step(const linalg::Vector3l& gyro, const linalg::Vector3l& accel, bool gyro_ok, bool accel_ok, bool line_due);
    void correct_tilt(float startup_left, bool hold_integrator);
    void integrate();
    void renormalise_rows();  // every kRenormaliseEvery integrations, on a step of its own
    static void turn_row(linalg::Vector3l& r, const linalg::Matrix3q30& d);
    void correct_gravity();
    void update_offset();
    static float inverse(uint8_t n);
    static int32_t scale_q15(int32_t x, uint16_t c);
    // Counts to the turn sums' units: a byte shift (a multiply by 256 may become avr-gcc's
    // 32x32 routine, ~105 cycles).
    static int32_t in_turn_units(int32_t counts) {
        static_assert(kTurnFraction == 8, "a byte shift");
        return (int32_t)((uint32_t)counts << 8);
    }
    void set_output_factors();
    linalg::Vector3l units_of(const linalg::Vector3f& rate_rad_s) const;  // in the turn sums' units
    float turn_rad_per_unit() const { return gyro_scale_ * settings_->step_s * (1.0f / (float)kTurnScale); }
    linalg::Vector3l pending_turn_units() const;  // summed since the last integration (turn sums' units)
    linalg::Vector3f pending_turn_rad() const;
    linalg::Vector3l last_rate_units() const;     // the last sample, corrected (turn sums' units per step)
    linalg::Vector3f last_rate_rad_s() const;
    // mean_off_bias: the rest test's gyro mean less the bias estimate (the hold test's too).
    void detect_rest(const linalg::Vector3l& gyro_mean, const linalg::Vector3l& accel_mean,
                     const linalg::Vector3l& mean_off_bias, bool whole_window);
    static bool exceeds(const linalg::Vector3l& v, const Limit& limit);
    // A limit L as a shift s and (L / 2^s)^2 with L / 2^s below 2^14: a vector that stays
    // within 16 bits after the shift up to twice the limit, and the limit resolved to 2^-13.
    static constexpr Limit limit_of(float value, uint8_t shift = 0) {
        return value >= 16384.0f && shift < 31 ? limit_of(value * 0.5f, (uint8_t)(shift + 1))
                                               : Limit{value > 0.0f ? (uint32_t)(value * value) : 0u, shift};
    }
    linalg::Vector3l bias_units() const;  // bias_fine_ rounded to units
    float correction_dt() const { return settings_->step_s * (float)kCorrectionDivider; }  // s between corrections
    float accel_units_per_m_s2() const { return accel_units_per_m_s2_; }
    linalg::Vector3f last_mag_field() const;
    static constexpr int32_t q30_of(float x) { return (int32_t)(x * 1073741824.0f); }
    bool renormalise(int32_t& skew_q30);  // skew: the X.Y it found
    static bool rescale(const linalg::Vector3l& row, linalg::Vector3l& out);
    linalg::Vector3l theta_q26(const linalg::Vector3l& units) const;  // the turn sums in Q26 radians
    linalg::Vector3l theta_q26_in_float(const linalg::Vector3l& units) const;
    int32_t theta_axis_q26(int32_t units) const;
    linalg::Vector3l theta_q30(const linalg::Vector3l& units) const;  // ... and in Q30
    linalg::Vector3l theta_q26_coarse(const linalg::Vector3l& units) const;  // Q26 by the 16-bit factor
    void recover();
    void clamp_bias();
    bool accel_plausible(const linalg::Vector3f& a) const;
    void learn_field(float norm, float down_component);
    bool field_matches(float norm, float down_component, float ref_norm, float ref_down,
                       float tolerance_scale) const;

    // The settings (not a copy: 84 bytes of RAM; they must outlive the estimator, as
    // kDefaultDcmSettings and a tool's own set do) and what follows from them, once.
    const DcmSettings* settings_;
    uint16_t startup_steps_;
    float inv_startup_steps_;
    int32_t accel_alpha_q30_;            // low-pass factor per correction
    int32_t tilt_turn_q30_;              // kp_rp * the correction interval
    uint16_t mag_recover_steps_;
    uint16_t rest_min_corrections_;
    int16_t rest_alpha_q14_;             // low-pass factor of the rest means, per correction (0.04: 2e-4 rounding)
    int32_t rest_bias_alpha_q30_;        // bias step towards the rest mean, per correction
    float startup_accel_alpha_;          // the accel low-pass factor at the start of the ramp, per correction
    float mag_new_min_turn_rad_;         // how far the board must turn while a new field stays steady

    linalg::Matrix3q30 r_;               // body -> earth, Q30 (integrate: turned in integers)
    // The rates in the turn sums' units per step ("units": gyro counts * 2^8).
    linalg::Vector3l bias_fine_;         // integrator: gyro-bias estimate, units * 2^8
    linalg::Vector3l correction_units_;  // roll/pitch correction, held between corrections
    linalg::Vector3l offset_units_;      // sensor bias + bias - correction: what the step subtracts
    linalg::Vector3l sensor_bias_units_; // set_sensor_bias_rad_s
    Limit hold_rate_;                    // integrator_hold_rate_rad_s (units)
    Limit rest_gyro_dev_;                // rest_gyro_deviation_rad_s (units)
    Limit rest_accel_dev_;               // rest_accel_deviation_m_s2 (accel counts * 2^8)
    int32_t bias_limit_fine_;            // bias_limit_rad_s (units * 2^8)
    int32_t ki_fine_;                    // ki_rp * the correction interval, units * 2^8 per rad/s
    int32_t kp_units_ = 0;               // kp_rp in units per rad/s (set_output_factors)
    uint32_t min_lp2_ = 0;               // (g/2)^2 as correct_tilt's |lp|^2 (set_output_factors)
    float gyro_scale_ = kFloatGyroScale; // rad/s per count
    float accel_scale_ = kFloatAccelScale; // m/s^2 per count
    float accel_units_per_m_s2_ = (float)kTurnScale / kFloatAccelScale;  // the accel sums' units (counts * 2^8)
    float units_per_rad_s_ = kFloatUnitsPerRad_s;  // the turn sums' units
    uint16_t lead_steps_q15_ = 0;        // output_lead_s / step_s, Q15 (set_output_factors)
    uint16_t theta_q26_per_unit_q15_ = 0;  // Q26 radians per unit of the turn sums, Q15; 0: float path
    int32_t theta_factor_q30_ = 0;       // Q26 radians per unit of the turn sums, Q30; 0: the float path
    int32_t theta_units_limit_ = 0;      // the turn sums' saturation (kMaxTurnAxisQ26)
    int16_t mag_latency_steps_q12_ = 0;  // mag_latency_s in steps (below 6), Q12
    linalg::Vector3l accel_lp_ef_;       // specific force low-passed in earth axes, accel counts * 2^8
    linalg::Vector3l last_accel_;        // for a rebuild if the matrix degenerates (counts)
    linalg::Vector3l last_gyro_;         // the last sample's rate (counts)
    linalg::Vector3i last_field_q5_;     // for a rebuild if the matrix degenerates (uT * 2^5)
    linalg::Vector3l gyro_sum_;          // gyro and accel counts summed over the correction period
    linalg::Vector3l accel_sum_;
    linalg::Vector3l rest_gyro_mean_;    // their low-passed means, for the rest test (units,
    linalg::Vector3l rest_accel_mean_;   // ... accel counts * 2^8)
    uint16_t rest_corrections_ = 0;      // how long the board has been still, in corrections
    linalg::Vector3i rest_field_;        // the field (body axes, uT Q5) when the board last seemed to turn
    linalg::Vector3l accel_sum_of_sums_; // the running sums summed: weights n - j + 1
    uint8_t window_samples_ = 0;         // samples in the sums
    linalg::Vector3l first_half_;        // corrected rates summed over the integration's first half (kTurnScale)
    linalg::Vector3l turn_sum_;          // ... and since
    uint8_t pending_steps_ = 0;          // steps summed, not yet integrated
    uint8_t updates_since_renormalise_ = 0;  // >= kRenormaliseEvery: renormalisation due
    linalg::Vector3l heading_field_sum_; // field samples in earth axes, summed for the heading (uT, Q17)
    uint32_t heading_norm2_sum_ = 0;     // ... and their squared strengths (uT^2 / 4)
    uint8_t heading_samples_ = 0;
    uint16_t heading_steps_ = 0;         // steps the summed samples stand for
    bool gravity_due_ = false;           // a gravity correction waits for a step without an integration
    bool heavy_ = false;                 // the last update integrated or corrected gravity
    float mag_ref_norm_ = 0.0f;          // learned field strength
    bool mag_take_heading_ = true;       // reset_mag_reference's take_heading
    float mag_ref_down_ = 0.0f;          // learned sine of the dip (field . down / |field|)
    float mag_candidate_norm_ = 0.0f;    // the recent disturbed field, for the new-field test
    float mag_candidate_down_ = 0.0f;
    uint16_t steps_ = 0;                 // since init, saturated (the start-up ramp's clock)
    uint16_t steps_since_mag_ = 0;
    uint16_t mag_steady_steps_ = 0;      // how long a different field has stayed the same
    float mag_steady_turn_rad_ = 0.0f;   // how far the board turned meanwhile
    uint16_t recoveries_ = 0;
    uint8_t correction_phase_ = 0;
    uint8_t status_ = kStatusNoHeading;
    bool rotating_fast_ = false;
};

}  // namespace dcm
