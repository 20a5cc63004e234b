// SPDX-License-Identifier: GPL-3.0-or-later
// build/scenario: synthetic trajectories in the format of ../shared/SIM.md.
//
//   build/scenario NAME [--seconds S] [--rate HZ] [sensor-error options]   CSV on stdout
//   build/scenario --from FILE [sensor-error options]     the errors on a trajectory file
//   build/scenario --list                             names, descriptions and the options
//
// The seeded motions (translate_slow, translate_fast, walk, pendulum, car, tapping,
// knocking, slow_rotation; see Motions.h) also move the board: specific force = R^T ((0, 0, -g) + a)
// with a the analytic second derivative of the motion; their random parts come from
// --seed.
//
// Physically consistent: each scenario is an analytic attitude q(t) (body -> earth, NED,
// built as Rz(yaw) Ry(pitch) Rx(roll) from smooth keyframed angles, any angle range);
// the body rate is omega = 2 vec(q* dq/dt) (central difference, h = 10 us), specific
// force = R^T (0, 0, -g) + linear acceleration, field = R^T * earth field. Earth field
// (NED) = (20, 0, 45) uT, a Berlin-like 49 uT at 66 deg inclination, declination 0.
// Sensor noise (white, fixed seed, so every run is identical): gyro 0.03 deg/s, accel
// 0.025 m/s^2, field 0.2 uT rms, about the MPU6000 / HMC5883L datasheet densities at the
// configured bandwidths. movement = 0 for the first 2 s (start-up), 1 after.
//
// Sensor errors a real, uncalibrated board has (all off by default, so that the default
// files stay exactly what they were): gyro bias and its drift, accel offset and scale,
// compass hard and soft iron, noise at the datasheets' densities, quantisation to the
// chips' resolution. They apply to the measured columns only; the truth is untouched.
// `--preset uncalibrated` sets all of them to values typical of an APM 2.5 (usage text).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "Constants.h"
#include "Hmc5883.h"
#include "Motions.h"
#include "Mpu6000.h"
#include "Rotation.h"
#include "Trajectory.h"

