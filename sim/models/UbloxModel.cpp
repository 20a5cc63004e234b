// SPDX-License-Identifier: GPL-3.0-or-later
#include "UbloxModel.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace sim {

namespace {

constexpr double kNever_s = std::numeric_limits<double>::infinity();
constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kKnotsPerMps = 3600.0 / 1852.0;

// The standard rates a u-blox 6 UART takes (CFG-PRT baudRate; PUBX,41).
constexpr uint32_t kBauds[] = {4800, 9600, 19200, 38400, 57600, 115200};
bool valid_baud(uint32_t baud) {
    for (uint32_t b : kBauds)
        if (b == baud) return true;
    return false;
}

// Nominal geometry with kNominalSatellites used.
constexpr int kNominalSatellites = 10;
constexpr double kHdop = 0.90, kVdop = 1.40, kTdop = 0.80;
constexpr double kNoDop = 99.99;

uint16_t key(uint8_t cls, uint8_t id) { return (uint16_t)((cls << 8) | id); }

// Days since 1970-01-01 to the civil date (H. Hinnant, "chrono-Compatible Low-Level Date
// Algorithms").
void civil_from_days(int64_t z, int& y, unsigned& m, unsigned& d) {
    z += 719468;
    const int64_t era = (z >= 0 ? z : z - 146096) / 146097;
    const unsigned doe = (unsigned)(z - era * 146097);
    const unsigned yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const int64_t yy = (int64_t)yoe + era * 400;
    const unsigned doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    const unsigned mp = (5 * doy + 2) / 153;
    d = doy - (153 * mp + 2) / 5 + 1;
    m = mp < 10 ? mp + 3 : mp - 9;
    y = (int)(yy + (m <= 2));
}
constexpr int64_t kGpsEpochDays = 3657;  // 1980-01-06 in days since 1970-01-01

struct Satellite {
    int prn, elevation_deg, azimuth_deg, snr_dbhz;
};
// The sky over the field, highest first: the first numSV are the ones used.
constexpr Satellite kSky[] = {
    {17, 78, 42, 47}, {28, 66, 311, 46}, {9, 57, 132, 45}, {15, 49, 228, 44}, {5, 44, 78, 43},
    {24, 38, 171, 42}, {12, 33, 286, 41}, {26, 27, 19, 39}, {2, 22, 250, 37}, {21, 18, 109, 35},
    {29, 12, 340, 32}, {6, 7, 200, 28},
};
constexpr int kSkySize = (int)(sizeof kSky / sizeof kSky[0]);

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    size_t start = 0;
    for (;;) {
        const size_t at = s.find(sep, start);
        out.push_back(s.substr(start, at == std::string::npos ? std::string::npos : at - start));
        if (at == std::string::npos) return out;
        start = at + 1;
    }
}

// ddmm.mmmmm / dddmm.mmmmm and the hemisphere, rounded to 1e-5 minute.
std::string nmea_angle(double deg, int degree_digits) {
    const long long units = std::llround(std::fabs(deg) * 60.0 * 1e5);  // 1e-5 minutes
    const long long whole_deg = units / (60ll * 100000ll);
    const long long minute_units = units - whole_deg * 60ll * 100000ll;
    char text[64];
    std::snprintf(text, sizeof text, "%0*lld%02lld.%05lld", degree_digits, whole_deg, minute_units / 100000,
                  minute_units % 100000);
    return text;
}

uint32_t to_u4(double v) {
    if (!(v >= 0.0)) return 0;
    if (v >= 4294967295.0) return 0xFFFFFFFFu;
    return (uint32_t)std::llround(v);
}
int32_t to_i4(double v) {
    if (v >= 2147483647.0) return 2147483647;
    if (v <= -2147483648.0) return (-2147483647 - 1);
    return (int32_t)std::llround(v);
}
uint16_t dop100(double dop) { return (uint16_t)std::min(9999.0, std::round(dop * 100.0)); }

}  // namespace

