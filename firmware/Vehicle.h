// SPDX-License-Identifier: GPL-3.0-or-later
// The vehicle's parts, one object each (as ArduPlane's `plane`): the attitude pipeline,
// the sensors, the settings store and the flight features, and the "# " message sink
// that everything says its lines through. Defined in Vehicle.cpp; setup() brings them
// up and the task table (firmware.ino) runs them.
#pragma once

#include <stdint.h>

#include "Compass.h"
#include "FlightIo.h"
#include "Imu.h"
#include "Mpu6000.h"
#include "Pipeline.h"
#include "SettingsStore.h"
#include "Text.h"

namespace vehicle {

// Every "# " message: to the serial port as text, or, while the port speaks MAVLink, as
// STATUSTEXT frames (Port.h).
extern const text::Sink* const out;
extern pipeline::AttitudePipeline pipe;
extern Imu imu;
extern Compass compass;
extern SettingsStore store;
extern FlightIo flight_io;

// The sample being worked on, for the sample tasks (the task table runs them in order).
struct Tick {
    uint32_t now_us;  // when its data-ready was seen
    uint32_t now_ms;
    mpu6000::Sample sample;
    bool output;       // an output line was due on this sample
    bool have_angles;  // the line worked out `angles` (the control step takes them)
    pipeline::AnglesCentideg angles;
};
extern Tick tick;

void say(text::Flash text);
// The LEDs from the pipeline's phase and the sensors' health.
void update_leds();

}  // namespace vehicle
