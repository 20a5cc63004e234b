// SPDX-License-Identifier: GPL-3.0-or-later
// AttitudePipeline: decoded sensor samples in, estimator state and output timing out.
// The firmware and the host replay tool run exactly this; the firmware adds the Arduino
// set-up, the buses, the data-ready pacing, serial I/O (the events' words:
// PipelineText.h), LEDs, EEPROM, the airspeed sensor and the flight control.
//
// Use (one call per MPU6000 data-ready, 200 Hz):
//
//   pipeline::AttitudePipeline pipe(events_or_nullptr); // null: silent
//   pipe.settings() = settings_from_eeprom_or_defaults;  // rate, declination, calibration
//   pipe.set_mag_present(true);                          // false: yaw is gyro-only
//   loop:
//     if (magnetometer delivered)  pipe.on_mag_sample(field_uT);   // body frame, before calibration
//     pipe.on_imu_sample(sample);                                  // decoded burst, body frame
//     if (pipe.output_due()) { pipeline::Angles a = pipe.angles(); ... }
//
// Start-up: the gyro bias is measured at rest (kGyroWindow samples, restarting when the
// board moves); then the DCM starts from the mean gravity and the latest field (TRIAD).
// If the board is never still for kStartupDeadlineSteps the estimator starts anyway
// with the saved bias (or zero) and the measurement goes on in the background.
// Each step, on the sample in the MPU6000's counts: a spike replaced by the previous
// sample (guard), Dcm::update at the fixed 5 ms step (the DCM subtracts the calibrated
// bias and, when an airspeed is set, the turn's centripetal term: configure_turn; an
// accelerometer stuck at full scale gets no gravity weight that step, a rate beyond any
// gyro's is not integrated), then Dcm::correct_heading with the latest field sample
// (waiting out up to kMaxMagWaitSteps of the DCM's heavy steps), and on a step with room
// the deferred compass work (the `cal mag` sums and fit, the offset learner).
//
// The board in its airframe (calib::BoardFrame, docs/board_frame.md): each sample's counts
// get INS_ACCOFFS/INS_ACCSCAL (board axes) and AHRS_ORIENTATION's turn, the field sample the
// turn, before anything else; AHRS_TRIM_X/Y is taken off where the angles and the
// quaternion are taken. The level and six-position calibrations set them.
//
// Compass: each field sample is calibrated (calib::apply_mag: the `cal mag` fit, then
// the offset learned in motion) before the DCM sees it; while running, the learner
// (calib::OffsetLearner) estimates the hard iron from the field's change against the
// gyro's rotation, and puts it in use once it is significant (settings' COMPASS_LEARN;
// COMPASS_USE 0 keeps the field from the heading, not from `cal mag`). A new calibration, or a
// learned offset that has moved by kMagReferenceShift_uT since the estimator learned the
// earth field, makes the estimator forget that field (Dcm::reset_mag_reference): its
// strength and dip are those of the calibrated field from then on.
//
// Events (to the EventSink, as plain numbers: the sketch words them, PipelineText.h):
// the gyro calibration's progress and result, spikes and saturation of the MPU6000,
// absurd fields from the HMC5883L (at most one per kWarnIntervalSteps per kind; what
// came meanwhile is told once that time is over, with its count), the `cal mag`
// progress and verdict.
#pragma once

#include <stdint.h>

#include "AccelFit.h"
#include "BoardFrame.h"
#include "Calibration.h"
#include "Dcm.h"
#include "GpsFix.h"
#include "LinAlg.h"
#include "Mpu6000.h"
#include "Settings.h"
#include "StartGravity.h"