namespace {

using linalg::dbl::kGravity_m_s2;
using linalg::dbl::kPi;
using linalg::dbl::kRadPerDeg;
constexpr const double* kEarthField_uT = sim::kEarthFieldNed_uT;  // NED
constexpr double kGyroNoise_rad_s = 0.03 * kRadPerDeg;
constexpr double kAccelNoise_m_s2 = 0.025;
constexpr double kMagNoise_uT = 0.2;
constexpr double kStartup_s = 2.0;

using sim::axis_angle;
using sim::earth_to_body;
using sim::Quat;

// Angles in degrees at keyframes; between keyframes a cosine ease (zero rate at both ends).
struct Key {
    double t_s, roll_deg, pitch_deg, yaw_deg;
};

struct Extras {
    double gyro_bias_rad_s[3] = {0, 0, 0};
    double vibration_m_s2 = 0.0;        // white linear acceleration, rms per axis
    double vibration_tone_m_s2 = 0.0;   // 25 Hz sinusoid amplitude on z
    double wobble_deg = 0.0;            // 8 Hz roll/pitch oscillation amplitude
    double disturb_from_s = 0, disturb_to_s = 0;
    double disturb_uT[3] = {0, 0, 0};   // added to the earth field (NED) in that window
};

struct Scenario {
    const char* name;
    const char* description;
    std::vector<Key> keys;
    Extras extras;
    sim::motion::Kind motion = sim::motion::kNone;  // a seeded motion (Motions.h) instead of keys
};

std::vector<Scenario> scenarios() {
    std::vector<Scenario> list;
    {
        Scenario s{"rest", "level, facing north, still for 60 s", {{0, 0, 0, 0}, {60, 0, 0, 0}}, {}};
        list.push_back(s);
    }
    {
        Scenario s{"rest_bias", "rest with a +2 deg/s gyro bias on every axis (the truth stays still)",
                   {{0, 0, 0, 0}, {60, 0, 0, 0}}, {}};
        for (double& b : s.extras.gyro_bias_rad_s) b = 2.0 * kRadPerDeg;
        list.push_back(s);
    }
    {
        Scenario s{"tilt_tour",
                   "rest 3 s, roll +-45, pitch +-45, a full yaw turn, a combined tilt, and back (40 s)",
                   {{0, 0, 0, 0}, {3, 0, 0, 0}, {6, 45, 0, 0}, {9, -45, 0, 0}, {11, 0, 0, 0},
                    {14, 0, 45, 0}, {17, 0, -45, 0}, {19, 0, 0, 0}, {27, 0, 0, 360}, {30, 0, 0, 360},
                    {33, 30, 20, 405}, {36, 0, 0, 360}, {40, 0, 0, 360}},
                   {}};
        list.push_back(s);
    }
    {
        Scenario s{"pitch90", "heading 30 deg, pitch up through 90 to 120, back, down through -90 to -120, back",
                   {{0, 0, 0, 30}, {3, 0, 0, 30}, {9, 0, 90, 30}, {11, 0, 90, 30}, {14, 0, 120, 30},
                    {17, 0, 90, 30}, {23, 0, 0, 30}, {29, 0, -90, 30}, {31, 0, -90, 30}, {34, 0, -120, 30},
                    {37, 0, -90, 30}, {43, 0, 0, 30}, {46, 0, 0, 30}},
                   {}};
        list.push_back(s);
    }
    {
        Scenario s{"roll_pitch_90", "90 deg roll held 5 s, back, 90 deg pitch held 5 s, back",
                   {{0, 0, 0, 0}, {3, 0, 0, 0}, {7, 90, 0, 0}, {12, 90, 0, 0}, {16, 0, 0, 0},
                    {20, 0, 90, 0}, {25, 0, 90, 0}, {29, 0, 0, 0}, {32, 0, 0, 0}},
                   {}};
        list.push_back(s);
    }
    {
        Scenario s{"yaw_spin", "level; three yaw turns clockwise, a pause, two turns back",
                   {{0, 0, 0, 0}, {3, 0, 0, 0}, {15, 0, 0, 1080}, {18, 0, 0, 1080}, {26, 0, 0, 360},
                    {30, 0, 0, 360}},
                   {}};
        list.push_back(s);
    }
    {
        Scenario s{"shake", "level with vibration: 2 m/s^2 white + 3 m/s^2 at 25 Hz, 1 deg wobble at 8 Hz",
                   {{0, 0, 0, 0}, {30, 0, 0, 0}}, {}};
        s.extras.vibration_m_s2 = 2.0;
        s.extras.vibration_tone_m_s2 = 3.0;
        s.extras.wobble_deg = 1.0;
        list.push_back(s);
    }
    {
        Scenario s{"mag_disturbance", "yaw to 90 deg, then a (30, 20, 0) uT field disturbance from 12 to 18 s",
                   {{0, 0, 0, 0}, {3, 0, 0, 0}, {8, 0, 0, 90}, {30, 0, 0, 90}}, {}};
        s.extras.disturb_from_s = 12.0;
        s.extras.disturb_to_s = 18.0;
        s.extras.disturb_uT[0] = 30.0;
        s.extras.disturb_uT[1] = 20.0;
        list.push_back(s);
    }
    {
        Scenario s{"fast", "fast turns peaking near 500 deg/s: roll 360, pitch +-60, yaw 360",
                   {{0, 0, 0, 0}, {3, 0, 0, 0}, {4.13, 360, 0, 0}, {6, 360, 0, 0}, {6.4, 360, 60, 0},
                    {7.0, 360, -60, 0}, {7.4, 360, 0, 0}, {9, 360, 0, 0}, {10.13, 360, 0, 360},
                    {14, 360, 0, 360}, {20, 360, 0, 360}},
                   {}};
        list.push_back(s);
    }
    {
        // Rolls, pitches to +-85 deg and yaw turns mixed so that the field, seen from the
        // body, points to each of the 26 directions of the compass calibration's coverage
        // (faces, edges and corners of a cube) at least 25 times at 75 Hz: what a compass
        // calibration asks for. Ends level, heading 180 deg as the first version of this
        // scenario did (tests compare against it; see test_compass.cpp on soft iron).
        Scenario s{"tumble", "still 5 s, tumbled through every orientation (all axes up and down) for 30 s, still 15 s",
                   {{0, 0, 0, 0}, {5, 0, 0, 0}, {7.5, 45, -85, 30}, {10, 180, 45, 60}, {12.5, 315, -85, 90},
                    {15, 360, 45, 180}, {17.5, 405, 0, 240}, {20, 450, 45, 240}, {22.5, 495, 85, 270},
                    {25, 585, 45, 270}, {27.5, 720, 45, 360}, {30, 810, -85, 420}, {32.5, 945, 0, 420},
                    {35, 1080, 0, 540}, {50, 1080, 0, 540}},
                   {}};
        list.push_back(s);
    }
    // Seeded motions (Motions.h): the random parts come from --seed; keys hold only the
    // default motion's length.
    const struct {
        const char* name;
        const char* description;
        sim::motion::Kind kind;
    } motions[] = {
        {"translate_slow", "seeded: moved by hand along x, y, z and diagonals, 0.3-1 m strokes at 0.3-0.8 Hz",
         sim::motion::kTranslateSlow},
        {"translate_fast", "seeded: the same at 0.8-1.5 Hz, up to 20 m/s^2", sim::motion::kTranslateFast},
        {"walk", "seeded: carried in hand while walking, 2 Hz steps, arm sway, 90 deg turns, pauses",
         sim::motion::kWalk},
        {"pendulum", "seeded: swinging 10-30 deg on a 1-2 m string, decaying, twisting in yaw",
         sim::motion::kPendulum},
        {"car", "seeded: flat road, 2-4 m/s^2 starts and stops, corners at 5-15 m/s, suspension",
         sim::motion::kCar},
        {"tapping", "seeded: held in a shaking hand, tapped (20-50 m/s^2, 10 ms) every 1-3 s",
         sim::motion::kTapping},
        {"knocking", "seeded: the same, knocked on a surface (60-150 m/s^2 stops, 10 ms) every 1-3 s", sim::motion::kKnocking},
        {"slow_rotation", "seeded: turned slowly back and forth, yaw 15-60 deg, roll and pitch 5-25 deg, 10-40 s periods",
         sim::motion::kSlowRotation},
    };
    for (const auto& m : motions) {
        const double end_s = sim::motion::make_plan(m.kind, 0).end_s;
        Scenario s{m.name, m.description, {{0, 0, 0, 0}, {end_s, 0, 0, 0}}, {}, m.kind};
        list.push_back(s);
    }
    return list;
}

double ease(double u) { return 0.5 - 0.5 * std::cos(kPi * u); }

void angles_at(const std::vector<Key>& keys, double t_s, double& roll, double& pitch, double& yaw) {
    const Key* a = &keys.front();
    const Key* b = &keys.front();
    for (size_t i = 0; i + 1 < keys.size(); ++i) {
        a = &keys[i];
        b = &keys[i + 1];
        if (t_s < keys[i + 1].t_s) break;
        a = b;
    }
    double u = (b->t_s > a->t_s) ? (t_s - a->t_s) / (b->t_s - a->t_s) : 1.0;
    u = u < 0 ? 0 : (u > 1 ? 1 : u);
    const double w = ease(u);
    roll = a->roll_deg + w * (b->roll_deg - a->roll_deg);
    pitch = a->pitch_deg + w * (b->pitch_deg - a->pitch_deg);
    yaw = a->yaw_deg + w * (b->yaw_deg - a->yaw_deg);
}

Quat attitude(const Scenario& s, double t_s) {
    double roll, pitch, yaw;
    angles_at(s.keys, t_s, roll, pitch, yaw);
    if (s.extras.wobble_deg > 0.0) {
        roll += s.extras.wobble_deg * std::sin(2 * kPi * 8.0 * t_s);
        pitch += s.extras.wobble_deg * std::cos(2 * kPi * 8.0 * t_s + 0.3);
    }
    return sim::from_euler(roll * kRadPerDeg, pitch * kRadPerDeg, yaw * kRadPerDeg);
}

using Noise = sim::Random;  // the fixed sequences of the default files

// Imperfections of the measured columns (body frame), applied after the physics:
//   gyro  = omega + bias + drift * t + walk(t) + noise
//   accel = scale .* f + offset + noise
//   mag   = S * B + hard_iron + noise        (S: soft iron, B: the field the board is in)
// then each rounded to its chip's resolution when quantise is set.
struct SensorErrors {
    double gyro_bias_dps[3] = {0, 0, 0};
    double gyro_drift_dps_per_min[3] = {0, 0, 0};  // a ramp: the warm-up drift of the zero-rate output
    double gyro_walk_dps_per_sqrt_min = 0.0;       // a random walk per axis (a bias instability)
    double accel_offset_m_s2[3] = {0, 0, 0};
    double accel_scale[3] = {1, 1, 1};
    double hard_iron_uT[3] = {0, 0, 0};
    double soft_iron[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    bool datasheet_noise = false;  // white noise at the datasheets' densities instead of the fixed amounts
    bool quantise = false;
    uint64_t seed = 0;             // 0: the fixed seed of the default files
};

// MPU6000 Product Specification 6.1/6.2: rate noise spectral density 0.005 deg/s/sqrt(Hz),
// accel 400 ug/sqrt(Hz); white noise of density d sampled at r Hz has sigma d * sqrt(r / 2).
// HMC5883L datasheet: noise floor 2 mG (0.2 uT) standard deviation per output sample.
constexpr double kGyroDensity_dps_sqrt_hz = 0.005;
constexpr double kAccelDensity_g_sqrt_hz = 400e-6;
constexpr double kMagFloor_uT = 0.2;
// The firmware's ranges (lib/MPU6000 kGyroRange 2000 deg/s, kAccelRange 16 g; lib/HMC5883
// kGain 1.3 Ga): one count of each chip.
constexpr double kGyroLsb_dps = 1.0 / mpu6000::kGyroLsbPerDps2000;
constexpr double kAccelLsb_m_s2 = (double)mpu6000::accel_m_s2_per_count(mpu6000::kAccelRange);
const double kMagLsb_uT = linalg::dbl::kMicroteslaPerGauss / (double)hmc5883::lsb_per_gauss(hmc5883::kGain);

// A realistic uncalibrated APM 2.5, each value well inside its datasheet tolerance:
// gyro zero-rate offset (MPU6000 +-20 deg/s initial) of 1-1.5 deg/s, drifting as the board
// warms (+-20 deg/s over 125 K is 0.16 deg/s/K; ~1 K/min after power-up: ~0.1 deg/s/min);
// accel zero-g offset (+-50 mg x/y, +-80 mg z) of 10-20 mg and sensitivity (+-3 %) of
// 1-2 %; compass hard iron of 5-10 uT from the board's own parts (ArduPilot accepts
// offsets up to 500 mG = 50 uT) and soft iron of a few percent with cross terms; noise at
// the densities above; values quantised to the chips' counts.
void set_uncalibrated(SensorErrors& e) {
    const double bias[3] = {1.5, -1.0, 0.8}, drift[3] = {0.10, -0.08, 0.06};
    const double offset[3] = {0.10, -0.08, 0.20}, scale[3] = {1.02, 0.985, 1.01};
    const double hard[3] = {6.0, -4.0, 9.0};
    const double soft[3][3] = {{1.04, 0.02, -0.015}, {0.02, 0.97, 0.01}, {-0.015, 0.01, 1.01}};
    for (int i = 0; i < 3; ++i) {
        e.gyro_bias_dps[i] = bias[i];
        e.gyro_drift_dps_per_min[i] = drift[i];
        e.accel_offset_m_s2[i] = offset[i];
        e.accel_scale[i] = scale[i];
        e.hard_iron_uT[i] = hard[i];
        for (int j = 0; j < 3; ++j) e.soft_iron[i][j] = soft[i][j];
    }
    e.datasheet_noise = true;
    e.quantise = true;
}

const char* const kOptionsHelp =
    "sensor-error options (default: none; they change only the measured columns):\n"
    "  --gyro-bias X,Y,Z       gyro bias, deg/s per body axis\n"
    "  --gyro-drift X,Y,Z      gyro bias ramp, deg/s per minute per axis (from t = 0)\n"
    "  --gyro-walk S           gyro bias random walk, deg/s per sqrt(minute), each axis\n"
    "  --accel-offset X,Y,Z    accel offset, m/s^2\n"
    "  --accel-scale X,Y,Z     accel scale factor per axis (1 = exact; 1.02 = +2 %)\n"
    "  --hard-iron X,Y,Z       compass hard iron, uT, body frame (added to the field)\n"
    "  --soft-iron A,B,C       compass soft iron: per-axis scales (diagonal matrix), or\n"
    "  --soft-iron A,B,C,XY,XZ,YZ   scales and symmetric cross terms, or\n"
    "  --soft-iron M11,...,M33 the full 3x3 matrix, row by row (mag = M * field + hard iron)\n"
    "  --noise datasheet       white noise at the datasheets' densities at the file's rate\n"
    "                          (MPU6000 0.005 deg/s/sqrt(Hz), 400 ug/sqrt(Hz); HMC5883L 0.2 uT);\n"
    "  --noise default         the fixed amounts (0.03 deg/s, 0.025 m/s^2, 0.2 uT rms)\n"
    "  --quantise              round to one count of each chip at the firmware's ranges\n"
    "                          (1/16.4 deg/s, 16 g / 32768, 1/1090 G)\n"
    "  --seed N                another noise sequence (default: the fixed one); for the\n"
    "                          seeded motions also another motion (0: the default one)\n"
    "  --preset uncalibrated   a realistic uncalibrated board: gyro bias (1.5,-1,0.8) deg/s\n"
    "                          drifting (0.1,-0.08,0.06) deg/s/min, accel offset\n"
    "                          (0.1,-0.08,0.2) m/s^2 and scale (1.02,0.985,1.01), hard iron\n"
    "                          (6,-4,9) uT, soft iron scales (1.04,0.97,1.01) with cross terms\n"
    "                          (0.02,-0.015,0.01), datasheet noise, quantised; later options\n"
    "                          override single values\n"
    "  --from FILE             the errors on a trajectory file's measured columns (a flight\n"
    "                          of sim/flight/fly.py), its truth kept; noise only with\n"
    "                          --noise or --preset\n";

void print_list(const std::vector<Scenario>& list) {
    for (const Scenario& s : list) {
        std::printf("%-16s %5.0f s  %s\n", s.name, s.keys.back().t_s, s.description);
    }
}

// --list: the names (one a line, as tools read them), then the options as `# ` lines.
void print_list_with_options(const std::vector<Scenario>& list) {
    print_list(list);
    const char* p = kOptionsHelp;
    while (*p) {
        const char* e = std::strchr(p, '\n');
        std::printf("# %.*s\n", (int)(e - p), p);
        p = e + 1;
    }
}

// "a,b,c" into exactly n_min..n_max doubles; false on anything else.
bool parse_list(const char* text, double* out, int n_min, int n_max, int& n) {
    n = 0;
    const char* p = text;
    while (true) {
        char* end = nullptr;
        const double v = std::strtod(p, &end);
        if (end == p || n >= n_max || !std::isfinite(v)) return false;
        out[n++] = v;
        if (*end == '\0') break;
        if (*end != ',') return false;
        p = end + 1;
    }
    return n >= n_min;
}

double quantised(double v, double lsb) { return std::round(v / lsb) * lsb; }

// The sensor-error model over a file: the errors, the noise levels (per sample), the two
// noise sequences and the bias's random walk.
struct Measuring {
    const SensorErrors& err;
    double gyro_sigma_rad_s, accel_sigma_m_s2, mag_sigma_uT;
    double walk_step_dps;  // the random walk's step per sample
    Noise noise, walk_noise;
    double walk_dps[3] = {0, 0, 0};