UbloxModel::UbloxModel(const Trajectory& trajectory, const UbloxOptions& options)
    : trajectory_(trajectory),
      options_(options),
      frame_(options.home),
      noise_(options.seed),
      garbage_noise_(options.seed ^ 0x6A09E667F3BCC909ull),
      pos_error_{GaussMarkov(options.horizontal_sigma_m, options.position_tau_s),
                 GaussMarkov(options.horizontal_sigma_m, options.position_tau_s),
                 GaussMarkov(options.vertical_sigma_m, options.position_tau_s)},
      baud_(options.baud),
      rx_(1.0 / options.baud) {
    for (GaussMarkov& g : pos_error_) g.start(noise_);
    // Factory default: the NMEA standard messages on every I/O target (DDC, UART1, UART2,
    // USB, SPI), every UBX message off.
    for (uint8_t id : {ubx::kNmeaGga, ubx::kNmeaGll, ubx::kNmeaGsa, ubx::kNmeaGsv, ubx::kNmeaRmc, ubx::kNmeaVtg})
        rates_[key(ubx::kClassNmea, id)] = {{1, 1, 1, 1, 1, 0}};
    // CFG-NAV5 defaults (u-blox 6): portable, auto 2D/3D, 5 deg elevation mask, PDOP and
    // TDOP masks 25.0, position and time accuracy masks 100 m and 300 m, DGPS time-out 60 s.
    std::memset(nav5_, 0, sizeof nav5_);
    std::vector<uint8_t> p;
    ubx::put_u2(p, 0xFFFF);
    ubx::put_u1(p, 0);       // dynModel
    ubx::put_u1(p, 3);       // fixMode
    ubx::put_u4(p, 0);       // fixedAlt, cm
    ubx::put_u4(p, 10000);   // fixedAltVar, 1e-4 m^2
    ubx::put_u1(p, 5);       // minElev
    ubx::put_u1(p, 0);       // drLimit
    ubx::put_u2(p, 250);     // pDop, 0.1
    ubx::put_u2(p, 250);     // tDop
    ubx::put_u2(p, 100);     // pAcc, m
    ubx::put_u2(p, 300);     // tAcc
    ubx::put_u1(p, 0);       // staticHoldThresh
    ubx::put_u1(p, 60);      // dgpsTimeOut
    std::memcpy(nav5_, p.data(), p.size());
    const uint8_t sbas[ubx::kLenCfgSbas] = {0x01, 0x07, 3, 0, 0, 0, 0, 0};  // enabled, auto scan
    std::memcpy(sbas_, sbas, sizeof sbas_);
    if (options_.kind == GpsKind::kNmea) out_proto_ = ubx::kProtoNmea;
    schedule_next_measurement(gps_ms(kBootTime_s), true);
}

uint64_t UbloxModel::gps_ms(double t_s) const { return kStartGps_ms + (uint64_t)std::llround(t_s * 1000.0); }

void UbloxModel::schedule_next_measurement(uint64_t after_gps_ms, bool inclusive) {
    // Epochs on the GPS-time grid of the measurement period ("CFG-RATE": aligned to the top
    // of a second when the period divides it).
    const uint64_t period = meas_rate_ms_;
    uint64_t next = (after_gps_ms + period - 1) / period * period;
    if (!inclusive && next <= after_gps_ms) next += period;
    next_measurement_s_ = (double)(next - kStartGps_ms) / 1000.0;
}

uint8_t UbloxModel::message_rate(uint8_t cls, uint8_t id) const {
    const auto it = rates_.find(key(cls, id));
    return it == rates_.end() ? 0 : it->second[1];
}

double UbloxModel::next_event_s() const {
    double t = next_measurement_s_;
    if (!pending_.empty()) t = std::min(t, pending_.front().out_s);
    if (!tx_.empty()) t = std::min(t, line_free_s_);
    if (!rx_pending_.empty()) t = std::min(t, rx_pending_.front().ready_s);
    if (!inbox_.empty()) t = std::min(t, inbox_.front().at_s);
    t = std::min(t, rx_.next_ready_s());
    if (faults_.garbage.ever()) t = std::min(t, next_garbage_s_);
    return t;
}

void UbloxModel::advance_to(double t_s) {
    if (t_s < time_s_) return;
    for (;;) {
        // The earliest event due; ties in the order received, acted on, measured, output,
        // noise, sent.
        const double rx_decode_s = rx_.next_ready_s();
        const double rx_s = rx_pending_.empty() ? kNever_s : rx_pending_.front().ready_s;
        const double inbox_s = inbox_.empty() ? kNever_s : inbox_.front().at_s;
        const double out_s = pending_.empty() ? kNever_s : pending_.front().out_s;
        const double tx_s = tx_.empty() ? kNever_s : line_free_s_;
        const double garbage_s = faults_.garbage.ever() ? next_garbage_s_ : kNever_s;
        const double events[7] = {rx_decode_s, rx_s, inbox_s, next_measurement_s_, out_s, garbage_s, tx_s};
        int which = -1;
        double te = kNever_s;
        for (int i = 0; i < 7; ++i) {
            if (events[i] < te) {
                te = events[i];
                which = i;
            }
        }
        if (which < 0 || te > t_s) break;
        time_s_ = std::max(time_s_, te);
        switch (which) {
        case 0:
            // Decoded characters are acted on at their stop-bit sample.
            rx_scratch_.clear();
            rx_.decode(te, rx_scratch_);
            for (UartChar c : rx_scratch_) {
                c.ready_s = std::max(c.ready_s, c.edge_s + 9.5 * rx_.bit_s());
                rx_pending_.push_back(c);
            }
            break;
        case 1: {
            const UartChar c = rx_pending_.front();
            rx_pending_.pop_front();
            receive_char(c, te);
            break;
        }
        case 2: {
            const Inbox in = inbox_.front();
            inbox_.pop_front();
            act_on(in.message, te);
            break;
        }
        case 3:
            measure(te);
            break;
        case 4: {
            const Solution s = pending_.front();
            pending_.pop_front();
            output(s);
            break;
        }
        case 5:
            inject_garbage(te);
            break;
        default:
            start_byte(te);
            break;
        }
    }
    time_s_ = t_s;
}

bool UbloxModel::pop_frame(UartFrame& frame) {
    if (wire_.empty()) return false;
    frame = wire_.front();
    wire_.pop_front();
    return true;
}

