#include "FaultSpec.h"

#include <cstdlib>
#include <cstring>

namespace sim {

const char* const kFaultHelp =
    "Fault SPEC: TARGET:KIND[=VALUE][@T1[-T2]]  (times in simulated seconds; no @: the whole run;\n"
    "            @T1: from T1 on; @T1-T2: from T1 until T2, then the part is healthy again)\n"
    "  mpu:absent             MPU6000 does not answer: MISO reads 0x00, writes ignored, INT low\n"
    "                         (its registers are kept: a loose wire, not a power cycle)\n"
    "  mpu:whoami=0xNN        WHO_AM_I reads NN instead of 0x68 (whole run; no window)\n"
    "  mpu:int-stuck-low      the MPU6000 INT line (PE6) stays low\n"
    "  mpu:frozen             the data registers stop updating, no data-ready\n"
    "  gyro:saturate          every gyro axis reads the end of its range (+32767 / -32768)\n"
    "  accel:saturate         every accel axis reads the end of its range\n"
    "  imu:spike              absurd in-range gyro and accel counts (~+-30000 on every axis)\n"
    "  mag:absent             HMC5883L NACKs its address, DRDY low\n"
    "  mag:id=XYZ             the ID registers read the three characters XYZ (whole run)\n"
    "  mag:overflow           every channel reads -4096 (ADC overflow)\n"
    "  mag:spike              absurd in-range counts (2000, -1990, 2040)\n"
    "  mag:drdy-stuck-low     DRDY (pin 31, PC6) stays low\n"
    "  mag:drdy-stuck-high    DRDY stays high\n"
    "  i2c:sda-low            a slave holds SDA low: every I2C address is NACKed\n"
    "                         (simavr 1.6 cannot show a stuck bus; Wire sees errors, not a hang)\n"
    "Examples: --fault mpu:absent@2.0-5.0  --fault mag:overflow@2-5  --fault gyro:saturate@2-3\n";

namespace {

bool parse_window(const std::string& text, TimeWindow& window) {
    if (text.empty()) {
        window = TimeWindow::always();
        return true;
    }
    const char* p = text.c_str();
    char* end = nullptr;
    const double t1_s = strtod(p, &end);
    if (end == p || t1_s < 0.0) return false;
    window = TimeWindow::between(t1_s, TimeWindow::always().end_s);
    if (*end == 0) return true;
    if (*end != '-') return false;
    p = end + 1;
    const double t2_s = strtod(p, &end);
    if (end == p || *end != 0 || !(t2_s > t1_s)) return false;
    window.end_s = t2_s;
    return true;
}

}  // namespace

bool apply_fault_spec(const std::string& spec, Mpu6000Model& mpu, Hmc5883Model& mag, BusFaults& bus,
                      std::string& error) {
    const size_t colon = spec.find(':');
    const size_t at = spec.find('@');
    if (colon == std::string::npos || (at != std::string::npos && at < colon)) {
        error = "fault '" + spec + "': expected TARGET:KIND[=VALUE][@T1[-T2]]";
        return false;
    }
    const std::string target = spec.substr(0, colon);
    std::string kind = spec.substr(colon + 1, at == std::string::npos ? std::string::npos : at - colon - 1);
    std::string value;
    const size_t eq = kind.find('=');
    if (eq != std::string::npos) {
        value = kind.substr(eq + 1);
        kind = kind.substr(0, eq);
    }
    TimeWindow window;
    if (!parse_window(at == std::string::npos ? std::string() : spec.substr(at + 1), window)) {
        error = "fault '" + spec + "': the time window must be @T1 or @T1-T2 with 0 <= T1 < T2";
        return false;
    }
    const std::string what = target + ":" + kind;
    Mpu6000Faults& mf = mpu.faults();
    Hmc5883Faults& hf = mag.faults();
    if (what == "mpu:absent") mf.absent = window;
    else if (what == "mpu:int-stuck-low") mf.int_stuck_low = window;
    else if (what == "mpu:frozen") mf.frozen = window;
    else if (what == "gyro:saturate") mf.gyro_saturate = window;
    else if (what == "accel:saturate") mf.accel_saturate = window;
    else if (what == "imu:spike") mf.spike = window;
    else if (what == "mag:absent") hf.absent = window;
    else if (what == "mag:overflow") hf.overflow = window;
    else if (what == "mag:spike") hf.spike = window;
    else if (what == "mag:drdy-stuck-low") hf.drdy_stuck_low = window;
    else if (what == "mag:drdy-stuck-high") hf.drdy_stuck_high = window;
    else if (what == "i2c:sda-low") bus.i2c_sda_low = window;
    else if (what == "mpu:whoami") {
        char* end = nullptr;
        const long v = strtol(value.c_str(), &end, 0);
        if (value.empty() || *end != 0 || v < 0 || v > 255) {
            error = "fault '" + spec + "': mpu:whoami needs a byte value, e.g. mpu:whoami=0x70";
            return false;
        }
        mf.who_am_i = (int)v;
    } else if (what == "mag:id") {
        if (value.size() != 3) {
            error = "fault '" + spec + "': mag:id needs three characters, e.g. mag:id=H44";
            return false;
        }
        for (int i = 0; i < 3; ++i) hf.id[i] = (unsigned char)value[(size_t)i];
    } else {
        error = "fault '" + spec + "': unknown TARGET:KIND '" + what + "' (see --help)";
        return false;
    }
    if (!value.empty() && what != "mpu:whoami" && what != "mag:id") {
        error = "fault '" + spec + "': '" + what + "' takes no value";
        return false;
    }
    return true;
}

}  // namespace sim