    // noisy: white noise at rate_hz, the datasheet's densities or the fixed amounts as err
    // says; else none.
    Measuring(const SensorErrors& errors, double rate_hz, bool noisy) : err(errors) {
        if (err.seed != 0) noise.state ^= err.seed * 0xD1B54A32D192ED03ull;
        walk_noise.state = noise.state ^ 0x5851F42D4C957F2Dull;  // its own: the options never shift the default noise
        const bool datasheet = err.datasheet_noise, none = !noisy;
        gyro_sigma_rad_s = none ? 0.0 : datasheet ? kGyroDensity_dps_sqrt_hz * std::sqrt(rate_hz / 2.0) * kRadPerDeg : kGyroNoise_rad_s;
        accel_sigma_m_s2 = none ? 0.0
                           : datasheet ? kAccelDensity_g_sqrt_hz * kGravity_m_s2 * std::sqrt(rate_hz / 2.0)
                                       : kAccelNoise_m_s2;
        mag_sigma_uT = none ? 0.0 : datasheet ? kMagFloor_uT : kMagNoise_uT;
        // Random walk: each step adds sigma * sqrt(dt) with sigma in deg/s per sqrt(s).
        walk_step_dps = err.gyro_walk_dps_per_sqrt_min / std::sqrt(60.0) * std::sqrt(1.0 / rate_hz);
    }