void UbloxModel::line_in(const UartFrame& frame) { rx_.push(frame); }

// --- measurement and output ------------------------------------------------------

void UbloxModel::measure(double t_s) {
    Solution s;
    s.meas_s = t_s;
    s.gps_ms = gps_ms(t_s);
    s.out_s = t_s + options_.latency_s;
    const TrajectorySample truth = trajectory_.at(t_s);
    const double dt_s = meas_rate_ms_ / 1000.0;
    for (int i = 0; i < 3; ++i) {
        s.truth_ned_m[i] = truth.ned_m[i];
        s.truth_vel_m_s[i] = truth.vel_ned_m_s[i];
        s.pos_error_m[i] = pos_error_[i].step(dt_s, noise_);
    }
    for (int i = 0; i < 3; ++i) s.vel_error_m_s[i] = options_.velocity_sigma_m_s * noise_.gauss();
    pending_.push_back(s);
    schedule_next_measurement(s.gps_ms, false);
}

UbloxModel::Report UbloxModel::report(const Solution& s, double out_s) {
    Report r;
    r.gps_ms = s.gps_ms;
    r.itow = itow_ms(s.gps_ms);
    r.week = gps_week(s.gps_ms);
    r.msss = (uint32_t)std::llround(s.meas_s * 1000.0);
    const bool acquiring = out_s < options_.first_fix_s;
    int satellites = options_.satellites;
    if (const ValueWindow* w = faults_.satellites.active(out_s)) satellites = (int)w->value;
    if (acquiring) {
        r.num_sv = std::min(3, (int)(4.0 * out_s / options_.first_fix_s));
    } else if (faults_.no_fix.active(out_s)) {
        r.num_sv = 2;
    } else {
        r.num_sv = satellites;
        r.fix = satellites >= 4 ? 3 : satellites == 3 ? 2 : 0;
    }
    if (r.fix != 0 && !first_fix_done_) {
        first_fix_done_ = true;
        first_fix_at_s_ = s.meas_s;  // ttff is the epoch's time tag
    }
    r.time_valid = first_fix_done_;
    r.ttff_ms = first_fix_done_ ? (uint32_t)std::llround(first_fix_at_s_ * 1000.0) : 0;
    if (r.fix != 0) {
        // Fewer satellites: a worse geometry, larger errors.
        const double k = std::max(1.0, std::pow((double)kNominalSatellites / r.num_sv, 1.5));
        r.hdop = kHdop * k;
        r.vdop = kVdop * k;
        r.tdop = kTdop * k;
        r.pdop = std::sqrt(r.hdop * r.hdop + r.vdop * r.vdop);
        r.gdop = std::sqrt(r.pdop * r.pdop + r.tdop * r.tdop);
        double ned[3];
        for (int i = 0; i < 3; ++i) {
            ned[i] = s.truth_ned_m[i] + k * s.pos_error_m[i];
            r.vel_ned_m_s[i] = s.truth_vel_m_s[i] + k * s.vel_error_m_s[i];
        }
        if (const ValueWindow* g = faults_.glitch.active(out_s)) ned[0] += g->value;
        r.position = frame_.to_geodetic(ned);
        r.have_position = true;
        last_fix_position_ = r.position;
        r.h_acc_m = k * options_.horizontal_sigma_m * std::sqrt(2.0);
        r.v_acc_m = k * options_.vertical_sigma_m;
        r.s_acc_m_s = k * options_.velocity_sigma_m_s * std::sqrt(3.0);
        const double ground_m_s = std::hypot(r.vel_ned_m_s[0], r.vel_ned_m_s[1]);
        if (ground_m_s >= kCourseHoldSpeed_m_s) {
            double heading = std::atan2(r.vel_ned_m_s[1], r.vel_ned_m_s[0]) * kRadToDeg;
            if (heading < 0.0) heading += 360.0;
            last_heading_deg_ = heading;
            r.c_acc_deg = std::min(180.0, std::atan2(r.s_acc_m_s, ground_m_s) * kRadToDeg);
        } else {
            r.c_acc_deg = 180.0;
        }
        r.heading_deg = last_heading_deg_;
        const uint16_t pdop_mask = ubx::get_u2(nav5_ + 14), pacc_mask_m = ubx::get_u2(nav5_ + 18);
        const double p_acc_m = std::hypot(r.h_acc_m, r.v_acc_m);
        r.fix_ok = r.pdop * 10.0 <= pdop_mask && p_acc_m <= pacc_mask_m;
    } else {
        r.have_position = first_fix_done_;
        r.position = last_fix_position_;
        r.heading_deg = last_heading_deg_;
    }
    if (r.have_position) {
        geodetic_to_ecef(r.position.lat_deg, r.position.lon_deg, r.position.alt_m + kGeoidSeparation_m, r.ecef_m);
        ned_to_ecef_vector(r.position.lat_deg, r.position.lon_deg, r.vel_ned_m_s, r.ecef_vel_m_s);
    }
    return r;
}

