// SPDX-License-Identifier: GPL-3.0-or-later
// build/replay: the firmware's estimator on the host (contract: ../shared/SIM.md).
//
//   build/replay --trajectory FILE.csv[.gz] [--seconds S] [--log] [--set NAME=VALUE ...]
//                [--airspeed M_S | --airspeed-log LOG.csv] [--gps-log LOG.csv [--gps-seed N]] [--trace FILE.csv] [--samples FILE.csv]
//
// The same pipeline as the board, minus the AVR: the simulator's register models
// (sim/models) answer the very drivers the firmware runs (lib/MPU6000, lib/HMC5883)
// through their bus seams, the bytes are decoded by the same code, and the same
// AttitudePipeline (lib/Pipeline: gyro calibration at rest, DCM at the fixed 5 ms
// step, mag folded in when DRDY says so) produces the angles. Time is the models':
// each step waits for the MPU6000's data-ready, as the firmware's loop does.
//
// stdout: CSV `t,roll,pitch,yaw` (s, degrees; yaw = heading 0..360 with the default
// declination) at the firmware's output rate. --log sends the pipeline's "# " lines
// (calibration, warnings) to stderr. --trace writes, per estimator step (200 Hz), the
// error against the trajectory's truth and what each correction did (lib/DCM/Trace.h):
// stdout is the same with or without it. --samples writes the estimator's input, decoded,
// as a trajectory file (a peer on the same samples as ours).
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "Hmc5883.h"
#include "Hmc5883Model.h"
#include "Mpu6000.h"
#include "Mpu6000Model.h"
#include "Pipeline.h"
#include "PipelineText.h"
#include "ScoreMetric.h"
#include "Text.h"
#include "Trajectory.h"
#include "UbloxFeed.h"