    // The measured columns of one sample from the true rate, specific force and field in
    // body axes (SensorErrors' model; extra_bias_rad_s and vibration_m_s2: a scenario's own).
    void measure(double t_s, const double extra_bias_rad_s[3], double vibration_m_s2, double gyro[3], double accel[3],
                 const double field_body[3], double mag[3]) {
        for (int i = 0; i < 3; ++i)
            mag[i] = err.soft_iron[i][0] * field_body[0] + err.soft_iron[i][1] * field_body[1] +
                     err.soft_iron[i][2] * field_body[2] + err.hard_iron_uT[i];
        for (int i = 0; i < 3; ++i) {
            const double bias_dps = err.gyro_bias_dps[i] + err.gyro_drift_dps_per_min[i] * t_s / 60.0 + walk_dps[i];
            gyro[i] += extra_bias_rad_s[i] + bias_dps * kRadPerDeg + gyro_sigma_rad_s * noise.gauss();
            accel[i] = err.accel_scale[i] * accel[i] + err.accel_offset_m_s2[i];
            accel[i] += accel_sigma_m_s2 * noise.gauss() + vibration_m_s2 * noise.gauss();
            mag[i] += mag_sigma_uT * noise.gauss();
            if (walk_step_dps > 0.0) walk_dps[i] += walk_step_dps * walk_noise.gauss();
        }
    }
};

void quantise(double gyro[3], double accel[3], double mag[3]) {
    for (int i = 0; i < 3; ++i) {
        gyro[i] = quantised(gyro[i], kGyroLsb_dps * kRadPerDeg);
        accel[i] = quantised(accel[i], kAccelLsb_m_s2);
        mag[i] = quantised(mag[i], kMagLsb_uT);
    }
}

// --from FILE: the sensor errors on a trajectory's measured columns (a flight of
// sim/flight/fly.py, a recording), its truth and movement as they are; noise only as
// --noise asks (the file has its own). 0 on success.
int errors_on_file(const std::string& path, const SensorErrors& err, bool noisy) {
    sim::Trajectory in;
    if (!in.load(path)) {
        std::fprintf(stderr, "scenario: %s\n", in.error().c_str());
        return 1;
    }
    const double span_s = in.size() < 2 ? 0.0 : in[in.size() - 1].t_s - in[0].t_s;
    if (!(span_s > 0.0)) {
        std::fprintf(stderr, "scenario: %s: needs two samples or more, in time order\n", path.c_str());
        return 1;
    }
    const double rate_hz = (double)(in.size() - 1) / span_s;
    Measuring m(err, rate_hz, noisy);
    const double no_extra[3] = {0, 0, 0};
    std::fputs(sim::kTrajectoryHeader, stdout);
    for (size_t k = 0; k < in.size(); ++k) {
        sim::TrajectorySample row = in[k];
        const double field_body[3] = {row.mag_uT[0], row.mag_uT[1], row.mag_uT[2]};
        m.measure(row.t_s, no_extra, 0.0, row.gyro_rad_s, row.accel_m_s2, field_body, row.mag_uT);
        if (err.quantise) quantise(row.gyro_rad_s, row.accel_m_s2, row.mag_uT);
        std::fputs(sim::format_trajectory_row(row).c_str(), stdout);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<Scenario> list = scenarios();
    std::string name, from;
    double seconds = -1.0, rate_hz = 400.0;
    SensorErrors err;
    bool noise_asked = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        const bool has_value = i + 1 < argc;
        int n = 0;
        if (arg == "--list") {
            print_list_with_options(list);
            return 0;
        } else if (arg == "--help" || arg == "-h") {
            std::printf("usage: scenario NAME [--seconds S] [--rate HZ] [options] > FILE.csv\n"
                        "       scenario --from TRAJECTORY.csv[.gz] [options] > FILE.csv\n"
                        "       scenario --list\n%s\nscenarios:\n", kOptionsHelp);
            print_list(list);
            return 0;
        } else if (arg == "--seconds" && has_value) {
            seconds = std::atof(argv[++i]);
        } else if (arg == "--rate" && has_value) {
            rate_hz = std::atof(argv[++i]);
        } else if (arg == "--preset" && has_value) {
            if (std::strcmp(argv[++i], "uncalibrated") != 0) {
                std::fprintf(stderr, "scenario: unknown preset '%s' (there is: uncalibrated)\n", argv[i]);
                return 1;
            }
            set_uncalibrated(err);
            noise_asked = true;
        } else if ((arg == "--gyro-bias" || arg == "--gyro-drift" || arg == "--accel-offset" ||
                    arg == "--accel-scale" || arg == "--hard-iron") && has_value) {
            double* out = arg == "--gyro-bias"      ? err.gyro_bias_dps
                          : arg == "--gyro-drift"   ? err.gyro_drift_dps_per_min
                          : arg == "--accel-offset" ? err.accel_offset_m_s2
                          : arg == "--accel-scale"  ? err.accel_scale
                                                    : err.hard_iron_uT;
            double v[3];
            if (!parse_list(argv[++i], v, 3, 3, n)) {
                std::fprintf(stderr, "scenario: %s needs X,Y,Z (three numbers), not '%s'\n", arg.c_str(), argv[i]);
                return 1;
            }
            for (int k = 0; k < 3; ++k) out[k] = v[k];
        } else if (arg == "--gyro-walk" && has_value) {
            double v[1];
            if (!parse_list(argv[++i], v, 1, 1, n) || v[0] < 0.0) {
                std::fprintf(stderr, "scenario: --gyro-walk needs one number >= 0, not '%s'\n", argv[i]);
                return 1;
            }
            err.gyro_walk_dps_per_sqrt_min = v[0];
        } else if (arg == "--soft-iron" && has_value) {
            double v[9];
            if (!parse_list(argv[++i], v, 3, 9, n) || (n != 3 && n != 6 && n != 9)) {
                std::fprintf(stderr, "scenario: --soft-iron needs 3, 6 or 9 numbers, not '%s'\n", argv[i]);
                return 1;
            }
            double (&m)[3][3] = err.soft_iron;
            if (n == 9) {
                for (int k = 0; k < 9; ++k) m[k / 3][k % 3] = v[k];
            } else {
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c) m[r][c] = r == c ? v[r] : 0.0;
                if (n == 6) {
                    m[0][1] = m[1][0] = v[3];
                    m[0][2] = m[2][0] = v[4];
                    m[1][2] = m[2][1] = v[5];
                }
            }
        } else if (arg == "--noise" && has_value) {
            const std::string v = argv[++i];
            if (v != "datasheet" && v != "default") {
                std::fprintf(stderr, "scenario: --noise is datasheet or default, not '%s'\n", v.c_str());
                return 1;
            }
            err.datasheet_noise = v == "datasheet";
            noise_asked = true;
        } else if (arg == "--quantise" || arg == "--quantize") {
            err.quantise = true;
        } else if (arg == "--seed" && has_value) {
            err.seed = std::strtoull(argv[++i], nullptr, 10);
        } else if (arg == "--from" && has_value) {
            from = argv[++i];
        } else if (name.empty() && arg[0] != '-') {
            name = arg;
        } else {
            std::fprintf(stderr, "scenario: unknown argument '%s' (try --help)\n", arg.c_str());
            return 1;
        }
    }
    if (!from.empty()) {
        if (!name.empty() || seconds >= 0.0) {
            std::fprintf(stderr, "scenario: --from takes the file's motion and length: no NAME or --seconds\n");
            return 1;
        }
        return errors_on_file(from, err, noise_asked);
    }
    const Scenario* scenario = nullptr;
    for (const Scenario& s : list)
        if (name == s.name) scenario = &s;
    if (!scenario) {
        std::fprintf(stderr, "scenario: unknown scenario '%s'; these exist:\n", name.c_str());
        print_list(list);
        return 1;
    }
    if (!(rate_hz > 0.0)) {
        std::fprintf(stderr, "scenario: --rate must be positive\n");
        return 1;
    }
    const sim::motion::Plan plan = sim::motion::make_plan(scenario->motion, err.seed);
    const bool moving = scenario->motion != sim::motion::kNone;
    if (seconds < 0.0) seconds = moving ? plan.end_s : scenario->keys.back().t_s;
    auto attitude_at = [&](double t_s) {
        return moving ? sim::motion::attitude(plan, t_s) : attitude(*scenario, t_s);
    };

