// SPDX-License-Identifier: GPL-3.0-or-later
#include "Arming.h"

namespace flight {

uint16_t prearm_failures(const PreArmInputs& in, uint16_t arming_check) {
    const bool all = (arming_check & kCheckAll) != 0u;
    const auto on = [&](uint16_t bit) { return all || (arming_check & bit) != 0u; };
    uint16_t f = 0;
    // One reason per sensor, the first that applies (AP_Arming's order within a check).
    if (on(kCheckIns)) {
        if (!in.imu_ok) f |= kPreArmGyrosNotHealthy;
        else if (in.gyro_calibrating) f |= kPreArmGyrosNotCalibrated;
        else if (!in.estimator_ok) f |= kPreArmAhrsNotHealthy;
    }
    if (on(kCheckCompass) && in.compass_used) {
        if (!in.compass_ok) f |= kPreArmCompassNotHealthy;
        else if (in.compass_calibrating) f |= kPreArmCompassCalibrating;
        else if (!in.compass_calibrated) f |= kPreArmCompassNotCalibrated;
    }
    if (on(kCheckBaro) && in.baro_present && !in.baro_ok) f |= kPreArmBaroNotHealthy;
    if (on(kCheckRc)) {
        if (!in.rc_seen) f |= kPreArmRcNotFound;
        else if (in.rc_failsafe) f |= kPreArmRadioFailsafe;
        else if (!in.throttle_low) f |= kPreArmThrottleHigh;
    }
    if (on(kCheckParameters) && !in.settings_loaded) f |= kPreArmSettingsNotLoaded;
    return f;
}

Gesture Arming::rudder(uint8_t arming_rudder, int16_t rudder_cd, int16_t throttle, bool flying, uint32_t now_ms) {
    const bool to_arm = !armed_ && rudder_cd > kGestureRudder_cd;
    // Disarming by the rudder only where ArduPlane allows it: ARMING_RUDDER 2, on the ground.
    const bool to_disarm = armed_ && arming_rudder == kRudderArmDisarm && !flying && rudder_cd < -kGestureRudder_cd;
    if (arming_rudder == kRudderDisabled || !throttle_at_zero(throttle) || !(to_arm || to_disarm)) {
        timing_ = false;
        return Gesture::None;
    }
    if (!timing_) {
        timing_ = true;
        gesture_ms_ = now_ms;
        return Gesture::None;
    }
    if (now_ms - gesture_ms_ < kGestureMs) return Gesture::None;
    timing_ = false;  // a refused arming starts the gesture again (another 3 s)
    return to_arm ? Gesture::Arm : Gesture::Disarm;
}

}  // namespace flight
