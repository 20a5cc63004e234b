// SPDX-License-Identifier: GPL-3.0-or-later
// What this build of the firmware has (README "Builds").
//
// APM25_FLIGHT 1, the default: the attitude and the flight features, the receiver's PPM
// (RcInput), lib/Flight's modes, controllers and mixer and the eight servo outputs
// (ServoOutputs), glued to the sketch by FlightIo. 0: the attitude-only build, the same
// firmware without them (`make FLIGHT=0`, `pio run -e attitude_only`, or the 0 written
// here for the Arduino IDE). Both read and write the same settings record: the flight
// settings stay in it (and in `params`, `get`, `set` and the ground station's
// parameters) whichever build saved it.
#pragma once

#ifndef APM25_FLIGHT
#define APM25_FLIGHT 1
#endif