    const Extras& x = scenario->extras;
    Measuring m(err, rate_hz, true);
    std::fputs(sim::kTrajectoryHeader, stdout);
    const long n = (long)std::floor(seconds * rate_hz + 1e-9);
    const double h_s = 1e-5;
    for (long k = 0; k <= n; ++k) {
        const double t_s = (double)k / rate_hz;
        const Quat q = attitude_at(t_s);
        // omega_body = 2 vec(q* dq/dt)
        const Quat qp = attitude_at(t_s + h_s), qm = attitude_at(t_s - h_s);
        const Quat dq{(qp.w - qm.w) / (2 * h_s), (qp.x - qm.x) / (2 * h_s), (qp.y - qm.y) / (2 * h_s),
                      (qp.z - qm.z) / (2 * h_s)};
        const Quat omega = q.conj() * dq;
        double gyro[3] = {2 * omega.x, 2 * omega.y, 2 * omega.z};

        const double down_g[3] = {0.0, 0.0, -kGravity_m_s2};  // specific force at rest, earth frame
        double accel[3];
        if (moving) {  // specific force = R^T ((0, 0, -g) + a), a the motion's linear acceleration
            double force_ned[3];
            sim::motion::accel_ned(plan, t_s, force_ned);
            force_ned[2] -= kGravity_m_s2;
            earth_to_body(q, force_ned, accel);
        } else {
            earth_to_body(q, down_g, accel);
        }
        double field_ned[3] = {kEarthField_uT[0], kEarthField_uT[1], kEarthField_uT[2]};
        if (t_s >= x.disturb_from_s && t_s < x.disturb_to_s)
            for (int i = 0; i < 3; ++i) field_ned[i] += x.disturb_uT[i];
        double field_body[3];
        earth_to_body(q, field_ned, field_body);
        double mag[3];
        m.measure(t_s, x.gyro_bias_rad_s, x.vibration_m_s2, gyro, accel, field_body, mag);
        accel[2] += x.vibration_tone_m_s2 * std::sin(2 * kPi * 25.0 * t_s);
        if (err.quantise) quantise(gyro, accel, mag);
        sim::TrajectorySample row{t_s, {gyro[0], gyro[1], gyro[2]}, {accel[0], accel[1], accel[2]},
                                  {mag[0], mag[1], mag[2]}, {q.w, q.x, q.y, q.z}, t_s >= kStartup_s};
        std::fputs(sim::format_trajectory_row(row).c_str(), stdout);
    }
    return 0;
}