void UbloxModel::output(const Solution& s) {
    const Report r = report(s, s.out_s);
    last_report_ = r;
    have_report_ = true;
    ++counters_.epochs;
    ++epoch_count_;
    const bool nmea_only = options_.kind == GpsKind::kNmea;
    if (!boot_text_sent_) {
        boot_text_sent_ = true;
        if (!nmea_only && (out_proto_ & ubx::kProtoNmea)) {
            for (const char* text : {"GPTXT,01,01,02,u-blox ag - www.u-blox.com", "GPTXT,01,01,02,HW  UBX-G60xx  00040007",
                                     "GPTXT,01,01,02,ROM CORE 7.03 (45969) Mar 17 2011 16:18:34"}) {
                const std::string line = ubx::nmea_sentence(text);
                queue_message(std::vector<uint8_t>(line.begin(), line.end()), false, s.out_s);
            }
        }
    }
    auto due = [&](uint8_t cls, uint8_t id) {
        const uint8_t rate = nmea_only ? (cls == ubx::kClassNmea ? 1 : 0) : message_rate(cls, id);
        return rate != 0 && epoch_count_ % rate == 0;
    };
    // Kind kNmea: NMEA at 1 Hz whatever the epoch rate (it is never changed).
    if ((out_proto_ & ubx::kProtoUbx) && !nmea_only) {
        for (uint8_t id : {ubx::kNavPosllh, ubx::kNavStatus, ubx::kNavDop, ubx::kNavSol, ubx::kNavVelned}) {
            if (!due(ubx::kClassNav, id)) continue;
            queue_message(ubx::frame(ubx::kClassNav, id, nav_payload(id, r)), true, s.out_s);
        }
    }
    if (out_proto_ & ubx::kProtoNmea) {
        for (uint8_t id : {ubx::kNmeaRmc, ubx::kNmeaVtg, ubx::kNmeaGga, ubx::kNmeaGsa, ubx::kNmeaGsv, ubx::kNmeaGll}) {
            if (!due(ubx::kClassNmea, id)) continue;
            for (const std::string& line : nmea_sentences(id, r)) {
                queue_message(std::vector<uint8_t>(line.begin(), line.end()), false, s.out_s);
            }
        }
    }
}

std::vector<uint8_t> UbloxModel::nav_payload(uint8_t id, const Report& r) const {
    std::vector<uint8_t> p;
    const uint8_t flags = (uint8_t)((r.fix_ok ? 0x01 : 0) | (r.time_valid ? 0x0C : 0));
    const double unknown = 4294967295.0;
    switch (id) {
    case ubx::kNavPosllh:
        ubx::put_u4(p, r.itow);
        ubx::put_i4(p, r.have_position ? to_i4(r.position.lon_deg * 1e7) : 0);
        ubx::put_i4(p, r.have_position ? to_i4(r.position.lat_deg * 1e7) : 0);
        ubx::put_i4(p, r.have_position ? to_i4((r.position.alt_m + kGeoidSeparation_m) * 1000.0) : 0);
        ubx::put_i4(p, r.have_position ? to_i4(r.position.alt_m * 1000.0) : 0);
        ubx::put_u4(p, to_u4(r.fix ? r.h_acc_m * 1000.0 : unknown));
        ubx::put_u4(p, to_u4(r.fix ? r.v_acc_m * 1000.0 : unknown));
        break;
    case ubx::kNavStatus:
        ubx::put_u4(p, r.itow);
        ubx::put_u1(p, r.fix);
        ubx::put_u1(p, flags);
        ubx::put_u1(p, 0);  // fixStat: no DGPS, no map matching
        ubx::put_u1(p, 0);  // flags2: power save off (acquisition state)
        ubx::put_u4(p, r.ttff_ms);
        ubx::put_u4(p, r.msss);
        break;
    case ubx::kNavDop:
        ubx::put_u4(p, r.itow);
        for (double dop : {r.gdop, r.pdop, r.tdop, r.vdop, r.hdop, r.hdop / std::sqrt(2.0), r.hdop / std::sqrt(2.0)})
            ubx::put_u2(p, dop100(r.fix ? dop : kNoDop));
        break;
    case ubx::kNavSol:
        ubx::put_u4(p, r.itow);
        ubx::put_i4(p, 0);  // fTOW: epochs are on whole milliseconds
        ubx::put_u2(p, r.week);
        ubx::put_u1(p, r.fix);
        ubx::put_u1(p, flags);
        for (int i = 0; i < 3; ++i) ubx::put_i4(p, to_i4(r.ecef_m[i] * 100.0));
        ubx::put_u4(p, to_u4(r.fix ? std::hypot(r.h_acc_m, r.v_acc_m) * 100.0 : unknown));
        for (int i = 0; i < 3; ++i) ubx::put_i4(p, to_i4(r.ecef_vel_m_s[i] * 100.0));
        ubx::put_u4(p, to_u4(r.fix ? r.s_acc_m_s * 100.0 : unknown));
        ubx::put_u2(p, dop100(r.fix ? r.pdop : kNoDop));
        ubx::put_u1(p, 0);  // reserved1
        ubx::put_u1(p, (uint32_t)r.num_sv);
        ubx::put_u4(p, 0);  // reserved2
        break;
    case ubx::kNavVelned: {
        ubx::put_u4(p, r.itow);
        for (int i = 0; i < 3; ++i) ubx::put_i4(p, to_i4(r.vel_ned_m_s[i] * 100.0));
        const double ground = std::hypot(r.vel_ned_m_s[0], r.vel_ned_m_s[1]);
        const double speed = std::sqrt(ground * ground + r.vel_ned_m_s[2] * r.vel_ned_m_s[2]);
        ubx::put_u4(p, to_u4(speed * 100.0));
        ubx::put_u4(p, to_u4(ground * 100.0));
        ubx::put_i4(p, to_i4(r.heading_deg * 1e5));
        ubx::put_u4(p, to_u4(r.fix ? r.s_acc_m_s * 100.0 : unknown));
        ubx::put_u4(p, to_u4(r.c_acc_deg * 1e5));
        break;
    }
    default:
        break;
    }
    return p;
}

