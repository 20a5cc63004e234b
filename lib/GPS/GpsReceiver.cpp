// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsReceiver.h"

#include <math.h>

#include "Constants.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define GPS_FLASH PROGMEM
static uint8_t flash_byte(const char* p) { return pgm_read_byte(p); }
#else
#define GPS_FLASH
static uint8_t flash_byte(const char* p) { return (uint8_t)*p; }
#endif

namespace gps {

using namespace ubx;

const char kPubx41[] GPS_FLASH = "$PUBX,41,1,0003,0001,38400,0*26\r\n";
static constexpr uint8_t kPubx41Len = sizeof("$PUBX,41,1,0003,0001,38400,0*26\r\n") - 1;

// The order ArduPilot tried on APM2's GPS port (the 3DR u-blox is set to 38400), as
// multiples of 4800 in flash (a switch would be a table in the AVR's RAM).
static const char kBaudIn4800s[] GPS_FLASH = {8, 12, 2, 24, 1};
uint32_t Receiver::baud_at(uint8_t index) {
    return 4800u * (uint32_t)flash_byte(kBaudIn4800s + (index < kBaudCount ? index : kBaudCount - 1u));
}

// Metres of a 1e-7 degree of latitude (WGS-84 equatorial radius, a sphere: AP_GPS_Glitch's scale).
static constexpr float kMetresPerE7 = 0.011131949f;

void Receiver::begin(const Config& config, uint32_t now_ms) {
    config_ = config;
    fix_ = Fix();
    quality_ = Quality::kNoFix;
    protocol_ = Protocol::kNone;
    glitching_ = have_good_ = no_gps_said_ = false;
    events_ = 0;
    bauds_tried_ = 0;
    if (config.type != Type::kAuto && config.type != Type::kUblox && config.type != Type::kNmea) {
        state_ = State::kOff;
        return;
    }
    state_ = State::kDetecting;
    start_baud(0, now_ms);
}

void Receiver::start_baud(uint8_t index, uint32_t now_ms) {
    baud_index_ = index;
    state_ms_ = now_ms;
    probe_step_ = config_.type == Type::kNmea ? 2u : 0u;  // an NMEA receiver is not probed
    probes_ms_ = now_ms;
    ubx_.reset();
    nmea_.reset();
    port_->set_baud(port_->ctx, baud_at(index));
}

bool Receiver::send_frame(uint8_t cls, uint8_t id, const uint8_t* payload, uint8_t len) {
    if (port_->room(port_->ctx) < len + kFrameOverhead) return false;
    uint8_t frame[kLenCfgNav5 + kFrameOverhead];
    port_->write(port_->ctx, frame, write_frame(frame, cls, id, payload, len));
    return true;
}

// The two probes, each when the port has room; true when both have left. $PUBX,41 first:
// a u-blox that hears it has left this baud (5 ms later) before the CFG-MSG's ACK, so
// that an ACK, which detection takes as the u-blox's first frame, comes only at the baud
// it stays at.
bool Receiver::send_probes() {
    if (probe_step_ == 0) {
        if (port_->room(port_->ctx) < kPubx41Len) return false;
        uint8_t text[kPubx41Len];
        for (uint8_t i = 0; i < kPubx41Len; ++i) text[i] = flash_byte(kPubx41 + i);
        port_->write(port_->ctx, text, kPubx41Len);
        probe_step_ = 1;
    }
    if (probe_step_ == 1) {
        uint8_t sol_on[kLenCfgMsg];  // (filled here: an initialiser would be a copy in RAM)
        sol_on[0] = kClassNav;
        sol_on[1] = kNavSol;
        sol_on[2] = 1;
        if (!send_frame(kClassCfg, kCfgMsg, sol_on, kLenCfgMsg)) return false;
        probe_step_ = 2;
    }
    return true;
}

// The configuration's next message; true when one was sent.
bool Receiver::send_step() {
    uint8_t p[kLenCfgNav5];
    switch (step_) {
        case kStepRate:
            p[0] = (uint8_t)kMeasRateMs;
            p[1] = (uint8_t)(kMeasRateMs >> 8);
            p[2] = 1;  // navRate: one solution a measurement
            p[3] = 0;
            p[4] = 0;  // timeRef 0: UTC, as ArduPilot
            p[5] = 0;
            return send_frame(kClassCfg, kCfgRate, p, kLenCfgRate);
        case kStepPosllh:
        case kStepStatus:
        case kStepSol:
        case kStepVelned: {
            p[0] = kClassNav;
            p[1] = step_ == kStepPosllh ? kNavPosllh : step_ == kStepStatus ? kNavStatus : step_ == kStepSol ? kNavSol : kNavVelned;
            p[2] = 1;  // every solution
            return send_frame(kClassCfg, kCfgMsg, p, kLenCfgMsg);
        }
        case kStepPollNav5: return send_frame(kClassCfg, kCfgNav5, nullptr, 0);  // a poll: no payload
        case kStepWriteNav5:
            for (uint8_t i = 0; i < kLenCfgNav5; ++i) p[i] = 0;  // only the masked field applies
            p[kNav5Mask] = (uint8_t)kNav5MaskDyn;
            p[kNav5DynModel] = config_.nav_filter;
            return send_frame(kClassCfg, kCfgNav5, p, kLenCfgNav5);
        default: return false;
    }
}

void Receiver::found_at(Protocol p, uint32_t now_ms) {
    protocol_ = p;
    events_ |= kEventFound;
    no_gps_said_ = false;
    bauds_tried_ = 0;
    last_data_ms_ = rate_ok_ms_ = state_ms_ = now_ms;
    if (p == Protocol::kUbx) {
        state_ = State::kConfiguring;
        step_ = kStepRate;
        nmea_.reset();
    } else {
        state_ = State::kRunning;
        ubx_.reset();
    }
}

void Receiver::feed(uint8_t byte, uint32_t now_ms) {
    if (state_ == State::kOff) return;
    const bool detecting = state_ == State::kDetecting;
    if (detecting ? config_.type != Type::kNmea : protocol_ == Protocol::kUbx) {
        const UbxParser::Message m = ubx_.feed(byte);
        if (m != UbxParser::Message::kNone) {
            last_data_ms_ = now_ms;
            if (detecting) {
                found_at(Protocol::kUbx, now_ms);
                return;
            }
            if (m == UbxParser::Message::kFix) {
                new_solution(ubx_.fix(), now_ms);
            } else if (m == UbxParser::Message::kNav5 && state_ == State::kConfiguring && step_ == kStepWaitNav5) {
                if (ubx_.dyn_model() == config_.nav_filter) {
                    state_ = State::kRunning;
                    events_ |= kEventConfigured;
                } else {
                    step_ = kStepWriteNav5;
                }
            }
        }
    }
    if (detecting ? config_.type != Type::kUblox : protocol_ == Protocol::kNmea) {
        const NmeaParser::Message m = nmea_.feed(byte);
        if (m == NmeaParser::Message::kNone) return;
        if (detecting) {
            // In auto, only once a u-blox that heard the probes would have left NMEA.
            if (config_.type == Type::kAuto && (probe_step_ < 2 || now_ms - probes_ms_ < kNmeaSettleMs)) return;
            found_at(Protocol::kNmea, now_ms);
            return;
        }
        last_data_ms_ = now_ms;
        if (m == NmeaParser::Message::kFix) new_solution(nmea_.fix(), now_ms);
    }
}

void Receiver::update(uint32_t now_ms) {
    switch (state_) {
        case State::kOff: return;
        case State::kDetecting:
            if (now_ms - state_ms_ >= kBaudDwellMs) {
                // A round and the first baud again: a u-blox that took the probes during
                // the round (at its factory 9600) is found at 38400 before it is missed.
                if (bauds_tried_ <= kBaudCount) ++bauds_tried_;
                if (bauds_tried_ == kBaudCount + 1u && !no_gps_said_) {
                    events_ |= kEventNoGpsFound;
                    no_gps_said_ = true;
                }
                start_baud((uint8_t)((baud_index_ + 1u) % kBaudCount), now_ms);
            }
            if (probe_step_ < 2 && send_probes()) probes_ms_ = now_ms;
            return;
        case State::kConfiguring:
        case State::kRunning:
            break;
    }
    if (now_ms - last_data_ms_ > kDataTimeoutMs) {  // lost: detection again, at this baud first
        events_ |= kEventLost;
        fix_.fix = FixType::kNoGps;
        ++fix_count_;
        if (quality_ != Quality::kNoFix) events_ |= kEventQuality;
        quality_ = Quality::kNoFix;
        protocol_ = Protocol::kNone;
        state_ = State::kDetecting;
        bauds_tried_ = 0;
        start_baud(baud_index_, now_ms);
        return;
    }
    if (state_ == State::kConfiguring) {
        if (step_ == kStepWaitNav5) {
            if (now_ms - state_ms_ >= kPollMs) step_ = kStepPollNav5;  // unanswered: again
            return;
        }
        if (send_step()) {
            step_ = step_ == kStepWriteNav5 ? (uint8_t)kStepPollNav5 : (uint8_t)(step_ + 1u);
            state_ms_ = now_ms;
        }
        return;
    }
    // Running.
    if (now_ms - rate_ok_ms_ > kRateLostMs) {
        rate_ok_ms_ = now_ms;
        if (protocol_ == Protocol::kUbx) {
            state_ = State::kConfiguring;  // the rates again
            step_ = kStepRate;
        } else if (config_.type == Type::kAuto) {
            probe_step_ = 0;  // a u-blox that missed the probes?
        }
    }
    if (probe_step_ < 2) send_probes();
}

void Receiver::new_solution(const Fix& f, uint32_t now_ms) {
    const uint32_t previous_itow = last_itow_ms_;
    fix_ = f;
    fix_.received_ms = now_ms;
    // A position off the earth or a speed beyond any aircraft's is no fix, whatever the
    // receiver says (a frame with a valid checksum can still carry nonsense).
    if (fix_.fix >= FixType::k2D &&
        (fix_.lat_e7 > 900000000 || fix_.lat_e7 < -900000000 || fix_.lon_e7 > 1800000000 ||
         fix_.lon_e7 < -1800000000 || fix_.ground_speed_cm_s > kMaxSpeedCmS || fix_.course_e5 < 0 ||
         fix_.course_e5 > 36000000))
        fix_.fix = FixType::kNoFix;
    last_itow_ms_ = f.itow_ms;
    if (protocol_ == Protocol::kUbx && f.itow_ms - previous_itow <= kRateGapMs) rate_ok_ms_ = now_ms;
    check_glitch(now_ms);
    ++fix_count_;
    Quality q = Quality::kNoFix;
    if (fix_.fix == FixType::k3D) q = fix_.sats < config_.min_sats ? Quality::k3DFewSats : Quality::k3D;
    else if (fix_.fix == FixType::k2D) q = Quality::k2D;
    if (q != quality_) events_ |= kEventQuality;
    quality_ = q;
}

// AP_GPS_Glitch: the distance from where the last good position and velocity say the
// receiver is now, against a radius plus what the largest acceleration explains.
void Receiver::check_glitch(uint32_t now_ms) {
    fix_.glitching = false;
    if (fix_.fix < FixType::k2D) {  // no position: the next one starts afresh
        if (glitching_) events_ |= kEventGlitchOver;
        glitching_ = have_good_ = false;
        return;
    }
    const float vel_n = (float)fix_.vel_ned_cm_s[0] * 0.01f, vel_e = (float)fix_.vel_ned_cm_s[1] * 0.01f;
    bool ok = true;
    if (have_good_) {
        const float dt_s = (float)(now_ms - good_ms_) * 0.001f;
        const float lon_scale = cosf((float)good_lat_e7_ * 1e-7f * linalg::kRadPerDeg);
        const float dn = (float)(fix_.lat_e7 - good_lat_e7_) * kMetresPerE7 - good_vel_n_m_s_ * dt_s;
        const float de = (float)(fix_.lon_e7 - good_lon_e7_) * kMetresPerE7 * lon_scale - good_vel_e_m_s_ * dt_s;
        glitch_m_ = sqrtf(dn * dn + de * de);
        ok = glitch_m_ <= kGlitchRadiusM + 0.5f * kGlitchAccelMss * dt_s * dt_s;
    }
    if (ok) {
        have_good_ = true;
        good_ms_ = now_ms;
        good_lat_e7_ = fix_.lat_e7;
        good_lon_e7_ = fix_.lon_e7;
        good_vel_n_m_s_ = vel_n;
        good_vel_e_m_s_ = vel_e;
        if (glitching_) events_ |= kEventGlitchOver;
        glitching_ = false;
        return;
    }
    if (!glitching_) events_ |= kEventGlitch;
    glitching_ = true;
    fix_.glitching = true;
}

}  // namespace gps
