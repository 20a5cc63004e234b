// SPDX-License-Identifier: GPL-3.0-or-later
#include "Vehicle.h"

#include "Board.h"
#include "Port.h"
#include "PipelineText.h"

namespace vehicle {

static const text::Sink message_sink = {nullptr, port::write_message};
const text::Sink* const out = &message_sink;
static const pipeline::EventSink pipeline_events = pipeline_text::events_to(&message_sink);
pipeline::AttitudePipeline pipe(&pipeline_events, pipeline::AttitudePipeline::SettingsLoadedLater{});
Imu imu(board::kSpi, out);
Compass compass(board::kI2c, out, pipe);
SettingsStore store(out);
FlightIo flight_io(out);
Tick tick;

void say(text::Flash text) { text::Writer(out).str(text).end(); }

void update_leds() {
    const pipeline::Phase ph = pipe.phase();
    board::set_leds(ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating(),
                    imu.ok() && ph == pipeline::Phase::Running, !imu.ok() || !compass.ok());
}

}  // namespace vehicle