std::vector<std::string> UbloxModel::nmea_sentences(uint8_t id, const Report& r) const {
    // UTC from GPS time.
    char time_text[32] = "", date_text[32] = "";
    if (r.time_valid) {
        const uint64_t utc_ms = r.gps_ms - (uint64_t)kLeapSeconds * 1000ull;
        const uint64_t day_ms = utc_ms % 86400000ull;
        int y;
        unsigned m, d;
        civil_from_days(kGpsEpochDays + (int64_t)(utc_ms / 86400000ull), y, m, d);
        std::snprintf(time_text, sizeof time_text, "%02u%02u%02u.%02u", (unsigned)(day_ms / 3600000ull),
                      (unsigned)(day_ms / 60000ull % 60ull), (unsigned)(day_ms / 1000ull % 60ull),
                      (unsigned)(day_ms % 1000ull / 10ull));
        std::snprintf(date_text, sizeof date_text, "%02u%02u%02u", d, m, (unsigned)(y % 100));
    }
    const bool fix = r.fix != 0;
    std::string lat, lon;
    char ns = 'N', ew = 'E';
    if (fix) {
        lat = nmea_angle(r.position.lat_deg, 2);
        lon = nmea_angle(r.position.lon_deg, 3);
        ns = r.position.lat_deg < 0 ? 'S' : 'N';
        ew = r.position.lon_deg < 0 ? 'W' : 'E';
    }
    const double ground = std::hypot(r.vel_ned_m_s[0], r.vel_ned_m_s[1]);
    char body[160];
    std::vector<std::string> out;
    switch (id) {
    case ubx::kNmeaRmc:
        if (fix)
            std::snprintf(body, sizeof body, "GPRMC,%s,A,%s,%c,%s,%c,%.3f,%.2f,%s,,,A", time_text, lat.c_str(), ns,
                          lon.c_str(), ew, ground * kKnotsPerMps, r.heading_deg, date_text);
        else
            std::snprintf(body, sizeof body, "GPRMC,%s,V,,,,,,,%s,,,N", time_text, date_text);
        out.push_back(ubx::nmea_sentence(body));
        break;
    case ubx::kNmeaVtg:
        if (fix)
            std::snprintf(body, sizeof body, "GPVTG,%.2f,T,,M,%.3f,N,%.3f,K,A", r.heading_deg, ground * kKnotsPerMps,
                          ground * 3.6);
        else
            std::snprintf(body, sizeof body, "GPVTG,,,,,,,,,N");
        out.push_back(ubx::nmea_sentence(body));
        break;
    case ubx::kNmeaGga:
        if (fix)
            std::snprintf(body, sizeof body, "GPGGA,%s,%s,%c,%s,%c,1,%02d,%.2f,%.1f,M,%.1f,M,,", time_text, lat.c_str(),
                          ns, lon.c_str(), ew, r.num_sv, r.hdop, r.position.alt_m, kGeoidSeparation_m);
        else
            std::snprintf(body, sizeof body, "GPGGA,%s,,,,,0,%02d,99.99,,,,,,", time_text, r.num_sv);
        out.push_back(ubx::nmea_sentence(body));
        break;
    case ubx::kNmeaGsa: {
        std::string s = "GPGSA,A," + std::to_string(fix ? (int)r.fix : 1);
        for (int i = 0; i < 12; ++i) {
            char prn[8] = "";
            if (fix && i < r.num_sv && i < kSkySize) std::snprintf(prn, sizeof prn, "%02d", kSky[i].prn);
            s += ",";
            s += prn;
        }
        std::snprintf(body, sizeof body, ",%.2f,%.2f,%.2f", fix ? r.pdop : kNoDop, fix ? r.hdop : kNoDop,
                      fix ? r.vdop : kNoDop);
        out.push_back(ubx::nmea_sentence(s + body));
        break;
    }
    case ubx::kNmeaGsv: {
        const int visible = std::min(kSkySize, fix ? r.num_sv + 2 : r.num_sv);
        const int sentences = visible == 0 ? 1 : (visible + 3) / 4;
        for (int n = 0; n < sentences; ++n) {
            std::snprintf(body, sizeof body, "GPGSV,%d,%d,%02d", sentences, n + 1, visible);
            std::string s = body;
            for (int i = 4 * n; i < std::min(visible, 4 * n + 4); ++i) {
                std::snprintf(body, sizeof body, ",%02d,%02d,%03d,%02d", kSky[i].prn, kSky[i].elevation_deg,
                              kSky[i].azimuth_deg, kSky[i].snr_dbhz);
                s += body;
            }
            out.push_back(ubx::nmea_sentence(s));
        }
        break;
    }
    case ubx::kNmeaGll:
        if (fix)
            std::snprintf(body, sizeof body, "GPGLL,%s,%c,%s,%c,%s,A,A", lat.c_str(), ns, lon.c_str(), ew, time_text);
        else
            std::snprintf(body, sizeof body, "GPGLL,,,,,%s,V,N", time_text);
        out.push_back(ubx::nmea_sentence(body));
        break;
    default:
        break;
    }
    return out;
}