namespace pipeline {

// The set-up timeline, fixed so that a run is reproducible: each stage starts at
// this time after reset (or as soon after as the one before it is done). The host
// replay tool follows the same timeline, so both sample the same instants of a
// trajectory and their angles can be compared one for one. The firmware's millis() starts
// kBootMs after reset, whatever the C runtime's start-up took before it
// (firmware/StartTime.cpp), so it waits for each stage's time less kBootMs.
constexpr uint16_t kBootMs = 10;        // > the C runtime's start-up (~4.5 ms), < 32 ms
constexpr uint16_t kMpuStartMs = 50;    // after the banner
constexpr uint16_t kMagStartMs = 200;   // after the MPU6000's 100 ms reset and wake
constexpr uint16_t kLoopStartMs = 350;  // after the compass self-test and the banner's drain
// The compass is read when its DRDY pin is high and at least this many estimator
// steps after the previous read (75 Hz = 13.3 ms; a DRDY stuck high: <= 100 Hz).
// Counted in steps, not milliseconds, so the reads fall on the same steps in the
// firmware and in the host replay tool.
constexpr uint8_t kMagReadMinSteps = 2;
// The offset learner takes a field sample at most every this many steps (25 Hz): each
// sample costs it a turn composed (docs/performance.md), and pairs close at 20 deg of
// turn (kLearnMinCos) whatever the rate; the gyro's turn between two samples is summed as a
// rotation vector, whose error over 40 ms (at most 0.2 rad at 300 deg/s) is below 0.003 rad.
constexpr uint8_t kLearnMinSteps = 8;
// A field sample waits at most this many steps for a step free of the DCM's heavy parts
// (an integration may be followed by a gravity correction: two in a row at most).
constexpr uint8_t kMaxMagWaitSteps = 2;

using mpu6000::kRateHz;                         // the MPU6000's sample rate = the estimator step
constexpr float kStep_s = 1.0f / kRateHz;
constexpr uint16_t kStartupDeadlineSteps = 260; // 1.3 s: the first line must be out within 2 s of reset
constexpr uint16_t kGyroCalTimeoutSteps = 2000; // `cal gyro` gives up after 10 s without a still second
// After a start that was never still (the board may be flying: a restart in the air), the
// calibration that goes on measuring is only taken within this of the bias in use (the
// saved one, or zero). A steady turn passes the still test (its rate is constant, and |accel|
// stays within 10 % of 1 g below ~25 deg of bank) and would be learned as bias: at 15 m/s
// even 5 deg of bank turns at 3 deg/s. The MPU6000's bias moves by about this between two
// starts ~20 deg C apart (its zero-rate output: +-20 deg/s over -40..85 deg C); a bias
// refused here is left to the estimator's own bias learning.
constexpr float kMaxBiasChangeInMotion_rad_s = 0.0524f;  // 3 deg/s
constexpr uint16_t kWarnIntervalSteps = 400;    // rate limit of each warning kind: 2 s
constexpr float kSpikeGyroJump_rad_s = 17.45f;  // 1000 deg/s in one 5 ms step: not a rotation
constexpr uint8_t kMaxSpikeRun = 10;            // up to 50 ms of glitch; longer is real (a crash): use it
constexpr uint8_t kAccelSaturationFaultSteps = 20;  // 100 ms of clipped accel: a stuck sensor, not a motion
constexpr float kMagMin_uT = 10.0f;             // Earth: 25..65 uT; outside 10..200 = not the Earth
constexpr float kMagMax_uT = 200.0f;
// ... as the squared strengths of dcm::field_norm2.
constexpr uint32_t kMagMinNorm2 = (uint32_t)(kMagMin_uT * kMagMin_uT / dcm::kFieldNorm2PerUnit_uT2);
constexpr uint32_t kMagMaxNorm2 = (uint32_t)(kMagMax_uT * kMagMax_uT / dcm::kFieldNorm2PerUnit_uT2);
// The estimator rejects a field whose strength is 10 % (~5 uT) off the one it learned:
// a learned offset that has moved by half that since it learned the field makes it
// learn the field again, before the shift can get a good field rejected.
constexpr float kMagReferenceShift_uT = 2.5f;

// The centripetal correction (Premerlani & Bizard, "Direction Cosine Matrix IMU: Theory",
// eq. 26; ArduPilot's AP_AHRS_DCM with an airspeed): in steady flight the velocity is
// (V, 0, 0) along the body's x axis and the accelerometer reads f = omega x v - g_body,
// so gravity is f - omega x v = f - (0, omega_z V, -omega_y V). Below this airspeed the
// velocity is not along x (on the ground, a launch, a stall): no correction. ArduPlane's
// ARSPD_FBW_MIN default, about two thirds of a small aeroplane's stall.
constexpr float kCentripetalMinAirspeed_m_s = 9.0f;
// The GPS aids the estimator only in motion: from this ground speed on (AP_AHRS_DCM's
// GPS_SPEED_MIN, where it takes the course as the heading: at a walk the course's noise,
// 0.1 m/s of velocity noise across the track, is degrees) until it falls below
// kGpsStillSpeed_m_s (its GPS_SPEED_RESET). Still or at a walk, the accelerations the GPS
// could take off are below its own noise (0.1 m/s differentiated over a fix: 0.7 m/s^2),
// and the accelerometer's low-pass averages a board's bounded motions without any: the
// GPS-aided tilt would only be noisier (~0.1 deg RMS, 0.25 deg of heading through the dip).
constexpr float kCourseMinSpeed_m_s = 3.0f;
constexpr float kGpsStillSpeed_m_s = 1.0f;
// A compass sample at most this old (steps: 0.5 s; it delivers at 75 Hz) is a working
// compass: older, the GPS course takes the heading.
constexpr uint16_t kCompassStaleSteps = 100;
// Above the MPXV7002DP's full scale (2 kPa: 57 m/s) an airspeed is a fault: clamped.
constexpr float kCentripetalMaxAirspeed_m_s = 60.0f;

// The correction's gain: accel counts per gyro count of omega x v at this airspeed, Q8
// (0 below kCentripetalMinAirspeed_m_s or not finite; clamped at the maximum). The
// estimator takes it off its gravity window (lib/DCM/Centripetal.h).
int16_t centripetal_gain_q8(float airspeed_m_s);
// Two measured airspeeds this many steps apart differ by the flight's acceleration along
// the body's x axis (dV/dt, in still air: what gusts add the estimator bounds), which the
// accelerometer reads as pitch (1 m/s^2 is 6 deg). ArduPilot's DCM differentiates its
// velocity the same way.
constexpr uint16_t kMaxAirspeedGapSteps = 40;  // readings further apart (0.2 s) are no derivative
constexpr float kMaxLongitudinal_m_s2 = 20.0f;  // 2 g along the path: no aeroplane's, held
// dV/dt in accel counts (0 unless both are flying speeds, centripetal_gain_q8 > 0, and at
// most kMaxAirspeedGapSteps apart).
int16_t longitudinal_counts(float before_m_s, float now_m_s, uint16_t steps);
enum class Phase : uint8_t {
    WaitImu,      // no sample yet
    Calibrating,  // measuring the gyro bias; nothing estimated yet
    Running,      // estimating
};

// An event of the start, told on the step after the one that starts the estimator
// (with the start's work and the line's words that step would overrun its 5 ms); kTold
// on the step after that: the event's words took the one before.
enum class StartMessage : uint8_t { kNone, kBias, kNotStill, kTold };

struct Angles {
    float roll_deg;
    float pitch_deg;
    float heading_deg;  // 0 <= h < 360, declination applied
};

// The same rounded to the hundredths the output lines print (fmt::format_plot_line_centideg).
using AnglesCentideg = dcm::AnglesCentideg;

// A per-kind rate limiter for warnings: allow() is true at most once per interval; what
// it holds back is not lost: once the interval since the last line is over, deferred()
// gives how many were held (and zero again), for a "N more" line that starts the next
// interval (while some are held, allow() holds the next ones too: that line counts
// them). A plain struct that starts zeroed: declare it static or value-initialise it
// (`RateLimiter r{};`).
struct RateLimiter {
    bool allow(uint32_t now_steps, uint16_t interval_steps);
    uint16_t deferred(uint32_t now_steps, uint16_t interval_steps);

