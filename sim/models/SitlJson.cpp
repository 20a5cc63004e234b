// SPDX-License-Identifier: GPL-3.0-or-later
#include "SitlJson.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "Rotation.h"

namespace sim {

namespace {

// A JSON value (RFC 8259), as much as the state needs: objects, arrays, numbers, strings,
// true/false/null.
struct Json {
    enum Kind { Null, Bool, Number, String, Array, Object } kind = Null;
    double number = 0.0;
    std::string text;
    std::vector<Json> items;
    std::vector<std::pair<std::string, Json>> members;

    const Json* get(const char* name) const {
        if (kind != Object) return nullptr;
        const Json* found = nullptr;
        for (const auto& m : members)
            if (m.first == name) found = &m.second;  // the last of repeated names
        return found;
    }
};

class JsonParser {
public:
    explicit JsonParser(const std::string& s) : s_(s) {}
    bool parse(Json& out) {
        if (!value(out, 0)) return false;
        skip();
        return pos_ == s_.size();
    }

private:
    static constexpr int kMaxDepth = 16;

    void skip() {
        while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\r' || s_[pos_] == '\n')) ++pos_;
    }
    bool literal(const char* word) {
        const size_t n = std::strlen(word);
        if (s_.compare(pos_, n, word) != 0) return false;
        pos_ += n;
        return true;
    }
    bool string(std::string& out) {
        if (pos_ >= s_.size() || s_[pos_] != '"') return false;
        ++pos_;
        while (pos_ < s_.size() && s_[pos_] != '"') {
            char c = s_[pos_++];
            if (c == '\\') {
                if (pos_ >= s_.size()) return false;
                c = s_[pos_++];
                if (c == 'u') {  // names here are ASCII: keep the escape's low byte
                    if (pos_ + 4 > s_.size()) return false;
                    c = (char)std::strtol(s_.substr(pos_, 4).c_str(), nullptr, 16);
                    pos_ += 4;
                } else if (c == 'n') {
                    c = '\n';
                } else if (c == 't') {
                    c = '\t';
                } else if (c == 'r') {
                    c = '\r';
                } else if (c == 'b') {
                    c = '\b';
                } else if (c == 'f') {
                    c = '\f';
                }
            }
            out.push_back(c);
        }
        if (pos_ >= s_.size()) return false;
        ++pos_;
        return true;
    }
    bool value(Json& out, int depth) {
        if (depth > kMaxDepth) return false;
        skip();
        if (pos_ >= s_.size()) return false;
        const char c = s_[pos_];
        if (c == '{') {
            out.kind = Json::Object;
            ++pos_;
            skip();
            if (pos_ < s_.size() && s_[pos_] == '}') return ++pos_, true;
            for (;;) {
                skip();
                std::pair<std::string, Json> m;
                if (!string(m.first)) return false;
                skip();
                if (pos_ >= s_.size() || s_[pos_++] != ':') return false;
                if (!value(m.second, depth + 1)) return false;
                out.members.push_back(std::move(m));
                skip();
                if (pos_ < s_.size() && s_[pos_] == ',') {
                    ++pos_;
                    continue;
                }
                return pos_ < s_.size() && s_[pos_++] == '}';
            }
        }
        if (c == '[') {
            out.kind = Json::Array;
            ++pos_;
            skip();
            if (pos_ < s_.size() && s_[pos_] == ']') return ++pos_, true;
            for (;;) {
                Json item;
                if (!value(item, depth + 1)) return false;
                out.items.push_back(std::move(item));
                skip();
                if (pos_ < s_.size() && s_[pos_] == ',') {
                    ++pos_;
                    continue;
                }
                return pos_ < s_.size() && s_[pos_++] == ']';
            }
        }
        if (c == '"') {
            out.kind = Json::String;
            return string(out.text);
        }
        if (literal("true")) {
            out.kind = Json::Bool;
            out.number = 1.0;
            return true;
        }
        if (literal("false")) {
            out.kind = Json::Bool;
            return true;
        }
        if (literal("null")) return true;
        const char* start = s_.c_str() + pos_;
        char* end = nullptr;
        out.number = std::strtod(start, &end);
        if (end == start) return false;
        out.kind = Json::Number;
        pos_ += (size_t)(end - start);
        return std::isfinite(out.number);
    }

    const std::string& s_;
    size_t pos_ = 0;
};

// The array `name` (under `parent`) of exactly n finite numbers.
bool numbers(const Json* parent, const char* name, int n, double* out) {
    const Json* a = parent ? parent->get(name) : nullptr;
    if (!a || a->kind != Json::Array || (int)a->items.size() != n) return false;
    for (int i = 0; i < n; ++i) {
        if (a->items[(size_t)i].kind != Json::Number) return false;
        out[i] = a->items[(size_t)i].number;
    }
    return true;
}

void put_le(std::string& out, uint32_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) out.push_back((char)((v >> (8 * i)) & 0xFF));
}

}  // namespace

std::string encode_servo_packet(uint16_t frame_rate_hz, uint32_t frame_count, const uint16_t pwm_us[kSitlServoChannels]) {
    std::string packet;
    packet.reserve(kSitlServoPacketSize);
    put_le(packet, kSitlServoMagic, 2);
    put_le(packet, frame_rate_hz, 2);
    put_le(packet, frame_count, 4);
    for (int i = 0; i < kSitlServoChannels; ++i) put_le(packet, pwm_us[i], 2);
    return packet;
}