// --- the line out ----------------------------------------------------------------------

void UbloxModel::queue_message(const std::vector<uint8_t>& bytes, bool is_ubx, double t_s) {
    if (bytes.empty()) return;
    if (tx_module_bytes_ + bytes.size() > options_.tx_buffer_bytes) {
        ++counters_.tx_dropped_messages;
        return;
    }
    if (tx_.empty() && line_free_s_ < t_s) line_free_s_ = t_s;
    for (uint8_t b : bytes) tx_.push_back(TxByte{b, false});
    tx_module_bytes_ += bytes.size();
    if (is_ubx) ++counters_.ubx_messages_out;
    else ++counters_.nmea_sentences_out;
}

void UbloxModel::start_byte(double t_s) {
    const TxByte b = tx_.front();
    tx_.pop_front();
    UartFrame f;
    f.start_s = t_s;
    f.bit_s = 1.0 / baud_;
    f.byte = b.byte;
    line_free_s_ = f.end_s();
    if (b.noise) {
        wire_.push_back(f);
        return;
    }
    --tx_module_bytes_;
    if (faults_.silent.active(t_s)) {
        ++counters_.bytes_silenced;
        return;
    }
    ++counters_.bytes_out;
    wire_.push_back(f);
}

void UbloxModel::inject_garbage(double t_s) {
    if (!faults_.garbage.active(t_s)) {
        // Asleep until the next window opens.
        next_garbage_s_ = kNever_s;
        for (const TimeWindow& w : faults_.garbage.windows())
            if (w.start_s > t_s && w.start_s < next_garbage_s_) next_garbage_s_ = w.start_s;
        return;
    }
    // A burst of 1..16 random bytes every 10..90 ms, ahead of what the module has queued
    // (inside its messages as often as between them).
    const int n = 1 + (int)(garbage_noise_.uniform() * 16.0);
    if (tx_.empty() && line_free_s_ < t_s) line_free_s_ = t_s;
    for (int i = 0; i < n; ++i) tx_.push_front(TxByte{(uint8_t)(garbage_noise_.next_u64() >> 56), true});
    counters_.garbage_bytes += (uint32_t)n;
    next_garbage_s_ = t_s + 0.010 + 0.080 * garbage_noise_.uniform();
}

// --- the line in ----------------------------------------------------------------------

void UbloxModel::receive_char(const UartChar& c, double t_s) {
    if (!c.framing_ok) {
        ++counters_.framing_errors_in;
        return;
    }
    ++counters_.bytes_in;
    if (faults_.deaf.active(t_s)) {
        ++counters_.ignored_deaf;
        return;
    }
    if (options_.kind == GpsKind::kNmea) {
        ++counters_.ignored_nmea_only;
        return;
    }
    ubx::StreamParser::Message m;
    if (parser_.feed(c.byte, m)) inbox_.push_back(Inbox{t_s + kAnswerDelay_s, m});
}

void UbloxModel::act_on(const ubx::StreamParser::Message& m, double t_s) {
    if (m.is_ubx) {
        if (!(in_proto_ & ubx::kProtoUbx)) ++counters_.ignored_protocol;
        else handle_ubx(m, t_s);
    } else {
        if (!(in_proto_ & ubx::kProtoNmea)) ++counters_.ignored_protocol;
        else handle_nmea(m.sentence, t_s);
    }
}

void UbloxModel::send_ubx(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload, double t_s) {
    if (!(out_proto_ & ubx::kProtoUbx)) return;  // the port does not speak UBX out
    queue_message(ubx::frame(cls, id, payload), true, t_s);
}

void UbloxModel::ack(uint8_t cls, uint8_t id, bool ok, double t_s) {
    if (ok) ++counters_.acks;
    else ++counters_.naks;
    send_ubx(ubx::kClassAck, ok ? ubx::kAckAck : ubx::kAckNak, {cls, id}, t_s);
}

