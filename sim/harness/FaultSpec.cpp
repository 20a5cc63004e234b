// SPDX-License-Identifier: GPL-3.0-or-later
#include "FaultSpec.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace sim {

const char* const kFaultHelp =
    "Fault SPEC: TARGET:KIND[=VALUE][@T1[-T2]]  (times in simulated seconds; no @: the whole run;\n"
    "            @T1: from T1 on; @T1-T2: from T1 until T2, then the part is healthy again)\n"
    "            Repeat --fault for more windows of one kind (mpu:absent@2-3 --fault mpu:absent@5-6);\n"
    "            windows of one kind must not overlap. A malformed SPEC, an unknown kind or an\n"
    "            overlap is an error: a message on stderr and exit status 1.\n"
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

// A time in seconds: digits with an optional fraction, nothing else (no sign, exponent,
// "inf" or "nan", which strtod would take). Returns the characters used, 0 if none.
size_t parse_seconds(const std::string& text, size_t pos, double& out) {
    size_t i = pos, digits = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
    if (i < text.size() && text[i] == '.') {
        ++i;
        while (i < text.size() && text[i] >= '0' && text[i] <= '9') ++i, ++digits;
    }
    if (digits == 0) return 0;
    out = std::strtod(text.substr(pos, i - pos).c_str(), nullptr);
    return i - pos;
}

bool parse_window(const std::string& text, TimeWindow& window) {
    double t1_s = 0.0, t2_s = 0.0;
    const size_t n1 = parse_seconds(text, 0, t1_s);
    if (n1 == 0) return false;
    window = TimeWindow::between(t1_s, TimeWindow::always().end_s);
    if (n1 == text.size()) return true;
    if (text[n1] != '-') return false;
    const size_t n2 = parse_seconds(text, n1 + 1, t2_s);
    if (n2 == 0 || n1 + 1 + n2 != text.size() || !(t2_s > t1_s)) return false;
    window.end_s = t2_s;
    return true;
}

std::string describe(const TimeWindow& w) {
    char text[64];
    if (w.end_s == TimeWindow::always().end_s) std::snprintf(text, sizeof text, "from %g s on", w.start_s);
    else std::snprintf(text, sizeof text, "%g-%g s", w.start_s, w.end_s);
    return text;
}

}  // namespace

bool parse_fault_spec(const std::string& spec, FaultSpec& out, std::string& error) {
    const std::string grammar = "fault '" + spec + "': expected TARGET:KIND[=VALUE][@T1[-T2]]";
    const size_t colon = spec.find(':');
    const size_t at = spec.find('@');
    if (colon == std::string::npos || colon == 0 || (at != std::string::npos && at < colon)) {
        error = grammar;
        return false;
    }
    FaultSpec f;
    std::string kind = spec.substr(colon + 1, at == std::string::npos ? std::string::npos : at - colon - 1);
    const size_t eq = kind.find('=');
    if (eq != std::string::npos) {
        f.value = kind.substr(eq + 1);
        f.has_value = true;
        kind = kind.substr(0, eq);
    }
    if (kind.empty() || (f.has_value && f.value.empty())) {
        error = grammar;
        return false;
    }
    f.what = spec.substr(0, colon) + ":" + kind;
    if (at != std::string::npos) {
        f.has_window = true;
        if (!parse_window(spec.substr(at + 1), f.window)) {
            error = "fault '" + spec + "': the time window must be @T1 or @T1-T2 (seconds, 0 <= T1 < T2)";
            return false;
        }
    }
    out = f;
    return true;
}

bool apply_fault_spec(const std::string& spec, Mpu6000Model& mpu, Hmc5883Model& mag, BusFaults& bus,
                      std::string& error) {
    FaultSpec f;
    if (!parse_fault_spec(spec, f, error)) return false;
    Mpu6000Faults& mf = mpu.faults();
    Hmc5883Faults& hf = mag.faults();
    const bool identity = f.what == "mpu:whoami" || f.what == "mag:id";
    TimeWindows* windows = nullptr;
    if (f.what == "mpu:absent") windows = &mf.absent;
    else if (f.what == "mpu:int-stuck-low") windows = &mf.int_stuck_low;
    else if (f.what == "mpu:frozen") windows = &mf.frozen;
    else if (f.what == "gyro:saturate") windows = &mf.gyro_saturate;
    else if (f.what == "accel:saturate") windows = &mf.accel_saturate;
    else if (f.what == "imu:spike") windows = &mf.spike;
    else if (f.what == "mag:absent") windows = &hf.absent;
    else if (f.what == "mag:overflow") windows = &hf.overflow;
    else if (f.what == "mag:spike") windows = &hf.spike;
    else if (f.what == "mag:drdy-stuck-low") windows = &hf.drdy_stuck_low;
    else if (f.what == "mag:drdy-stuck-high") windows = &hf.drdy_stuck_high;
    else if (f.what == "i2c:sda-low") windows = &bus.i2c_sda_low;
    else if (!identity) {
        error = "fault '" + spec + "': unknown TARGET:KIND '" + f.what + "' (see --help)";
        return false;
    }
    if (windows != nullptr) {
        if (f.has_value) {
            error = "fault '" + spec + "': '" + f.what + "' takes no value";
            return false;
        }
        for (const TimeWindow& w : windows->windows()) {
            if (w.overlaps(f.window)) {
                error = "fault '" + spec + "': its window overlaps an earlier '" + f.what + "' window (" +
                        describe(w) + ")";
                return false;
            }
        }
        windows->add(f.window);
        return true;
    }
    // The identity faults hold for the whole run: a window or a second value is a mistake.
    if (f.has_window) {
        error = "fault '" + spec + "': '" + f.what + "' holds for the whole run and takes no @ window";
        return false;
    }
    if (f.what == "mpu:whoami") {
        char* end = nullptr;
        const long v = strtol(f.value.c_str(), &end, 0);
        if (f.value.empty() || *end != 0 || v < 0 || v > 255) {
            error = "fault '" + spec + "': mpu:whoami needs a byte value, e.g. mpu:whoami=0x70";
            return false;
        }
        if (mf.who_am_i >= 0) {
            error = "fault '" + spec + "': mpu:whoami given twice";
            return false;
        }
        mf.who_am_i = (int)v;
        return true;
    }
    if (f.value.size() != 3) {
        error = "fault '" + spec + "': mag:id needs three characters, e.g. mag:id=H44";
        return false;
    }
    if (hf.id[0] >= 0) {
        error = "fault '" + spec + "': mag:id given twice";
        return false;
    }
    for (int i = 0; i < 3; ++i) hf.id[i] = (unsigned char)f.value[(size_t)i];
    return true;
}

}  // namespace sim