namespace {

void usage(FILE* out) {
    fprintf(out,
            "usage: replay --trajectory FILE.csv[.gz] [--seconds S] [--log] [--set NAME=VALUE ...]\n"
            "  Runs the firmware's drivers, calibration and DCM on the host against the\n"
            "  simulated MPU6000 and HMC5883L, and prints CSV t,roll,pitch,yaw (degrees)\n"
            "  at the firmware's output rate.\n"
            "  --seconds S  stop after S simulated seconds (default: the trajectory's length)\n"
            "  --log        the pipeline's messages (calibration, warnings) on stderr\n"
            "  --set NAME=VALUE  one of the estimator's settings instead of the firmware's\n"
            "               (lib/DCM/Dcm.h, DcmSettings; angles in degrees): for tuning and\n"
            "               cross-validation (bench/tune.py). --set list prints them.\n"
            "  --airspeed M_S  a configured cruise speed (the firmware's TRIM_ARSPD_CM,\n"
            "               for the centripetal correction), grown in a banked turn as\n"
            "               the firmware does: default none\n"
            "  --airspeed-log LOG.csv  the airspeed over time from a flight's state log\n"
            "               (sim/flight: columns t and airspeed_m_s), given every\n"
            "               8 steps as the firmware reads its sensor\n"
            "  --gps-log LOG.csv  a GPS on the flight's path: the state log's t, north_m,\n"
            "               east_m, down_m, vn_m_s, ve_m_s, vd_m_s (sim/flight) drive the\n"
            "               simulator's u-blox model (0.2 s latency, 0.1 m/s velocity\n"
            "               noise, first fix at 3 s), configured for UBX at 5 Hz; each\n"
            "               fix goes to the pipeline (AttitudePipeline::on_gps_fix)\n"
            "  --gps-seed N  the GPS model's noise seed (default 1)\n"
            "  --trace FILE.csv  per estimator step (200 Hz, from the estimator's start):\n"
            "               the error against the trajectory's truth (signed, deg; the tilt\n"
            "               error split about magnetic north and east; the heading error a\n"
            "               compass would see from that tilt, tilt_n tan(dip)), which\n"
            "               corrections ran and why (gravity: ran/not_due/no_direction and\n"
            "               held; heading: used/disturbed/new_field/too_vertical/not_due and\n"
            "               the error it measured), the field against the learned reference,\n"
            "               rest, and the gyro bias estimate (deg/s) with its changes summed\n"
            "               by source (gravity integrator, compass integrator, rest), the\n"
            "               status bits and the matrix R as a quaternion (body to NED; the\n"
            "               errors are those of the printed angles, R carried forward) and\n"
            "               the accelerometer's sample as the step used it (m/s^2).\n"
            "               stdout is unchanged.\n"
            "  --samples FILE.csv  the estimator's input as a trajectory file: per\n"
            "               MPU6000 sample (200 Hz) the gyro and accelerometer as the\n"
            "               driver decoded them, the latest compass read (uT, held; NaN\n"
            "               before the first) and the truth at that time, so that a peer\n"
            "               can run on what the firmware sees. stdout is unchanged.\n");
}

// The estimator's settings by name, for --set (DcmSettings in lib/DCM/Dcm.h).
struct SettingName {
    const char* name;
    float dcm::DcmSettings::*member;
    float scale;  // from the command line's unit to the setting's
};
const SettingName kSettingNames[] = {
    {"kp_rp_1_s", &dcm::DcmSettings::kp_rp_1_s, 1.0f},
    {"ki_rp_1_s2", &dcm::DcmSettings::ki_rp_1_s2, 1.0f},
    {"ki_rp_measured_1_s2", &dcm::DcmSettings::ki_rp_measured_1_s2, 1.0f},
    {"kp_yaw_1_s", &dcm::DcmSettings::kp_yaw_1_s, 1.0f},
    {"ki_yaw_1_s2", &dcm::DcmSettings::ki_yaw_1_s2, 1.0f},
    {"kp_startup_1_s", &dcm::DcmSettings::kp_startup_1_s, 1.0f},
    {"startup_s", &dcm::DcmSettings::startup_s, 1.0f},
    {"accel_lowpass_s", &dcm::DcmSettings::accel_lowpass_s, 1.0f},
    {"integrator_hold_rate_deg_s", &dcm::DcmSettings::integrator_hold_rate_rad_s, linalg::kRadPerDeg},
    {"bias_limit_deg_s", &dcm::DcmSettings::bias_limit_rad_s, linalg::kRadPerDeg},
    {"mag_norm_tolerance", &dcm::DcmSettings::mag_norm_tolerance, 1.0f},
    {"mag_dip_tolerance", &dcm::DcmSettings::mag_dip_tolerance, 1.0f},
    {"mag_recover_s", &dcm::DcmSettings::mag_recover_s, 1.0f},
    {"mag_latency_s", &dcm::DcmSettings::mag_latency_s, 1.0f},
    {"rest_gyro_deviation_deg_s", &dcm::DcmSettings::rest_gyro_deviation_rad_s, linalg::kRadPerDeg},
    {"rest_accel_deviation_m_s2", &dcm::DcmSettings::rest_accel_deviation_m_s2, 1.0f},
    {"rest_min_s", &dcm::DcmSettings::rest_min_s, 1.0f},
    {"rest_bias_s", &dcm::DcmSettings::rest_bias_s, 1.0f},
    {"output_lead_s", &dcm::DcmSettings::output_lead_s, 1.0f},
    {"gps_lowpass_s", &dcm::DcmSettings::gps_lowpass_s, 1.0f},
    {"mag_new_min_rate_deg_s", &dcm::DcmSettings::mag_new_min_rate_rad_s, linalg::kRadPerDeg},
};

// NAME=VALUE into settings; false (with a message) for an unknown name or a bad number.
bool set_setting(dcm::DcmSettings& settings, const std::string& assignment) {
    const size_t eq = assignment.find('=');
    const std::string name = assignment.substr(0, eq);
    for (const SettingName& s : kSettingNames) {
        if (name != s.name) continue;
        char* end = nullptr;
        const char* text = eq == std::string::npos ? "" : assignment.c_str() + eq + 1;
        const double value = strtod(text, &end);
        if (!*text || !end || *end || !(value == value)) {
            fprintf(stderr, "replay: --set %s needs a number, not '%s'\n", name.c_str(), text);
            return false;
        }
        settings.*(s.member) = (float)value * s.scale;
        return true;
    }
    fprintf(stderr, "replay: --set: no setting '%s' (--set list names them)\n", name.c_str());
    return false;
}

// Simulated time shared by both sensor models; the drivers' waits move it on.
struct Board {
    sim::Mpu6000Model* mpu;
    sim::Hmc5883Model* mag;
    double t_s;
    uint32_t spi_clock_hz;