void UbloxModel::handle_ubx(const ubx::StreamParser::Message& m, double t_s) {
    if (m.cls == ubx::kClassCfg) {
        handle_cfg(m, t_s);
        return;
    }
    if (!m.payload.empty()) return;  // an output message sent to the module: ignored
    if (m.cls == ubx::kClassNav && have_report_ &&
        (m.id == ubx::kNavPosllh || m.id == ubx::kNavStatus || m.id == ubx::kNavDop || m.id == ubx::kNavSol ||
         m.id == ubx::kNavVelned)) {
        ++counters_.polls;
        send_ubx(ubx::kClassNav, m.id, nav_payload(m.id, last_report_), t_s);
    } else if (m.cls == ubx::kClassMon && m.id == ubx::kMonVer) {
        ++counters_.polls;
        std::vector<uint8_t> p(40, 0);
        const char sw[] = "7.03 (45969)", hw[] = "00040007";
        std::memcpy(p.data(), sw, sizeof sw - 1);
        std::memcpy(p.data() + 30, hw, sizeof hw - 1);
        send_ubx(ubx::kClassMon, ubx::kMonVer, p, t_s);
    }
}

std::vector<uint8_t> UbloxModel::cfg_prt_payload() const {
    std::vector<uint8_t> p;
    ubx::put_u1(p, 1);         // portID: UART1
    ubx::put_u1(p, 0);         // reserved0
    ubx::put_u2(p, 0);         // txReady: off
    ubx::put_u4(p, 0x000008D0); // mode: 8 bits, no parity, 1 stop bit (bit 4 reserved, set)
    ubx::put_u4(p, baud_);
    ubx::put_u2(p, in_proto_);
    ubx::put_u2(p, out_proto_);
    ubx::put_u2(p, 0);         // flags
    ubx::put_u2(p, 0);         // reserved5
    return p;
}

std::vector<uint8_t> UbloxModel::cfg_msg_payload(uint8_t cls, uint8_t id) const {
    std::vector<uint8_t> p = {cls, id};
    const auto it = rates_.find(key(cls, id));
    for (int i = 0; i < 6; ++i) p.push_back(it == rates_.end() ? 0 : it->second[(size_t)i]);
    return p;
}

bool UbloxModel::set_port(uint32_t baud, uint16_t in_proto, uint16_t out_proto) {
    if (!valid_baud(baud)) return false;
    baud_ = baud;
    rx_.set_bit_s(1.0 / baud);
    in_proto_ = in_proto;
    out_proto_ = out_proto;
    ++counters_.port_changes;
    return true;
}

