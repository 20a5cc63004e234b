// SPDX-License-Identifier: GPL-3.0-or-later
#include "UbloxFeed.h"

#include <cstring>

namespace sim {

UbloxFeed::UbloxFeed(const Trajectory& path, const UbloxOptions& options) : model_(path, options) {}

void UbloxFeed::send(double t_s, const std::vector<uint8_t>& bytes, uint32_t baud) {
    double at = t_s;
    for (uint8_t b : bytes) {
        UartFrame f;
        f.start_s = at;
        f.bit_s = 1.0 / baud;
        f.byte = b;
        model_.line_in(f);
        at = f.end_s();
    }
}

bool UbloxFeed::poll(double t_s, gps::Fix& fix) {
    if (!configured_ && t_s >= kConfigure_s) {
        configured_ = true;
        const char* pubx = "$PUBX,41,1,0003,0001,38400,0*26\r\n";
        send(kConfigure_s, std::vector<uint8_t>(pubx, pubx + std::strlen(pubx)), 9600);
        std::vector<uint8_t> config;
        // The firmware's four (lib/DCM/GpsAid.h's latency counts their bytes on the line).
        for (uint8_t id : {ubx::kNavPosllh, ubx::kNavStatus, ubx::kNavSol, ubx::kNavVelned}) {
            const std::vector<uint8_t> m = ubx::frame(ubx::kClassCfg, ubx::kCfgMsg, {ubx::kClassNav, id, 1});
            config.insert(config.end(), m.begin(), m.end());
        }
        const std::vector<uint8_t> rate = ubx::frame(ubx::kClassCfg, ubx::kCfgRate, {200, 0, 1, 0, 1, 0});
        config.insert(config.end(), rate.begin(), rate.end());
        send(kConfigure_s + 0.1, config, 38400);
    }
    for (;;) {
        // The bytes whose stop bit has left by the time the module is run to.
        while (!line_.empty() && line_.front().end_s() <= now_s_) {
            const UartFrame f = line_.front();
            line_.pop_front();
            // Only what a receiver at 38400 decodes (the NMEA at 9600 before is noise to it).
            if (f.bit_s > 1.0 / 38000.0 || f.bit_s < 1.0 / 38800.0) continue;
            ubx::StreamParser::Message m;
            if (parser_.feed(f.byte, m) && take(m, f.end_s(), fix)) return true;
        }
        if (now_s_ >= t_s) return false;
        now_s_ = std::min(t_s, std::min(model_.next_event_s(), now_s_ + 0.001));
        model_.advance_to(now_s_);
        UartFrame f;
        while (model_.pop_frame(f)) line_.push_back(f);
    }
}

// NAV-SOL then NAV-VELNED of the same iTOW (the order the module sends them): one fix.
bool UbloxFeed::take(const ubx::StreamParser::Message& m, double t_s, gps::Fix& fix) {
    if (!m.is_ubx || m.cls != ubx::kClassNav) return false;
    const uint8_t* p = m.payload.data();
    if (m.id == ubx::kNavSol && m.payload.size() == ubx::kLenNavSol) {
        sol_itow_ = ubx::get_u4(p);
        sol_fix_ = p[10];
        sol_flags_ = p[11];
        sol_pdop_ = ubx::get_u2(p + 44);
        sol_sats_ = p[47];
        have_sol_ = true;
        return false;
    }
    if (m.id != ubx::kNavVelned || m.payload.size() != ubx::kLenNavVelned || !have_sol_ || ubx::get_u4(p) != sol_itow_)
        return false;
    fix = gps::Fix();
    fix.itow_ms = sol_itow_;
    fix.received_ms = (uint32_t)(t_s * 1000.0);
    for (int i = 0; i < 3; ++i) fix.vel_ned_cm_s[i] = ubx::get_i4(p + 4 + 4 * i);
    fix.ground_speed_cm_s = ubx::get_u4(p + 20);
    fix.course_e5 = ubx::get_i4(p + 24);
    fix.speed_acc_cm_s = ubx::get_u4(p + 28);
    fix.hdop_cm = sol_pdop_;
    fix.sats = sol_sats_;
    fix.have_vertical_velocity = true;
    const bool valid = (sol_flags_ & 1u) != 0u;
    fix.fix = !valid || sol_fix_ < 2u ? gps::FixType::kNoFix : (sol_fix_ == 2u ? gps::FixType::k2D : gps::FixType::k3D);
    have_sol_ = false;
    return true;
}

}  // namespace sim
