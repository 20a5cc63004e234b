// SPDX-License-Identifier: GPL-3.0-or-later
// The flight features as the sketch sees them (README "Flying"): the receiver (RcInput)
// and the attitude go through lib/Flight's modes, controllers and mixer to the eight
// servo outputs (ServoOutputs), 50 times a second, and this says so on the console and
// the ground station link. In the attitude-only build (Features.h: APM25_FLIGHT 0) the
// same calls do nothing, the `flight`, `rc` and `servo` commands answer an error, and
// none of those parts is in the firmware.
//
// It flies the vehicle's pipeline and IMU (Vehicle.h), named rather than held as
// references: the compiler then knows where they are and keeps the attitude's code
// specialised for them.
#pragma once

#include <stdint.h>

#include "Console.h"
#include "Features.h"
#include "FlightSettings.h"
#include "Imu.h"
#include "MavLink.h"
#include "Mpu6000.h"
#include "Pipeline.h"
#include "Text.h"
#if APM25_FLIGHT
#include "Arming.h"
#include "Flight.h"
#include "Ppm.h"
#endif

class FlightIo {
public:
    static constexpr bool kEnabled = APM25_FLIGHT != 0;

    // constexpr: the static object needs no start-up code. `settings`: the pipeline's
    // (its flight part), kept by reference; configure() works them out after setup()'s load.
#if APM25_FLIGHT
    constexpr FlightIo(const text::Sink* out, const flight::FlightSettings& settings)
        : out_(out), control_(settings, flight::FlightControl::ConfiguredLater{}) {}
#else
    constexpr FlightIo(const text::Sink* out, const flight::FlightSettings&) : out_(out) {}
#endif

    // In setup(), once the settings are loaded: the outputs at trim and the throttle at
    // its failsafe value until the receiver's first frame, then the receiver.
    void begin();
    // Just before the first loop(): the control step's clock starts.
    void loop_starts(uint32_t now_us);
    // The flight settings changed (`set`, `defaults`).
    void configure();
    // Every loop(): the receiver's frames; without samples (the MPU6000 gone) the
    // control step on its own every 20 ms, without an attitude.
    void poll(uint32_t now_us, uint32_t now_ms);
    // Sample task (counts the samples): the control step is due every kControlDivider
    // samples (50 Hz, the servo frame), on the output line's sample when the line rate is
    // 50 Hz or less (to take the angles the line worked out), never on the estimator's
    // start (its long steps).
    bool control_due(bool output_line);
    // Sample task: the control step on this sample (its angles, if the line has them).
    void control_run(uint32_t now_us, uint32_t now_ms, const mpu6000::Sample& sample,
                     const pipeline::AnglesCentideg* angles);

    // The receiver's throttle above idle: the aeroplane flies at its cruise speed.
    bool powered() const;
    // The throttle output (OUT3) between its SERVO3_MIN and _MAX, percent (VFR_HUD).
    uint8_t throttle_percent() const;
    // The mode flying now as ArduPlane numbers it (HEARTBEAT custom_mode), and whether it
    // is the failsafe (HEARTBEAT's state CRITICAL).
    mav::PlaneMode plane_mode() const;
    bool failsafe() const;

    // The throttle armed (lib/Flight/Arming.h; always with ARMING_REQUIRE 0): HEARTBEAT's
    // MAV_MODE_FLAG_SAFETY_ARMED. The attitude-only build drives no throttle: armed.
    bool armed() const;
    // MAV_CMD_COMPONENT_ARM_DISARM: arm (the pre-arm checks first, skipped when forced)
    // or disarm (refused while flying unless forced). Already so: ACCEPTED. A refusal's
    // reasons follow as "# PreArm: ..." lines (prearm_due/say_prearm).
    mav::Result arm_disarm(bool arm, bool force);
    // SET_MODE and MAV_CMD_DO_SET_MODE: a mode of lib/Flight/Modes.h by ArduPlane's
    // number, held until the mode switch next moves; false (and a line saying so) for a
    // number the board does not have.
    bool set_mode(uint32_t number);
    // The navigation modes (NavModes.h): the navigation mode flying now (its bank, pitch and
    // throttle are set_nav_demands'), or Mode::Manual when none is; a stick by role.
    flight::Mode nav_mode() const;
    int16_t stick(uint8_t role) const;
    void set_nav_demands(int16_t roll_cd, int16_t pitch_cd, int16_t throttle);
    void set_unavailable(uint16_t rows);
    // A failsafe's RTL (`which`: the battery's, ArduPlane's low_battery_event; the long
    // one): RTL chosen and said ("# failsafe: <which>: RTL"), or, when it cannot run, the
    // mode kept and the reason said.
    void failsafe_rtl(text::Flash which);
    // RC_CHANNELS_OVERRIDE's channels 1-8 (FlightControl::on_override).
    void rc_override(const uint16_t width_us[8]);
    // The pre-arm checks' failures now (lib/Flight/Arming.h's PreArm bits; 0: may arm):
    // SYS_STATUS's MAV_SYS_STATUS_PREARM_CHECK healthy bit is prearm_failures() == 0.
    uint16_t prearm_failures() const;
    // Loop task: one "# PreArm: <reason>" line of the last refused arming a run, when the
    // output has room (a refusal can have several; each goes out as one STATUSTEXT).
    bool prearm_due() const;
    void say_prearm();

    // `status`'s flight line: false (no line) without the flight features.
    bool print_status_line();
    // `flight MODE`, `arm`, `disarm`, `rc`, `servo`.
    void answer(const console::Command& c);
    // The ground station's RC_CHANNELS and SERVO_OUTPUT_RAW frames (kEnabled only).
    uint8_t rc_channels(mav::Packer& mavlink, uint8_t* frame, uint32_t now_ms) const;
    uint8_t servo_output_raw(mav::Packer& mavlink, uint8_t* frame, uint32_t now_us) const;

private:
    const text::Sink* out_;
#if APM25_FLIGHT
    void print_flight_line(text::Flash prefix);
    void print_widths(text::Flash prefix, const uint16_t* widths);
    void say_events();
    void control_step(uint32_t now_us, uint32_t now_ms, const mpu6000::Sample* sample,
                      const pipeline::AnglesCentideg* angles);

    void arming_step(uint32_t now_ms);
    mav::Result arm_now(bool force);
    bool flying() const;
    bool choose_checked(flight::Mode m);
    void long_failsafe(uint32_t now_ms);

    flight::PpmDecoder ppm_;
    flight::FlightControl control_;
    flight::Arming arming_;
    uint16_t prearm_unsaid_ = 0;  // PreArm bits still to say
    uint8_t unsaid_events_ = 0;   // flight::Event bits taken, still to say (say_events: a line a step)
    uint32_t failsafe_since_ms_ = 0;
    bool in_failsafe_ = false;
    bool long_failsafe_done_ = false;  // FS_LONG_ACTN acted on in this failsafe
    bool compass_found_ = false;  // the HMC5883L answered since power-up: its heading is used
    uint8_t control_count_ = 0;
    uint32_t last_control_us_ = 0;
    // The gyro bias in the control's rate units, worked out again once a second.
    int16_t bias_cds_[2] = {0, 0};
    uint8_t bias_age_ = 49;  // the first step with an attitude works it out (0xFF wrapped to 0: a second late)
#endif
};
