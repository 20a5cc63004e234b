// SPDX-License-Identifier: GPL-3.0-or-later
#include "FlightIo.h"

#include <string.h>

#include "AirspeedInput.h"
#include "Board.h"
#include "Vehicle.h"

#if APM25_FLIGHT

#include "Baro.h"
#include "GcsLink.h"
#include "GpsPort.h"
#include "NavModes.h"
#include "RcInput.h"
#include "SerialText.h"
#include "ServoOutputs.h"

using text::Flash;
using text::Writer;

// The control step, every 4th sample (50 Hz) after the estimator's: the servo pulse only
// changes once a 20 ms period, so a faster step would compute widths that are never
// sent. It moves onto the output line's samples when the output rate is 50 Hz or less,
// to take the angles the line worked out (the Euler extraction is the step's largest
// part). Without samples (the MPU6000 gone) the loop runs it on its own every 20 ms,
// without an attitude: the receiver, MANUAL and the failsafe go on.
constexpr uint8_t kControlDivider = 4;
constexpr uint16_t kControlPeriodUs = 20000;

// The rates are the sample's body-frame counts less the calibrated bias, in integers (the
// pipeline's float rates cost several times as much; the D term needs no more); the
// bias in those units is worked out again once a second (`cal gyro` changes it).
constexpr float kCdsPerRad_s = 100.0f * linalg::kDegPerRad;
constexpr int32_t kCdsPerCountQ10 =
    (int32_t)(mpu6000::gyro_rad_s_per_count(mpu6000::kGyroRange) * kCdsPerRad_s * 1024.0f + 0.5f);

// The cruise speed counts while the throttle is above 10 % of the stick (tenths of a
// percent): on the ground, or gliding, the velocity is not the cruise's.
constexpr int16_t kIdleThrottle = 100;

using vehicle::compass;
using vehicle::imu;
using vehicle::pipe;

// RC_OVERRIDE_TIME (s) in the override's 8 ms units: 0 off, < 0 forever.
static uint16_t override_timeout_8ms(float s) {
    if (s < 0.0f) return flight::FlightControl::kOverrideForever;
    const float t = s * 125.0f + 0.5f;
    return t >= 65534.0f ? (uint16_t)65534u : (uint16_t)t;
}

void FlightIo::begin() {
    uint16_t widths[flight::kChannels];
    configure();  // the loaded settings
    nav_modes::mission_store();  // the mission's areas checked now, not in a loop pass
    // Disarmed at power-up: with ARMING_REQUIRE 1 the throttle at its minimum from the first pulse.
    control_.set_throttle_live(arming_.throttle_live(pipe.settings().vehicle.arming_require));
    control_.step(0, flight::Attitude{0, 0, 0, 0, false, 0}, widths);
    servo_outputs::begin(widths);
    rc_input::begin();
}

void FlightIo::loop_starts(uint32_t now_us) { last_control_us_ = now_us; }

void FlightIo::configure() {
    control_.configure();
    nav_modes::configure();
    control_.set_override_timeout(override_timeout_8ms(pipe.settings().vehicle.rc_override_time_s));
}

void FlightIo::poll(uint32_t now_us, uint32_t now_ms) {
    while (rc_input::poll(ppm_)) control_.on_frame(ppm_.frame_us(), now_ms);
    // Only when the samples have stopped: while they flow, the sample task runs it (the
    // estimator's start holds it for two long steps: the line after them takes it).
    const bool samples_stopped = !imu.ok() || imu.us_since_sample(now_us) >= kControlPeriodUs;
    if (samples_stopped && now_us - last_control_us_ >= kControlPeriodUs + kControlPeriodUs / 4u) {
        board::mark_begin(board::kSecControl);
        control_step(now_us, now_ms, nullptr, nullptr);
        board::mark_end(board::kSecControl);
    }
}

bool FlightIo::control_due(bool output_line) {
    ++control_count_;
    if (pipe.starting()) return false;  // the estimator's start fills the step: on the next one
    return control_count_ >= kControlDivider ||
           (output_line && control_count_ >= kControlDivider / 2u && pipe.settings().rate_hz <= 50u);
}

void FlightIo::control_run(uint32_t now_us, uint32_t now_ms, const mpu6000::Sample& sample,
                           const pipeline::AnglesCentideg* angles) {
    control_step(now_us, now_ms, &sample, angles);
}