    void advance(double to_s) {
        if (to_s < t_s) return;
        t_s = to_s;
        mpu->advance_to(t_s);
        mag->advance_to(t_s);
    }
};

void spi_select(void* ctx, bool selected, uint32_t clock_hz) {
    Board* b = static_cast<Board*>(ctx);
    b->spi_clock_hz = clock_hz;
    b->mpu->set_chip_select(selected);
}
uint8_t spi_transfer(void* ctx, uint8_t out) {
    Board* b = static_cast<Board*>(ctx);
    return b->mpu->transfer(out, (double)b->spi_clock_hz);
}
void delay_ms(void* ctx, uint16_t ms) {
    Board* b = static_cast<Board*>(ctx);
    b->advance(b->t_s + ms * 1e-3);
}
bool i2c_write_reg(void* ctx, uint8_t addr7, uint8_t reg, uint8_t value) {
    Board* b = static_cast<Board*>(ctx);
    return addr7 == hmc5883::kAddress7 && b->mag->write_register(reg, value);
}
bool i2c_read_regs(void* ctx, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len) {
    Board* b = static_cast<Board*>(ctx);
    return addr7 == hmc5883::kAddress7 && b->mag->read_registers(reg, data, len);
}

void log_write(void*, const char* data, uint8_t len) { fwrite(data, 1, len, stderr); }

// Hundredths of a degree as the firmware prints them ("-0.05", never "-0.00").
void print_centideg(int32_t c, char end) {
    char buf[16];
    const uint8_t n = text::format_fixed(buf, c, 2);
    printf("%.*s%c", (int)n, buf, end);
}

const char* gravity_word(dcm::GravityEvent e) {
    switch (e) {
        case dcm::GravityEvent::kRan: return "ran";
        case dcm::GravityEvent::kNoDirection: return "no_direction";
        default: return "not_due";
    }
}

const char* heading_word(dcm::HeadingEvent e) {
    switch (e) {
        case dcm::HeadingEvent::kTooVertical: return "too_vertical";
        case dcm::HeadingEvent::kDisturbed: return "disturbed";
        case dcm::HeadingEvent::kNewField: return "new_field";
        case dcm::HeadingEvent::kUsed: return "used";
        default: return "not_due";
    }
}

double wrap_deg(double d) {
    while (d > 180.0) d -= 360.0;
    while (d <= -180.0) d += 360.0;
    return d;
}

// Roll, pitch, yaw (deg) of a body -> earth quaternion (Z-Y-X, as the firmware prints).
void euler_deg(const score::Quat& q, double out[3]) {
    out[0] = score::rad2deg(std::atan2(2.0 * (q.w * q.x + q.y * q.z), 1.0 - 2.0 * (q.x * q.x + q.y * q.y)));
    const double s = 2.0 * (q.w * q.y - q.z * q.x);
    out[1] = score::rad2deg(std::asin(s > 1.0 ? 1.0 : (s < -1.0 ? -1.0 : s)));
    out[2] = score::rad2deg(std::atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z)));
}