void UbloxModel::handle_cfg(const ubx::StreamParser::Message& m, double t_s) {
    const std::vector<uint8_t>& p = m.payload;
    const size_t n = p.size();
    switch (m.id) {
    case ubx::kCfgPrt:
        if (n == 0 || (n == 1 && p[0] == 1)) {
            ++counters_.polls;
            send_ubx(ubx::kClassCfg, ubx::kCfgPrt, cfg_prt_payload(), t_s);
            ack(m.cls, m.id, true, t_s);
        } else if (n == 1) {
            ++counters_.not_modelled;  // another port's configuration
            ack(m.cls, m.id, false, t_s);
        } else if (n % ubx::kLenCfgPrt == 0) {
            // Every block checked before any is applied.
            for (size_t b = 0; b < n; b += ubx::kLenCfgPrt) {
                if (p[b] == 1 && !valid_baud(ubx::get_u4(&p[b + 8]))) {
                    ack(m.cls, m.id, false, t_s);
                    return;
                }
            }
            for (size_t b = 0; b < n; b += ubx::kLenCfgPrt) {
                if (p[b] != 1) {
                    ++counters_.not_modelled;
                    continue;
                }
                // The line is modelled as 8N1 only: another character format is kept off.
                if ((ubx::get_u4(&p[b + 4]) & 0x3EC0) != 0x08C0) ++counters_.not_modelled;
                set_port(ubx::get_u4(&p[b + 8]), ubx::get_u2(&p[b + 12]), ubx::get_u2(&p[b + 14]));
            }
            ack(m.cls, m.id, true, t_s);  // at the new baud: it starts after the change
        } else {
            ack(m.cls, m.id, false, t_s);
        }
        return;
    case ubx::kCfgMsg:
        if (n == 2) {
            ++counters_.polls;
            send_ubx(ubx::kClassCfg, ubx::kCfgMsg, cfg_msg_payload(p[0], p[1]), t_s);
            ack(m.cls, m.id, true, t_s);
        } else if (n == 3) {
            auto it = rates_.find(key(p[0], p[1]));
            if (it == rates_.end()) it = rates_.insert({key(p[0], p[1]), {{0, 0, 0, 0, 0, 0}}}).first;
            it->second[1] = p[2];
            ack(m.cls, m.id, true, t_s);
        } else if (n == 8) {
            std::array<uint8_t, 6> r;
            for (int i = 0; i < 6; ++i) r[(size_t)i] = p[(size_t)(2 + i)];
            rates_[key(p[0], p[1])] = r;
            ack(m.cls, m.id, true, t_s);
        } else {
            ack(m.cls, m.id, false, t_s);
        }
        return;
    case ubx::kCfgRate:
        if (n == 0) {
            ++counters_.polls;
            std::vector<uint8_t> r;
            ubx::put_u2(r, meas_rate_ms_);
            ubx::put_u2(r, 1);
            ubx::put_u2(r, time_ref_);
            send_ubx(ubx::kClassCfg, ubx::kCfgRate, r, t_s);
            ack(m.cls, m.id, true, t_s);
        } else if (n == ubx::kLenCfgRate) {
            const uint16_t meas = ubx::get_u2(&p[0]), nav = ubx::get_u2(&p[2]), ref = ubx::get_u2(&p[4]);
            const bool ok = meas >= 200 && nav == 1 && ref <= 1;
            if (ok) {
                meas_rate_ms_ = meas;
                time_ref_ = ref;
                schedule_next_measurement(gps_ms(t_s), false);
            }
            ack(m.cls, m.id, ok, t_s);
        } else {
            ack(m.cls, m.id, false, t_s);
        }
        return;
    case ubx::kCfgNav5:
        if (n == 0) {
            ++counters_.polls;
            send_ubx(ubx::kClassCfg, ubx::kCfgNav5, std::vector<uint8_t>(nav5_, nav5_ + sizeof nav5_), t_s);
            ack(m.cls, m.id, true, t_s);
        } else if (n == ubx::kLenCfgNav5) {
            const uint16_t mask = ubx::get_u2(&p[0]);
            const uint8_t dyn = p[2], fix_mode = p[3];
            const bool ok = (!(mask & 0x01) || dyn == 0 || (dyn >= 2 && dyn <= 8)) &&
                            (!(mask & 0x04) || (fix_mode >= 1 && fix_mode <= 3));
            if (ok) {
                // The parameter groups the mask selects (field offsets of the payload).
                struct Group {
                    uint16_t bit;
                    uint8_t from, to;  // bytes [from, to)
                };
                static const Group kGroups[] = {{0x01, 2, 3},   {0x02, 12, 13}, {0x04, 3, 12}, {0x08, 13, 14},
                                                {0x10, 14, 16}, {0x10, 18, 20}, {0x20, 16, 18}, {0x20, 20, 22},
                                                {0x40, 22, 23}, {0x80, 23, 24}};
                for (const Group& g : kGroups)
                    if (mask & g.bit)
                        for (uint8_t i = g.from; i < g.to; ++i) nav5_[i] = p[i];
            }
            ack(m.cls, m.id, ok, t_s);
        } else {
            ack(m.cls, m.id, false, t_s);
        }
        return;
    case ubx::kCfgSbas:
        if (n == 0) {
            ++counters_.polls;
            send_ubx(ubx::kClassCfg, ubx::kCfgSbas, std::vector<uint8_t>(sbas_, sbas_ + sizeof sbas_), t_s);
            ack(m.cls, m.id, true, t_s);
        } else if (n == ubx::kLenCfgSbas) {
            std::memcpy(sbas_, p.data(), sizeof sbas_);
            ack(m.cls, m.id, true, t_s);
        } else {
            ack(m.cls, m.id, false, t_s);
        }
        return;
    case ubx::kCfgCfg:
        ack(m.cls, m.id, n == 12 || n == 13, t_s);
        return;
    case ubx::kCfgRst:
        ++counters_.not_modelled;  // a real module resets without an answer
        return;
    default:
        ack(m.cls, m.id, false, t_s);
        return;
    }
}

void UbloxModel::handle_nmea(const std::string& sentence, double t_s) {
    (void)t_s;
    const std::vector<std::string> f = split(sentence, ',');
    if (f.size() < 2 || f[0] != "PUBX") {
        ++counters_.not_modelled;  // a standard sentence sent to the module (a poll): not modelled
        return;
    }
    if (f[1] == "41" && f.size() >= 7) {
        ++counters_.pubx41;
        char* end = nullptr;
        const long port = std::strtol(f[2].c_str(), &end, 10);
        const unsigned long in = std::strtoul(f[3].c_str(), nullptr, 16);
        const unsigned long out = std::strtoul(f[4].c_str(), nullptr, 16);
        const unsigned long baud = std::strtoul(f[5].c_str(), nullptr, 10);
        if (port != 1 || !set_port((uint32_t)baud, (uint16_t)in, (uint16_t)out)) ++counters_.not_modelled;
        return;
    }
    if (f[1] == "40" && f.size() >= 8) {
        ++counters_.pubx40;
        static const struct {
            const char* name;
            uint8_t id;
        } kNames[] = {{"GGA", ubx::kNmeaGga}, {"GLL", ubx::kNmeaGll}, {"GSA", ubx::kNmeaGsa},
                      {"GSV", ubx::kNmeaGsv}, {"RMC", ubx::kNmeaRmc}, {"VTG", ubx::kNmeaVtg}};
        for (const auto& n : kNames) {
            if (f[2] != n.name) continue;
            auto it = rates_.find(key(ubx::kClassNmea, n.id));
            if (it == rates_.end()) it = rates_.insert({key(ubx::kClassNmea, n.id), {{0, 0, 0, 0, 0, 0}}}).first;
            for (int i = 0; i < 5; ++i) it->second[(size_t)i] = (uint8_t)std::strtoul(f[(size_t)(3 + i)].c_str(), nullptr, 10);
            return;
        }
        ++counters_.not_modelled;
        return;
    }
    ++counters_.not_modelled;
}

}  // namespace sim