// angles: the output line's, or nullptr; sample: this step's, or nullptr (no attitude).
void FlightIo::control_step(uint32_t now_us, uint32_t now_ms, const mpu6000::Sample* sample,
                            const pipeline::AnglesCentideg* angles) {
    last_control_us_ = now_us;
    control_count_ = 0;
    flight::Attitude att{0, 0, 0, 0, sample != nullptr && imu.ok() && pipe.phase() == pipeline::Phase::Running,
                         0};
    control_.update_signal(now_ms);
    if (att.valid && control_.wants_attitude()) {  // MANUAL and no receiver yet need none
        const pipeline::AnglesCentideg a = angles != nullptr ? *angles : pipe.angles_centideg();
        att.roll_cd = a.roll_centideg;
        att.pitch_cd = a.pitch_centideg;
        if (++bias_age_ >= 50u) {
            const linalg::Vector3f& bias = pipe.settings().cal.gyro_bias_rad_s;
            bias_cds_[0] = (int16_t)(bias.x * kCdsPerRad_s);
            bias_cds_[1] = (int16_t)(bias.y * kCdsPerRad_s);
            bias_age_ = 0;
        }
        att.roll_rate_cds = (((int32_t)sample->gyro.x * kCdsPerCountQ10) >> 10) - bias_cds_[0];
        att.pitch_rate_cds = (((int32_t)sample->gyro.y * kCdsPerCountQ10) >> 10) - bias_cds_[1];
        // The pitot's airspeed for the turn coordination (at least 1: 0 is "none measured").
        if (airspeed_input::state() == airspeed_input::State::kSensor) {
            const float v_cm_s = pipe.airspeed_m_s() * 100.0f;
            att.airspeed_cm_s = v_cm_s >= 6000.0f ? 6000u : (v_cm_s >= 1.0f ? (uint16_t)v_cm_s : 1u);
        }
    }
    arming_step(now_ms);
    long_failsafe(now_ms);
    uint16_t widths[flight::kChannels];
    control_.step(now_ms, att, widths);
    servo_outputs::set(widths);
    say_events();
}

// --- Arming (lib/Flight/Arming.h) -------------------------------------------------------

// ArduPlane's is_flying, as far as the board can tell: the pitot or the GPS says 5 m/s.
bool FlightIo::flying() const {
    if (airspeed_input::state() == airspeed_input::State::kSensor && pipe.airspeed_m_s() >= 5.0f) return true;
    const gps::Fix& fix = gps_port::fix();
    return (uint8_t)fix.fix >= (uint8_t)gps::FixType::k2D && fix.ground_speed_cm_s >= 500u;
}

uint16_t FlightIo::prearm_failures() const {
    flight::PreArmInputs in;
    const pipeline::Phase ph = pipe.phase();
    in.imu_ok = imu.ok();
    // A restart in the air runs on the saved bias while the calibration measures on in the
    // background: the estimator is healthy and the board may be armed again (docs/arming.md).
    in.gyro_calibrating = ph == pipeline::Phase::Calibrating || (pipe.gyro_calibrating() && !pipe.gyro_measuring_on());
    in.estimator_ok = ph == pipeline::Phase::Running;  // its angles are finite by construction (lib/DCM)
    const settings::Settings& s = pipe.settings();
    in.compass_used = compass_found_ && s.vehicle.compass_use != 0u;  // COMPASS_USE 0: the heading is the gyro's
    in.compass_ok = compass.ok();
    // Calibrated by `cal mag` (or a ground station's), or learning the offset in motion
    // (COMPASS_LEARN 1, the default: ArduPlane's, with which its check passes).
    in.compass_calibrated = (s.flags & settings::kFlagMagCalibrated) != 0u || s.vehicle.compass_learn != 0u;
    in.compass_calibrating = pipe.mag_calibrating();
    in.baro_present = baro::present();
    in.baro_ok = baro::healthy();
    in.rc_seen = control_.state() != flight::State::NoSignal;
    in.rc_failsafe = control_.state() == flight::State::Failsafe;
    in.throttle_low = flight::throttle_at_zero(control_.stick(flight::kThrottle, millis()));
    in.settings_loaded = vehicle::store.settings_loaded();
    return flight::prearm_failures(in, pipe.settings().vehicle.arming_check);
}

