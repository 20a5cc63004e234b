// SPDX-License-Identifier: GPL-3.0-or-later
#include "FaultSpec.h"

#include <cmath>
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
    "  GPS faults act on what leaves the module in the window (an epoch measured before T1 and\n"
    "  sent after it is already affected); an error with --gps none:\n"
    "  gps:no-fix             the fix is lost: gpsFix 0, flags 0, numSV 2, NMEA status V; the\n"
    "                         module talks on, the last position held (a loss of sky)\n"
    "  gps:silent             no byte reaches the firmware (a cut TX wire); without @ the whole\n"
    "                         run: a module that never answers anything\n"
    "  gps:deaf               the module ignores every byte from the firmware (a cut RX wire):\n"
    "                         no ACK, no baud change; it keeps talking as configured\n"
    "  gps:garbage            random bytes on the line: bursts of 1-16 every 10-90 ms, among\n"
    "                         (and inside) the module's messages, at the module's baud\n"
    "  gps:glitch[=M]         the reported position jumps M metres north (default 50)\n"
    "  gps:sats=N             N satellites used: N >= 4 a 3D fix with DOPs and errors grown\n"
    "                         by (10/N)^1.5, N = 3 a 2D fix, N <= 2 no fix (N 0..12)\n"
    "  baro:absent            the MS5611 does not answer: MISO reads 0x00, commands ignored\n"
    "                         (its PROM then reads all 0, whose CRC-4 is 0: check for it)\n"
    "  baro:stuck             every conversion returns the last D1 / D2 from before the window\n"
    "  baro:spike             D1 reads with bit 19 flipped: ~100 hPa (~900 m) off\n"
    "Examples: --fault mpu:absent@2.0-5.0  --fault mag:overflow@2-5  --fault gyro:saturate@2-3\n"
    "          --fault gps:no-fix@20-30  --fault gps:glitch=50@40-45  --fault baro:spike@12-12.2\n";

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
    FaultTargets targets;
    targets.mpu = &mpu;
    targets.mag = &mag;
    targets.bus = &bus;
    return apply_fault_spec(spec, targets, error);
}

bool apply_fault_spec(const std::string& spec, const FaultTargets& targets, std::string& error) {
    FaultSpec f;
    if (!parse_fault_spec(spec, f, error)) return false;
    const std::string target = f.what.substr(0, f.what.find(':'));
    if ((target == "gps" && !targets.gps) || (target == "baro" && !targets.baro)) {
        error = "fault '" + spec + "': no " + (target == "gps" ? std::string("GPS (--gps none)") : "barometer (--baro none)") +
                " on this board";
        return false;
    }
    const bool imu = target == "mpu" || target == "gyro" || target == "accel" || target == "imu";
    if ((imu && !targets.mpu) || (target == "mag" && !targets.mag) || (target == "i2c" && !targets.bus)) {
        error = "fault '" + spec + "': that part is not attached";
        return false;
    }
    // Faults that carry a value in each window.
    ValueWindows* valued = nullptr;
    double value = 0.0;
    if (f.what == "gps:glitch") {
        valued = &targets.gps->glitch;
        value = 50.0;
        if (f.has_value) {
            char* end = nullptr;
            value = std::strtod(f.value.c_str(), &end);
            if (*end != 0 || !std::isfinite(value) || std::fabs(value) > 100000.0) {
                error = "fault '" + spec + "': gps:glitch takes metres, e.g. gps:glitch=50";
                return false;
            }
        }
    } else if (f.what == "gps:sats") {
        valued = &targets.gps->satellites;
        char* end = nullptr;
        const long n = f.has_value ? std::strtol(f.value.c_str(), &end, 10) : -1;
        if (!f.has_value || *end != 0 || n < 0 || n > 12) {
            error = "fault '" + spec + "': gps:sats needs a satellite count 0..12, e.g. gps:sats=4";
            return false;
        }
        value = (double)n;
    }
    if (valued) {
        for (const ValueWindow& w : valued->windows()) {
            if (w.window.overlaps(f.window)) {
                error = "fault '" + spec + "': its window overlaps an earlier '" + f.what + "' window (" +
                        describe(w.window) + ")";
                return false;
            }
        }
        valued->add(f.window, value);
        return true;
    }
    const bool identity = f.what == "mpu:whoami" || f.what == "mag:id";
    TimeWindows* windows = nullptr;
    if (f.what == "mpu:absent") windows = &targets.mpu->faults().absent;
    else if (f.what == "mpu:int-stuck-low") windows = &targets.mpu->faults().int_stuck_low;
    else if (f.what == "mpu:frozen") windows = &targets.mpu->faults().frozen;
    else if (f.what == "gyro:saturate") windows = &targets.mpu->faults().gyro_saturate;
    else if (f.what == "accel:saturate") windows = &targets.mpu->faults().accel_saturate;
    else if (f.what == "imu:spike") windows = &targets.mpu->faults().spike;
    else if (f.what == "mag:absent") windows = &targets.mag->faults().absent;
    else if (f.what == "mag:overflow") windows = &targets.mag->faults().overflow;
    else if (f.what == "mag:spike") windows = &targets.mag->faults().spike;
    else if (f.what == "mag:drdy-stuck-low") windows = &targets.mag->faults().drdy_stuck_low;
    else if (f.what == "mag:drdy-stuck-high") windows = &targets.mag->faults().drdy_stuck_high;
    else if (f.what == "i2c:sda-low") windows = &targets.bus->i2c_sda_low;
    else if (f.what == "gps:no-fix") windows = &targets.gps->no_fix;
    else if (f.what == "gps:silent") windows = &targets.gps->silent;
    else if (f.what == "gps:deaf") windows = &targets.gps->deaf;
    else if (f.what == "gps:garbage") windows = &targets.gps->garbage;
    else if (f.what == "baro:absent") windows = &targets.baro->absent;
    else if (f.what == "baro:stuck") windows = &targets.baro->stuck;
    else if (f.what == "baro:spike") windows = &targets.baro->spike;
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
        Mpu6000Faults& mf = targets.mpu->faults();
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
    Hmc5883Faults& hf = targets.mag->faults();
    if (hf.id[0] >= 0) {
        error = "fault '" + spec + "': mag:id given twice";
        return false;
    }
    for (int i = 0; i < 3; ++i) hf.id[i] = (unsigned char)f.value[(size_t)i];
    return true;
}

}  // namespace sim
