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
static uint16_t zero = 0;
static uint16_t n = 0;
static uint32_t sum = 0;

State state() { return state_; }

// What a board without the pitot flies on: the cruise speed, or no turn correction.
static void say_no_sensor(bool moving) {
    const uint16_t trim_cm_s = pipe.settings().flight.trim_arspd_cm;
    text::Writer w(vehicle::out);
    if (moving)
        w.str(TXT("# airspeed: the board was moving at start (a restart in flight?): no pitot zero taken, "));
    else
        w.str(TXT("# airspeed: no sensor on A0: "));
    if (trim_cm_s == 0u)
        w.str(TXT("TRIM_ARSPD_CM 0, no turn correction (sustained turns spiral down)"));
    else
        w.str(TXT("cruise speed TRIM_ARSPD_CM ")).fixed2((float)trim_cm_s * 0.01f).str(TXT(" m/s assumed"));
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
    if (state_ == State::kZero) {
        if (pipe.phase() != pipeline::Phase::Running || n < kReadings) return;
        zero = (uint16_t)(sum / n);
        // A zero is what the pitot reads in still air, so only a board the start's gyro
        // calibration found still gives one: one that never was (it starts measuring on,
        // pipe.gyro_calibrating()) may be flying, and its zero would be the flight's dynamic
        // pressure, within the sensor's offset tolerance at cruise (0.2 kPa at 18 m/s) and
        // reading every airspeed as none. It flies on the cruise speed instead, as without one.
        const bool moving = pipe.gyro_calibrating();
        state_ = airspeed::present(zero) && !moving ? State::kSensor : State::kNone;
        if (state_ == State::kNone) say_no_sensor(moving && airspeed::present(zero));
    } else if (n >= kReadings) {
        pipe.set_airspeed_m_s(airspeed::airspeed_m_s(sum, (uint8_t)n, zero));
    } else {
        return;
    }
    sum = 0;
    n = 0;
}

}  // namespace airspeed_input
