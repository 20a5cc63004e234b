// SPDX-License-Identifier: GPL-3.0-or-later
// The navigation's stored settings (lib/Settings' NavSettings, in the second EEPROM record)
// as the float parameters lib/Nav's L1Control and Tecs and the MissionExecutor hold
// references to (those live in RAM beside the objects; a change of a row calls
// nav_params() again, then Tecs::set_params()). Here, not in lib/Settings: the settings
// know no navigation library, the mission's store uses the settings' CRC.
#pragma once

#include "FlightSettings.h"
#include "L1Control.h"
#include "MissionExecutor.h"
#include "NavSettings.h"
#include "Tecs.h"

namespace mission {

// The float parameters of L1, TECS (with LIM_PITCH_*, ARSPD_FBW_* from the flight
// settings) and the executor, from the stored ones.
void nav_params(const settings::NavSettings& n, const flight::FlightSettings& f, nav::L1Params& l1,
                nav::TecsParams& tecs, ExecutorParams& ex);

}  // namespace mission