    uint32_t last;  // when the last line (allowed or deferred) went out
    uint16_t held;  // how many were held back since (saturates)
    bool ever;      // allow() has said yes before
};

// What the pipeline tells, as numbers; the words are the sketch's (PipelineText.h).
enum class EventKind : uint8_t {
    kGyroCalStart,     // the start-up gyro calibration begins
    kGyroCalAgain,     // `cal gyro` begins
    kGyroCalMoved,     // the board moved: the calibration restarts; count more since the last line
    kGyroCalTimeout,   // `cal gyro` gave up (never still for 1 s): the bias unchanged
    kGyroBias,         // the calibration's result: settings().cal.gyro_bias_rad_s
    kNotStill,         // never still: started anyway; code 1 with the saved bias, 0 with zero
    kGyroBiasRefused,  // a calibration after a moving start, value deg/s off the bias in use: not
                       // taken (code 1: the saved bias kept, 0: zero)
    kSpike,            // MPU6000 samples replaced by the previous one; total so far
    kGyroSaturated,    // MPU6000 gyro at its full scale (used: a lower bound)
    kAccelSaturated,   // MPU6000 accel at its full scale
    kMagNotEarth,      // an HMC5883L field outside kMagMin_uT..kMagMax_uT dropped; value uT
                       // (kSpike .. kMagNotEarth: the rate-limited warnings, in this order)
    kMagCalStart,      // `cal mag` begins
    kMagCalNoCompass,  // `cal mag` refused: no magnetometer
    kMagCalProgress,   // `cal mag` collecting: count seconds left, total samples
    kMagCalDone,       // the verdict: code a calib::MagCalibrator::Quality (Ok: in settings().cal)
    kLevelStart,       // the level calibration begins
    kLevelDone,        // its verdict: code a LevelResult (Ok: the trims in settings().vehicle)
    kOrientation,      // AHRS_ORIENTATION changed to code: the estimator and the gyro start again
    kAccelCalAsk,      // the six-position calibration asks for position code (calib::AccelPosition)
    kAccelCalRefused,  // position code not taken: value 0 the board moved, 1 not in that position
    kAccelCalDone,     // its verdict: code a calib::AccelFit::Quality (Ok: INS_ACC* in settings().vehicle)
};

// The level calibration's verdict (kLevelDone's code).
enum class LevelResult : uint8_t {
    kOk,
    kMoved,     // the board moved: nothing changed
    kTooFar,    // the board is more than AHRS_TRIM's 10 deg from level: nothing changed
    kTimeout,   // never still for 1 s within 10 s
};

// One event. count, for the rate-limited kinds (kGyroCalMoved, kSpike, kGyroSaturated,
// kAccelSaturated, kMagNotEarth): 0 for the first, at once; else how many the limit held
// back since the last line. kMagCalDone: count the coverage (%), total the samples,
// value the residual (uT; the fitted field's radius for NotEarthField).
struct Event {
    EventKind kind;
    uint8_t code;
    uint16_t count;
    uint32_t total;
    float value;
};

// Where the latest `cal mag` run stands (a ground station's MAG_CAL_PROGRESS and REPORT).
enum class MagCalState : uint8_t {
    kNone,        // none since the start, or cancelled
    kCollecting,  // the board is being turned: the sums grow
    kFitting,     // the fit, a part a step
    kWaiting,     // a good result waits for accept_mag_calibration() (a run started with hold)
    kApplied,     // a good result is in use (settings().cal)
    kFailed,      // the fit was refused: mag_calibrator().quality() says why
};

class AttitudePipeline;
// Where the events go: a function and its context (no virtual call: avr-gcc keeps
// vtables in SRAM). The function may read the pipeline's state (settings, bias).
struct EventSink {
    void* ctx;
    void (*tell)(void* ctx, const AttitudePipeline& pipe, const Event& e);
};

class AttitudePipeline {
public:
    // dcm_settings: the estimator's gains (the firmware's are the defaults; the host
    // replay tool may try others, `replay --set`).
    explicit AttitudePipeline(const EventSink* events = nullptr,
                              const dcm::DcmSettings& dcm_settings = dcm::kDefaultDcmSettings);
    // The firmware's static object: settings zeroed until setup() loads them. A static
    // constructor runs before Arduino's init() starts millis(): its work is within the
    // start-up that kBootMs absorbs (firmware/StartTime.cpp), but kept light all the same.
    // Never inline: inlined into the static constructors, its member stores are 4-byte
    // absolute `sts` each; called, they go through `this` (380 B less flash).
    struct SettingsLoadedLater {};
    __attribute__((noinline)) AttitudePipeline(const EventSink* events, SettingsLoadedLater,
                     const dcm::DcmSettings& dcm_settings = dcm::kDefaultDcmSettings);