// v turned by the unit quaternion q (body -> earth).
void rotate(const score::Quat& q, const double v[3], double out[3]) {
    const score::Quat p{0.0, v[0], v[1], v[2]};
    const score::Quat r = score::quat_mul(score::quat_mul(q, p), score::quat_conj(q));
    out[0] = r.x;
    out[1] = r.y;
    out[2] = r.z;
}

// --trace: one row per estimator step.
class TraceWriter {
public:
    explicit TraceWriter(FILE* out) : out_(out) {
        if (!out_) return;
        fprintf(out_,
                "t,roll_err_deg,pitch_err_deg,heading_err_deg,incl_err_deg,tilt_n_deg,tilt_e_deg,"
                "true_dip_deg,tilt_n_tan_dip_deg,gravity,integrator_held,gravity_kp_1_s,est_tilt_n_deg,"
                "est_tilt_e_deg,rest,heading,mag_err_deg,field_norm_uT,field_dip_deg,ref_norm_uT,ref_dip_deg,"
                "bias_x_deg_s,bias_y_deg_s,bias_z_deg_s,grav_bias_x_deg_s,grav_bias_y_deg_s,grav_bias_z_deg_s,"
                "mag_bias_x_deg_s,mag_bias_y_deg_s,mag_bias_z_deg_s,rest_bias_x_deg_s,rest_bias_y_deg_s,"
                "rest_bias_z_deg_s,status,r_qw,r_qx,r_qy,r_qz,ax_m_s2,ay_m_s2,az_m_s2\n");
    }

