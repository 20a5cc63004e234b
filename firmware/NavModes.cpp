// SPDX-License-Identifier: GPL-3.0-or-later
#include "NavModes.h"

#if APM25_FLIGHT


#include "AirspeedInput.h"
#include "ArduinoCore.h"
#include "Baro.h"
#include "GcsLink.h"
#include "GpsLoss.h"
#include "GpsPort.h"
#include "L1Control.h"
#include "MissionExecutor.h"
#include "MissionLink.h"
#include "Modes.h"
#include "NeVector.h"
#include "NavParams.h"
#include "Position.h"
#include "SerialText.h"
#include "Tecs.h"
#include "Vehicle.h"

namespace nav_modes {

using vehicle::flight_io;
using vehicle::pipe;

namespace {

constexpr float kGravity_m_s2 = 9.80665f;
constexpr float kCdPerRad = 5729.578f;
// CRUISE: the locked track runs from where it was locked to a point this far ahead
// (ArduPlane's update_cruise: 1 km along the heading).
constexpr float kCruiseAhead_m = 1000.0f;

// The parameters as lib/Nav and lib/Mission hold them (references): worked out from the
// settings by configure().
nav::L1Params l1_params = nav::kL1Defaults;
nav::TecsParams tecs_params = nav::kTecsDefaults;
mission::ExecutorParams ex_params = mission::kExecutorDefaults;

nav::L1Control l1(l1_params, nav::L1Control::CoefficientsSetLater{});  // configure() sets them
nav::Tecs tecs(tecs_params, nav::Tecs::ParamsSetLater{});  // configure() sets them

// The mission is MissionLink's (the upload's, or the simulator's --mission in the EEPROM).
mission::MissionExecutor executor(mission_link::store, position::navigator().map(), position::navigator().home(),
                                  ex_params);
uint16_t mission_changes = 0;  // mission_link::changes() when AUTO last started its mission

flight::Mode flying = flight::Mode::Manual;  // the navigation mode last stepped (Manual: none)
uint32_t last_run_ms = 0;
uint32_t last_filter_ms = 0;
bool filters_started = false;
bool had_home = false;  // home when the mode was entered: its arrival changes the heights' datum
nav::NorthEast centre_m = {0.0f, 0.0f};      // LOITER's circle; CRUISE's locked track's start
nav::NorthEast cruise_end_m = {0.0f, 0.0f};
bool cruise_locked = false;
float height_dem_m = 0.0f;                    // CIRCLE, LOITER, FBWB, CRUISE: the height held
bool have_report = false;
// The step's first half (the guidance) for its second (TECS), on the next loop pass.
struct Pending {
    nav::TecsInput in;
    float dt_s;
    int16_t roll_cd;
    int16_t heading_deg;
    bool guided;
};
Pending pending;
bool tecs_pending = false;
mav::NavOutput last_report;      // NAV_CONTROLLER_OUTPUT's fields but L1's (report())
bool report_guided = false;      // ... L1 gave the bank: its fields; else the heading's
int16_t report_heading_deg = 0;
nav::GpsLoss gps_loss;
uint8_t gps_unsaid = 0;  // GpsLoss's events not said yet (waiting for room)

const settings::Settings& cfg() { return pipe.settings(); }

bool gps_mode(flight::Mode m) {
    return m == flight::Mode::Cruise || m == flight::Mode::Auto || m == flight::Mode::Rtl ||
           m == flight::Mode::Loiter || m == flight::Mode::Guided;
}

// The stick's share of a limit (the sticks are -4500..4500).
int16_t stick_share(int16_t stick_cd, int16_t limit) {
    return (int16_t)((int32_t)stick_cd * limit / flight::kFullThrow_cd);
}

// The height TECS flies: above home; before home (CIRCLE, FBWB without a fix) the
// barometer's since power-up, not a constant 0 (which let them sink unseen).
float height_m() {
    const nav::Navigator& n = position::navigator();
    return n.home_set() ? n.height_above_home_m() : baro::height_m();
}

mission::NavState state_now(uint32_t now_ms) {
    return mission::NavState{position::navigator().from_home_m(), height_m(), now_ms};
}

// A mode entered: its target, and TECS from the aircraft's state (ArduPlane's set_mode).
void enter(flight::Mode m, const mission::NavState& st) {
    had_home = position::navigator().home_set();
    tecs.reset();
    height_dem_m = st.height_m;
    centre_m = st.pos_m;
    cruise_locked = false;
    if (m == flight::Mode::Auto) {
        mission_changes = mission_link::changes();
        mission_link::reporter.start(executor, st);  // from MISSION_SET_CURRENT's seq, if one came
    }
    if (m == flight::Mode::Rtl) executor.return_home(st);
    if (m == flight::Mode::Guided) executor.guide_to(nullptr, st);  // by its number alone: here
}

// NAV_TAKEOFF, a hand launch (ArduPlane's takeoff_calc_roll and _pitch before the course is
// locked): wings level, TECS's takeoff stage (full throttle, at least the item's pitch) up to
// the item's height. L1 is not stepped: the takeoff has no leg. Returns "L1 banks": false.
bool takeoff(const mission::NavTarget& t, nav::TecsInput& in) {
    in.stage = nav::TecsStage::kTakeoff;
    in.takeoff_pitch_cd = t.takeoff_pitch_cd;
    return false;
}

// GPS loss in a GPS mode (docs/navigation.md "GPS loss"): pos_m and vel, the navigator's,
// become what to fly (dead reckoning); true when there is none left (wings level).
__attribute__((noinline)) bool gps_loss_step(nav::NorthEast& pos_m, nav::NorthEast& vel,
                                             const pipeline::AnglesCentideg& att, float dt_s, uint32_t now_ms) {
    const gps::Fix& f = gps_port::fix();
    // Fresh: the navigator moves a fix on for at most as long.
    const bool fix_ok = f.fix == gps::FixType::k3D && now_ms - f.received_ms <= nav::Navigator::kMaxExtrapolation_ms;
    const nav::WindEstimator& w = position::wind();  // learnt with the pitot only
    gps_unsaid = (uint8_t)(gps_unsaid | gps_loss.step(fix_ok, pos_m, vel, (uint16_t)att.heading_centideg,
                                                      w.valid() ? &w.wind_m_s() : nullptr, dt_s, (uint16_t)now_ms));
    return gps_loss.wings_level();
}

// Its lines, once each, in a loop pass of their own when the output has room (two
// STATUSTEXT frames and an output line: a write into a full queue would wait for the UART).
bool say_gps_loss() {
    if (gps_unsaid == 0u || serial_text::room() < 2u * mav::kMaxFrame + gcs_link::output_line_bytes()) return false;
    text::Writer w(vehicle::out);
    if (gps_unsaid & nav::GpsLoss::kLost) {
        gps_unsaid = (uint8_t)(gps_unsaid & ~nav::GpsLoss::kLost);
        w.str(TXT(TXT_WARN "GPS lost: dead reckoning, then wings level")).end();
    } else {
        gps_unsaid = 0;
        w.str(TXT("# GPS back: on the route again")).end();
    }
    return true;
}

}  // namespace

const mission::MissionStore& mission_store() { return mission_link::store; }

bool fly_to(const mission::Command& to) {
    if (!flight_io.set_mode((uint8_t)flight::Mode::Guided)) return false;
    const mission::NavState st = state_now(millis());
    if (flying != flight::Mode::Guided) enter(flight::Mode::Guided, st);
    flying = flight::Mode::Guided;  // entered: the next step flies the place given
    executor.guide_to(&to, st);
    return true;
}

void configure() {
    mission::nav_params(cfg().vehicle.nav, cfg().flight, l1_params, tecs_params, ex_params);
    l1.set_coefficients();
    tecs.set_params();
}

bool refused(flight::Mode m, text::Flash& reason) {
    const nav::Navigator& n = position::navigator();
    if (gps_mode(m) && (gps_port::fix().fix != gps::FixType::k3D || !n.have_position())) {
        reason = TXT("no 3D GPS fix");
    } else if (gps_mode(m) && !n.home_set()) {
        reason = TXT("no home");
    } else if (m == flight::Mode::Auto && mission_store().count() == 0u) {
        reason = TXT("no mission");
    } else {
        return false;
    }
    return true;
}

uint16_t unavailable_rows() {
    uint16_t rows = 0;
    text::Flash why;
    for (uint8_t i = 0; i < flight::kModeCount; ++i)
        if (refused((flight::Mode)flight::mode_number(i), why)) rows = (uint16_t)(rows | (1u << i));
    return rows;
}

bool due() {
    // At once when the mode changed, so that its first demands are its own.
    return tecs_pending || millis() - last_run_ms >= kPeriodMs || flight_io.nav_mode() != flying;
}

// Neither half inlined (into each other, or run into the loop tasks' function): together
// their locals took the frame past the 63 bytes ldd/std reach from Y (a subi/sbci pair
// each side of every access beyond: 1.8 KB of them in run alone).
__attribute__((noinline)) static void run_tecs();

__attribute__((noinline)) void run() {
    if (tecs_pending) return run_tecs();
    if (say_gps_loss()) return;  // the step on the next pass
    const uint32_t now_ms = millis();
    // At most 0.5 s: FBWB's stick moves the height by it (the task runs every 100 ms in any
    // mode, so only a stalled loop comes near).
    const uint32_t since_ms = now_ms - last_run_ms;
    const float dt_s = (float)(since_ms < 500u ? since_ms : 500u) * 0.001f;
    last_run_ms = now_ms;
    flight_io.set_unavailable(unavailable_rows());
    const flight::Mode m = flight_io.nav_mode();
    if (m == flight::Mode::Manual) {  // not a navigation mode
        flying = m;
        have_report = false;
        return;
    }
    const nav::Navigator& n = position::navigator();
    mission::NavState st = state_now(now_ms);
    nav::NorthEast vel = n.ground_velocity_m_s();
    const pipeline::AnglesCentideg att = pipe.angles_centideg();
    const float pitch_rad = (float)att.pitch_centideg * (1.0f / kCdPerRad);
    const float cos_pitch = 1.0f - 0.5f * pitch_rad * pitch_rad;  // within 0.5 % to 25 degrees
    // The GPS lost: the dead reckoning's position, or none (wings level).
    bool no_position = false;
    if (gps_mode(m)) no_position = gps_loss_step(st.pos_m, vel, att, dt_s, now_ms);
    else gps_loss.reset();
    // A mission uploaded while AUTO flies: flown from its start (the commands the executor
    // holds may be gone).
    // Home's arrival under CIRCLE or FBWB moves the heights' datum: the mode entered again
    // holds the height flown.
    if (m != flying || (m == flight::Mode::Auto && mission_changes != mission_link::changes()) ||
        had_home != n.home_set())
        enter(m, st);
    flying = m;
    const flight::FlightSettings& fs = cfg().flight;
    const settings::NavSettings& ns = cfg().vehicle.nav;
    int16_t roll_cd = 0;
    nav::TecsInput& in = pending.in;
    in = nav::TecsInput{};
    in.eas_dem_m_s = fs.trim_arspd_cm != 0u ? (float)fs.trim_arspd_cm * 0.01f
                                            : 0.5f * (float)(fs.arspd_min_m_s + fs.arspd_max_m_s);
    // No position (the GPS lost past its dead reckoning): the wings level and the height
    // held, the mode kept; CRUISE flies as FBWB.
    const bool wings_level = no_position && m != flight::Mode::Cruise;
    bool guided = !wings_level;  // L1 gives the bank
    if (!wings_level) switch (m) {
        case flight::Mode::Circle:
            // ArduPlane's CIRCLE: a third of the bank limit, the height held.
            roll_cd = (int16_t)(fs.lim_roll_cd / 3);
            guided = false;
            break;
        case flight::Mode::Loiter: {
            const int16_t r = ns.wp_loiter_rad_m;
            l1.update_loiter(st.pos_m, vel, centre_m, (float)(r < 0 ? -r : r), r < 0 ? (int8_t)-1 : (int8_t)1);
            break;
        }
        case flight::Mode::Auto:
        case flight::Mode::Rtl:
        case flight::Mode::Guided: {
            const mission::NavTarget& t = executor.target();
            if (t.kind == mission::TargetKind::kTakeoff) {
                guided = takeoff(t, in);
            } else if (t.kind == mission::TargetKind::kWaypoint) {
                l1.update_waypoint(st.pos_m, vel, t.prev_m, t.next_m);
            } else {
                l1.update_loiter(st.pos_m, vel, t.next_m, t.radius_m, t.direction);
            }
            executor.update(st, l1);
            if (m == flight::Mode::Auto) mission_link::reporter.follow(executor, st);  // MISSION_SET_CURRENT, the news
            height_dem_m = executor.height_demand_m(st);
            if (executor.airspeed_cm_s() != 0u) in.eas_dem_m_s = (float)executor.airspeed_cm_s() * 0.01f;
            break;
        }
        default: {  // FBWB, CRUISE: the pitch stick moves the height at FBWB_CLIMB_RATE
            const int16_t roll_stick = flight_io.stick(flight::kRoll);
            height_dem_m += (float)flight_io.stick(flight::kPitch) * ((float)ns.fbwb_climb_rate_m_s / 4500.0f) * dt_s;
            roll_cd = stick_share(roll_stick, fs.lim_roll_cd);
            guided = false;
            // CRUISE: the roll stick centred locks the track along the course flown
            // (ArduPlane's update_cruise, from 0.5 m/s ground speed); moved, it banks.
            const float speed_sq = nav::length_squared(vel);
            if (m == flight::Mode::Cruise && roll_stick == 0 && !no_position && (cruise_locked || speed_sq > 0.25f)) {
                if (!cruise_locked) {
                    centre_m = st.pos_m;
                    cruise_end_m = st.pos_m + vel * (kCruiseAhead_m / sqrtf(speed_sq));
                    cruise_locked = true;
                }
                l1.update_waypoint(st.pos_m, vel, centre_m, cruise_end_m);
                guided = true;
            } else {
                cruise_locked = false;
            }
            break;
        }
    }
    if (guided) roll_cd = l1.nav_roll_cd(fs.lim_roll_cd, cos_pitch);
    in.height_dem_m = height_dem_m;
    in.pitch_rad = pitch_rad;
    pending.roll_cd = roll_cd;
    pending.guided = guided;
    pending.dt_s = dt_s;
    pending.heading_deg = (int16_t)(att.heading_centideg / 100);
    tecs_pending = true;
}

// The step's second half, on the next loop pass: TECS and the demands (the two halves
// together took up to 5 ms, past what fits between two samples).
static void run_tecs() {
    tecs_pending = false;
    nav::TecsInput& in = pending.in;
    // The bank's cos^2 from the DCM's rows (a.y^2 + b.y^2).
    const linalg::Matrix3f r = pipe.estimator().matrix();
    in.have_airspeed = airspeed_input::state() == airspeed_input::State::kSensor;
    in.eas_m_s = pipe.airspeed_m_s();
    in.eas2tas = 1.0f;
    in.cos_bank_sq = r.a.y * r.a.y + r.b.y * r.b.y;
    tecs.update_pitch_throttle(in, pending.dt_s);
    const int16_t roll_cd = pending.roll_cd;
    const bool guided = pending.guided;
    flight_io.set_nav_demands(roll_cd, tecs.pitch_dem_cd(), (int16_t)(tecs.throttle_pct() * 10u));

    // NAV_CONTROLLER_OUTPUT's fields; L1's when the report is asked for (report()).
    mav::NavOutput& rep = last_report;
    rep.nav_roll_deg = (float)roll_cd * 0.01f;
    rep.nav_pitch_deg = (float)tecs.pitch_dem_cd() * 0.01f;
    rep.alt_error_m = tecs.height_dem_adj_m() - tecs.height_m();
    report_guided = guided;
    report_heading_deg = pending.heading_deg;
    have_report = true;
}

bool report(mav::NavOutput& r) {
    if (!have_report) return false;
    r = last_report;
    // ArduPlane's: bearings in degrees, 0..360 as int16; from L1's last step, worked out at
    // the report's rate (1 Hz), not at each 10 Hz step: two atan2 and a square root.
    if (report_guided) {
        const float to_deg = 57.29578f;
        int16_t nb = (int16_t)(l1.nav_bearing_rad() * to_deg);
        int16_t tb = (int16_t)(l1.target_bearing_rad() * to_deg);
        r.nav_bearing_deg = nb < 0 ? (int16_t)(nb + 360) : nb;
        r.target_bearing_deg = tb < 0 ? (int16_t)(tb + 360) : tb;
        const float d = nav::length(l1.to_target_m());
        r.wp_dist_m = d < 65535.0f ? (uint16_t)d : 65535u;
        r.xtrack_error_m = l1.crosstrack_error_m();
    } else {
        r.nav_bearing_deg = r.target_bearing_deg = report_heading_deg;
        r.wp_dist_m = 0;
        r.xtrack_error_m = 0.0f;
    }
    return true;
}

bool filters_due() { return millis() - last_filter_ms >= kFilterPeriodMs && pipe.phase() == pipeline::Phase::Running; }

// TECS's 50 Hz filters: the height above home, the vertical acceleration (earth frame,
// up, gravity removed) and the acceleration along the fuselage (accelerometer x + g R31).
void filters_run() {
    const uint32_t now_ms = millis();
    const float dt_s = filters_started ? (float)(now_ms - last_filter_ms) * 0.001f : 0.02f;
    last_filter_ms = now_ms;
    filters_started = true;
    const linalg::Matrix3f r = pipe.estimator().matrix();
    const linalg::Vector3f a = pipe.accel_m_s2();
    const float accel_down = r.c.x * a.x + r.c.y * a.y + r.c.z * a.z;  // specific force: -g at rest
    tecs.update_50hz(height_m(), -(accel_down + kGravity_m_s2),
                     a.x + kGravity_m_s2 * r.c.x, dt_s);
}

}  // namespace nav_modes

#else  // the attitude-only build

namespace nav_modes {
bool due() { return false; }
void run() {}
bool filters_due() { return false; }
void filters_run() {}
void configure() {}
bool refused(flight::Mode, text::Flash&) { return false; }
uint16_t unavailable_rows() { return 0; }
bool report(mav::NavOutput&) { return false; }
bool fly_to(const mission::Command&) { return false; }
}  // namespace nav_modes

#endif
