// SPDX-License-Identifier: GPL-3.0-or-later
#include "Pipeline.h"

#include "Profile.h"
#include "Fixed.h"
#include "Mpu6000.h"

#include <math.h>

namespace pipeline {

using linalg::Vector3f;
using text::Writer;

namespace {
constexpr float kG = mpu6000::kStandardGravity_m_s2;
// The checks' thresholds in the counts of the MPU6000 driver's ranges (the samples'; a
// host test's sample_from_si uses the same).
constexpr float kGyroCount_rad_s = mpu6000::gyro_rad_s_per_count(mpu6000::kGyroRange);
constexpr float kAccelCount_m_s2 = mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
constexpr int32_t kSpikeGyroJumpCounts = (int32_t)(kSpikeGyroJump_rad_s / kGyroCount_rad_s);
constexpr uint32_t kSpikeAccelCounts2 =
    (uint32_t)((kSpikeAccel_g * kG / kAccelCount_m_s2) * (kSpikeAccel_g * kG / kAccelCount_m_s2));
constexpr uint32_t kNormalAccelCounts2 =
    (uint32_t)((kNormalAccel_g * kG / kAccelCount_m_s2) * (kNormalAccel_g * kG / kAccelCount_m_s2));
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

// An int32 into int16's range.
static int16_t sat16(int32_t v) { return v > 32767 ? 32767 : v < -32767 ? -32767 : (int16_t)v; }

int16_t centripetal_gain_q8(float airspeed_m_s) {
    if (!(airspeed_m_s >= kCentripetalMinAirspeed_m_s)) return 0;  // NaN too
    const float v = airspeed_m_s < kCentripetalMaxAirspeed_m_s ? airspeed_m_s : kCentripetalMaxAirspeed_m_s;
    return (int16_t)(v * (kGyroCount_rad_s / kAccelCount_m_s2 * 256.0f) + 0.5f);
}

linalg::Vector3i centripetal_corrected(const linalg::Vector3i& a, int16_t gyro_y, int16_t gyro_z, int16_t gain_q8) {
    // omega x v = (0, omega_z V, -omega_y V): y loses omega_z V, z gains omega_y V.
    return linalg::Vector3i(a.x, sat16((int32_t)a.y - (linalg::mul_s16(gyro_z, gain_q8) >> 8)),
                            sat16((int32_t)a.z + (linalg::mul_s16(gyro_y, gain_q8) >> 8)));
}

// A rate in gyro counts, rounded and clamped (NaN: 0).
static int16_t gyro_counts_of(float rate_rad_s) {
    const float c = rate_rad_s / kGyroCount_rad_s;
    if (!(c > -32767.0f)) return c < 0.0f ? -32767 : 0;
    return c >= 32767.0f ? 32767 : (int16_t)(c < 0.0f ? c - 0.5f : c + 0.5f);
}

void AttitudePipeline::set_airspeed_m_s(float airspeed_m_s) {
    airspeed_m_s_ = airspeed_m_s;
    centripetal_gain_q8_ = centripetal_gain_q8(airspeed_m_s);
    // The calibrated bias in counts (the estimator's own residual is left: a fraction of
    // a deg/s, a few tenths of a m/s^2 at cruise).
    gyro_bias_y_counts_ = gyro_counts_of(settings_.cal.gyro_bias_rad_s.y);
    gyro_bias_z_counts_ = gyro_counts_of(settings_.cal.gyro_bias_rad_s.z);
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

AttitudePipeline::AttitudePipeline(const text::Sink* log, const dcm::DcmSettings& dcm_settings)
    : AttitudePipeline(log, SettingsLoadedLater{}, dcm_settings) {
    settings_ = settings::defaults();
}

AttitudePipeline::AttitudePipeline(const text::Sink* log, SettingsLoadedLater, const dcm::DcmSettings& dcm_settings)
    : log_(log), settings_(), dcm_(dcm_settings), st_() {
    last_ = mpu6000::sample_from_si(Vector3f(), Vector3f(0.0f, 0.0f, -kG), 25.0f);
}

void AttitudePipeline::set_mag_present(bool present) {
    st_.mag_present = present;
    if (!present) st_.mag_pending = false;
}

void AttitudePipeline::on_mag_sample(const Vector3f& field_uT) {
    if (!field_uT.is_finite()) return;
    // The fit's sums (~10 k cycles) wait for a step free of heavy work, as the learner does.
    cal_field_uT_ = field_uT;
    if (st_.mag_cal_active) st_.cal_pending = true;
    Vector3f f = calib::apply_mag(settings_.cal, field_uT);
    const float n = f.length();
    if (!(n >= kMagMin_uT && n <= kMagMax_uT)) {
        if (st_.warn_mag.allow(st_.steps, kWarnIntervalSteps)) {
            Writer(log_).str(TXT(TXT_WARN TXT_HMC " field ")).fixed2(n)
                .str(TXT(" uT is not the Earth's (10..200): sample dropped")).end();
        }
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
    } else if (st_.phase == Phase::Running && dcm_.initialised() && st_.mag_present) {
        // A sample every kLearnMinSteps at most; the turn goes on summing until then.
        turn_restarts = st_.steps_since_mag >= kLearnMinSteps;
        if (turn_restarts) take_learner_sample(f);
    }
    if (turn_restarts) {
        st_.steps_since_mag = 0;
        turn_counts_ = linalg::Vector3l();
    }
    mag_cal_uT_ = f;
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
    // the solve's last part on its step (that part is the estimate's update, ~5 k).
    if (!(one_piece && solved_part) && !learner_.solving() && st_.learn_pending) {
        st_.learn_pending = false;
        // The turn less every bias estimate (the one now stands for the interval's).
        learner_.add(learn_field_uT_, dcm_.gyro_turn_q30(learn_turn_counts_, st_.learn_steps), st_.learn_steps, learned);
    }
    if (learned == before) return;
    mag_cal_uT_ -= learned - before;
    if ((learned - learned_at_reference_uT_).length_squared() > kMagReferenceShift_uT * kMagReferenceShift_uT)
        forget_mag_reference(false);
}

// The DCM takes the next calibrated sample as the earth field (and, take_heading, its
// heading at once: a new calibration).
void AttitudePipeline::forget_mag_reference(bool take_heading) {
    dcm_.reset_mag_reference(take_heading);
    learned_at_reference_uT_ = settings_.cal.mag_learned_uT;
}

// Spikes and non-finite values are replaced by the previous sample; saturation is
// reported (a saturated gyro is used: the true rate is at least the full scale; a
// saturated accel is withheld from the DCM by on_imu_sample).
const mpu6000::Sample& AttitudePipeline::guard(const mpu6000::Sample& s) {
    bool spike = false;
    if (st_.have_last) {
        spike = jump(s.gyro.x, last_.gyro.x) > kSpikeGyroJumpCounts || jump(s.gyro.y, last_.gyro.y) > kSpikeGyroJumpCounts ||
                jump(s.gyro.z, last_.gyro.z) > kSpikeGyroJumpCounts;
        spike = spike || (norm2(s.accel) > kSpikeAccelCounts2 && norm2(last_.accel) < kNormalAccelCounts2);
    }
    if (spike && st_.spike_run < kMaxSpikeRun) {
        ++st_.spike_run;
        ++st_.spikes;
        if (st_.warn_spike.allow(st_.steps, kWarnIntervalSteps)) {
            Writer(log_).str(TXT(TXT_WARN TXT_MPU " spike: previous sample used instead ("))
                .u32(st_.spikes).str(TXT(" so far)")).end();
        }
        last_.temperature_raw = s.temperature_raw;  // the previous sample, with this one's temperature
        st_.turn_doubtful = true;  // the gyro stood in for, not measured: no learner pair across it
        return last_;
    }
    // A run longer than kMaxSpikeRun is real (saturation, a crash) and used.
    st_.spike_run = 0;
    if (s.gyro_saturated) st_.turn_doubtful = true;  // the rate is only a lower bound
    if (s.gyro_saturated && st_.warn_gyro_sat.allow(st_.steps, kWarnIntervalSteps))
        Writer(log_).str(TXT(TXT_WARN TXT_MPU " gyro saturated (beyond 2000 deg/s)")).end();
    if (s.accel_saturated && st_.warn_accel_sat.allow(st_.steps, kWarnIntervalSteps))
        Writer(log_).str(TXT(TXT_WARN TXT_MPU " accel saturated (beyond 8 g)")).end();
    last_ = s;
    st_.have_last = true;
    return last_;
}

void AttitudePipeline::print_bias(text::Flash prefix, bool status) const {
    Writer w(log_);
    w.str(prefix).vec(status ? gyro_bias_rad_s() : settings_.cal.gyro_bias_rad_s, linalg::kDegPerRad)
        .str(TXT(" deg/s"));
    if (!status) {
        w.end();
        return;
    }
    w.str(TXT(", temperature ")).fixed2(last_.temperature_c()).str(TXT(" C")).end();
    w.str(TXT("# compass: cal "))
        .str((settings_.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none"))
        .str(TXT(", learned offset ")).vec(settings_.cal.mag_learned_uT).str(TXT(" uT ("))
        .u32(learner_.updates()).str(TXT(" updates)")).end();
}

// The DCM started from gravity and the latest field (TRIAD, ~20 k cycles). A DCM that has
// run is reset first (~10 k: a fresh object copied in) and given its scales; at the first
// start it is as the constructor made it with the scales set when the calibration began
// (nothing else touches it while calibrating): only the sensor bias is set (~2 k).
void AttitudePipeline::start_estimator(const Vector3f& gravity) {
    if (st_.phase == Phase::Running) {
        dcm_ = dcm::Dcm(dcm_.settings());
        dcm_.set_sample_scales(last_.gyro_rad_s_per_count, last_.accel_m_s2_per_count);
    }
    dcm_.set_sensor_bias_rad_s(settings_.cal.gyro_bias_rad_s);
    dcm_.init(gravity, st_.have_mag && st_.mag_present ? mag_cal_uT_ : Vector3f());
    st_.mag_pending = false;
    // How far off the offset in use may be: a fraction of a uT after `cal mag` or
    // learning, tens of uT on a compass never calibrated.
    const bool calibrated = (settings_.flags & settings::kFlagMagCalibrated) != 0 ||
                            !(settings_.cal.mag_learned_uT == Vector3f());
    learner_.restart(calibrated ? calib::kLearnPriorCalibrated_uT : calib::kLearnPriorUncalibrated_uT,
                     settings_.cal.mag_learned_uT);
    learned_at_reference_uT_ = settings_.cal.mag_learned_uT;
    st_.phase = Phase::Running;
    st_.output_acc = kRateHz;  // the first line comes with the first step
}

void AttitudePipeline::step_calibration(const mpu6000::Sample& raw) {
    const calib::GyroCalibrator::Result r =
        gyro_cal_.add(raw.gyro, raw.accel, raw.gyro_rad_s_per_count, raw.accel_m_s2_per_count);
    ++st_.gyro_cal_steps;
    if (r == calib::GyroCalibrator::Result::Done) {
        st_.gyro_cal_active = false;
        settings_.cal.gyro_bias_rad_s = gyro_cal_.bias();
        settings_.flags = (uint8_t)(settings_.flags | settings::kFlagGyroCalibrated);
        // The message (~11 k cycles) goes out on the next step: with the start's work this
        // one would overrun its 5 ms.
        st_.start_message = StartMessage::kBias;
        if (st_.phase == Phase::Calibrating) {
            start_estimator(gyro_cal_.mean_accel_m_s2());
        } else {
            dcm_.set_sensor_bias_rad_s(settings_.cal.gyro_bias_rad_s);
            dcm_.set_gyro_bias_rad_s(Vector3f());  // the estimator's residual starts again
        }
        return;
    }
    if (r == calib::GyroCalibrator::Result::Moved && st_.warn_moved.allow(st_.steps, kRateHz)) {
        Writer(log_).str(TXT("# calibrating gyro: board moved, retrying")).end();
    } else if (const uint16_t n = st_.warn_moved.deferred(st_.steps, kRateHz)) {
        Writer(log_).str(TXT("# calibrating gyro: board moved ")).u32(n).str(TXT(" more times, retrying")).end();
    }
    if (st_.phase == Phase::Calibrating && st_.gyro_cal_steps >= kStartupDeadlineSteps) {
        // Never still long enough: run with what we have, keep measuring in the background
        // (the warning on the next step, as the bias message).
        st_.start_message = StartMessage::kNotStill;
        start_estimator(raw.accel_m_s2());
        return;
    }
    if (st_.phase == Phase::Running && st_.gyro_cal_steps >= kGyroCalTimeoutSteps) {
        st_.gyro_cal_active = false;
        Writer(log_).str(TXT(TXT_ERROR "cal gyro: board never still for 1 s; bias unchanged")).end();
    }
}

// How many axes sit at the accelerometer's full scale (decode_burst's saturation).
static uint8_t clipped_axes(const linalg::Vector3i& a) {
    return (uint8_t)((a.x >= 32767 || a.x <= -32767) + (a.y >= 32767 || a.y <= -32767) + (a.z >= 32767 || a.z <= -32767));
}

void AttitudePipeline::on_imu_sample(const mpu6000::Sample& raw) {
    st_.output_due = false;
    ++st_.steps;
    if (st_.steps_since_mag < 0xFFFFu) ++st_.steps_since_mag;
    profile::begin(profile::kChecks);
    if (st_.start_message == StartMessage::kBias) print_bias(TXT("# gyro bias: "), false);
    if (st_.start_message == StartMessage::kNotStill) {
        Writer(log_).str(TXT(TXT_WARN "board not still: starting with "))
            .str((settings_.flags & settings::kFlagGyroCalibrated) ? TXT("the saved") : TXT("zero"))
            .str(TXT(" gyro bias, measuring on")).end();
    }
    st_.start_message = StartMessage::kNone;
    const mpu6000::Sample& s = guard(raw);  // last_, the sample the step uses
    if (st_.phase == Phase::WaitImu) {
        st_.phase = Phase::Calibrating;
        // The DCM's scales now (~4 k cycles): the step that ends the calibration starts it.
        dcm_.set_sample_scales(s.gyro_rad_s_per_count, s.accel_m_s2_per_count);
        Writer(log_).str(TXT("# calibrating gyro: keep the board still")).end();
        start_gyro_calibration();
    }
    if (st_.gyro_cal_active) step_calibration(s);
    if (st_.phase != Phase::Running) {
        profile::end(profile::kChecks);
        return;
    }
    if (st_.reinit_pending) {
        st_.reinit_pending = false;
        start_estimator(s.accel_m_s2());  // a restart after an outage (rare): ~50 k cycles
    }

    // A clipped accelerometer sample still points roughly the right way: in a violent
    // motion one axis clips for a few ms, and dropping those samples would bias the
    // estimator's low-passed gravity (BROAD's 10 g fast translation: 1.7 -> 5.2 deg
    // RMSE; its clipped samples never have two axes clipped at once). Two or more
    // axes at full scale (at least 11 g) is not a motion but a stuck or broken sensor,
    // and so is one axis clipped for longer than kAccelSaturationFaultSteps: then the
    // DCM gets NaN and gives gravity no weight that step (Dcm::update). The gyro is
    // always integrated (saturated, it is a lower bound of the rate).
    st_.accel_saturated_steps = s.accel_saturated ? (uint8_t)(st_.accel_saturated_steps < 255 ? st_.accel_saturated_steps + 1 : 255) : 0;
    const bool accel_stuck = s.accel_saturated && (clipped_axes(s.accel) >= 2 ||
                                                   st_.accel_saturated_steps > kAccelSaturationFaultSteps);
    profile::end(profile::kChecks);
    // A field sample (10-20 k cycles: into earth axes, and the heading's correction
    // every kHeadingSteps) waits out a step on which the DCM integrates or corrects
    // gravity (~18-30 k), up to kMaxMagWaitSteps: its age is counted in the latency
    // compensation. A line (Euler angles and formatting, ~10 k) is not made on a step
    // with a field sample: it moves to the next step, 5 ms later (samples come at
    // least two steps apart). The DCM brings its matrix up to date for the line.
    bool heading_corrected = st_.mag_pending && st_.mag_present;
    if (heading_corrected && st_.mag_wait_steps < kMaxMagWaitSteps && dcm_.heavy_due()) {
        heading_corrected = false;
        ++st_.mag_wait_steps;
    }
    st_.output_acc = (uint16_t)(st_.output_acc + settings_.rate_hz);
    if (st_.output_acc >= kRateHz && !heading_corrected) {
        st_.output_acc = (uint16_t)(st_.output_acc - kRateHz);
        if (st_.output_acc >= kRateHz) st_.output_acc = 0;  // rate lowered: no burst of lines
        st_.output_due = true;
    }
    const bool heading_heavy = heading_corrected && dcm_.heading_due_next();
    if (centripetal_gain_q8_ != 0) {
        // Gravity for the DCM: the turn's centripetal acceleration taken off (see
        // kCentripetalMinAirspeed_m_s); the clip checks above saw the measured sample.
        const linalg::Vector3i accel = centripetal_corrected(
            s.accel, sat16((int32_t)s.gyro.y - gyro_bias_y_counts_), sat16((int32_t)s.gyro.z - gyro_bias_z_counts_),
            centripetal_gain_q8_);
        dcm_.update(s.gyro, accel, norm2(s.gyro) < kMaxCredibleRateCounts2, !accel_stuck, st_.output_due);
    } else {
        dcm_.update(s.gyro, s.accel, norm2(s.gyro) < kMaxCredibleRateCounts2, !accel_stuck, st_.output_due);
    }
    // The board's turn for the compass learner: the gyro alone (the biases come off when
    // a field sample takes it).
    turn_counts_ += s.gyro;
    if (heading_corrected) {
        profile::begin(profile::kCompass);
        dcm_.correct_heading(mag_cal_uT_, st_.mag_wait_steps);
        profile::end(profile::kCompass);
        st_.mag_pending = false;
        st_.mag_wait_steps = 0;
    }

    if (st_.mag_cal_active) {
        ++st_.mag_cal_steps;
        if (st_.mag_cal_steps % (5u * kRateHz) == 0u && st_.mag_cal_steps < calib::kMagCalSeconds * kRateHz) {
            Writer(log_).str(TXT("# cal mag: "))
                .u32(calib::kMagCalSeconds - st_.mag_cal_steps / kRateHz)
                .str(TXT(" s left, keep turning ("))
                .u32(mag_cal_.count()).str(TXT(" samples)")).end();
        }
        if (st_.mag_cal_steps >= calib::kMagCalSeconds * kRateHz) {
            // The fit (several steps' worth) goes a part a step, on steps with room.
            st_.mag_cal_active = false;
            st_.cal_pending = false;
            st_.mag_fit_active = true;
            mag_cal_.begin_fit();
        }
    }

    // The deferred compass work (the cal mag sums ~10 k cycles on the AVR; the learner:
    // a sample ~6 k, or one part of a completed pair's solve, <= ~15 k) goes on a step
    // with neither an output line nor the heading's correction from its mean or its first
    // heading (Dcm::heading_due_next; a field sample's own ~3 k leaves room). On a step
    // with the DCM's integration or gravity correction (Dcm::heavy_step, ~8.5 k and
    // ~12-15 k) only one short piece of it fits, under 30 k: a sample or a part of the
    // solve but its long second one. A pair's solve takes three such steps, and the
    // samples that come meanwhile wait (the turn goes on summing). Each step kept from
    // the learner delays the offset it finds, and in a fast turn with a compass never
    // calibrated the first one ends the heading's freeze on a field the disturbance test
    // rejects (fast+uncal over ten noise seeds: 2.98 deg with the heavy steps kept from
    // the learner, 2.92 with its short pieces on them).
    if (st_.output_due || heading_heavy) return;
    const bool short_room = dcm_.heavy_step();
    bool fit_step = false;
    if (!short_room) {
        fit_step = st_.mag_fit_active;
        if (st_.cal_pending && st_.mag_cal_active) mag_cal_.add(cal_field_uT_);
        else if (fit_step) step_mag_fit();
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
// line a step at most: a line is a few thousand cycles).
void AttitudePipeline::report_deferred() {
    uint16_t n = st_.warn_spike.deferred(st_.steps, kWarnIntervalSteps);
    if (n != 0) {
        Writer(log_).str(TXT(TXT_WARN TXT_MPU " spike: ")).u32(n).str(TXT(" more samples replaced ("))
            .u32(st_.spikes).str(TXT(" so far)")).end();
        return;
    }
    if ((n = st_.warn_gyro_sat.deferred(st_.steps, kWarnIntervalSteps)) != 0) {
        Writer(log_).str(TXT(TXT_WARN TXT_MPU " gyro saturated: ")).u32(n).str(TXT(" more samples")).end();
        return;
    }
    if ((n = st_.warn_accel_sat.deferred(st_.steps, kWarnIntervalSteps)) != 0) {
        Writer(log_).str(TXT(TXT_WARN TXT_MPU " accel saturated: ")).u32(n).str(TXT(" more samples")).end();
        return;
    }
    if ((n = st_.warn_mag.deferred(st_.steps, kWarnIntervalSteps)) != 0)
        Writer(log_).str(TXT(TXT_WARN TXT_HMC " field not the Earth's: ")).u32(n).str(TXT(" more samples dropped")).end();
}

Angles AttitudePipeline::angles() const {
    const dcm::EulerAngles e = dcm_.euler_now();
    const float h = dcm::heading_deg(e.yaw_rad, settings_.declination_deg());
    return Angles{e.roll_rad * linalg::kDegPerRad, e.pitch_rad * linalg::kDegPerRad, h};
}

AnglesCentideg AttitudePipeline::angles_centideg() const {
    return dcm::angles_centideg(dcm_.euler_now_q24(), settings_.declination_centideg);
}

linalg::Quaternion AttitudePipeline::quaternion() const {
    // The DCM's earth frame is magnetic north: turned about down by the declination.
    const float half_rad = 0.5f * settings_.declination_deg() * linalg::kRadPerDeg;
    return linalg::quat_turned_about_down(linalg::quat_from_rotation(dcm_.matrix()), cosf(half_rad), sinf(half_rad));
}

Vector3f AttitudePipeline::gyro_rad_s() const { return calib::apply_gyro(settings_.cal, last_.gyro_rad_s()); }

Vector3f AttitudePipeline::gyro_bias_rad_s() const {
    return settings_.cal.gyro_bias_rad_s + dcm_.gyro_bias_rad_s();
}

void AttitudePipeline::start_gyro_calibration() {
    gyro_cal_.restart();
    st_.gyro_cal_steps = 0;
    st_.gyro_cal_active = true;
    if (st_.phase == Phase::Running)
        Writer(log_).str(TXT("# cal gyro: keep the board still for 1 s")).end();
}

void AttitudePipeline::restart_estimator() {
    st_.reinit_pending = (st_.phase == Phase::Running);
    st_.have_last = false;  // the previous sample is too old to judge spikes by
    st_.spike_run = 0;
}

void AttitudePipeline::start_mag_calibration() {
    if (!st_.mag_present) {
        Writer(log_).str(TXT(TXT_ERROR "cal mag: " TXT_HMC " absent")).end();
        return;
    }
    // The centre in use (the fit's offset plus the learned one, which W ~ I barely
    // changes) centres the fit's sums.
    mag_cal_.restart(settings_.cal.mag_offset_uT + settings_.cal.mag_learned_uT);
    st_.mag_cal_steps = 0;
    st_.mag_cal_active = true;
    st_.mag_fit_active = false;  // a fit under way is dropped
    Writer(log_).str(TXT("# cal mag: turn the board every way for 30 s")).end();
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
    Writer w(log_);
    if (q == calib::MagCalibrator::Quality::Ok) {
        calib::Calibration& c = settings_.cal;
        mag_cal_.result(c);
        // The latest field (and a sample waiting for the heading's correction) was
        // calibrated the old way: the DCM takes the heading from the new one.
        mag_cal_uT_ = calib::apply_mag(c, cal_field_uT_);
        settings_.flags = (uint8_t)(settings_.flags | settings::kFlagMagCalibrated);
        w.str(TXT("# cal mag: offset ")).vec(c.mag_offset_uT).str(TXT(" uT, scale ")).vec(c.mag_scale)
            .str(TXT(", cross ")).vec(c.mag_cross).str(TXT(", residual ")).fixed2(mag_cal_.residual_uT())
            .str(TXT(" uT, coverage ")).u32(mag_cal_.coverage_pct()).str(TXT("% (save to keep)")).end();
        // Applied from the next sample: the estimator learns the calibrated field afresh.
        learner_.restart(calib::kLearnPriorCalibrated_uT, Vector3f());
        if (st_.phase == Phase::Running) {
            forget_mag_reference(true);
            // The estimator's bias residual was learned partly from heading corrections
            // against the old calibration (a simulated tumble with 8 uT of hard iron, `cal
            // mag` at its end: kept, the heading at rest swung from -0.9 to +0.9 deg over
            // the next 15 s; dropped, it settles from -0.9 to 0.0): it goes with it, and
            // is learned again.
            dcm_.set_gyro_bias_rad_s(Vector3f());
        }
        return;
    }
    w.str(TXT(TXT_ERROR "cal mag failed: "));
    switch (q) {
        case calib::MagCalibrator::Quality::TooFewSamples:
            w.str(TXT("too few samples (")).u32(mag_cal_.count()).chr(')');
            break;
        case calib::MagCalibrator::Quality::ThinCoverage:
            w.str(TXT("not turned every way (coverage ")).u32(mag_cal_.coverage_pct()).str(TXT("%, need "))
                .u32(calib::kMagMinCoveragePct).str(TXT("%)"));
            break;
        case calib::MagCalibrator::Quality::FitFailed: w.str(TXT("no ellipsoid fits the samples")); break;
        case calib::MagCalibrator::Quality::NotEarthField:
            w.str(TXT("field ")).fixed2(mag_cal_.radius_uT()).str(TXT(" uT is not the Earth's (magnet near?)"));
            break;
        case calib::MagCalibrator::Quality::SoftIronTooLarge: w.str(TXT("soft iron beyond 20% (magnet near?)")); break;
        default:
            w.str(TXT("residual ")).fixed2(mag_cal_.residual_uT()).str(TXT(" uT, over "))
                .fixed2(calib::kMagMaxResidual_uT).str(TXT(" (field changed while turning?)"));
            break;
    }
    w.str(TXT("; calibration unchanged")).end();
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
