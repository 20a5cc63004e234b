// SPDX-License-Identifier: GPL-3.0-or-later
// The words of the AttitudePipeline's numbers: its events as "# " lines, and the gyro
// bias and compass lines of `status`. The pipeline itself only returns numbers
// (pipeline::Event, its accessors); the sketch, and the host replay tool's --log, word
// them here, so both say the same.
//
//   const pipeline::EventSink events = pipeline_text::events_to(&text_sink);
//   pipeline::AttitudePipeline pipe(&events);
#pragma once

#include "Pipeline.h"
#include "Text.h"

namespace pipeline_text {

// An event's line on out (a text::Sink*, as the EventSink's context).
void write_event(void* out, const pipeline::AttitudePipeline& pipe, const pipeline::Event& e);

// An EventSink that writes each event's line on out.
constexpr pipeline::EventSink events_to(const text::Sink* out) {
    return pipeline::EventSink{const_cast<text::Sink*>(out), write_event};
}

// `status`: "# gyro bias x y z deg/s, temperature T C" (the calibrated bias plus the
// estimator's).
void write_bias_status(const text::Sink* out, const pipeline::AttitudePipeline& pipe);
// `status`: "# compass: cal yes|none, learned offset x y z uT (n updates)".
void write_compass_status(const text::Sink* out, const pipeline::AttitudePipeline& pipe);

}  // namespace pipeline_text
