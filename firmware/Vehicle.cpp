// SPDX-License-Identifier: GPL-3.0-or-later
#include "Vehicle.h"

#include "Board.h"
#include "GcsLink.h"
#include "Port.h"
#include "PipelineText.h"

namespace vehicle {

static const text::Sink message_sink = {nullptr, port::write_message};
const text::Sink* const out = &message_sink;
// Each event's line; a calibration's good verdict also tells the ground station the
// parameters it wrote.
static void tell(void* out, const pipeline::AttitudePipeline& p, const pipeline::Event& e) {
    pipeline_text::write_event(out, p, e);
    gcs_link::announce_calibration(p, e);
}
static const pipeline::EventSink pipeline_events = {const_cast<text::Sink*>(&message_sink), tell};
pipeline::AttitudePipeline pipe(&pipeline_events, pipeline::AttitudePipeline::SettingsLoadedLater{});
Imu imu(board::kSpi, out);
Compass compass(board::kI2c, out, pipe);
SettingsStore store(out);
FlightIo flight_io(out, pipeline::AttitudePipeline::settings_of(pipe).flight);
Tick tick = {};  // zeros at compile time (default-initialised, its vectors' constructors ran at start-up)

void say(text::Flash text) { text::Writer(out).str(text).end(); }

void update_leds() {
    const pipeline::Phase ph = pipe.phase();
    board::set_leds(ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating(),
                    imu.ok() && ph == pipeline::Phase::Running, !imu.ok() || !compass.ok());
}

}  // namespace vehicle