    // The step just run: the estimate (as printed) against the truth at t.
    void row(double t_s, const sim::TrajectorySample& truth, const pipeline::AttitudePipeline& pipe,
             const dcm::DcmTrace& tr) {
        const pipeline::Angles a = pipe.angles();
        const score::Quat q_est = score::quat_from_euler_deg(a.roll_deg, a.pitch_deg, a.heading_deg);
        const score::Quat q_true{truth.quat[0], truth.quat[1], truth.quat[2], truth.quat[3]};
        double err[9];
        for (double& e : err) e = NAN;
        if (score::quat_finite(q_true)) {
            const score::Quat qt = score::quat_normalized(q_true);
            // The magnetic north and dip in the truth's earth frame: the field turned into
            // it, averaged (10 s) so that the sensor's noise does not turn the axes.
            double field_earth[3];
            rotate(qt, truth.mag_uT, field_earth);
            const double alpha = have_field_ ? 0.005 / 10.0 : 1.0;
            for (int i = 0; i < 3; ++i) field_ef_[i] += alpha * (field_earth[i] - field_ef_[i]);
            have_field_ = true;
            const double horizontal = std::hypot(field_ef_[0], field_ef_[1]);
            const double dip_rad = std::atan2(field_ef_[2], horizontal);
            const double cn = horizontal > 0.0 ? field_ef_[0] / horizontal : 1.0;
            const double sn = horizontal > 0.0 ? field_ef_[1] / horizontal : 0.0;
            double e_true[3], e_est[3];
            euler_deg(qt, e_true);
            euler_deg(q_est, e_est);
            // The error in the earth frame, e = q_est q_true^-1, as its rotation vector.
            score::Quat e = score::quat_normalized(score::quat_mul(q_est, score::quat_conj(qt)));
            if (e.w < 0.0) e = score::Quat{-e.w, -e.x, -e.y, -e.z};
            const double vn = std::sqrt(e.x * e.x + e.y * e.y + e.z * e.z);
            const double angle = 2.0 * std::atan2(vn, e.w);
            const double k = vn > 1e-12 ? angle / vn : 2.0;
            const double rx = k * e.x, ry = k * e.y;
            const score::ErrorAngles split = score::error_angles(qt, q_est);
            err[0] = wrap_deg(e_est[0] - e_true[0]);
            err[1] = wrap_deg(e_est[1] - e_true[1]);
            err[2] = score::rad2deg(2.0 * std::atan2(e.z, e.w));  // signed: estimate - truth
            err[3] = score::rad2deg(split.inclination_rad);
            err[4] = score::rad2deg(cn * rx + sn * ry);   // about magnetic north
            err[5] = score::rad2deg(-sn * rx + cn * ry);  // about magnetic east
            err[6] = score::rad2deg(dip_rad);
            // The compass measures heading - tilt_n tan(dip) (a field (H, 0, Z) seen in an
            // earth frame tilted by tilt_n about north has an east part -tilt_n Z): driving
            // that to zero puts the heading at tilt_n tan(dip).
            err[7] = err[4] * std::tan(dip_rad);
        }
        const dcm::Dcm& d = pipe.estimator();
        const linalg::Vector3f b = d.gyro_bias_rad_s();
        fprintf(out_, "%.4f", t_s);
        for (int i = 0; i < 8; ++i) fprintf(out_, ",%.4f", err[i]);
        const double deg = 1.0 / (double)linalg::kRadPerDeg;
        fprintf(out_, ",%s,%d,%.4f,%.4f,%.4f,%d,%s,%.4f,%.3f,%.3f,%.3f,%.3f", gravity_word(tr.gravity),
                tr.integrator_held ? 1 : 0, (double)tr.gravity_kp_1_s, tr.tilt_error_n_rad * deg,
                tr.tilt_error_e_rad * deg, (d.status() & dcm::kStatusAtRest) ? 1 : 0, heading_word(tr.heading),
                (double)tr.heading_error_deg, (double)tr.field_norm_uT, (double)tr.field_dip_deg,
                (double)tr.ref_norm_uT, (double)tr.ref_dip_deg);
        const linalg::Vector3f* vs[4] = {&b, &tr.bias_from_gravity_rad_s, &tr.bias_from_heading_rad_s,
                                         &tr.bias_from_rest_rad_s};
        for (const linalg::Vector3f* v : vs) fprintf(out_, ",%.5f,%.5f,%.5f", v->x * deg, v->y * deg, v->z * deg);
        const linalg::Quaternion r = pipe.quaternion();
        const linalg::Vector3f accel = pipe.accel_m_s2();
        fprintf(out_, ",0x%02x,%.7f,%.7f,%.7f,%.7f,%.4f,%.4f,%.4f\n", (unsigned)d.status(), (double)r.w, (double)r.x,
                (double)r.y, (double)r.z, (double)accel.x, (double)accel.y, (double)accel.z);
    }

private:
    FILE* out_;
    double field_ef_[3] = {0.0, 0.0, 0.0};
    bool have_field_ = false;
};

}  // namespace

// --samples: one trajectory row per MPU6000 sample as the drivers decoded it (gyro
// rad/s and accel m/s^2 in body axes, the latest compass read in uT, held until the
// next; NaN before the first), with the truth at that time: the estimator's own input,
// for a peer to run on what the firmware sees (the sensor models' ranges, resolution,
// low-pass and rates) instead of the recording as it is.
void write_sample_row(FILE* out, double t_s, const mpu6000::Sample& sample, const sim::TrajectorySample& truth,
                      sim::TrajectorySample& row) {
    const linalg::Vector3f gyro = sample.gyro_rad_s(), accel = sample.accel_m_s2();
    row.t_s = t_s;
    row.gyro_rad_s[0] = gyro.x;
    row.gyro_rad_s[1] = gyro.y;
    row.gyro_rad_s[2] = gyro.z;
    row.accel_m_s2[0] = accel.x;
    row.accel_m_s2[1] = accel.y;
    row.accel_m_s2[2] = accel.z;
    for (int i = 0; i < 4; ++i) row.quat[i] = truth.quat[i];
    row.movement = truth.movement;
    fputs(sim::format_trajectory_row(row).c_str(), out);
}

