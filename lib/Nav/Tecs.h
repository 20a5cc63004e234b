// SPDX-License-Identifier: GPL-3.0-or-later
// Height and speed: the Total Energy Control System as ArduPlane 3.x's AP_TECS (Lambregts;
// ArduPilot's port by Paul Riseborough). Specific energies per unit mass:
//
//   potential SPE = g h, kinetic SKE = V^2 / 2 (V the true airspeed)
//   throttle <- the total SPE + SKE and its rate (PD + integrator + feed-forward)
//   pitch    <- the balance SPE w_p - SKE w_k and its rate (PI + damping + feed-forward)
//
// with w_k = TECS_SPDWEIGHT (0 height first ... 2 speed first) and w_p = 2 - w_k, each then
// held at most 1 (ArduPlane 3.8's fix: a weight of 2 doubles that loop's gain). Without
// an airspeed sensor w_k = 0 (pitch holds the height) and the throttle is ArduPlane's:
// TRIM_THROTTLE moved towards THR_MAX / THR_MIN in proportion to the pitch demand over
// LIM_PITCH_MAX / LIM_PITCH_MIN (the pitch demand carries the energy error), plus the
// bank's extra TECS_RLL2THR x (1/cos^2 bank - 1).
//
// Two rates, as ArduPlane flies it: update_50hz() runs the complementary filters
// (height and climb rate from the barometer and the vertical acceleration, third order
// with its three poles at TECS_HGT_OMEGA, Widnall & Sinha 1978; the along-track
// acceleration low-passed); update_pitch_throttle() at 10 Hz filters the airspeed (second
// order at TECS_SPD_OMEGA), shapes the demands (climb within TECS_CLMB_MAX, sink within
// TECS_SINK_MAX, speed within ARSPD_FBW_MIN..MAX and half the energy rate the aircraft
// has) and works out the demands. The 10 Hz step's constants (the height demand's 0.05 /
// 0.95 lag, the 0.1 s rate limits) are AP_TECS's, written for 10 Hz.
//
// Units: metres, m/s, m/s^2, radians inside; the demands out in ArduPilot's units
// (centi-degrees of pitch, throttle percent). Params / coefficients / state apart.
#pragma once

#include <stdint.h>

