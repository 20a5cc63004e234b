// SPDX-License-Identifier: GPL-3.0-or-later
#include "Position.h"

#include "AirspeedInput.h"
#include "ArduinoCore.h"
#include "Baro.h"
#include "Constants.h"
#include "GcsLink.h"
#include "GpsPort.h"
#include "SerialText.h"
#include "Vehicle.h"

namespace position {

using text::Writer;
using vehicle::pipe;

nav::Navigator nav_;
static nav::WindEstimator wind_;
static uint16_t last_fix_count = 0;
static uint32_t last_run_ms = 0;
static uint32_t last_wind_fix_ms = 0;
// Home's line waits for room in the output queue (a write into a full queue would wait
// for the UART, past the next sample): the satellites and hDOP of the fix that set it.
static bool home_line_pending = false;
static bool home_from_gps = false;
static uint8_t home_sats = 0;
static uint16_t home_hdop_cm = 0;

const nav::WindEstimator& wind() { return wind_; }
uint8_t home_changes() { return nav_.home_changes(); }

static nav::BaroReading baro_now() { return nav::BaroReading{baro::healthy(), baro::height_m()}; }

// Room for the line (two STATUSTEXT frames in MAVLink, 90 characters as text) and an
// output line after it.
static bool room_for_line() { return serial_text::room() >= 2u * mav::kMaxFrame + gcs_link::output_line_bytes(); }

bool due() {
    return gps_port::fix_count() != last_fix_count || millis() - last_run_ms >= kPeriodMs ||
           (home_line_pending && room_for_line());
}

static void say_home() {
    home_line_pending = false;
    const nav::Location& h = nav_.home();
    Writer w(vehicle::out);
    w.str(TXT("# home: set at ")).degrees_e7(h.lat_e7).chr(' ').degrees_e7(h.lon_e7).str(TXT(", "))
        .fixed2((float)h.alt_cm * 0.01f).str(TXT(" m ("));
    if (home_from_gps) {
        w.u32(home_sats).str(TXT(" satellites, hdop ")).fixed2((float)home_hdop_cm * 0.01f);
    } else {
        w.str(TXT("ground station"));
    }
    w.str(TXT(")")).end();
}

// The pitot's airspeed (the estimator's), made true by the barometer's air density.
static float true_airspeed_m_s() {
    const float eas_to_tas = baro::healthy() ? nav::eas_to_tas(baro::pressure_pa(), baro::temperature_c()) : 1.0f;
    return pipe.airspeed_m_s() * eas_to_tas;
}

static void learn_wind(const gps::Fix& fix) {
    const uint32_t dt_ms = fix.received_ms - last_wind_fix_ms;
    last_wind_fix_ms = fix.received_ms;
    if (airspeed_input::state() != airspeed_input::State::kSensor || fix.fix != gps::FixType::k3D ||
        pipe.phase() != pipeline::Phase::Running || dt_ms > 2000u)
        return;
    const pipeline::AnglesCentideg a = pipe.angles_centideg();
    constexpr float kRadPerCentideg = linalg::kRadPerDeg * 0.01f;
    wind_.update(nav_.ground_velocity_m_s(), true_airspeed_m_s(), (float)a.heading_centideg * kRadPerCentideg,
                 (float)a.pitch_centideg * kRadPerCentideg, (float)dt_ms * 0.001f);
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) void run() {
    const uint32_t now_ms = millis();
    last_run_ms = now_ms;
    const nav::BaroReading baro = baro_now();
    const uint16_t count = gps_port::fix_count();
    if (count == last_fix_count) {
        nav_.update(now_ms, baro);
        if (home_line_pending && room_for_line()) say_home();
        return;
    }
    last_fix_count = count;
    const gps::Fix& fix = gps_port::fix();
    if (nav_.on_fix(fix, baro, pipe.settings().flight.ahrs_gps_minsats)) {
        home_line_pending = home_from_gps = true;
        home_sats = fix.sats;
        home_hdop_cm = fix.hdop_cm;
    }
    learn_wind(fix);
    nav_.update(now_ms, baro);
}

// The ground station's request (its task checked the room for an ACK and two frames).
static bool ground_station_home(bool ok) {
    if (!ok) return false;
    home_from_gps = false;
    say_home();
    return true;
}

bool set_home_here() { return ground_station_home(nav_.set_home_here(baro_now())); }
bool set_home(const nav::Location& home) { return ground_station_home(nav_.set_home(home, baro_now())); }

void report(mav::PositionReport& r) {
    // Moved on to this instant: at 18 m/s the 10 Hz position is up to 1.8 m old.
    const uint32_t now_ms = millis();
    nav_.update(now_ms, baro_now());
    const nav::Location& p = nav_.position();
    r.time_boot_ms = now_ms;
    r.lat_e7 = p.lat_e7;
    r.lon_e7 = p.lon_e7;
    r.alt_msl_mm = p.alt_cm * 10;
    r.relative_alt_mm = nav_.home_set() ? (int32_t)(nav_.height_above_home_m() * 1000.0f) : 0;
    const float* v = nav_.velocity_ned_m_s();
    for (uint8_t i = 0; i < 3; ++i) r.vel_ned_m_s[i] = v[i];
    r.heading_deg = pipe.phase() == pipeline::Phase::Running
                        ? (float)pipe.angles_centideg().heading_centideg * 0.01f
                        : -1.0f;
    // VFR_HUD: the pitot's airspeed when fitted, else the ground speed (ArduPlane without
    // an airspeed sensor reports its estimate, which is the GPS's here).
    const float ground_speed_m_s = sqrtf(v[0] * v[0] + v[1] * v[1]);
    r.airspeed_m_s = airspeed_input::state() == airspeed_input::State::kSensor ? pipe.airspeed_m_s() : ground_speed_m_s;
    r.climb_m_s = nav_.height_from_baro() ? baro::climb_m_s() : -v[2];
    r.throttle_pct = vehicle::flight_io.throttle_percent();
}

void print_status_line(const text::Sink* out) {
    Writer w(out);
    w.str(TXT("# home: "));
    if (!nav_.home_set()) {
        w.str(nav_.have_position() ? TXT("not set (waiting for a good fix)") : TXT("not set (no GPS fix)")).end();
        return;
    }
    const nav::NorthEast ne = nav_.from_home_m();
    w.fixed2(ne.north_m).str(TXT(" m N, ")).fixed2(ne.east_m).str(TXT(" m E, "))
        .fixed2(nav_.height_above_home_m()).str(nav_.height_from_baro() ? TXT(" m up (baro)") : TXT(" m up (gps)"));
    if (wind_.valid())
        w.str(TXT(", wind ")).fixed2(wind_.speed_m_s()).str(TXT(" m/s from ")).u32((uint32_t)(wind_.from_deg() + 0.5f));
    w.end();
}

}  // namespace position
