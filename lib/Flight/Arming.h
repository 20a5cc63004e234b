// SPDX-License-Identifier: GPL-3.0-or-later
// Arming, as ArduPlane's (AP_Arming, ArduPlane's rudder_arm_disarm_check): with
// ARMING_REQUIRE 1 the throttle output holds its minimum until the board is armed, the
// surfaces stay live; the board is disarmed at every power-up. It is armed by the rudder
// stick (full right, the throttle at zero, for 3 s), a ground station's
// MAV_CMD_COMPONENT_ARM_DISARM or the console's `arm`, each only when the pre-arm checks
// pass (ARMING_CHECK), or forced (param2 21196). Disarmed by the command, `disarm`, or
// with ARMING_RUDDER 2 the rudder full left for 3 s, the throttle at zero.
//
// Pure C++: the caller supplies the time, the sticks and the sensors' state.
#pragma once

#include <stdint.h>

namespace flight {

// ARMING_CHECK's bits (ArduPilot's AP_Arming::ArmingChecks): 1 all, else the ones set.
enum CheckBit : uint16_t {
    kCheckAll = 1u,
    kCheckBaro = 2u,
    kCheckCompass = 4u,
    kCheckGps = 8u,          // no mode here needs a position: nothing checked yet
    kCheckIns = 16u,
    kCheckParameters = 32u,
    kCheckRc = 64u,
};

// ARMING_RUDDER (AP_Arming's ArmingRudder).
enum RudderArming : uint8_t { kRudderDisabled = 0, kRudderArmOnly = 1, kRudderArmDisarm = 2 };

// The reasons a pre-arm check fails: bits of prearm_failures(), the check bit each
// belongs to in the comment, the text (ArduPilot's words after "PreArm: ") in the firmware.
enum PreArm : uint16_t {
    kPreArmGyrosNotHealthy = 1u << 0,      // INS: the MPU6000 does not answer
    kPreArmGyrosNotCalibrated = 1u << 1,   // INS: the gyro bias is being measured (start-up, `cal gyro`)
    kPreArmAhrsNotHealthy = 1u << 2,       // INS: the estimator is not running or not finite
    kPreArmCompassNotHealthy = 1u << 3,    // COMPASS: found at start-up, not answering now
    kPreArmCompassNotCalibrated = 1u << 4, // COMPASS: used, no calibration and not learning
    kPreArmCompassCalibrating = 1u << 5,   // COMPASS: `cal mag` running
    kPreArmBaroNotHealthy = 1u << 6,       // BARO: the MS5611 found, not healthy now
    kPreArmRcNotFound = 1u << 7,           // RC: no receiver frame since power-up
    kPreArmRadioFailsafe = 1u << 8,        // RC: FAILSAFE (receiver lost, or its encoder's failsafe)
    kPreArmThrottleHigh = 1u << 9,         // RC: the throttle stick not at zero
    kPreArmSettingsNotLoaded = 1u << 10,   // PARAMETERS: running on defaults after an unreadable record
};
constexpr uint8_t kPreArmReasons = 11;

struct PreArmInputs {
    bool imu_ok;               // the MPU6000 answers
    bool gyro_calibrating;     // the gyro bias is being measured
    bool estimator_ok;         // the estimator runs and its angles are finite
    bool compass_used;         // the HMC5883L was found at start-up (its heading is used)
    bool compass_ok;
    bool compass_calibrated;   // `cal mag` accepted, or the offset is learned in motion
    bool compass_calibrating;  // `cal mag` running
    bool baro_present;
    bool baro_ok;
    bool rc_seen;              // a receiver frame since power-up
    bool rc_failsafe;          // FAILSAFE now
    bool throttle_low;         // the throttle stick at zero (throttle_at_zero)
    bool settings_loaded;      // the settings were read (or the EEPROM blank: a new board), or saved since
};

// The reasons the checks ARMING_CHECK asks for fail (PreArm bits; 0: the board may arm).
uint16_t prearm_failures(const PreArmInputs& in, uint16_t arming_check);

// The throttle stick (0..1000, tenths of a percent) at zero: within 3 % of its low end,
// ArduPlane's 30 us dead zone (RC3_DZ) on a 1000 us throttle.
constexpr int16_t kThrottleZero = 30;
inline bool throttle_at_zero(int16_t throttle) { return throttle <= kThrottleZero; }

// The rudder gesture: full rudder is beyond 4000 of 4500 cd (89 % of its throw), held
// kGestureMs with the throttle at zero (ArduPlane's rudder_arm_disarm_check).
constexpr int16_t kGestureRudder_cd = 4000;
constexpr uint16_t kGestureMs = 3000;
enum class Gesture : uint8_t { None, Arm, Disarm };

class Arming {
public:
    bool armed() const { return armed_; }
    // The throttle follows the stick (ARMING_REQUIRE 0, or armed).
    bool throttle_live(uint8_t arming_require) const { return arming_require == 0u || armed_; }
    void arm() { armed_ = true; gesture_ms_ = 0; timing_ = false; }
    void disarm() { armed_ = false; gesture_ms_ = 0; timing_ = false; }

    // Every control step while good receiver frames arrive (not in FAILSAFE): the rudder
    // (-4500..4500, + right) and the throttle (0..1000) sticks. Returns Arm once the
    // rudder has been full right for kGestureMs while disarmed, Disarm once full left
    // while armed (ARMING_RUDDER 2, not flying); the caller arms (the checks) or disarms.
    // Any other input starts the gesture again.
    Gesture rudder(uint8_t arming_rudder, int16_t rudder_cd, int16_t throttle, bool flying, uint32_t now_ms);
    // The gesture's timer stops (no receiver, FAILSAFE).
    void rudder_released() { timing_ = false; }

private:
    uint32_t gesture_ms_ = 0;  // when the stick reached full rudder
    bool timing_ = false;
    bool armed_ = false;       // always disarmed at power-up
};

}  // namespace flight
