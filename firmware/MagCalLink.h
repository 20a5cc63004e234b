// SPDX-License-Identifier: GPL-3.0-or-later
// The ground station's compass calibration, as ArduPilot's AP_Compass answers it
// (MAVProxy's `magcal start|accept|cancel`, Mission Planner's onboard calibration):
//
//   MAV_CMD_DO_START_MAG_CAL   `cal mag` started; param3 autosave: the result is used and
//                              saved when the fit succeeds, else it waits for ACCEPT
//   MAG_CAL_PROGRESS           at 2 Hz while it runs: completion %, status, the cells seen
//   MAG_CAL_REPORT             once at its end: SUCCESS or FAILED, COMPASS_OFS_*, _DIA_*,
//                              _ODI_* of the fit, its fitness (mGauss), autosaved
//   MAV_CMD_DO_ACCEPT_MAG_CAL  the result waiting put in use and saved
//   MAV_CMD_DO_CANCEL_MAG_CAL  the run stopped, or the result waiting dropped: the
//                              calibration in use stays
//
// PREFLIGHT_CALIBRATION's compass (param2 1) is DO_START_MAG_CAL with autosave. A
// PARAM_SET (or `set`) of a COMPASS_OFS/DIA/ODI row is a calibration in use at once.
#pragma once

#include <stdint.h>

#include "MavLink.h"

namespace mag_cal_link {

// A command this module answers (START, ACCEPT, CANCEL).
bool handles(uint16_t command);
// Its COMMAND_ACK result.
mav::Result command(const mav::CommandLong& c);
// Starts a calibration that the ground station hears of (PROGRESS, REPORT), in the task's
// next pass; autosave: the result used and saved when good. Accepted, or
// TemporarilyRejected while the estimator starts or the gyro calibrates, Failed without a
// compass.
mav::Result start(bool autosave);
// In the gcs_position task's runs (GcsLink): the run started, then one MAG_CAL_PROGRESS
// every 500 ms while it goes on, then its MAG_CAL_REPORT (and the save, with autosave).
bool due();
void send();
// A parameter changed (PARAM_SET, `set`): a compass calibration row's new value is the
// calibration in use, as after `cal mag`.
void parameter_changed(uint16_t index);

}  // namespace mag_cal_link