mav::Result FlightIo::arm_now(bool force) {
    if (arming_.armed()) return mav::Result::Accepted;
    const uint16_t failures = force ? 0u : prearm_failures();
    if (failures != 0u) {
        prearm_unsaid_ = failures;  // said a line a run (say_prearm)
        return mav::Result::Failed;
    }
    arming_.arm();
    Writer(out_).str(force ? TXT("# Throttle armed (forced: no pre-arm checks)") : TXT("# Throttle armed")).end();
    return mav::Result::Accepted;
}

// The rudder gesture while good frames arrive, then the throttle held or live.
void FlightIo::arming_step(uint32_t now_ms) {
    const settings::VehicleSettings& v = pipe.settings().vehicle;
    if (compass.ok()) compass_found_ = true;
    const flight::State st = control_.state();
    if (st == flight::State::Manual || st == flight::State::Stabilize) {
        const flight::Gesture g = arming_.rudder(v.arming_rudder, control_.stick(flight::kYaw, now_ms),
                                                 control_.stick(flight::kThrottle, now_ms), flying(), now_ms);
        if (g == flight::Gesture::Arm) {
            arm_now(false);
        } else if (g == flight::Gesture::Disarm) {
            arming_.disarm();
            Writer(out_).str(TXT("# Throttle disarmed (rudder)")).end();
        }
    } else {
        arming_.rudder_released();
    }
    control_.set_throttle_live(arming_.throttle_live(v.arming_require));
}

bool FlightIo::armed() const { return arming_.throttle_live(pipe.settings().vehicle.arming_require); }

mav::Result FlightIo::arm_disarm(bool arm, bool force) {
    if (arm) return armed() ? mav::Result::Accepted : arm_now(force);
    if (!arming_.armed()) return mav::Result::Accepted;
    if (flying() && !force) {  // ArduPlane refuses a ground station's disarm in flight
        Writer(out_).str(TXT("# Disarm refused: flying (param2 21196 forces it)")).end();
        return mav::Result::Failed;
    }
    arming_.disarm();
    Writer(out_).str(TXT("# Throttle disarmed")).end();
    return mav::Result::Accepted;
}

// ArduPilot's words (AP_Arming), in the order of lib/Flight/Arming.h's PreArm bits.
static Flash prearm_text(uint8_t bit) {
    switch (bit) {
        case 0: return TXT("Gyros not healthy");
        case 1: return TXT("Gyros not calibrated");
        case 2: return TXT("AHRS not healthy");
        case 3: return TXT("Compass not healthy");
        case 4: return TXT("Compass not calibrated");
        case 5: return TXT("Compass calibration running");
        case 6: return TXT("Barometer not healthy");
        case 7: return TXT("RC not found");
        case 8: return TXT("Radio failsafe on");
        case 9: return TXT("Throttle too high");
        default: return TXT("Settings are defaults (EEPROM unreadable)");
    }
}
static_assert(flight::kPreArmReasons == 11, "a text for each PreArm bit");

bool FlightIo::prearm_due() const {
    return prearm_unsaid_ != 0u && serial_text::room() >= 2u * mav::kMaxFrame + gcs_link::output_line_bytes();
}

void FlightIo::say_prearm() {
    uint8_t bit = 0;
    while (((prearm_unsaid_ >> bit) & 1u) == 0u) ++bit;
    prearm_unsaid_ = (uint16_t)(prearm_unsaid_ & ~(1u << bit));
    Writer(out_).str(TXT("# PreArm: ")).str(prearm_text(bit)).end();
}

// --- The ground station's modes and sticks ------------------------------------------------

bool FlightIo::set_mode(uint32_t number) {
    if (number > 255u || !flight::mode_known((uint8_t)number)) {
        Writer(out_).str(TXT("# Mode change refused: no mode ")).u32(number).str(TXT(" on this board")).end();
        return false;
    }
    return choose_checked((flight::Mode)number);
}

static void write_mode_name(Writer& w, flight::Mode m);

