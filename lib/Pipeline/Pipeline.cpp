// SPDX-License-Identifier: GPL-3.0-or-later
#include "Pipeline.h"

#include "Airspeed.h"
#include "Profile.h"
#include "Fixed.h"
#include "Mpu6000.h"

#include <math.h>

namespace pipeline {

using linalg::Vector3f;

namespace {
constexpr float kG = mpu6000::kStandardGravity_m_s2;
// The checks' thresholds in the counts of the MPU6000 driver's ranges (the samples'; a
// host test's sample_from_si uses the same).
constexpr float kGyroCount_rad_s = mpu6000::gyro_rad_s_per_count(mpu6000::kGyroRange);
constexpr float kAccelCount_m_s2 = mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
constexpr int32_t kSpikeGyroJumpCounts = (int32_t)(kSpikeGyroJump_rad_s / kGyroCount_rad_s);
// A rate beyond any MEMS gyro's (the DCM's kMaxCredibleRate_rad_s; three axes at the
// 2000 deg/s full scale make 60 rad/s) is a broken read, not a rotation.
constexpr uint32_t kMaxCredibleRateCounts2 = (uint32_t)((dcm::kMaxCredibleRate_rad_s / kGyroCount_rad_s) *
                                                        (dcm::kMaxCredibleRate_rad_s / kGyroCount_rad_s));
// |a - b| of two counts.
int32_t jump(int16_t a, int16_t b) {
    const int32_t d = (int32_t)a - b;
    return d < 0 ? -d : d;
}
// |v|^2 in counts^2 (three 16x16 multiplies; below 3 * 2^30).
uint32_t norm2(const linalg::Vector3i& v) {
    return (uint32_t)linalg::mul_s16(v.x, v.x) + (uint32_t)linalg::mul_s16(v.y, v.y) +
           (uint32_t)linalg::mul_s16(v.z, v.z);
}
}  // namespace

int16_t centripetal_gain_q8(float airspeed_m_s) {
    if (!(airspeed_m_s >= kCentripetalMinAirspeed_m_s)) return 0;  // NaN too
    const float v = airspeed_m_s < kCentripetalMaxAirspeed_m_s ? airspeed_m_s : kCentripetalMaxAirspeed_m_s;
    return (int16_t)(v * (kGyroCount_rad_s / kAccelCount_m_s2 * 256.0f) + 0.5f);
}

int16_t longitudinal_counts(float before_m_s, float now_m_s, uint16_t steps) {
    if (centripetal_gain_q8(before_m_s) == 0 || centripetal_gain_q8(now_m_s) == 0 || steps == 0u ||
        steps > kMaxAirspeedGapSteps)
        return 0;
    float dv_dt = (now_m_s - before_m_s) * (float)kRateHz / (float)steps;
    dv_dt = dv_dt > kMaxLongitudinal_m_s2 ? kMaxLongitudinal_m_s2 : (dv_dt < -kMaxLongitudinal_m_s2 ? -kMaxLongitudinal_m_s2 : dv_dt);
    return (int16_t)lroundf(dv_dt * (1.0f / kAccelCount_m_s2));
}

void AttitudePipeline::set_airspeed_m_s(float airspeed_m_s) {
    const int16_t dv_dt = longitudinal_counts(airspeed_m_s_, airspeed_m_s, (uint16_t)st_.steps - airspeed_step_);
    airspeed_step_ = (uint16_t)st_.steps;
    airspeed_m_s_ = airspeed_m_s;
    if (st_.phase == Phase::Running) configure_turn(dv_dt);
}

void AttitudePipeline::set_cruise_airspeed_m_s(float trim_m_s) {
    // A configured speed has no change to tell: no longitudinal term.
    airspeed_m_s_ = trim_m_s > 0.0f ? airspeed::cruise_in_turn_m_s(trim_m_s, dcm_.cos_tilt()) : 0.0f;
    if (st_.phase == Phase::Running) configure_turn();
}

void AttitudePipeline::configure_turn(int16_t dv_dt_counts) {
    constexpr int16_t kGravityCounts = (int16_t)(kG / kAccelCount_m_s2 + 0.5f);
    const int16_t gain_q8 = centripetal_gain_q8(airspeed_m_s_);
    // Landed or below the speed: the turn's mean starts again with the next flight.
    if (gain_q8 == 0) turn_mean_ = dcm::TurnMean();
    turn_mean_.configure(gain_q8, kGravityCounts, dv_dt_counts);
    dcm_.set_turn(gain_q8 != 0 ? &turn_mean_ : nullptr);
}

void AttitudePipeline::on_gps_fix(const gps::Fix& fix) {
    profile::begin(profile::kGpsAid);
    take_gps_fix(fix);
    profile::end(profile::kGpsAid);
}

void AttitudePipeline::take_gps_fix(const gps::Fix& fix) {
    const flight::FlightSettings& fs = settings_.flight;
    const float speed_cm_s = (float)fix.ground_speed_cm_s;
    if (speed_cm_s >= kCourseMinSpeed_m_s * 100.0f) st_.gps_moving = true;
    if (speed_cm_s < kGpsStillSpeed_m_s * 100.0f) st_.gps_moving = false;
    const bool usable = fs.ahrs_gps_use != 0u && fix.fix == gps::FixType::k3D && fix.sats >= fs.ahrs_gps_minsats &&
                        st_.phase == Phase::Running && st_.gps_moving;
    if (!usable) {
        dcm_.gps_unusable();
        gps_itow_ms_ = 0;
        return;
    }
    // The interval from the receiver's own clock (a fix's arrival jitters with the serial
    // line and the loop); across the week's end it wraps within uint32.
    const float interval_s = gps_itow_ms_ != 0u ? (float)(fix.itow_ms - gps_itow_ms_) * 0.001f : 0.0f;
    gps_itow_ms_ = fix.itow_ms != 0u ? fix.itow_ms : 1u;
    // Into the estimator's earth axes, whose north is the magnetic one: turned about down
    // by the declination (a vector at true bearing b is at magnetic bearing b - decl).
    const float decl_rad = settings_.declination_rad();
    const float c = cosf(decl_rad), s = sinf(decl_rad);
    const float n = (float)fix.vel_ned_cm_s[0] * 0.01f, e = (float)fix.vel_ned_cm_s[1] * 0.01f;
    // NMEA carries no vertical speed: level, its change unseen (a climb's start, small).
    const float d = fix.have_vertical_velocity ? (float)fix.vel_ned_cm_s[2] * 0.01f : 0.0f;
    dcm_.on_gps_velocity(Vector3f(n * c + e * s, e * c - n * s, d), interval_s, fs.ahrs_gps_gain);
    // The course for the heading without a working compass (AP_AHRS_DCM: above 3 m/s).
    const bool compass_working = st_.mag_present && st_.steps_since_mag < kCompassStaleSteps;
    if (compass_working || speed_cm_s < kCourseMinSpeed_m_s * 100.0f) return;
    const uint16_t since = (uint16_t)((uint16_t)st_.steps - gps_course_step_);
    gps_course_step_ = (uint16_t)st_.steps;
    dcm_.correct_heading_from_course((float)fix.course_e5 * (linalg::kRadPerDeg * 1e-5f) - decl_rad, since);
}

bool RateLimiter::allow(uint32_t now, uint16_t interval) {
    // Events held back go out first, in deferred()'s line, which counts this one too.
    if (ever && (now - last < interval || held != 0)) {
        if (held < 0xFFFFu) ++held;
        return false;
    }
    ever = true;
    last = now;
    return true;
}

uint16_t RateLimiter::deferred(uint32_t now, uint16_t interval) {
    if (held == 0 || now - last < interval) return 0;
    const uint16_t n = held;
    held = 0;
    last = now;
    return n;
}

AttitudePipeline::AttitudePipeline(const EventSink* events, const dcm::DcmSettings& dcm_settings)
    : AttitudePipeline(events, SettingsLoadedLater{}, dcm_settings) {
    settings_ = settings::defaults();
}

AttitudePipeline::AttitudePipeline(const EventSink* events, SettingsLoadedLater, const dcm::DcmSettings& dcm_settings)
    : events_(events), settings_(), dcm_(dcm_settings), st_(), frame_(), trim_(), start_gravity_() {
    last_ = mpu6000::sample_from_si(Vector3f(), Vector3f(0.0f, 0.0f, -kG), 25.0f, mpu6000::kGyroRange, mpu6000::kAccelRange);
    st_.frame_due = true;  // the board frame from the settings: refresh_board_frame, or the first sample
}

void AttitudePipeline::tell(EventKind kind, uint16_t count, uint32_t total, float value, uint8_t code) const {
    if (events_ != nullptr) events_->tell(events_->ctx, *this, Event{kind, code, count, total, value});
}
void AttitudePipeline::tell(EventKind kind, uint16_t count) const { tell(kind, count, 0, 0.0f, 0); }
void AttitudePipeline::tell(EventKind kind) const { tell(kind, 0); }

void AttitudePipeline::set_mag_present(bool present) {
    st_.mag_present = present;
    if (!present) st_.mag_pending = false;
}

void AttitudePipeline::on_mag_sample(const Vector3f& board_field_uT) {
    if (!board_field_uT.is_finite()) return;
    // The compass is on the board (the APM 2.5's HMC5883L): it turns with it. Everything
    // after this, the calibration too, is in the airframe's axes, as ArduPilot's.
    Vector3f field_uT = board_field_uT;
    calib::rotate(frame_.rotation, field_uT);
    // The fit's sums wait for a step free of heavy work, as the learner does.
    cal_field_uT_ = field_uT;
    if (st_.mag_cal_active) st_.cal_pending = true;
    // COMPASS_USE 0: `cal mag` takes the samples, the heading none (as without a compass).
    if (settings_.vehicle.compass_use == 0u) return;
    Vector3f f = calib::apply_mag(settings_.cal, field_uT);
    // The DCM's integer form, made once here (the range check takes its strength).
    linalg::Vector3i f_q5;
    const uint32_t n2 = dcm::field_q5_of(f, f_q5) ? dcm::field_norm2(f_q5) : 0;
    if (!(n2 >= kMagMinNorm2 && n2 <= kMagMaxNorm2)) {
        if (warn_of(EventKind::kMagNotEarth).allow(st_.steps, kWarnIntervalSteps))
            tell(EventKind::kMagNotEarth, 0, 0, f.length(), 0);
        return;
    }
    // The learner takes the sample on a later step with neither an output line, a heading
    // correction nor the DCM's heavy parts (see the end of on_imu_sample); the turn it
    // uses is the gyro's up to this sample.
    bool turn_restarts = true;  // this sample ends the turn the learner sums
    if (st_.turn_doubtful) {
        // The gyro's turn since the last field sample is not the board's (a spike stood
        // in for, a saturated or frozen gyro): a pair across it would read the turn's
        // error as hard iron. The open pair goes; the next sample starts another.
        learner_.forget_pair();
        st_.learn_pending = false;
        st_.turn_doubtful = false;
    } else if (st_.phase == Phase::Running && dcm_.initialised() && st_.mag_present &&
               settings_.vehicle.compass_learn != 0u) {  // COMPASS_LEARN
        // A sample every kLearnMinSteps at most; the turn goes on summing until then.
        turn_restarts = st_.steps_since_mag >= kLearnMinSteps;
        if (turn_restarts) take_learner_sample(f);
    }
    if (turn_restarts) {
        st_.steps_since_mag = 0;
        turn_counts_ = linalg::Vector3l();
    }
    mag_cal_q5_ = f_q5;
    st_.mag_pending = true;
    st_.mag_wait_steps = 0;  // a sample still waiting is replaced by this one
    st_.have_mag = true;
}

// The field sample f (calibrated) and the turn since the previous one, for the learner's
// next free step.
void AttitudePipeline::take_learner_sample(const Vector3f& f) {
    // The sample is mag_latency_s older than the attitude: turned forward by the
    // rotation since (dm/dt = m x w), as the estimator does, or a fast turn reads
    // as an offset.
    // The learner takes the field without the learned offset: it works from its own
    // estimate, which is not always the offset in use.
    const Vector3f rate = calib::apply_gyro(settings_.cal, last_.gyro_rad_s());
    learn_field_uT_ = f + settings_.cal.mag_learned_uT + f.cross(rate) * dcm_.settings().mag_latency_s;
    // The gyro since the previous sample (that one's too, if it never got its step), in
    // counts: the learner's step makes it a turn (Dcm::gyro_turn_q30).
    learn_turn_counts_ = st_.learn_pending ? learn_turn_counts_ + turn_counts_ : turn_counts_;
    st_.learn_steps = st_.learn_pending ? (uint16_t)(st_.learn_steps + st_.steps_since_mag) : st_.steps_since_mag;
    st_.learn_pending = true;
}

// The learner moves the offset that apply_mag subtracts last (when its estimate is
// significant); the latest field (calibrated with the old one) is brought up to date.
// Once the offset has moved by kMagReferenceShift_uT since the DCM learned the earth
// field, the DCM learns its strength and dip again (not its heading: see Dcm).
// one_piece: a step with little room, for one part of the solve or one sample only.
void AttitudePipeline::learn_mag_offset(bool one_piece) {
    Vector3f& learned = settings_.cal.mag_learned_uT;
    const Vector3f before = learned;
    const bool solved_part = learner_.solving();
    if (solved_part) learner_.solve_part(learned);
    // The sample waits for the solve (the learner composes no turn meanwhile); it follows
    // the solve's last part on its step (that part is the estimate's update, a short one).
    if (!(one_piece && solved_part) && !learner_.solving() && st_.learn_pending) {
        st_.learn_pending = false;
        // The turn less every bias estimate (the one now stands for the interval's).
        learner_.add(learn_field_uT_, dcm_.gyro_turn_q30(learn_turn_counts_, st_.learn_steps), st_.learn_steps, learned);
    }
    if (learned == before) return;
    recalibrate_latest_field(field_uT() - (learned - before));
    if ((learned - learned_at_reference_uT_).length_squared() > kMagReferenceShift_uT * kMagReferenceShift_uT)
        forget_mag_reference(false);
}

// The compass calibration moved: the latest field (and a sample waiting for the
// heading's correction) is taken in the new one, and the start's heading mean begins
// again (its samples were calibrated the old way).
void AttitudePipeline::recalibrate_latest_field(const Vector3f& field_uT) {
    linalg::Vector3i q5;
    if (dcm::field_q5_of(field_uT, q5)) mag_cal_q5_ = q5;
    dcm_.restart_heading_mean();
}

// The DCM takes the next calibrated sample as the earth field (and, take_heading, its
// heading at once: a new calibration).
void AttitudePipeline::forget_mag_reference(bool take_heading) {
    dcm_.reset_mag_reference(take_heading);
    learned_at_reference_uT_ = settings_.cal.mag_learned_uT;
}

// Spikes (a gyro jump no rotation makes: a broken read) are replaced by the previous
// sample; saturation is reported (a saturated gyro is used: the true rate is at least the
// full scale; on_imu_sample decides whether a saturated accel is gravity). An accel jump
// is no spike: the DLPF passes 70 % of a shock within one 5 ms sample, so a tap, a knock
// or a strong vibration jumps by several g, and standing in for its one-sided peaks would
// leave the rest of it in the gravity low-pass as tilt.
const mpu6000::Sample& AttitudePipeline::guard(const mpu6000::Sample& s) {
    bool spike = false;
    if (st_.have_last) {
        spike = jump(s.gyro.x, last_.gyro.x) > kSpikeGyroJumpCounts || jump(s.gyro.y, last_.gyro.y) > kSpikeGyroJumpCounts ||
                jump(s.gyro.z, last_.gyro.z) > kSpikeGyroJumpCounts;
    }
    if (spike && st_.spike_run < kMaxSpikeRun) {
        ++st_.spike_run;
        ++st_.spikes;
        if (warn_of(EventKind::kSpike).allow(st_.steps, kWarnIntervalSteps)) tell(EventKind::kSpike, 0, st_.spikes, 0.0f, 0);
        last_.temperature_raw = s.temperature_raw;  // the previous sample, with this one's temperature
        st_.turn_doubtful = true;  // the gyro stood in for, not measured: no learner pair across it
        return last_;
    }
    // A run longer than kMaxSpikeRun is real (saturation, a crash) and used.
    st_.spike_run = 0;
    if (s.gyro_saturated) st_.turn_doubtful = true;  // the rate is only a lower bound
    if (s.gyro_saturated && warn_of(EventKind::kGyroSaturated).allow(st_.steps, kWarnIntervalSteps)) tell(EventKind::kGyroSaturated);
    if (s.accel_saturated && warn_of(EventKind::kAccelSaturated).allow(st_.steps, kWarnIntervalSteps)) tell(EventKind::kAccelSaturated);
    last_ = s;
    st_.have_last = true;
    return last_;
}

// The DCM started from gravity and the latest field (TRIAD). A DCM that has run is reset
// first (a fresh object copied in) and given its scales; at the first start it is as the
// constructor made it with the scales set when the calibration began (nothing else
// touches it while calibrating): only the sensor bias is set.
void AttitudePipeline::start_estimator(const Vector3f& gravity, bool gravity_is_mean) {
    if (st_.phase == Phase::Running) {
        dcm_ = dcm::Dcm(dcm_.settings());
        dcm_.set_sample_scales(last_.gyro_rad_s_per_count, last_.accel_m_s2_per_count);
    }
    dcm_.set_sensor_bias_rad_s(settings_.cal.gyro_bias_rad_s);
    dcm_.init(gravity, st_.have_mag && st_.mag_present ? field_uT() : Vector3f(), gravity_is_mean);
    st_.mag_pending = false;
    // How far off the offset in use may be: a fraction of a uT after `cal mag` or
    // learning, tens of uT on a compass never calibrated.
    const bool calibrated = (settings_.flags & settings::kFlagMagCalibrated) != 0 ||
                            !(settings_.cal.mag_learned_uT == Vector3f());
    learner_.restart(calibrated ? calib::kLearnPriorCalibrated_uT : calib::kLearnPriorUncalibrated_uT,
                     settings_.cal.mag_learned_uT);
    learned_at_reference_uT_ = settings_.cal.mag_learned_uT;
    st_.phase = Phase::Running;
    turn_mean_ = dcm::TurnMean();  // the start's gravity is spent: its space holds the turn's mean
    configure_turn();
    st_.output_acc = kRateHz;  // the first line comes with the first step it fits on
}

void AttitudePipeline::step_calibration(const mpu6000::Sample& raw) {
    const calib::GyroCalibrator::Result r =
        gyro_cal_.add(raw.gyro, raw.accel, raw.gyro_rad_s_per_count, raw.accel_m_s2_per_count);
    ++st_.gyro_cal_steps;
    // The window's samples for a start that is never still, from the board's first move
    // (a still board's gravity is the calibration's mean; not the step that starts: it has
    // the start's work).
    if (st_.phase == Phase::Calibrating && gyro_cal_.restarts() != 0 && r != calib::GyroCalibrator::Result::Done &&
        st_.gyro_cal_steps < kStartupDeadlineSteps)
        start_gravity_.add(raw.gyro, raw.accel, raw.gyro_rad_s_per_count, raw.accel_m_s2_per_count,
                           settings_.cal.gyro_bias_rad_s, 1.0f / kRateHz);
    if (r == calib::GyroCalibrator::Result::Done && st_.phase == Phase::Running && st_.start_moved) {
        // Measuring on after a moving start: a constant-rate turn looks still; a bias far
        // from the one in use is such a turn, not the gyro's.
        const float off_rad_s = (gyro_cal_.bias() - settings_.cal.gyro_bias_rad_s).length();
        st_.start_moved = false;
        if (!(off_rad_s <= kMaxBiasChangeInMotion_rad_s)) {
            st_.gyro_cal_active = false;
            tell(EventKind::kGyroBiasRefused, 0, 0, off_rad_s * linalg::kDegPerRad,
                 (settings_.flags & settings::kFlagGyroCalibrated) ? 1 : 0);
            return;
        }
    }
    if (st_.level_cal_active && r == calib::GyroCalibrator::Result::Moved) {
        st_.gyro_cal_active = false;
        finish_level_calibration(LevelResult::kMoved);
        return;
    }
    if (r == calib::GyroCalibrator::Result::Done && st_.level_cal_active) {
        // The still second's mean specific force, in the airframe's axes less the trim.
        float tx, ty;
        const bool ok = calib::level_trim(gyro_cal_.mean_accel_m_s2(), tx, ty);
        if (ok) {
            settings_.vehicle.ahrs_trim_x_rad = tx;
            settings_.vehicle.ahrs_trim_y_rad = ty;
            trim_ = calib::trim_q14(tx, ty);
        }
        finish_level_calibration(ok ? LevelResult::kOk : LevelResult::kTooFar);
        // and the bias of the same still second, as `cal gyro`'s (below)
    }
    if (r == calib::GyroCalibrator::Result::Done) {
        st_.gyro_cal_active = false;
        settings_.cal.gyro_bias_rad_s = gyro_cal_.bias();
        settings_.flags = (uint8_t)(settings_.flags | settings::kFlagGyroCalibrated);
        // The event goes out on the next step: with the start's work and the line's words
        // this one would overrun its 5 ms.
        st_.start_message = StartMessage::kBias;
        if (st_.phase == Phase::Calibrating) {
            start_estimator(gyro_cal_.mean_accel_m_s2(), true);
        } else {
            dcm_.set_sensor_bias_rad_s(settings_.cal.gyro_bias_rad_s);
            dcm_.set_gyro_bias_rad_s(Vector3f());  // the estimator's residual starts again
        }
        dcm_.set_gyro_bias_measured();
        return;
    }
    if (r == calib::GyroCalibrator::Result::Moved && st_.warn_moved.allow(st_.steps, kRateHz)) {
        tell(EventKind::kGyroCalMoved);
    } else if (const uint16_t n = st_.warn_moved.deferred(st_.steps, kRateHz)) {
        tell(EventKind::kGyroCalMoved, n);
    }
    if (st_.phase == Phase::Calibrating && st_.gyro_cal_steps >= kStartupDeadlineSteps) {
        // Never still long enough: run with what we have, gravity the window's mean carried
        // by the gyro (StartGravity.h), keep measuring in the background (the event on the
        // next step, as the bias's).
        st_.start_message = StartMessage::kNotStill;
        st_.start_moved = true;
        start_estimator(start_gravity_.mean_m_s2(), true);
        return;
    }
    if (st_.phase == Phase::Running && st_.gyro_cal_steps >= kGyroCalTimeoutSteps) {
        st_.gyro_cal_active = false;
        if (st_.level_cal_active) finish_level_calibration(LevelResult::kTimeout);
        else tell(EventKind::kGyroCalTimeout);
    }
}

// How many axes sit at the accelerometer's full scale (decode_burst's saturation).
static uint8_t clipped_axes(const linalg::Vector3i& a) {
    return (uint8_t)((a.x >= 32767 || a.x <= -32767) + (a.y >= 32767 || a.y <= -32767) + (a.z >= 32767 || a.z <= -32767));
}

namespace {
// The bytes of the settings the board frame is made of (AHRS_ORIENTATION .. INS_ACCSCAL_*,
// together in VehicleSettings), summed: a change of any of them changes it (almost surely;
// a coincidence only waits for the next refresh a path asks for).
uint16_t frame_settings_sum(const settings::VehicleSettings& v) {
    const uint8_t* p = &v.ahrs_orientation;
    const uint8_t* const end = reinterpret_cast<const uint8_t*>(&v.ins_accscal[3]);
    uint16_t sum = 0;
    for (uint8_t k = 1; p < end; ++p, ++k) sum = (uint16_t)(sum + (uint16_t)(*p * k));
    return sum;
}
}  // namespace

void AttitudePipeline::on_imu_sample(const mpu6000::Sample& board_sample) {
    st_.output_due = false;
    ++st_.steps;
    // The settings as loaded, unless the caller took them up before the samples (the
    // firmware does, in setup: the refresh, ~6k cycles, would lengthen the first step).
    if (st_.phase == Phase::WaitImu && st_.frame_due) refresh_board_frame();
    // Once a second the frame follows the settings if they changed by a path that did not
    // refresh it (the refresh itself, ~5k cycles, would take a busy step past its budget).
    if ((uint8_t)st_.steps == 0u && frame_settings_sum(settings_.vehicle) != st_.frame_sum) st_.frame_due = true;
    // The accelerometer's calibration and the board's orientation, on the counts: the
    // vehicle's axes from here on.
    profile::begin(profile::kBoardFrame);
    mpu6000::Sample turned;
    const bool identity = frame_.rotation == 0 && !frame_.accel_corrected;
    if (!identity) {
        turned = board_sample;
        calib::apply_gyro(frame_, turned.gyro);
        calib::apply_accel(frame_, turned.accel);
    }
    const mpu6000::Sample& raw = identity ? board_sample : turned;
    profile::end(profile::kBoardFrame);
    if (st_.steps_since_mag < 0xFFFFu) ++st_.steps_since_mag;
    profile::begin(profile::kChecks);
    if (st_.start_message == StartMessage::kBias) tell(EventKind::kGyroBias);
    if (st_.start_message == StartMessage::kNotStill)
        tell(EventKind::kNotStill, 0, 0, 0.0f, (settings_.flags & settings::kFlagGyroCalibrated) ? 1 : 0);
    st_.start_message = st_.start_message == StartMessage::kTold || st_.start_message == StartMessage::kNone
                            ? StartMessage::kNone
                            : StartMessage::kTold;
    const mpu6000::Sample& s = guard(raw);  // last_, the sample the step uses
    if (st_.phase == Phase::WaitImu) {
        st_.phase = Phase::Calibrating;
        // The DCM's scales now: the step that ends the calibration starts the DCM.
        dcm_.set_sample_scales(s.gyro_rad_s_per_count, s.accel_m_s2_per_count);
        tell(EventKind::kGyroCalStart);
        start_gyro_calibration();
    }
    if (st_.gyro_cal_active) step_calibration(s);
    if (st_.accel_collecting) step_accel_position(board_sample);
    if (st_.phase != Phase::Running) {
        profile::end(profile::kChecks);
        return;
    }
    if (st_.reinit_pending) {
        st_.reinit_pending = false;
        start_estimator(s.accel_m_s2(), false);  // a restart after an outage (rare): a long step
    }

    // A clipped accelerometer sample still points roughly the right way: in a violent
    // motion one axis clips for a few ms, and dropping those samples would bias the
    // estimator's low-passed gravity (they are one side of the motion's acceleration,
    // which averages out only as a whole). Two or more axes at full scale (at least
    // 22 g) is not a motion but a stuck or broken sensor, and so is one axis clipped for
    // longer than kAccelSaturationFaultSteps: then the DCM is told the accel is not
    // valid and gives gravity no weight that step (Dcm::update). The gyro is integrated
    // (saturated, it is a lower bound of the rate) unless the rate is beyond any MEMS
    // gyro's.
    st_.accel_saturated_steps = s.accel_saturated ? (uint8_t)(st_.accel_saturated_steps < 255 ? st_.accel_saturated_steps + 1 : 255) : 0;
    const bool accel_stuck = s.accel_saturated && (clipped_axes(s.accel) >= 2 ||
                                                   st_.accel_saturated_steps > kAccelSaturationFaultSteps);
    profile::end(profile::kChecks);
    // A field sample (into earth axes, and the heading's correction every kHeadingSteps)
    // waits out a step on which the DCM integrates or corrects gravity, up to
    // kMaxMagWaitSteps: its age is counted in the latency compensation. A line (Euler
    // angles and formatting) is not made on a step with a field sample, nor on the
    // start's two (starting()): it moves to the next step, 5 ms later (samples come at
    // least two steps apart). The DCM brings its matrix up to date for the line. (The
    // parts' costs: docs/performance.md.)
    bool heading_corrected = st_.mag_pending && st_.mag_present;
    if (heading_corrected && st_.mag_wait_steps < kMaxMagWaitSteps && dcm_.heavy_due()) {
        heading_corrected = false;
        ++st_.mag_wait_steps;
    }
    st_.output_acc = (uint16_t)(st_.output_acc + settings_.rate_hz);
    if (starting()) {
        // The first line on the step after the start's two, the next ones a period after it.
        st_.output_acc = settings_.rate_hz < kRateHz ? (uint16_t)(kRateHz - settings_.rate_hz) : 0u;
    } else if (st_.output_acc >= kRateHz && !heading_corrected) {
        st_.output_acc = (uint16_t)(st_.output_acc - kRateHz);
        if (st_.output_acc >= kRateHz) st_.output_acc = 0;  // rate lowered: no burst of lines
        st_.output_due = true;
    }
    const bool heading_heavy = heading_corrected && dcm_.heading_due_next();
    dcm_.update(s.gyro, s.accel, norm2(s.gyro) < kMaxCredibleRateCounts2, !accel_stuck, st_.output_due);
    // The board's turn for the compass learner: the gyro alone (the biases come off when
    // a field sample takes it).
    turn_counts_ += s.gyro;
    if (heading_corrected) {
        profile::begin(profile::kCompass);
        dcm_.correct_heading(mag_cal_q5_, st_.mag_wait_steps);
        profile::end(profile::kCompass);
        st_.mag_pending = false;
        st_.mag_wait_steps = 0;
    }

    if (st_.mag_cal_active) {
        ++st_.mag_cal_steps;
        if (st_.mag_cal_steps % (5u * kRateHz) == 0u && st_.mag_cal_steps < calib::kMagCalSeconds * kRateHz) {
            tell(EventKind::kMagCalProgress, (uint16_t)(calib::kMagCalSeconds - st_.mag_cal_steps / kRateHz),
                 mag_cal_.count(), 0.0f, 0);
        }
        if (st_.mag_cal_steps >= calib::kMagCalSeconds * kRateHz) {
            // The fit (several steps' worth) goes a part a step, on steps with room.
            st_.mag_cal_active = false;
            st_.cal_pending = false;
            st_.mag_fit_active = true;
            mag_cal_.begin_fit();
        }
    }

    // The deferred compass work (the cal mag sums; the learner: a sample, or one part of
    // a completed pair's solve) goes on a step with neither an output line nor the
    // heading's correction from its mean or its first heading (Dcm::heading_due_next; a
    // field sample's own short work leaves room). On a step with the DCM's integration
    // or gravity correction (Dcm::heavy_step) only one short piece of it fits within the
    // step's budget: a sample or a part of the solve but its long second one. A pair's
    // solve takes three such steps, and the samples that come meanwhile wait (the turn
    // goes on summing). Each step kept from the learner delays the offset it finds, and
    // in a fast turn with a compass never calibrated the first offset is what ends the
    // heading's freeze on a field the disturbance test rejects: so the short pieces go on
    // the heavy steps too.
    if (st_.output_due || heading_heavy) return;
    const bool short_room = dcm_.heavy_step();
    bool fit_step = false;
    if (!short_room) {
        fit_step = st_.mag_fit_active;
        if (st_.cal_pending && st_.mag_cal_active) mag_cal_.add(cal_field_uT_);
        else if (fit_step) step_mag_fit();
        else if (st_.accel_pos == calib::kAccelPositions + 1) step_accel_fit();
        else if (st_.frame_due) refresh_board_frame();
        else report_deferred();
        st_.cal_pending = false;
    }
    // A part of the `cal mag` fit leaves no room for the learner: it waits a step.
    if ((learner_.solving() || st_.learn_pending) && !fit_step && !(short_room && learner_.long_part_next())) {
        profile::begin(profile::kLearner);
        learn_mag_offset(short_room);
        profile::end(profile::kLearner);
    }
}

// The warnings the rate limits held back, each kind once its quiet time is over (one
// a step at most: each is a line to word).
void AttitudePipeline::report_deferred() {
    for (uint8_t i = 0; i < kWarnKinds; ++i) {
        const uint16_t n = st_.warn[i].deferred(st_.steps, kWarnIntervalSteps);
        if (n == 0) continue;
        tell((EventKind)((uint8_t)EventKind::kSpike + i), n, i == 0 ? st_.spikes : 0, 0.0f, 0);
        return;
    }
}

Angles AttitudePipeline::angles() const {
    const dcm::EulerAngles e = dcm::euler_in_rad(dcm_.euler_now_q24(trim_rows()));
    const float h = dcm::heading_deg(e.yaw_rad, settings_.declination_deg());
    return Angles{e.roll_rad * linalg::kDegPerRad, e.pitch_rad * linalg::kDegPerRad, h};
}

AnglesCentideg AttitudePipeline::angles_centideg() const {
    return dcm::angles_centideg(dcm_.euler_now_q24(trim_rows()), settings_.declination_centideg);
}

linalg::Quaternion AttitudePipeline::quaternion() const {
    // The DCM's earth frame is magnetic north: turned about down by the declination.
    const float half_rad = 0.5f * settings_.declination_rad();
    linalg::Matrix3f r = dcm_.matrix();
    if (trim_.active) {
        // The airframe's: R T^T, as the angles (27 products, only in `mode quat`).
        const int16_t(*t)[3] = trim_.t;
        const float k = 1.0f / 16384.0f;
        const linalg::Matrix3f tt(Vector3f((float)t[0][0] * k, (float)t[1][0] * k, (float)t[2][0] * k),
                                  Vector3f((float)t[0][1] * k, (float)t[1][1] * k, (float)t[2][1] * k),
                                  Vector3f((float)t[0][2] * k, (float)t[1][2] * k, (float)t[2][2] * k));
        r = r * tt;
    }
    return linalg::quat_turned_about_down(linalg::quat_from_rotation(r), cosf(half_rad), sinf(half_rad));
}

Vector3f AttitudePipeline::gyro_rad_s() const { return calib::apply_gyro(settings_.cal, last_.gyro_rad_s()); }

Vector3f AttitudePipeline::gyro_bias_rad_s() const {
    return settings_.cal.gyro_bias_rad_s + dcm_.gyro_bias_rad_s();
}

bool AttitudePipeline::start_level_calibration() {
    if (st_.phase != Phase::Running || st_.gyro_cal_active || mag_calibrating() || accel_calibrating()) return false;
    begin_gyro_window();
    st_.level_cal_active = true;
    tell(EventKind::kLevelStart);
    return true;
}

bool AttitudePipeline::start_accel_calibration() {
    if (st_.phase != Phase::Running || st_.gyro_cal_active || mag_calibrating() || accel_calibrating()) return false;
    st_.accel_pos = (uint8_t)calib::AccelPosition::kLevel;
    ask_accel_position();
    return true;
}

void AttitudePipeline::ask_accel_position() {
    st_.accel_waiting = true;
    ++st_.accel_asks;
    tell(EventKind::kAccelCalAsk, 0, 0, 0.0f, st_.accel_pos);
}

bool AttitudePipeline::confirm_accel_position(uint8_t position) {
    if (!st_.accel_waiting || position != st_.accel_pos) return false;
    st_.accel_waiting = false;
    st_.accel_collecting = true;
    gyro_cal_.restart();
    return true;
}

// A still second's mean of the board's own counts (before INS_ACC* and the orientation:
// the fit is in the board's axes), checked against the position asked in the airframe's.
void AttitudePipeline::step_accel_position(const mpu6000::Sample& b) {
    const calib::GyroCalibrator::Result r =
        gyro_cal_.add(b.gyro, b.accel, b.gyro_rad_s_per_count, b.accel_m_s2_per_count);
    if (r == calib::GyroCalibrator::Result::Collecting) return;
    st_.accel_collecting = false;
    const calib::AccelPosition p = (calib::AccelPosition)st_.accel_pos;
    Vector3f mean = gyro_cal_.mean_accel_m_s2();
    Vector3f in_airframe = mean;
    calib::rotate(frame_.rotation, in_airframe);
    const bool moved = r == calib::GyroCalibrator::Result::Moved;
    if (moved || !calib::in_position(p, in_airframe)) {
        tell(EventKind::kAccelCalRefused, 0, 0, moved ? 0.0f : 1.0f, st_.accel_pos);
        ask_accel_position();  // again
        return;
    }
    accel_fit_.set_mean((uint8_t)(st_.accel_pos - 1), mean);
    ++st_.accel_pos;
    if (st_.accel_pos <= calib::kAccelPositions) {
        ask_accel_position();
        return;
    }
    accel_fit_.begin(kG);  // then a Newton iteration a step with room
}

void AttitudePipeline::step_accel_fit() {
    profile::begin(profile::kMagFit);
    const calib::AccelFit::Quality q = accel_fit_.step();
    profile::end(profile::kMagFit);
    if (q == calib::AccelFit::Quality::Fitting) return;
    st_.accel_pos = 0;
    if (q == calib::AccelFit::Quality::Ok) {
        settings::VehicleSettings& v = settings_.vehicle;
        const Vector3f o = accel_fit_.offset_m_s2(), sc = accel_fit_.scale();
        v.ins_accoffs_m_s2[0] = o.x;
        v.ins_accoffs_m_s2[1] = o.y;
        v.ins_accoffs_m_s2[2] = o.z;
        v.ins_accscal[0] = sc.x;
        v.ins_accscal[1] = sc.y;
        v.ins_accscal[2] = sc.z;
        refresh_board_frame();
    }
    tell(EventKind::kAccelCalDone, 0, 0, accel_fit_.residual_m_s2(), (uint8_t)q);
}

void AttitudePipeline::finish_level_calibration(LevelResult r) {
    st_.level_cal_active = false;
    tell(EventKind::kLevelDone, 0, 0, 0.0f, (uint8_t)r);
}

// The settings' frame and trim in the sample path's forms (a few thousand cycles, on a
// step with room). A new orientation makes the gyro bias and the estimator's attitude
// those of another frame: both start again (the user is setting the board up: it is
// still, as a start).
void AttitudePipeline::refresh_board_frame() {
    st_.frame_due = false;
    const settings::VehicleSettings& v = settings_.vehicle;
    st_.frame_sum = frame_settings_sum(v);
    const uint8_t before = frame_.rotation;
    frame_ = calib::make_board_frame(Vector3f(v.ins_accoffs_m_s2[0], v.ins_accoffs_m_s2[1], v.ins_accoffs_m_s2[2]),
                                     Vector3f(v.ins_accscal[0], v.ins_accscal[1], v.ins_accscal[2]),
                                     v.ahrs_orientation, kAccelCount_m_s2);
    const bool trims_ok = v.ahrs_trim_x_rad <= calib::kTrimMax_rad && v.ahrs_trim_x_rad >= -calib::kTrimMax_rad &&
                          v.ahrs_trim_y_rad <= calib::kTrimMax_rad && v.ahrs_trim_y_rad >= -calib::kTrimMax_rad;
    trim_ = calib::trim_q14(trims_ok ? v.ahrs_trim_x_rad : 0.0f, trims_ok ? v.ahrs_trim_y_rad : 0.0f);
    if (frame_.rotation == before || st_.phase != Phase::Running) return;
    tell(EventKind::kOrientation, 0, 0, 0.0f, frame_.rotation);
    restart_estimator();
    if (!st_.gyro_cal_active) start_gyro_calibration();
}

void AttitudePipeline::start_gyro_calibration() {
    begin_gyro_window();
    if (st_.phase == Phase::Running) tell(EventKind::kGyroCalAgain);
}

void AttitudePipeline::begin_gyro_window() {
    gyro_cal_.restart();
    if (st_.phase != Phase::Running) start_gravity_.restart();  // running: the space is the turn's
    st_.gyro_cal_steps = 0;
    st_.gyro_cal_active = true;
    st_.start_moved = false;  // asked for (`cal gyro`): the user says the board is still
    st_.level_cal_active = false;
    st_.accel_pos = 0;  // a six-position calibration under way is given up
    st_.accel_waiting = false;
    st_.accel_collecting = false;
}

void AttitudePipeline::restart_estimator() {
    st_.reinit_pending = (st_.phase == Phase::Running);
    st_.have_last = false;  // the previous sample is too old to judge spikes by
    st_.spike_run = 0;
}

void AttitudePipeline::start_mag_calibration(bool hold) {
    if (!st_.mag_present) {
        tell(EventKind::kMagCalNoCompass);
        return;
    }
    st_.mag_cal_hold = hold;
    st_.mag_cal_end = MagCalState::kNone;
    // The centre in use (the fit's offset plus the learned one, which W ~ I barely
    // changes) centres the fit's sums.
    mag_cal_.restart(settings_.cal.mag_offset_uT + settings_.cal.mag_learned_uT);
    st_.mag_cal_steps = 0;
    st_.mag_cal_active = true;
    st_.mag_fit_active = false;  // a fit under way is dropped
    tell(EventKind::kMagCalStart);
}

// A part of the fit, or (on the step after its last) the verdict.
void AttitudePipeline::step_mag_fit() {
    if (mag_cal_.fitting()) {
        profile::begin(profile::kMagFit);
        mag_cal_.fit_part();
        profile::end(profile::kMagFit);
        return;
    }
    st_.mag_fit_active = false;
    finish_mag_calibration();
}

void AttitudePipeline::finish_mag_calibration() {
    const calib::MagCalibrator::Quality q = mag_cal_.quality();
    const bool ok = q == calib::MagCalibrator::Quality::Ok;
    st_.mag_cal_end = !ok ? MagCalState::kFailed : st_.mag_cal_hold ? MagCalState::kWaiting : MagCalState::kApplied;
    if (st_.mag_cal_end == MagCalState::kApplied) {
        mag_cal_.result(settings_.cal);
        use_mag_calibration();
    }
    tell(EventKind::kMagCalDone, mag_cal_.coverage_pct(), mag_cal_.count(),
         q == calib::MagCalibrator::Quality::NotEarthField ? mag_cal_.radius_uT() : mag_cal_.residual_uT(),
         (uint8_t)q);
}

bool AttitudePipeline::accept_mag_calibration() {
    if (st_.mag_cal_end != MagCalState::kWaiting) return false;
    mag_cal_.result(settings_.cal);
    use_mag_calibration();
    st_.mag_cal_end = MagCalState::kApplied;
    return true;
}

void AttitudePipeline::cancel_mag_calibration() {
    st_.mag_cal_active = st_.mag_fit_active = st_.cal_pending = false;
    st_.mag_cal_end = MagCalState::kNone;
}

void AttitudePipeline::take_mag_calibration() {
    settings_.cal.mag_learned_uT = Vector3f();
    use_mag_calibration();
}

MagCalState AttitudePipeline::mag_cal_state() const {
    return st_.mag_cal_active ? MagCalState::kCollecting : st_.mag_fit_active ? MagCalState::kFitting : st_.mag_cal_end;
}

uint8_t AttitudePipeline::mag_cal_progress_pct() const {
    const MagCalState m = mag_cal_state();
    if (m == MagCalState::kCollecting)
        return (uint8_t)((uint32_t)st_.mag_cal_steps * 100u / ((uint32_t)calib::kMagCalSeconds * kRateHz));
    return m == MagCalState::kFitting ? 99u : m == MagCalState::kNone ? 0u : 100u;
}

// settings_.cal holds a new compass calibration (learned offset zero): in use from the
// next sample, the compass flagged calibrated.
void AttitudePipeline::use_mag_calibration() {
    // The DCM takes the heading from the new calibration.
    recalibrate_latest_field(calib::apply_mag(settings_.cal, cal_field_uT_));
    settings_.flags = (uint8_t)(settings_.flags | settings::kFlagMagCalibrated);
    // Applied from the next sample: the estimator learns the calibrated field afresh.
    learner_.restart(calib::kLearnPriorCalibrated_uT, Vector3f());
    if (st_.phase == Phase::Running) {
        forget_mag_reference(true);
        // The estimator's bias residual was learned partly from heading corrections
        // against the old calibration: kept, it turns the heading at rest while the new
        // field's corrections unlearn it. It goes with the old calibration and is
        // learned again.
        dcm_.set_gyro_bias_rad_s(Vector3f());
    }
}

void AttitudePipeline::restore_defaults() {
    // The gyro bias measured at this start is a measurement, not a setting: keep it.
    const Vector3f bias = settings_.cal.gyro_bias_rad_s;
    const uint8_t gyro_flag = (uint8_t)(settings_.flags & settings::kFlagGyroCalibrated);
    settings_ = settings::defaults();
    settings_.cal.gyro_bias_rad_s = bias;
    settings_.flags = (uint8_t)(settings_.flags | gyro_flag);
    // The compass is uncalibrated again: the estimator relearns its field, the learner
    // starts from scratch.
    if (st_.phase == Phase::Running) forget_mag_reference(true);
    learner_.restart(calib::kLearnPriorUncalibrated_uT, Vector3f());
}

}  // namespace pipeline