// The state log's airspeed (sim/flight/flightio.py LOG_HEADER: t and airspeed_m_s
// columns), as (t, airspeed) pairs; false with a message when unreadable.
// The named columns of a flight's state log (sim/flight: a CSV with a header), one row of
// them per line, each finite; false (with a message) when a column is missing or a value
// is not finite.
bool load_log_columns(const std::string& path, const std::vector<const char*>& names,
                      std::vector<std::vector<double>>& rows) {
    FILE* f = fopen(path.c_str(), "r");
    if (!f) {
        fprintf(stderr, "replay: cannot open %s\n", path.c_str());
        return false;
    }
    char line[1024];
    std::vector<int> cols(names.size(), -1);
    if (fgets(line, sizeof line, f)) {
        int col = 0;
        for (char* tok = strtok(line, ",\r\n"); tok; tok = strtok(nullptr, ",\r\n"), ++col)
            for (size_t k = 0; k < names.size(); ++k)
                if (strcmp(tok, names[k]) == 0) cols[k] = col;
    }
    for (size_t k = 0; k < names.size(); ++k) {
        if (cols[k] >= 0) continue;
        fprintf(stderr, "replay: %s has no %s column\n", path.c_str(), names[k]);
        fclose(f);
        return false;
    }
    int line_no = 1;
    while (fgets(line, sizeof line, f)) {
        ++line_no;
        std::vector<double> row(names.size(), NAN);
        int col = 0;
        for (char* tok = strtok(line, ",\r\n"); tok; tok = strtok(nullptr, ",\r\n"), ++col)
            for (size_t k = 0; k < names.size(); ++k)
                if (col == cols[k]) row[k] = strtod(tok, nullptr);
        for (size_t k = 0; k < names.size(); ++k) {
            if (std::isfinite(row[k])) continue;
            fprintf(stderr, "replay: %s line %d: no finite %s\n", path.c_str(), line_no, names[k]);
            fclose(f);
            return false;
        }
        rows.push_back(row);
    }
    fclose(f);
    return true;
}

bool load_airspeed_log(const std::string& path, std::vector<std::pair<double, double>>& out) {
    std::vector<std::vector<double>> rows;
    if (!load_log_columns(path, {"t", "airspeed_m_s"}, rows)) return false;
    for (const std::vector<double>& r : rows) out.emplace_back(r[0], r[1]);
    return true;
}

// The flight's path from its state log (t, position and velocity NED), for the GPS model.
bool load_gps_path(const std::string& path, sim::Trajectory& out) {
    std::vector<std::vector<double>> rows;
    if (!load_log_columns(path, {"t", "north_m", "east_m", "down_m", "vn_m_s", "ve_m_s", "vd_m_s"}, rows)) return false;
    for (const std::vector<double>& r : rows) {
        sim::TrajectorySample s{};
        s.t_s = r[0];
        for (int k = 0; k < 3; ++k) {
            s.ned_m[k] = r[1 + k];
            s.vel_ned_m_s[k] = r[4 + k];
        }
        s.quat[0] = 1.0;
        out.append(s);
    }
    return true;
}

