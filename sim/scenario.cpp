// build/scenario: synthetic trajectories in the format of ../shared/SIM.md.
//
//   build/scenario NAME [--seconds S] [--rate HZ]     CSV on stdout
//   build/scenario --list                             names and one-line descriptions
//
// Physically consistent: each scenario is an analytic attitude q(t) (body -> earth, NED,
// built as Rz(yaw) Ry(pitch) Rx(roll) from smooth keyframed angles, any angle range);
// the body rate is omega = 2 vec(q* dq/dt) (central difference, h = 10 us), specific
// force = R^T (0, 0, -g) + linear acceleration, field = R^T * earth field. Earth field
// (NED) = (20, 0, 45) uT, a Berlin-like 49 uT at 66 deg inclination, declination 0.
// Sensor noise (white, fixed seed, so every run is identical): gyro 0.03 deg/s, accel
// 0.025 m/s^2, field 0.2 uT rms, about the MPU6000 / HMC5883L datasheet densities at the
// configured bandwidths. movement = 0 for the first 2 s (start-up), 1 after.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;
constexpr double kGravity_m_s2 = 9.80665;
constexpr double kEarthField_uT[3] = {20.0, 0.0, 45.0};  // NED
constexpr double kGyroNoise_rad_s = 0.03 * kDeg;
constexpr double kAccelNoise_m_s2 = 0.025;
constexpr double kMagNoise_uT = 0.2;
constexpr double kStartup_s = 2.0;

struct Quat {
    double w, x, y, z;
    Quat operator*(const Quat& q) const {
        return Quat{w * q.w - x * q.x - y * q.y - z * q.z, w * q.x + x * q.w + y * q.z - z * q.y,
                    w * q.y - x * q.z + y * q.w + z * q.x, w * q.z + x * q.y - y * q.x + z * q.w};
    }
    Quat conj() const { return Quat{w, -x, -y, -z}; }
};

Quat axis_angle(int axis, double angle_rad) {
    const double c = std::cos(angle_rad / 2), s = std::sin(angle_rad / 2);
    return Quat{c, axis == 0 ? s : 0.0, axis == 1 ? s : 0.0, axis == 2 ? s : 0.0};
}

// v_body = R^T v_earth with R the body -> earth rotation of q.
void earth_to_body(const Quat& q, const double v[3], double out[3]) {
    const Quat p{0.0, v[0], v[1], v[2]};
    const Quat r = q.conj() * p * q;
    out[0] = r.x;
    out[1] = r.y;
    out[2] = r.z;
}

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
        for (double& b : s.extras.gyro_bias_rad_s) b = 2.0 * kDeg;
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
    return axis_angle(2, yaw * kDeg) * axis_angle(1, pitch * kDeg) * axis_angle(0, roll * kDeg);
}

// Deterministic Gaussian noise: xorshift64* and Box-Muller (same numbers on every libc).
struct Noise {
    uint64_t state = 0x9E3779B97F4A7C15ull;
    double uniform() {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        return ((state * 2685821657736338717ull) >> 11) * (1.0 / 9007199254740992.0);
    }
    double gauss() {
        const double u1 = uniform() + 1e-300, u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2 * kPi * u2);
    }
};

void print_list(const std::vector<Scenario>& list) {
    for (const Scenario& s : list) {
        std::printf("%-16s %5.0f s  %s\n", s.name, s.keys.back().t_s, s.description);
    }
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<Scenario> list = scenarios();
    std::string name;
    double seconds = -1.0, rate_hz = 400.0;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--list") {
            print_list(list);
            return 0;
        } else if (arg == "--help" || arg == "-h") {
            std::printf("usage: scenario NAME [--seconds S] [--rate HZ] > FILE.csv\n       scenario --list\n");
            print_list(list);
            return 0;
        } else if (arg == "--seconds" && i + 1 < argc) {
            seconds = std::atof(argv[++i]);
        } else if (arg == "--rate" && i + 1 < argc) {
            rate_hz = std::atof(argv[++i]);
        } else if (name.empty() && arg[0] != '-') {
            name = arg;
        } else {
            std::fprintf(stderr, "scenario: unknown argument '%s' (try --help)\n", arg.c_str());
            return 1;
        }
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
    if (seconds < 0.0) seconds = scenario->keys.back().t_s;

    const Extras& x = scenario->extras;
    Noise noise;
    std::printf("t,gx,gy,gz,ax,ay,az,mx,my,mz,qw,qx,qy,qz,movement\n");
    const long n = (long)std::floor(seconds * rate_hz + 1e-9);
    const double h_s = 1e-5;
    for (long k = 0; k <= n; ++k) {
        const double t_s = (double)k / rate_hz;
        const Quat q = attitude(*scenario, t_s);
        // omega_body = 2 vec(q* dq/dt)
        const Quat qp = attitude(*scenario, t_s + h_s), qm = attitude(*scenario, t_s - h_s);
        const Quat dq{(qp.w - qm.w) / (2 * h_s), (qp.x - qm.x) / (2 * h_s), (qp.y - qm.y) / (2 * h_s),
                      (qp.z - qm.z) / (2 * h_s)};
        const Quat omega = q.conj() * dq;
        double gyro[3] = {2 * omega.x, 2 * omega.y, 2 * omega.z};

        const double down_g[3] = {0.0, 0.0, -kGravity_m_s2};  // specific force at rest, earth frame
        double accel[3];
        earth_to_body(q, down_g, accel);
        double field_ned[3] = {kEarthField_uT[0], kEarthField_uT[1], kEarthField_uT[2]};
        if (t_s >= x.disturb_from_s && t_s < x.disturb_to_s)
            for (int i = 0; i < 3; ++i) field_ned[i] += x.disturb_uT[i];
        double mag[3];
        earth_to_body(q, field_ned, mag);

        for (int i = 0; i < 3; ++i) {
            gyro[i] += x.gyro_bias_rad_s[i] + kGyroNoise_rad_s * noise.gauss();
            accel[i] += kAccelNoise_m_s2 * noise.gauss() + x.vibration_m_s2 * noise.gauss();
            mag[i] += kMagNoise_uT * noise.gauss();
        }
        accel[2] += x.vibration_tone_m_s2 * std::sin(2 * kPi * 25.0 * t_s);
        const Quat qc = q.w < 0 ? Quat{-q.w, -q.x, -q.y, -q.z} : q;  // scalar part >= 0
        std::printf("%.6f,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.7g,%.9f,%.9f,%.9f,%.9f,%d\n", t_s, gyro[0],
                    gyro[1], gyro[2], accel[0], accel[1], accel[2], mag[0], mag[1], mag[2], qc.w, qc.x, qc.y, qc.z,
                    t_s >= kStartup_s ? 1 : 0);
    }
    return 0;
}
