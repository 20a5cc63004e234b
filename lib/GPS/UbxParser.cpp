// SPDX-License-Identifier: GPL-3.0-or-later
#include "UbxParser.h"

namespace gps {

using namespace ubx;

FixType ubx_fix_type(uint8_t gps_fix, bool fix_ok) {
    if (!fix_ok) return FixType::kNoFix;
    if (gps_fix == kGpsFix3D || gps_fix == kGpsFixGpsDr) return FixType::k3D;
    if (gps_fix == kGpsFix2D) return FixType::k2D;
    return FixType::kNoFix;  // dead reckoning only, time only
}

void UbxParser::reset() {
    state_ = kWaitSync1;
    have_pos_ = have_vel_ = false;
}

UbxParser::Message UbxParser::feed(uint8_t byte) {
    if (state_ >= kClass && state_ <= kPayload) ck_.add(byte);  // class .. payload are summed
    switch (state_) {
        case kWaitSync1:
            if (byte == ubx::kSync1) state_ = kWaitSync2;
            return Message::kNone;
        case kWaitSync2:
            state_ = byte == ubx::kSync2 ? kClass : (byte == ubx::kSync1 ? kWaitSync2 : kWaitSync1);
            ck_ = Checksum();
            return Message::kNone;
        case kClass:
            class_ = byte;
            state_ = kId;
            return Message::kNone;
        case kId:
            id_ = byte;
            state_ = kLen1;
            return Message::kNone;
        case kLen1:
            length_ = byte;
            state_ = kLen2;
            return Message::kNone;
        case kLen2:
            length_ = (uint16_t)(length_ | (uint16_t)((uint16_t)byte << 8));
            count_ = 0;
            if (length_ > kMaxPayload) ++counters_.too_long;
            if (length_ > kMaxSkip) {  // noise: look for the next sync now
                state_ = kWaitSync1;
                return Message::kNone;
            }
            state_ = length_ == 0 ? kCkA : kPayload;
            return Message::kNone;
        case kPayload:
            if (count_ < kMaxPayload) payload_[count_] = byte;
            if (++count_ == length_) state_ = kCkA;
            return Message::kNone;
        case kCkA:
            ck_a_ = byte;
            state_ = kCkB;
            return Message::kNone;
        case kCkB:
            state_ = kWaitSync1;
            if (ck_a_ != ck_.a || byte != ck_.b) {
                ++counters_.bad_checksum;
                return Message::kNone;
            }
            ++counters_.frames;
            return decode();
    }
    return Message::kNone;
}

// A valid frame: its payload is in payload_ when length_ <= kMaxPayload.
UbxParser::Message UbxParser::decode() {
    const uint8_t* p = payload_;
    if (class_ == kClassNav) {
        if (id_ == kNavPosllh && length_ == kLenNavPosllh) {
            pos_itow_ = get_u4(p + kPosllhItow);
            fix_.lon_e7 = get_i4(p + kPosllhLon);
            fix_.lat_e7 = get_i4(p + kPosllhLat);
            fix_.alt_msl_mm = get_i4(p + kPosllhHmsl);
            fix_.h_acc_mm = get_u4(p + kPosllhHacc);
            have_pos_ = true;
        } else if (id_ == kNavStatus && length_ == kLenNavStatus) {
            gps_fix_ = p[kStatusFix];
            fix_ok_ = (p[kStatusFlags] & kFlagFixOk) != 0;
            return Message::kOther;
        } else if (id_ == kNavSol && length_ == kLenNavSol) {
            gps_fix_ = p[kSolFix];
            fix_ok_ = (p[kSolFlags] & kFlagFixOk) != 0;
            fix_.hdop_cm = get_u2(p + kSolPdop);  // pDOP, as ArduPilot's u-blox driver reports it
            fix_.sats = p[kSolNumSv];
            fix_.week = get_u2(p + kSolWeek);
            return Message::kOther;
        } else if (id_ == kNavVelned && length_ == kLenNavVelned) {
            vel_itow_ = get_u4(p + kVelnedItow);
            for (uint8_t i = 0; i < 3; ++i) fix_.vel_ned_cm_s[i] = get_i4(p + kVelnedN + 4 * i);
            fix_.ground_speed_cm_s = get_u4(p + kVelnedGspeed);
            fix_.course_e5 = get_i4(p + kVelnedHeading);
            fix_.speed_acc_cm_s = get_u4(p + kVelnedSacc);
            have_vel_ = true;
        } else {
            return Message::kOther;
        }
        if (!(have_pos_ && have_vel_ && pos_itow_ == vel_itow_)) return Message::kOther;
        have_pos_ = have_vel_ = false;
        fix_.itow_ms = pos_itow_;
        fix_.fix = ubx_fix_type(gps_fix_, fix_ok_);
        fix_.have_vertical_velocity = true;
        return Message::kFix;
    }
    if (class_ == kClassAck && length_ == kLenAck) {
        ack_[0] = p[0];
        ack_[1] = p[1];
        return id_ == kAckAck ? Message::kAck : Message::kNak;
    }
    if (class_ == kClassCfg && id_ == kCfgNav5 && length_ == kLenCfgNav5) {
        dyn_model_ = p[kNav5DynModel];
        return Message::kNav5;
    }
    return Message::kOther;
}

}  // namespace gps