    // Rate, declination, mode and calibration; change them freely (console commands).
    settings::Settings& settings() { return settings_; }
    const settings::Settings& settings() const { return settings_; }
    // The same as a constant expression (static: the class is not a literal type), for a
    // static object that keeps a reference to them with no start-up code (FlightIo).
    static constexpr settings::Settings& settings_of(AttitudePipeline& p) { return p.settings_; }

    // Whether a magnetometer is delivering. false: yaw is gyro-only, heading not corrected.
    void set_mag_present(bool present);
    bool mag_present() const { return st_.mag_present; }

    // The measured airspeed along the body's x axis (m/s; 0: none, no correction) for the
    // centripetal correction of the accelerometer, and with the reading before it the
    // flight's dV/dt (longitudinal_counts): holds until set again.
    void set_airspeed_m_s(float airspeed_m_s);
    // A configured cruise speed instead (no sensor; 0: none), grown in a banked turn as
    // the lift needs (airspeed::cruise_in_turn_m_s): set it again as the bank changes.
    void set_cruise_airspeed_m_s(float trim_m_s);
    float airspeed_m_s() const { return airspeed_m_s_; }

    // A new GPS solution (call once per fix: the driver's fix_count() moved): its velocity
    // aids the gravity correction (dcm::GpsAccel: the accelerometer less the GPS's
    // acceleration, in place of the airspeed's or cruise speed's turn term) while the fix
    // is 3D with AHRS_GPS_MINSATS satellites, AHRS_GPS_USE is 1 and the board moves
    // (kCourseMinSpeed_m_s); AHRS_GPS_GAIN weighs it. Without a compass (or with one that stopped), its course above
    // kCourseMinSpeed_m_s is the heading reference.
    void on_gps_fix(const gps::Fix& fix);
    // One MPU6000 sample at the fixed 200 Hz step.
    void on_imu_sample(const mpu6000::Sample& s);
    // One magnetometer sample (body frame, uT, self-test scale applied, before the
    // calibration): used by the next on_imu_sample.
    void on_mag_sample(const linalg::Vector3f& field_uT);
    // True once per output period after on_imu_sample (only while Running).
    bool output_due() const { return st_.output_due; }
    // The step that ended the gyro calibration (it started the estimator: the TRIAD in
    // floats) or the next (it tells the start's event): long steps, so the first output
    // line comes on the step after them, and so should other long work that can wait
    // (the flight control step).
    bool starting() const { return st_.start_message != StartMessage::kNone; }
    // Current angles (Euler extraction in integers, then floats; call when due).
    Angles angles() const;
    // The same in printed hundredths, with no float after the matrix entries (cheaper
    // than angles(): docs/performance.md): what the plot and csv lines print.
    AnglesCentideg angles_centideg() const;
    // The same attitude as a unit quaternion, body to the true-north earth frame
    // (declination applied like the heading's): `mode quat`.
    linalg::Quaternion quaternion() const;
    // The latest sample, calibrated (body frame: gyro less its calibrated bias, accel as
    // measured, field with the compass calibration): `mode raw`.
    linalg::Vector3f gyro_rad_s() const;
    linalg::Vector3f accel_m_s2() const { return last_.accel_m_s2(); }
    linalg::Vector3f field_uT() const { return dcm::field_uT_of(mag_cal_q5_); }
    // The body rates less every bias estimate, rad/s (MAVLink ATTITUDE).
    linalg::Vector3f body_rate_rad_s() const { return last_.gyro_rad_s() - gyro_bias_rad_s(); }