// A mode chosen by the ground station or the console: refused with its reason when it
// cannot run now (NavModes), the mode before flying on.
bool FlightIo::choose_checked(flight::Mode m) {
    text::Flash why;
    if (nav_modes::refused(m, why)) {
        Writer w(out_);
        w.str(TXT("# Mode change refused: "));
        write_mode_name(w, m);
        w.str(TXT(": ")).str(why).end();
        return false;
    }
    control_.choose(m);
    print_flight_line(TXT("# flight "));
    return true;
}

// ArduPlane 3.x's long failsafe (failsafe_long_on_event): FS_LONG_TIMEOUT after the
// receiver was lost, RTL (FS_LONG_ACTN 0 or 1; AUTO, LOITER and GUIDED go on with 0, RTL goes on),
// or the failsafe glide (2: FBWA chosen, which glides until the receiver is back).
void FlightIo::long_failsafe(uint32_t now_ms) {
    const bool fs = control_.state() == flight::State::Failsafe;
    if (fs != in_failsafe_) {
        in_failsafe_ = fs;
        failsafe_since_ms_ = now_ms;
        long_failsafe_done_ = false;
    }
    const settings::NavSettings& ns = pipe.settings().vehicle.nav;
    if (!fs || long_failsafe_done_ || now_ms - failsafe_since_ms_ < (uint32_t)ns.fs_long_timeout_s * 1000u) return;
    long_failsafe_done_ = true;
    const flight::Mode m = control_.chosen();
    if (m == flight::Mode::Rtl) return;
    if (ns.fs_long_actn == settings::kFsLongGlide) {
        control_.choose(flight::Mode::FlyByWireA);
    } else if (ns.fs_long_actn == settings::kFsLongRtl ||
               (m != flight::Mode::Auto && m != flight::Mode::Loiter && m != flight::Mode::Guided)) {
        failsafe_rtl(TXT("long (FS_LONG_TIMEOUT)"));
        return;
    } else {
        return;
    }
    print_flight_line(TXT("# failsafe: long (FS_LONG_TIMEOUT), flight "));
}

flight::Mode FlightIo::nav_mode() const {
    const flight::State st = control_.state();
    if ((st == flight::State::Navigate && !control_.without_attitude()) || control_.navigating_in_failsafe())
        return control_.chosen();
    return flight::Mode::Manual;
}

int16_t FlightIo::stick(uint8_t role) const {
    return control_.state() == flight::State::Failsafe ? (int16_t)0 : control_.stick(role, millis());
}

void FlightIo::set_nav_demands(int16_t roll_cd, int16_t pitch_cd, int16_t throttle) {
    control_.set_nav_demands(roll_cd, pitch_cd, throttle);
}

void FlightIo::set_unavailable(uint16_t rows) { control_.set_unavailable(rows); }

void FlightIo::failsafe_rtl(text::Flash which) {
    if (control_.chosen() == flight::Mode::Rtl) return;
    Writer w(out_);
    w.str(TXT("# failsafe: ")).str(which);
    text::Flash why;
    if (nav_modes::refused(flight::Mode::Rtl, why)) {
        w.str(TXT(": no RTL (")).str(why).str(TXT("), mode kept")).end();
        return;
    }
    control_.choose(flight::Mode::Rtl);
    w.str(TXT(": RTL")).end();
}

void FlightIo::rc_override(const uint16_t width_us[8]) { control_.on_override(width_us, millis()); }

bool FlightIo::powered() const {
    return armed() && control_.state() != flight::State::NoSignal &&
           control_.stick(flight::kThrottle, millis()) > kIdleThrottle;
}

uint8_t FlightIo::throttle_percent() const {
    constexpr uint8_t kOut = 2;  // the mixer's throttle output, OUT3
    const flight::FlightSettings& fs = pipe.settings().flight;
    const int16_t t = flight::width_to_throttle(servo_outputs::width_us(kOut), fs.servo[kOut],
                                                (fs.servo_reversed >> kOut) & 1u);
    return (uint8_t)((t + 5) / 10);
}

// The failsafe's wings-level glide is ArduPlane's FBWA glide (MavLink.h), an attitude
// mode without an attitude flies as MANUAL.
mav::PlaneMode FlightIo::plane_mode() const {
    if (control_.state() == flight::State::Failsafe && !control_.navigating_in_failsafe())
        return mav::PlaneMode::FlyByWireA;
    if (control_.without_attitude()) return mav::PlaneMode::Manual;
    return (mav::PlaneMode)(uint8_t)control_.chosen();
}