bool parse_physics_state(const std::string& datagram, PhysicsState& state, std::string& error) {
    // The last non-blank line: a datagram may carry more than one state; the newest wins.
    size_t end = datagram.find_last_not_of(" \t\r\n");
    if (end == std::string::npos) {
        error = "an empty reply";
        return false;
    }
    const size_t begin = datagram.find_last_of('\n', end);
    const std::string line = datagram.substr(begin == std::string::npos ? 0 : begin + 1, end + 1 - (begin == std::string::npos ? 0 : begin + 1));
    Json root;
    if (!JsonParser(line).parse(root) || root.kind != Json::Object) {
        error = "not a JSON object: '" + line.substr(0, 80) + "'";
        return false;
    }
    PhysicsState s;
    const Json* timestamp = root.get("timestamp");
    if (!timestamp || timestamp->kind != Json::Number) {
        error = "no timestamp";
        return false;
    }
    s.timestamp_s = timestamp->number;
    const Json* imu = root.get("imu");
    if (!numbers(imu, "gyro", 3, s.gyro_rad_s)) {
        error = "no imu.gyro [3]";
        return false;
    }
    if (!numbers(imu, "accel_body", 3, s.accel_body_m_s2)) {
        error = "no imu.accel_body [3]";
        return false;
    }
    if (!numbers(&root, "position", 3, s.position_m)) {
        error = "no position [3]";
        return false;
    }
    if (!numbers(&root, "velocity", 3, s.velocity_m_s)) {
        error = "no velocity [3]";
        return false;
    }
    double attitude[3];
    if (root.get("quaternion")) {
        if (!numbers(&root, "quaternion", 4, s.quat)) {
            error = "quaternion is not 4 numbers";
            return false;
        }
        const double norm = std::sqrt(s.quat[0] * s.quat[0] + s.quat[1] * s.quat[1] + s.quat[2] * s.quat[2] +
                                      s.quat[3] * s.quat[3]);
        if (!(norm > 0.5 && norm < 1.5)) {
            error = "quaternion is not a unit quaternion";
            return false;
        }
        for (double& q : s.quat) q /= norm;
    } else if (numbers(&root, "attitude", 3, attitude)) {
        const Quat q = from_euler(attitude[0], attitude[1], attitude[2]);
        s.quat[0] = q.w;
        s.quat[1] = q.x;
        s.quat[2] = q.y;
        s.quat[3] = q.z;
    } else {
        error = "no quaternion [4] or attitude [3]";
        return false;
    }
    if (const Json* rc = root.get("rc")) {
        if (rc->kind != Json::Object) {
            error = "rc is not an object";
            return false;
        }
        s.has_rc = true;
        for (int c = 0; c < kRcChannels; ++c) {
            char name[8];
            std::snprintf(name, sizeof name, "rc_%d", c + 1);
            const Json* v = rc->get(name);
            if (!v) continue;
            if (v->kind != Json::Number) {
                error = std::string("rc.") + name + " is not a number";
                return false;
            }
            s.rc_us[c] = v->number;
            ++s.rc_channels;
        }
    }
    if (const Json* airspeed = root.get("airspeed")) {
        if (airspeed->kind != Json::Number) {
            error = "airspeed is not a number";
            return false;
        }
        s.has_airspeed = true;
        s.airspeed_m_s = airspeed->number;
    }
    if (root.get("velocity_wind")) {
        if (!numbers(&root, "velocity_wind", 3, s.velocity_wind_m_s)) {
            error = "velocity_wind is not 3 numbers";
            return false;
        }
        s.has_wind = true;
    }
    state = s;
    return true;
}

bool ReplyClock::take(double timestamp_s) {
    if (started_ && !(timestamp_s > last_s_)) {
        ++stale_;
        return false;
    }
    started_ = true;
    last_s_ = timestamp_s;
    ++taken_;
    return true;
}

TrajectorySample physics_sample(const PhysicsState& state, double t_s, const double earth_field_ned_uT[3]) {
    TrajectorySample sample;
    sample.t_s = t_s;
    for (int i = 0; i < 3; ++i) {
        sample.gyro_rad_s[i] = state.gyro_rad_s[i];
        sample.accel_m_s2[i] = state.accel_body_m_s2[i];
        sample.ned_m[i] = state.position_m[i];
        sample.vel_ned_m_s[i] = state.velocity_m_s[i];
    }
    for (int i = 0; i < 4; ++i) sample.quat[i] = state.quat[i];
    const Quat q{state.quat[0], state.quat[1], state.quat[2], state.quat[3]};
    earth_to_body(q, earth_field_ned_uT, sample.mag_uT);
    sample.movement = true;
    return sample;
}

bool physics_rc_row(const PhysicsState& state, double t_s, RcRow& row, std::string& error) {
    row = RcRow();
    row.t_s = t_s;
    bool all_zero = true;
    for (int c = 0; c < kRcChannels; ++c) all_zero = all_zero && state.rc_us[c] == 0.0;
    if (state.rc_channels == 0 || all_zero) return true;  // dead
    if (state.rc_channels != kRcChannels) {
        error = "rc holds some of rc_1..rc_8 but not all";
        return false;
    }
    for (int c = 0; c < kRcChannels; ++c) {
        if (state.rc_us[c] < RcScript::kMinWidth_us || state.rc_us[c] > RcScript::kMaxWidth_us) {
            char why[96];
            std::snprintf(why, sizeof why, "rc.rc_%d = %g us is outside %.0f..%.0f us", c + 1, state.rc_us[c],
                          RcScript::kMinWidth_us, RcScript::kMaxWidth_us);
            error = why;
            return false;
        }
        row.width_us[c] = state.rc_us[c];
    }
    row.signal = true;
    return true;
}

}  // namespace sim
