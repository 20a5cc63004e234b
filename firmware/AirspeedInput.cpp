// SPDX-License-Identifier: GPL-3.0-or-later
#include "AirspeedInput.h"

#include "Adc.h"
#include "Airspeed.h"
#include "ArduinoCore.h"
#include "Vehicle.h"

namespace airspeed_input {

using vehicle::pipe;

constexpr uint8_t kReadings = 8;
static State state_ = State::kZero;
static bool started = false;
static uint16_t n = 0;
static uint32_t sum = 0;

State state() { return state_; }

// What the start made of the pitot (but a zero kept as saved: nothing to say).
static void say_start(airspeed::StartZero z, uint16_t offset) {
    using airspeed::StartZero;
    const uint16_t trim_cm_s = pipe.settings().flight.trim_arspd_cm;
    text::Writer w(vehicle::out);
    w.str(TXT("# airspeed: "));
    if (z == StartZero::kSave) {
        w.str(TXT("new zero "));
    } else if (z == StartZero::kNone) {
        w.str(TXT("no sensor on A0: "));
    } else {
        w.str(TXT("the board was moving at start (a restart in flight?): "));
        w.str(z == StartZero::kSaved ? TXT("the saved zero ") : TXT("no pitot zero taken, "));
    }
    if (z == StartZero::kSave || z == StartZero::kSaved) {
        w.str(TXT("ARSPD_OFFSET ")).u32(offset);
        if (z == StartZero::kSaved) w.str(TXT(" used"));
    } else if (trim_cm_s == 0u) {
        w.str(TXT("TRIM_ARSPD_CM 0, no turn correction (sustained turns spiral down)"));
    } else {
        w.str(TXT("cruise speed TRIM_ARSPD_CM ")).fixed2((float)trim_cm_s * 0.01f).str(TXT(" m/s assumed"));
    }
    w.end();
}

void begin() { adc::begin(); }

void step() {
    // A0's reading when its conversion is over, and the ADC's next (a battery pin's turn:
    // Adc.h), with or without a sensor.
    uint16_t counts = 0;
    const bool converted = adc::take_a0(counts);
    if (state_ == State::kNone) {
        // No sensor: the configured cruise speed (TRIM_ARSPD_CM, grown in a banked turn as
        // the lift needs), only while the receiver's throttle is above idle (FlightIo).
        const flight::FlightSettings& fs = pipe.settings().flight;
        if (fs.trim_arspd_cm == 0u || pipe.steps() % kReadings != 0u) return;
        pipe.set_cruise_airspeed_m_s(vehicle::flight_io.powered() ? (float)fs.trim_arspd_cm * 0.01f : 0.0f);
        return;
    }
    if (!converted) return;
    if (!started) {  // the first conversion is the ADC's longer first one: not used
        started = true;
        return;
    }
    sum += counts;
    ++n;
    // The zero in use is ARSPD_OFFSET (the settings: no copy in RAM).
    uint16_t& zero = pipe.settings().vehicle.arspd_offset;
    if (state_ == State::kZero) {
        if (pipe.phase() != pipeline::Phase::Running || n < kReadings) return;
        // A zero is what the pitot reads in still air, so only a board the start's gyro
        // calibration found still measures one: one that never was (it starts measuring on,
        // pipe.gyro_calibrating()) may be flying, and takes the zero an earlier still start
        // saved, or flies on the cruise speed (airspeed::start_zero).
        const uint16_t measured = airspeed::offset_of(sum, n);
        const airspeed::StartZero z = airspeed::start_zero(measured, !pipe.gyro_calibrating(), zero);
        state_ = z <= airspeed::StartZero::kSaved ? State::kSensor : State::kNone;
        if (z == airspeed::StartZero::kSave) {
            zero = measured;
            // Saved as `save` does (a save under way takes it in), unless the settings are a
            // bad record's defaults: those are not to replace the user's record.
            if (vehicle::store.settings_loaded() && !vehicle::store.busy()) vehicle::store.start_save(pipe.settings());
        }
        if (z != airspeed::StartZero::kKeep) say_start(z, zero);
    } else if (n >= kReadings) {
        pipe.set_airspeed_m_s(airspeed::airspeed_m_s(sum, (uint8_t)n, zero));
    } else {
        return;
    }
    sum = 0;
    n = 0;
}

}  // namespace airspeed_input
