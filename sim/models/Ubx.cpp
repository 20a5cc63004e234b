// SPDX-License-Identifier: GPL-3.0-or-later
#include "Ubx.h"

#include <cstdio>

namespace sim {
namespace ubx {

std::vector<uint8_t> frame(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload) {
    std::vector<uint8_t> f = {kSync1, kSync2, cls, id};
    put_u2(f, (uint32_t)payload.size());
    f.insert(f.end(), payload.begin(), payload.end());
    Checksum ck;
    ck.add(f.data() + 2, f.size() - 2);
    f.push_back(ck.a);
    f.push_back(ck.b);
    return f;
}

void put_u1(std::vector<uint8_t>& p, uint32_t v) { p.push_back((uint8_t)v); }
void put_u2(std::vector<uint8_t>& p, uint32_t v) {
    p.push_back((uint8_t)v);
    p.push_back((uint8_t)(v >> 8));
}
void put_u4(std::vector<uint8_t>& p, uint32_t v) {
    for (int i = 0; i < 4; ++i) p.push_back((uint8_t)(v >> (8 * i)));
}

std::string nmea_sentence(const std::string& body) {
    char tail[8];
    std::snprintf(tail, sizeof tail, "*%02X\r\n", gps::nmea::checksum(body.data(), body.size()));
    return "$" + body + tail;
}

using gps::nmea::hex_value;

bool StreamParser::start(uint8_t byte) {
    if (byte == kSync1) {
        state_ = kGotSync1;
        return true;
    }
    if (byte == '$') {
        state_ = kNmea;
        msg_ = Message();
        return true;
    }
    return false;
}

bool StreamParser::feed(uint8_t byte, Message& out) {
    switch (state_) {
    case kIdle:
        if (!start(byte)) ++counters_.bytes_outside;
        return false;
    case kGotSync1:
        if (byte == kSync2) {
            state_ = kClass;
            msg_ = Message();
            msg_.is_ubx = true;
        } else {
            state_ = kIdle;
            if (!start(byte)) ++counters_.bytes_outside;
        }
        return false;
    case kClass:
        msg_.cls = byte;
        state_ = kId;
        return false;
    case kId:
        msg_.id = byte;
        state_ = kLen1;
        return false;
    case kLen1:
        length_ = byte;
        state_ = kLen2;
        return false;
    case kLen2:
        length_ = (uint16_t)(length_ | (byte << 8));
        if (length_ > kMaxPayload) {
            ++counters_.ubx_too_long;
            state_ = kIdle;
            return false;
        }
        state_ = length_ == 0 ? kCkA : kPayload;
        return false;
    case kPayload:
        msg_.payload.push_back(byte);
        if (msg_.payload.size() == length_) state_ = kCkA;
        return false;
    case kCkA:
        got_ck_a_ = byte;
        state_ = kCkB;
        return false;
    case kCkB: {
        state_ = kIdle;
        const uint8_t head[4] = {msg_.cls, msg_.id, (uint8_t)length_, (uint8_t)(length_ >> 8)};
        Checksum ck;
        ck.add(head, sizeof head);
        ck.add(msg_.payload.data(), msg_.payload.size());
        if (ck.a != got_ck_a_ || ck.b != byte) {
            ++counters_.ubx_bad_checksum;
            return false;
        }
        ++counters_.ubx_frames;
        out = msg_;
        return true;
    }
    case kNmea: {
        if (byte == '\n') {
            state_ = kIdle;
            std::string& s = msg_.sentence;
            if (!s.empty() && s.back() == '\r') s.pop_back();
            const size_t star = s.rfind('*');
            if (star == std::string::npos || star + 3 != s.size() || hex_value((uint8_t)s[star + 1]) < 0 ||
                hex_value((uint8_t)s[star + 2]) < 0) {
                ++counters_.nmea_malformed;
                return false;
            }
            const uint8_t x = gps::nmea::checksum(s.data(), star);
            const int given = hex_value((uint8_t)s[star + 1]) * 16 + hex_value((uint8_t)s[star + 2]);
            if (given != x) {
                ++counters_.nmea_bad_checksum;
                return false;
            }
            s.resize(star);
            ++counters_.nmea_sentences;
            out = msg_;
            return true;
        }
        if (byte == '$' || msg_.sentence.size() >= kMaxSentence) {  // a new start, or no end
            ++counters_.nmea_malformed;
            state_ = kIdle;
            if (byte == '$') start(byte);
            return false;
        }
        msg_.sentence.push_back((char)byte);
        return false;
    }
    }
    return false;
}

}  // namespace ubx
}  // namespace sim