bool FlightIo::failsafe() const { return control_.state() == flight::State::Failsafe; }

static void write_mode_name(Writer& w, flight::Mode m) {
    char name[flight::kModeNameMax + 1];
    const int8_t i = flight::mode_index((uint8_t)m);
    flight::mode_name(i >= 0 ? (uint8_t)i : 0u, name);
    w.str(name, (uint8_t)strlen(name));
}

// "<prefix>MODE, receiver ok|no signal yet|FAILSAFE (lost|encoder failsafe)"
void FlightIo::print_flight_line(Flash prefix) {
    Writer w(out_);
    w.str(prefix);
    const flight::State st = control_.state();
    if (st == flight::State::Failsafe) {
        w.str(TXT("FAILSAFE ("))
            .str(control_.failsafe_cause() == flight::FailsafeCause::Lost ? TXT("receiver lost")
                                                                           : TXT("receiver's encoder failsafe"))
            .str(TXT("), then "));
    }
    write_mode_name(w, control_.chosen());
    if (control_.without_attitude()) w.str(TXT(" (no attitude: MANUAL)"));
    if (st == flight::State::NoSignal) w.str(TXT(", no receiver signal yet: outputs at trim"));
    w.end();
}

// "# rc 1500 ..." or "# servo 1500 ...": eight widths, us.
void FlightIo::print_widths(Flash prefix, const uint16_t* widths) {
    Writer w(out_);
    w.str(prefix);
    for (uint8_t i = 0; i < flight::kChannels; ++i) w.chr(' ').u32(widths[i]);
    w.end();
}

// The flight control's events, said as "# " lines (STATUSTEXT in `mode mavlink`).
// One line a call (a control step, 50 Hz), the events in this order; the others wait. Two
// lines in one step (the STABILIZE warning's two STATUSTEXT frames and the mode's line at
// start-up) outgrew the room a parameter list leaves for a line, and the second was held
// back; one line's frames are also all a step packs (~7 700 cycles a frame).
void FlightIo::say_events() {
    unsaid_events_ = (uint8_t)(unsaid_events_ | control_.take_events());
    const uint8_t e = unsaid_events_;
    if (e == 0) return;
    uint8_t said;
    if (e & flight::kEvFailsafeLost) {
        said = flight::kEvFailsafeLost;
        if (control_.navigating_in_failsafe())
            Writer(out_).str(TXT("# failsafe: receiver lost (no PPM frame for 0.5 s): the mode goes on")).end();
        else
            Writer(out_).str(TXT("# failsafe: receiver lost (no PPM frame for 0.5 s): wings level, gliding, throttle THR_FS_OUT")).end();
    } else if (e & flight::kEvFailsafeEncoder) {
        said = flight::kEvFailsafeEncoder;
        Writer(out_).str(TXT("# failsafe: receiver's encoder failsafe (throttle below THR_FS_VALUE): wings level, gliding")).end();
    } else if (e & flight::kEvFailsafeEnd) {
        said = flight::kEvFailsafeEnd;
        print_flight_line(TXT("# failsafe cleared: receiver back, flight "));
    } else if (e & flight::kEvSensorFallback) {
        said = flight::kEvSensorFallback;
        Writer(out_).str(TXT(TXT_WARN "STABILIZE without an attitude (" TXT_MPU " or estimator): MANUAL until it returns")).end();
    } else if (e & flight::kEvAttitudeBack) {
        said = flight::kEvAttitudeBack;
        Writer(out_).str(TXT("# attitude back: flight STABILIZE")).end();
    } else if (e & flight::kEvModeChanged) {
        said = flight::kEvModeChanged;
        print_flight_line(TXT("# flight "));
    } else if (e & flight::kEvModeRefused) {
        said = flight::kEvModeRefused;
        text::Flash why;
        if (!nav_modes::refused(control_.refused_mode(), why)) why = TXT("not available");
        Writer w(out_);
        w.str(TXT("# Mode change refused (switch): "));
        write_mode_name(w, control_.refused_mode());
        w.str(TXT(": ")).str(why).end();
    } else {
        said = e;  // no line of its own
    }
    unsaid_events_ = (uint8_t)(unsaid_events_ & ~said);
}