    // Back to the default settings and calibration, keeping the gyro bias measured at
    // this start (a measurement, not a setting). Not saved until the caller saves.
    void restore_defaults();
    void start_gyro_calibration();
    // `cal mag`: collect for calib::kMagCalSeconds, then fit. A good result is used at once,
    // or with hold (a ground station's DO_START_MAG_CAL without autosave) kept in the
    // calibrator until accept_mag_calibration(); a new start drops a result not accepted.
    void start_mag_calibration(bool hold = false);
    // A result waiting (kWaiting) into settings().cal and used, as `cal mag` uses one: true;
    // false when none waits.
    bool accept_mag_calibration();
    // The run stopped, or the result waiting dropped: the calibration in use stays.
    void cancel_mag_calibration();
    // settings().cal's compass terms were set from outside (a parameter): the compass is
    // calibrated, the learned offset goes, the estimator learns the field afresh, as
    // after `cal mag`.
    void take_mag_calibration();
    MagCalState mag_cal_state() const;
    // The run's progress, percent: the collection's time, 100 once the fit is over.
    uint8_t mag_cal_progress_pct() const;
    // The level calibration (ArduPilot's "Calibrate Level", MAV_CMD_PREFLIGHT_CALIBRATION
    // param5 2): a still second's mean specific force sets AHRS_TRIM_X/Y so that the
    // airframe, level and at rest, reads level (calib::level_trim); the gyro bias is
    // measured again in the same second. False (nothing started) while not running or
    // while another calibration runs. The verdict is kLevelDone.
    bool start_level_calibration();
    bool level_calibrating() const { return st_.level_cal_active; }
    // The accelerometer's six-position calibration (ArduPilot's, PREFLIGHT_CALIBRATION
    // param5 1): asks for each position in turn (kAccelCalAsk), takes a still second's
    // mean of the raw accelerometer once the user says the airframe is there
    // (confirm_accel_position), refuses a moving board or a wrong position (asking again),
    // then fits INS_ACCOFFS_* and INS_ACCSCAL_* (calib::AccelFit, one iteration a step with
    // room) and uses them at once (kAccelCalDone). False while not running or busy.
    bool start_accel_calibration();
    // The user says the airframe is in `position` (1..6): false unless that is the one asked.
    bool confirm_accel_position(uint8_t position);
    bool accel_calibrating() const { return st_.accel_pos != 0; }
    calib::AccelFit::Quality accel_fit_quality() const { return accel_fit_.quality(); }
    // The position asked and not yet confirmed (0: none), for a ground station's prompt.
    uint8_t accel_position_asked() const { return st_.accel_waiting ? st_.accel_pos : 0; }
    // How many times a position has been asked (again after a refusal): a new prompt to send.
    uint8_t accel_asks() const { return st_.accel_asks; }
    // The board's frame and trim from the settings now (AHRS_ORIENTATION, AHRS_TRIM_*,
    // INS_ACC*): the pipeline takes them up by itself within a second of a change.
    void refresh_board_frame();
    // After a sensor outage: the next sample restarts the DCM from gravity and the latest
    // field, keeping the gyro bias (before the first start it just goes on calibrating).
    void restart_estimator();
    // The MPU6000's samples may not be the board's motion for now (the firmware paces
    // on its timer: a sensor whose data-ready stopped may be repeating a frozen sample):
    // the compass learner takes no pair across this.
    void imu_doubtful() { st_.turn_doubtful = true; }

