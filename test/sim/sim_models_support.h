// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the GPS and barometer model tests: a GPS module on a line with a firmware's
// USART at its own baud (no simavr), and a reading of what came down the line written
// from the u-blox 6 protocol specification, not from the model's code.
#pragma once

#include <stdint.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "Trajectory.h"
#include "UartLine.h"
#include "UbloxModel.h"

namespace simtest {

// A message as the firmware would read it off the line.
struct LineMessage {
    double first_s = 0.0, last_s = 0.0;  // edges of its first and last characters
    bool ubx = false;
    uint8_t cls = 0, id = 0;
    std::vector<uint8_t> payload;  // UBX
    bool checksum_ok = false;
    std::string sentence;          // NMEA, "$...*hh" without CR LF
};

// The u-blox 6 UBX checksum (Protocol Specification, "UBX Checksum"), over class..payload.
inline void fletcher8(const std::vector<uint8_t>& bytes, uint8_t& a, uint8_t& b) {
    a = 0;
    b = 0;
    for (uint8_t x : bytes) {
        a = (uint8_t)(a + x);
        b = (uint8_t)(b + a);
    }
}

inline uint32_t le32(const std::vector<uint8_t>& p, size_t at) {
    return (uint32_t)p[at] | ((uint32_t)p[at + 1] << 8) | ((uint32_t)p[at + 2] << 16) | ((uint32_t)p[at + 3] << 24);
}
inline int32_t le32s(const std::vector<uint8_t>& p, size_t at) { return (int32_t)le32(p, at); }
inline uint16_t le16(const std::vector<uint8_t>& p, size_t at) { return (uint16_t)(p[at] | (p[at + 1] << 8)); }

// A UBX frame built by hand.
inline std::vector<uint8_t> ubx_frame(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload) {
    std::vector<uint8_t> body = {cls, id, (uint8_t)payload.size(), (uint8_t)(payload.size() >> 8)};
    body.insert(body.end(), payload.begin(), payload.end());
    uint8_t a, b;
    fletcher8(body, a, b);
    std::vector<uint8_t> f = {0xB5, 0x62};
    f.insert(f.end(), body.begin(), body.end());
    f.push_back(a);
    f.push_back(b);
    return f;
}

inline std::vector<uint8_t> bytes_of(const std::string& s) { return std::vector<uint8_t>(s.begin(), s.end()); }

// Splits received characters (edge time, byte) into UBX frames and NMEA sentences, as a
// driver would: a frame whose checksum fails is kept (checksum_ok false) and the search
// resumes at the byte after its first, so that garbage cannot swallow what follows.
inline std::vector<LineMessage> split_messages(const std::vector<sim::UartChar>& chars) {
    std::vector<LineMessage> out;
    size_t i = 0;
    while (i < chars.size()) {
        if (chars[i].byte == 0xB5 && i + 7 < chars.size() && chars[i + 1].byte == 0x62) {
            const size_t len = (size_t)chars[i + 4].byte | ((size_t)chars[i + 5].byte << 8);
            if (len > 1024 || i + 8 + len > chars.size()) {
                ++i;
                continue;
            }
            LineMessage m;
            m.ubx = true;
            m.first_s = chars[i].edge_s;
            m.last_s = chars[i + 7 + len].edge_s;
            m.cls = chars[i + 2].byte;
            m.id = chars[i + 3].byte;
            std::vector<uint8_t> body;
            for (size_t k = i + 2; k < i + 6 + len; ++k) body.push_back(chars[k].byte);
            for (size_t k = i + 6; k < i + 6 + len; ++k) m.payload.push_back(chars[k].byte);
            uint8_t a, b;
            fletcher8(body, a, b);
            m.checksum_ok = a == chars[i + 6 + len].byte && b == chars[i + 7 + len].byte;
            out.push_back(m);
            i += m.checksum_ok ? 8 + len : 1;
        } else if (chars[i].byte == '$') {
            size_t j = i + 1;
            while (j < chars.size() && chars[j].byte != '\n' && chars[j].byte != '$' && j - i < 120) ++j;
            if (j == chars.size() || chars[j].byte != '\n') {
                i = j;
                continue;
            }
            LineMessage m;
            m.first_s = chars[i].edge_s;
            m.last_s = chars[j].edge_s;
            for (size_t k = i; k < j; ++k) m.sentence.push_back((char)chars[k].byte);
            if (!m.sentence.empty() && m.sentence.back() == '\r') m.sentence.pop_back();
            const size_t star = m.sentence.rfind('*');
            if (star != std::string::npos && star + 3 == m.sentence.size()) {
                uint8_t x = 0;
                for (size_t k = 1; k < star; ++k) x = (uint8_t)(x ^ (uint8_t)m.sentence[k]);
                m.checksum_ok = std::strtoul(m.sentence.substr(star + 1).c_str(), nullptr, 16) == x;
            }
            out.push_back(m);
            i = j + 1;
        } else {
            ++i;
        }
    }
    return out;
}

// The module on a line with a firmware's USART at fw_baud (both 8N1).
struct GpsBench {
    sim::UbloxModel gps;
    sim::UartReceiver firmware_rx;  // the firmware's receiver
    double firmware_bit_s;
    double tx_free_s = 0.0;
    double now_s = 0.0;
    std::vector<sim::UartChar> received;  // what the firmware's USART decoded
    std::vector<sim::UartFrame> frames;   // what the module put on the line