bool FlightIo::print_status_line() {
    print_flight_line(armed() ? TXT("# armed, flight ") : TXT("# disarmed, flight "));
    return true;
}

void FlightIo::answer(const console::Command& c) {
    if (c.id == console::CommandId::Flight && (c.arg == console::kArm || c.arg == console::kDisarm)) {
        const bool was = armed();
        const bool arm = c.arg == console::kArm;
        if (arm_disarm(arm, false) == mav::Result::Accepted && was == arm)
            Writer(out_).str(arm ? TXT("# Throttle already armed") : TXT("# Throttle already disarmed")).end();
    } else if (c.id == console::CommandId::Flight) {
        choose_checked((flight::Mode)flight::mode_number(c.arg));
    } else if (c.arg == console::kShowRc) {
        uint16_t widths[flight::kChannels];
        const uint32_t now_ms = millis();
        for (uint8_t i = 0; i < flight::kChannels; ++i) widths[i] = control_.input_us(i, now_ms);
        print_widths(TXT("# rc"), widths);
    } else {
        uint16_t widths[flight::kChannels];
        for (uint8_t i = 0; i < flight::kChannels; ++i) widths[i] = servo_outputs::width_us(i);
        print_widths(TXT("# servo"), widths);
    }
}

uint8_t FlightIo::rc_channels(mav::Packer& mavlink, uint8_t* frame, uint32_t now_ms) const {
    const bool signal =
        control_.state() != flight::State::NoSignal && control_.failsafe_cause() != flight::FailsafeCause::Lost;
    uint16_t widths[flight::kChannels];  // as flown: the overrides in force, else the receiver's
    for (uint8_t i = 0; i < flight::kChannels; ++i) widths[i] = control_.input_us(i, now_ms);
    return mavlink.rc_channels(frame, now_ms, widths, signal ? flight::kChannels : 0u);
}

uint8_t FlightIo::servo_output_raw(mav::Packer& mavlink, uint8_t* frame, uint32_t now_us) const {
    uint16_t widths[flight::kChannels];
    for (uint8_t i = 0; i < flight::kChannels; ++i) widths[i] = servo_outputs::width_us(i);
    return mavlink.servo_output_raw(frame, now_us, widths);
}

#else  // the attitude-only build: nothing to fly

void FlightIo::begin() {}
void FlightIo::loop_starts(uint32_t) {}
void FlightIo::configure() {}
void FlightIo::poll(uint32_t, uint32_t) {}
bool FlightIo::control_due(bool) { return false; }
void FlightIo::control_run(uint32_t, uint32_t, const mpu6000::Sample&, const pipeline::AnglesCentideg*) {}
bool FlightIo::powered() const { return false; }
uint8_t FlightIo::throttle_percent() const { return 0; }
mav::PlaneMode FlightIo::plane_mode() const { return mav::PlaneMode::Manual; }
bool FlightIo::failsafe() const { return false; }
bool FlightIo::armed() const { return true; }
mav::Result FlightIo::arm_disarm(bool, bool) { return mav::Result::Unsupported; }
bool FlightIo::set_mode(uint32_t) { return false; }
flight::Mode FlightIo::nav_mode() const { return flight::Mode::Manual; }
int16_t FlightIo::stick(uint8_t) const { return 0; }
void FlightIo::set_nav_demands(int16_t, int16_t, int16_t) {}
void FlightIo::set_unavailable(uint16_t) {}
void FlightIo::failsafe_rtl(text::Flash) {}
void FlightIo::rc_override(const uint16_t*) {}
bool FlightIo::prearm_due() const { return false; }
uint16_t FlightIo::prearm_failures() const { return 0; }
void FlightIo::say_prearm() {}
bool FlightIo::print_status_line() { return false; }
void FlightIo::answer(const console::Command&) {
    text::Writer(out_).str(TXT("# error: this build has no flight features (README \"Builds\"); nothing changed")).end();
}
uint8_t FlightIo::rc_channels(mav::Packer&, uint8_t*, uint32_t) const { return 0; }
uint8_t FlightIo::servo_output_raw(mav::Packer&, uint8_t*, uint32_t) const { return 0; }

#endif