int main(int argc, char** argv) {
    std::string path;
    double seconds = -1.0;
    bool log = false;
    double airspeed_m_s = 0.0;
    std::vector<std::pair<double, double>> airspeed_log;
    std::string trace_path;
    std::string samples_path;
    std::string gps_log_path;
    uint64_t gps_seed = 1;
    dcm::DcmSettings dcm_settings = dcm::kDefaultDcmSettings;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--trajectory" && i + 1 < argc) {
            path = argv[++i];
        } else if (a == "--seconds" && i + 1 < argc) {
            char* end = nullptr;
            seconds = strtod(argv[++i], &end);
            if (!end || *end || !(seconds > 0.0)) {
                fprintf(stderr, "replay: --seconds needs a positive number, not '%s'\n", argv[i]);
                return 1;
            }
        } else if (a == "--airspeed" && i + 1 < argc) {
            char* end = nullptr;
            airspeed_m_s = strtod(argv[++i], &end);
            if (!end || *end || !(airspeed_m_s >= 0.0 && airspeed_m_s < 1000.0)) {
                fprintf(stderr, "replay: --airspeed needs a speed in m/s, not '%s'\n", argv[i]);
                return 1;
            }
        } else if (a == "--airspeed-log" && i + 1 < argc) {
            if (!load_airspeed_log(argv[++i], airspeed_log)) return 1;
        } else if (a == "--gps-log" && i + 1 < argc) {
            gps_log_path = argv[++i];
        } else if (a == "--gps-seed" && i + 1 < argc) {
            gps_seed = strtoull(argv[++i], nullptr, 10);
        } else if (a == "--trace" && i + 1 < argc) {
            trace_path = argv[++i];
        } else if (a == "--samples" && i + 1 < argc) {
            samples_path = argv[++i];
        } else if (a == "--log") {
            log = true;
        } else if (a == "--set" && i + 1 < argc) {
            if (std::string(argv[i + 1]) == "list") {
                for (const SettingName& s : kSettingNames)
                    printf("%s=%g\n", s.name, (double)(dcm_settings.*(s.member) / s.scale));
                return 0;
            }
            if (!set_setting(dcm_settings, argv[++i])) return 1;
        } else if (a == "--help" || a == "-h") {
            usage(stdout);
            return 0;
        } else {
            fprintf(stderr, "replay: unknown argument '%s'\n", a.c_str());
            usage(stderr);
            return 1;
        }
    }
    if (path.empty()) {
        usage(stderr);
        return 1;
    }
    sim::Trajectory trajectory;
    if (!trajectory.load(path)) {
        fprintf(stderr, "replay: %s\n", trajectory.error().c_str());
        return 2;
    }
    const double end_s = seconds > 0.0 ? seconds : trajectory.duration_s();
    // The optional outputs: none when not asked for; a file that cannot be written is an
    // error before anything runs.
    bool unwritable = false;
    const auto open_output = [&unwritable](const std::string& out_path) -> FILE* {
        if (out_path.empty()) return nullptr;
        FILE* f = fopen(out_path.c_str(), "w");
        if (!f) {
            fprintf(stderr, "replay: cannot write %s\n", out_path.c_str());
            unwritable = true;
        }
        return f;
    };
    FILE* trace_file = open_output(trace_path);
    FILE* samples_file = open_output(samples_path);
    if (unwritable) return 1;
    if (samples_file) fputs(sim::kTrajectoryHeader, samples_file);

    // The GPS: the u-blox model on the flight's path, its fixes into the pipeline.
    sim::Trajectory gps_path;
    if (!gps_log_path.empty() && !load_gps_path(gps_log_path, gps_path)) return 1;
    sim::UbloxOptions gps_options;
    gps_options.seed = gps_seed;
    std::unique_ptr<sim::UbloxFeed> gps;
    if (!gps_log_path.empty()) gps.reset(new sim::UbloxFeed(gps_path, gps_options));

    sim::Mpu6000Model mpu_model(trajectory);
    sim::Hmc5883Model mag_model(trajectory);
    Board board{&mpu_model, &mag_model, 0.0, mpu6000::kConfigClockHz};
    const mpu6000::SpiDevice spi{&board, spi_select, spi_transfer, delay_ms};
    const hmc5883::I2cBus i2c{&board, i2c_write_reg, i2c_read_regs, delay_ms};
    const text::Sink log_sink{nullptr, log_write};

    // Set-up, in the firmware's order and on its timeline (firmware/firmware.ino setup()).
    mpu6000::Mpu6000 mpu(spi);
    hmc5883::Hmc5883 mag(i2c);
    const pipeline::EventSink log_events = pipeline_text::events_to(&log_sink);
    pipeline::AttitudePipeline pipe(log ? &log_events : nullptr, dcm_settings);
    dcm::DcmTrace trace;
    if (trace_file) pipe.set_trace(&trace);
    TraceWriter trace_writer(trace_file);
    board.advance(pipeline::kMpuStartMs * 1e-3);
    const mpu6000::InitResult mpu_init = mpu.begin();
    if (mpu_init.status != mpu6000::InitStatus::Ok) {
        fprintf(stderr, "replay: the MPU6000 model did not come up (status %d)\n", (int)mpu_init.status);
        return 2;
    }
    board.advance(pipeline::kMagStartMs * 1e-3);
    const bool mag_ok = mag.begin(true).status == hmc5883::InitStatus::Ok;
    pipe.set_mag_present(mag_ok);
    if (!mag_ok) fprintf(stderr, "replay: the HMC5883L model did not come up: yaw is gyro-only\n");

    board.advance(pipeline::kLoopStartMs * 1e-3);
    printf("t,roll,pitch,yaw\n");
    uint32_t last_mag_read_step = 0;
    size_t airspeed_cursor = 0;
    sim::TrajectorySample as_read{};  // --samples: the latest values as the drivers decoded them
    for (double& m : as_read.mag_uT) m = NAN;
    while (board.t_s < end_s) {
        // Wait for the data-ready line, as the loop does.
        while (!mpu_model.int_pin_high() && board.t_s < end_s) board.advance(mpu_model.next_event_s());
        if (board.t_s >= end_s) break;
        trace.reset_step();
        mpu6000::Sample sample;
        if (mpu.read(sample) != mpu6000::BurstStatus::Ok) {
            fprintf(stderr, "replay: MPU6000 burst read failed at t=%.3f s\n", board.t_s);
            return 2;
        }
        if (mag_ok && mag_model.drdy_pin_high() && pipe.steps() - last_mag_read_step >= pipeline::kMagReadMinSteps) {
            linalg::Vector3f field_uT;
            if (mag.read(field_uT) == hmc5883::ReadStatus::Ok) {
                pipe.on_mag_sample(field_uT);
                as_read.mag_uT[0] = field_uT.x;
                as_read.mag_uT[1] = field_uT.y;
                as_read.mag_uT[2] = field_uT.z;
            }
            last_mag_read_step = pipe.steps();
        }
        if (samples_file) write_sample_row(samples_file, board.t_s, sample, trajectory.at(board.t_s), as_read);
        if (pipe.steps() % 8u == 0u) {
            if (!airspeed_log.empty()) {
                while (airspeed_cursor + 1 < airspeed_log.size() && airspeed_log[airspeed_cursor + 1].first <= board.t_s)
                    ++airspeed_cursor;
                pipe.set_airspeed_m_s((float)airspeed_log[airspeed_cursor].second);
            } else if (airspeed_m_s > 0.0) {
                pipe.set_cruise_airspeed_m_s((float)airspeed_m_s);  // as the firmware does with TRIM_ARSPD_CM
            }
        }
        gps::Fix fix;
        if (gps && gps->poll(board.t_s, fix)) pipe.on_gps_fix(fix);
        pipe.on_imu_sample(sample);
        if (trace_file && pipe.estimator().initialised()) trace_writer.row(board.t_s, trajectory.at(board.t_s), pipe, trace);
        if (pipe.output_due()) {
            // The hundredths the firmware prints, from the same integers.
            const pipeline::AnglesCentideg a = pipe.angles_centideg();
            printf("%.4f,", board.t_s);
            print_centideg(a.roll_centideg, ',');
            print_centideg(a.pitch_centideg, ',');
            print_centideg(a.heading_centideg, '\n');
        }
    }
    const bool trace_lost = trace_file && fclose(trace_file) != 0;
    if (trace_lost) fprintf(stderr, "replay: cannot write %s\n", trace_path.c_str());
    const bool samples_lost = samples_file && fclose(samples_file) != 0;
    if (samples_lost) fprintf(stderr, "replay: cannot write %s\n", samples_path.c_str());
    return trace_lost || samples_lost ? 1 : 0;
}