namespace nav {

struct TecsParams {
    float time_const_s;       // TECS_TIME_CONST: s, 3..10; the energy loops' time constant
    float clmb_max_m_s;       // TECS_CLMB_MAX: m/s, 0.1..20; the climb at THR_MAX and cruise speed
    float sink_min_m_s;       // TECS_SINK_MIN: m/s, 0.1..10; the sink at THR_MIN and cruise speed
    float sink_max_m_s;       // TECS_SINK_MAX: m/s, 0..20; the steepest sink asked for
    float thr_damp;           // TECS_THR_DAMP: 0.1..1; throttle damping of the energy rate error
    float integ_gain;         // TECS_INTEG_GAIN: 0..0.5; throttle and pitch integrators
    float ptch_damp;          // TECS_PTCH_DAMP: 0.1..1; pitch damping of the balance rate error
    float spdweight;          // TECS_SPDWEIGHT: 0..2; speed's weight in the pitch loop
    float rll2thr;            // TECS_RLL2THR: m^2/s^3, 5..30; the energy rate a 60-deg bank costs
    float hgt_omega_rad_s;    // TECS_HGT_OMEGA: rad/s, 1..5; the height filter's crossover
    float spd_omega_rad_s;    // TECS_SPD_OMEGA: rad/s, 0.5..2; the airspeed filter's crossover
    float vert_acc_m_s2;      // TECS_VERT_ACC: m/s^2, 1..10; limits the pitch demand's rate
    int16_t pitch_max_cd;     // LIM_PITCH_MAX: centi-degrees
    int16_t pitch_min_cd;     // LIM_PITCH_MIN: centi-degrees (negative)
    uint8_t thr_min_pct;      // THR_MIN: percent
    uint8_t thr_max_pct;      // THR_MAX: percent
    uint8_t trim_throttle_pct;  // TRIM_THROTTLE: percent; the cruise throttle
    uint8_t arspd_min_m_s;    // ARSPD_FBW_MIN: m/s
    uint8_t arspd_max_m_s;    // ARSPD_FBW_MAX: m/s
};
// ArduPlane 3.x's defaults.
constexpr TecsParams kTecsDefaults = {5.0f, 5.0f, 2.0f, 5.0f, 0.5f, 0.1f, 0.0f, 1.0f, 10.0f,
                                      3.0f, 2.0f, 7.0f, 2000, -2500, 0, 75, 45, 9, 22};

// Worked out from the parameters once (set_params): no divide per step but 1 / V and the
// bank's 1 / cos^2, no product of two parameters.
struct TecsCoefficients {
    float ste_dot_max;     // TECS_CLMB_MAX g: the total energy rate at THR_MAX, m^2/s^3
    float ste_dot_min;     // -TECS_SINK_MIN g: at THR_MIN
    float k_ste_to_thr;    // 1 / (TECS_TIME_CONST (STEdot_max - STEdot_min) / throttle range)
    float thr_per_ste_dot; // throttle range / (STEdot_max - STEdot_min): the feed-forward's slope
    float inv_tc_g;        // 1 / (TECS_TIME_CONST g): the pitch gain's inverse, divided by V
    float pitch_max_rad, pitch_min_rad;
    float inv_pitch_max, inv_pitch_min;  // 1/rad: the throttle without airspeed
    float thr_max, thr_min, thr_trim;  // fractions
    float hgt_k1, hgt_k2, hgt_k3;  // the height filter's gains: TECS_HGT_OMEGA^3, 3 omega^2, 3 omega
    // The 10 Hz step's (AP_TECS's constants for its 0.1 s step folded in):
    float spd_kx, spd_kv;          // the airspeed filter's TECS_SPD_OMEGA^2 and sqrt(2) TECS_SPD_OMEGA
    float arspd_min, arspd_max;    // ARSPD_FBW_MIN and _MAX (the larger), m/s
    float tas_step_up, tas_step_down;  // 0.5 STEdot_max 0.1 s and 0.5 STEdot_min 0.1 s: over V,
                                       // the speed demand's most change in a step
    float hgt_step_up, hgt_step_down;  // TECS_CLMB_MAX 0.1 s, TECS_SINK_MAX 0.1 s
    float spe_w, ske_w;            // the pitch loop's weights with a pitot, neither above 1
    float integ_thr_k;             // TECS_INTEG_GAIN k_ste_to_thr
    float tc_g;                    // TECS_TIME_CONST g: times V, the energy balance per radian
    float pitch_max_margin, pitch_min_margin;  // the pitch integrator's reach, 4.5 deg beyond
    float thr_underspeed;          // THR_MAX 0.95: at or above it, slow is underspeed
    bool pitch_damped;             // TECS_PTCH_DAMP not 0 (its term is skipped at 0)
    bool unit_weights;             // both weights 1 (TECS_SPDWEIGHT 1): their products skipped
};

enum class TecsStage : uint8_t {
    kNormal,
    kTakeoff,  // a hand launch: pitch at least the takeoff pitch, full throttle, speed first
};

// What the 10 Hz step is asked for and what the aircraft is doing.
struct TecsInput {
    float height_dem_m;     // above home
    float eas_dem_m_s;      // airspeed demand (TRIM_ARSPD_CM / 100, or DO_CHANGE_SPEED's)
    float eas_m_s;          // the pitot's; ignored without one
    bool have_airspeed;
    float eas2tas;          // true airspeed per equivalent (1 at sea level)
    float cos_bank_sq;      // cos^2 of the bank (the DCM's rows: a.y^2 + b.y^2)
    float pitch_rad;        // the attitude's, to start the pitch demand from
    TecsStage stage;
    int16_t takeoff_pitch_cd;  // the takeoff's least pitch (NAV_TAKEOFF's param 1)
};

class Tecs {
public:
    explicit Tecs(const TecsParams& params) : params_(params) { set_params(); }
    // A static object's (constexpr: no start-up code): set_params() before the first step
    // (the firmware's configure(), once the settings are loaded).
    struct ParamsSetLater {};
    constexpr Tecs(const TecsParams& params, ParamsSetLater) : params_(params) {}
    // After a change of the parameters.
    void set_params();
    // Starts over at the next steps (a mode entered): filters and demands from the aircraft.
    void reset() { need_reset_ = true; }