    Phase phase() const { return st_.phase; }
    bool gyro_calibrating() const { return st_.gyro_cal_active; }
    // After a start that was never still (a restart in the air): running on the saved bias,
    // the calibration measuring on in the background (gyro_calibrating() true meanwhile).
    bool gyro_measuring_on() const { return st_.gyro_cal_active && st_.start_moved; }
    bool mag_calibrating() const { return st_.mag_cal_active || st_.mag_fit_active; }
    uint32_t steps() const { return st_.steps; }
    uint32_t time_ms() const { return st_.steps * 5u; }
    const dcm::Dcm& estimator() const { return dcm_; }
#if DCM_TRACE
    // The estimator's corrections step by step into *trace (host tools: replay --trace).
    void set_trace(dcm::DcmTrace* trace) { dcm_.set_trace(trace); }
#endif
    // Calibrated bias plus what the estimator has learned since, rad/s.
    linalg::Vector3f gyro_bias_rad_s() const;
    float temperature_c() const { return last_.temperature_c(); }
    uint32_t spikes() const { return st_.spikes; }
    // The `cal mag` collection and fit: its sample count, coverage and residual.
    const calib::MagCalibrator& mag_calibrator() const { return mag_cal_; }
    const calib::OffsetLearner& offset_learner() const { return learner_; }

private:
    void step_calibration(const mpu6000::Sample& raw);
    // gravity_is_mean: the window's mean, not one sample (Dcm::init).
    void start_estimator(const linalg::Vector3f& gravity, bool gravity_is_mean);
    const mpu6000::Sample& guard(const mpu6000::Sample& s);
    // The estimator's turn correction from the airspeed (once running: TurnMean's space).
    void configure_turn(int16_t dv_dt_counts = 0);
    void step_mag_fit();
    void take_gps_fix(const gps::Fix& fix);
    void finish_mag_calibration();
    void use_mag_calibration();
    void report_deferred();
    void finish_level_calibration(LevelResult r);
    void begin_gyro_window();  // start_gyro_calibration without its line
    void step_accel_position(const mpu6000::Sample& board_sample);
    void step_accel_fit();
    void ask_accel_position();
    // The trim's rotation for the angles (null: none).
    const int16_t (*trim_rows() const)[3] { return trim_.active ? trim_.t : nullptr; }
    // An event to the sink; the short forms keep each call site small (flash).
    void tell(EventKind kind, uint16_t count, uint32_t total, float value, uint8_t code) const;
    __attribute__((noinline)) void tell(EventKind kind, uint16_t count) const;
    __attribute__((noinline)) void tell(EventKind kind) const;
    // The rate-limited warnings: the kinds kSpike .. kMagNotEarth, each with its limiter.
    static constexpr uint8_t kWarnKinds = 4;
    RateLimiter& warn_of(EventKind kind) { return st_.warn[(uint8_t)kind - (uint8_t)EventKind::kSpike]; }
    void take_learner_sample(const linalg::Vector3f& field_uT);
    void learn_mag_offset(bool one_piece);
    void forget_mag_reference(bool take_heading);
    void recalibrate_latest_field(const linalg::Vector3f& field_uT);