    GpsBench(const sim::Trajectory& t, const sim::UbloxOptions& o, double fw_baud = 9600.0)
        : gps(t, o), firmware_rx(1.0 / fw_baud), firmware_bit_s(1.0 / fw_baud) {}

    void set_firmware_baud(double baud) {
        firmware_bit_s = 1.0 / baud;
        firmware_rx.set_bit_s(firmware_bit_s);
    }
    // The firmware sends `bytes` from time t_s on (after what it sent before).
    void send(double t_s, const std::vector<uint8_t>& bytes) {
        double at = std::max(t_s, tx_free_s);
        for (uint8_t b : bytes) {
            sim::UartFrame f;
            f.start_s = at;
            f.bit_s = firmware_bit_s;
            f.byte = b;
            gps.line_in(f);
            at = f.end_s();
        }
        tx_free_s = at;
    }
    // Runs to t_s in steps of step_s.
    void run_to(double t_s, double step_s = 0.0005) {
        while (now_s < t_s) {
            now_s = std::min(t_s, now_s + step_s);
            gps.advance_to(now_s);
            sim::UartFrame f;
            while (gps.pop_frame(f)) {
                frames.push_back(f);
                firmware_rx.push(f);
            }
            firmware_rx.decode(now_s, received);
        }
    }
    std::vector<LineMessage> messages() const { return split_messages(received); }
    // Messages whose first character came in [from_s, to_s).
    std::vector<LineMessage> messages_between(double from_s, double to_s) const {
        std::vector<LineMessage> out;
        for (const LineMessage& m : messages())
            if (m.first_s >= from_s && m.first_s < to_s) out.push_back(m);
        return out;
    }
};

// A trajectory at rest (no n,e,d) or moving at a constant NED velocity from the origin.
inline sim::Trajectory moving_trajectory(double seconds, const double vel_ned[3], double rate_hz = 100.0) {
    sim::Trajectory t;
    const int n = (int)(seconds * rate_hz) + 1;
    for (int k = 0; k < n; ++k) {
        sim::TrajectorySample s{};
        s.t_s = k / rate_hz;
        s.accel_m_s2[2] = -9.80665;
        s.mag_uT[0] = 20.0;
        s.mag_uT[2] = 45.0;
        s.quat[0] = 1.0;
        s.movement = true;
        for (int i = 0; i < 3; ++i) {
            s.ned_m[i] = vel_ned[i] * s.t_s;
            s.vel_ned_m_s[i] = vel_ned[i];
        }
        t.append(s);
    }
    return t;
}

}  // namespace simtest