    // 50 Hz: the barometer's height above home (m), the vertical acceleration (m/s^2 up,
    // gravity removed: -(a_earth_z + g)), the acceleration along the fuselage (m/s^2:
    // the accelerometer's x plus g R31, the DCM's), and the time since the last call.
    void update_50hz(float height_m, float accel_up_m_s2, float accel_fwd_m_s2, float dt_s);
    // 10 Hz: the pitch and throttle demands for `in`; dt_s the time since the last call
    // (over 1 s: a start over).
    void update_pitch_throttle(const TecsInput& in, float dt_s);

    int16_t pitch_dem_cd() const;
    uint8_t throttle_pct() const;
    float pitch_dem_rad() const { return pitch_dem_; }
    float throttle_dem() const { return throttle_dem_; }  // 0..1
    // The filters' estimates and the shaped demands (NAV_CONTROLLER_OUTPUT's alt_error,
    // the tests).
    float height_m() const { return height_m_; }
    float climb_rate_m_s() const { return climb_m_s_; }
    float tas_m_s() const { return tas_m_s_; }
    float height_dem_adj_m() const { return hgt_dem_adj_; }
    float tas_dem_adj_m_s() const { return tas_dem_adj_; }
    bool underspeed() const { return underspeed_; }
    const TecsCoefficients& coefficients() const { return k_; }

private:
    struct Demands {
        float hgt_rate, tas_rate;  // this step's rates
    };
    // The speed range in true airspeed for an EAS2TAS (its bits: a float's == is a call),
    // kept until EAS2TAS or a parameter changes: ARSPD_FBW_MIN and _MAX x EAS2TAS, their
    // kinetic energies V^2 / 2, and underspeed's 0.9 of the least.
    struct SpeedRange {
        uint32_t eas2tas_bits;
        float tas_min, tas_max, ske_min, ske_max, underspeed_tas;
    };
    void refresh_speed_range(float eas2tas);
    // An equivalent airspeed in true airspeed (no multiply at EAS2TAS 1).
    float tas_of(float eas_m_s, float eas2tas) const;
    void initialise(const TecsInput& in, float tas_m_s);
    void update_speed(const TecsInput& in, float eas_m_s, float dt_s);
    Demands update_demands(const TecsInput& in, float inv_tas);
    void update_throttle(const TecsInput& in, float thr_min, float ste_error, float ste_dot, float ste_dot_dem,
                         float dt_s);
    void update_throttle_without_airspeed(const TecsInput& in, float thr_min, float pitch_min);
    // TECS_RLL2THR (1/cos^2 bank - 1): the energy rate the bank's induced drag costs.
    float bank_ste_dot(const TecsInput& in) const;
    void update_pitch(const TecsInput& in, float pitch_min, float balance_err, float balance_dot_dem,
                      float balance_dot_err, float inv_tas, float dt_s);

    const TecsParams& params_;
    TecsCoefficients k_ = {};
    SpeedRange range_ = {};
    // 50 Hz filters
    float height_m_ = 0.0f;        // the complementary filter's height, m
    float climb_m_s_ = 0.0f;       // ... its climb rate
    float accel_bias_m_s2_ = 0.0f; // ... its third state (the accelerometer's bias)
    float vel_dot_m_s2_ = 0.0f;    // along-track acceleration, low-passed
    // 10 Hz
    float tas_m_s_ = 0.0f;         // the airspeed filter's true airspeed
    float tas_integ_ = 0.0f;       // ... its integrator
    float tas_dem_adj_ = 0.0f;     // the speed demand, rate-limited
    float tas_dem_last_ = 0.0f;
    float hgt_dem_in_old_ = 0.0f;  // the height demand's 2-point average
    float hgt_dem_prev_ = 0.0f;    // ... rate-limited
    float hgt_dem_adj_ = 0.0f;     // ... lagged: the demand the energies take
    float ste_dot_err_last_ = 0.0f;
    float integ_thr_ = 0.0f;
    float integ_pitch_ = 0.0f;
    float pitch_dem_ = 0.0f;
    float throttle_dem_ = 0.0f;
    bool filters_started_ = false;
    bool need_reset_ = true;
    bool underspeed_ = false;
    bool bad_descent_ = false;
};

}  // namespace nav