    const EventSink* events_;
    settings::Settings settings_;
    dcm::Dcm dcm_;
    calib::GyroCalibrator gyro_cal_;
    calib::MagCalibrator mag_cal_;
    calib::OffsetLearner learner_;
    linalg::Vector3f learned_at_reference_uT_;  // the learned offset when the DCM last learned the field
    linalg::Vector3l turn_counts_;              // the gyro summed since the last field sample (counts)
    linalg::Vector3f learn_field_uT_;           // the sample waiting for the learner, and the gyro before it
    linalg::Vector3l learn_turn_counts_;        // (counts summed over st_.learn_steps)
    linalg::Vector3f cal_field_uT_;             // the latest raw sample (for the `cal mag` sums)
    mpu6000::Sample last_;            // previous accepted sample (spike substitute)
    uint32_t gps_itow_ms_ = 0;        // the last usable fix's time of week (0: none)
    uint16_t gps_course_step_ = 0;    // st_.steps's low half at the last course given to the estimator
    float airspeed_m_s_ = 0.0f;
    uint16_t airspeed_step_ = 0;  // st_.steps's low half at the last measured airspeed
    linalg::Vector3i mag_cal_q5_;     // latest calibrated field (uT * 2^dcm::kFieldQ: dcm::field_q5_of)
    // Every counter and flag, zero at the start: one plain struct, so the constructor
    // clears it in one loop instead of a store per member (less flash).
    struct State {
        RateLimiter warn[kWarnKinds];  // kSpike .. kMagNotEarth (warn_of)
        RateLimiter warn_moved;
        uint32_t steps;
        uint32_t spikes;
        uint16_t gyro_cal_steps;
        uint16_t mag_cal_steps;
        uint16_t steps_since_mag;       // for the offset learner's pairs
        uint16_t learn_steps;           // steps_since_mag of the waiting sample
        uint16_t output_acc;
        Phase phase;                    // WaitImu
        uint8_t spike_run;
        uint8_t accel_saturated_steps;  // consecutive saturated accel samples
        uint8_t mag_wait_steps;         // steps the pending field sample has waited
        bool have_last;
        bool mag_present;
        bool mag_pending;
        bool have_mag;
        bool gyro_cal_active;
        bool mag_cal_active;            // `cal mag` collecting
        bool mag_fit_active;            // its fit, a part a step
        bool output_due;
        bool reinit_pending;
        StartMessage start_message;     // told on the step after the calibration's end
        bool learn_pending;             // learn_field_uT_ waits for a step without output
        bool cal_pending;               // cal_field_uT_ likewise
        bool turn_doubtful;             // since the last field sample the gyro was not the board's turn
        bool start_moved;               // the start was never still: the calibration measuring on may see a turn
        bool gps_moving;                // the GPS's ground speed passed kCourseMinSpeed_m_s (and not below kGpsStillSpeed_m_s since)
        bool mag_cal_hold;              // the run's good result waits for accept_mag_calibration()
        MagCalState mag_cal_end;        // how the last run ended (kNone, kWaiting, kApplied, kFailed)
        bool level_cal_active;          // the gyro calibration under way is the level calibration
        bool frame_due;                 // refresh_board_frame on the next step with room
        uint16_t frame_sum;             // the frame's settings' bytes summed at the last refresh (frame_settings_sum)
        uint8_t accel_pos;              // the six-position calibration's position (1..6; 7 fitting; 0 off)
        bool accel_waiting;             // ... asked, not yet confirmed
        bool accel_collecting;          // ... confirmed: its still second under way (gyro_cal_)
        uint8_t accel_asks;             // positions asked so far (wraps)
    };
    State st_;
    calib::BoardFrame frame_;  // the accelerometer's calibration and the board's orientation, in counts
    calib::TrimQ14 trim_;      // the level trim for the angles
    calib::AccelFit accel_fit_;  // the six positions' means and their fit
    // One space for two phases (RAM): before the estimator runs the start's gravity if
    // never still (StartGravity.h), then the turn's mean (TurnMean: a plain struct, taken
    // up by assignment in start_estimator; the phase never goes back).
    union {
        StartGravity start_gravity_;
        dcm::TurnMean turn_mean_;
    };
};

}  // namespace pipeline
