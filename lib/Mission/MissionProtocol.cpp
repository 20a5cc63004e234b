// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionProtocol.h"

#include "Location.h"

namespace mission {

namespace {

constexpr int32_t kMaxLatE7 = 900000000;
constexpr int32_t kMaxLonE7 = 1800000000;

bool place_frame(uint8_t frame, bool& relative) {
    switch (frame) {
    case kFrameGlobal:
    case kFrameGlobalInt:
        relative = false;
        return true;
    case kFrameGlobalRelativeAlt:
    case kFrameGlobalRelativeAltInt:
        relative = true;
        return true;
    default:
        return false;
    }
}

// Not inlined: its eight calls inlined took ~430 bytes more of the AVR's flash.
__attribute__((noinline)) uint16_t clamp_u16(float x, float hi) {
    if (!(x > 0.0f)) return 0;
    return (uint16_t)(x > hi ? hi : x + 0.5f);
}

}  // namespace

int32_t e7_from_degrees(float degrees) { return nav::round_to_int32(degrees * 1e7f); }
float degrees_from_e7(int32_t e7) { return (float)e7 * 1e-7f; }

bool guided_command(const Item& item, Command& c, Result& why) {
    if (!from_item(item, c, why)) return false;
    why = Result::kUnsupported;
    return is_nav(c.id) && c.has_place();
}

bool from_item(const Item& item, Command& c, Result& why) {
    c = Command();
    c.id = item.command;
    if (!is_supported(item.command)) {
        why = Result::kUnsupported;
        return false;
    }
    if (is_nav(item.command) && item.command != kNavReturnToLaunch) {
        bool relative = true;
        if (!place_frame(item.frame, relative)) {
            why = Result::kUnsupportedFrame;
            return false;
        }
        if (item.x > kMaxLatE7 || item.x < -kMaxLatE7) {
            why = Result::kInvalidParam5;
            return false;
        }
        if (item.y > kMaxLonE7 || item.y < -kMaxLonE7) {
            why = Result::kInvalidParam6;
            return false;
        }
        c.relative_alt = relative;
        c.lat_e7 = item.x;
        c.lon_e7 = item.y;
        c.alt_cm = nav::round_to_int32(item.z * 100.0f);
    }
    const float p3 = item.param3;
    switch (item.command) {
    case kNavLoiterUnlim:
        c.p1 = clamp_u16(p3 < 0.0f ? -p3 : p3, 65535.0f);
        c.loiter_ccw = p3 < 0.0f;
        break;
    case kNavLoiterTurns:
        c.p1 = (uint16_t)((uint16_t)(clamp_u16(p3 < 0.0f ? -p3 : p3, 255.0f) << 8) | clamp_u16(item.param1, 255.0f));
        c.loiter_ccw = p3 < 0.0f;
        break;
    case kNavLoiterTime:
        c.p1 = clamp_u16(item.param1, 65535.0f);
        c.loiter_ccw = p3 < 0.0f;
        break;
    case kNavTakeoff:
        c.p1 = clamp_u16(item.param1, 90.0f);
        break;
    case kDoJump:
        c.p1 = clamp_u16(item.param1, 65535.0f);
        c.lat_e7 = item.param2 < 0.0f ? -1 : (int32_t)clamp_u16(item.param2, 32767.0f);
        break;
    case kDoChangeSpeed:
        c.p1 = clamp_u16(item.param1, 1.0f);
        c.lat_e7 = item.param2 > 0.0f ? nav::round_to_int32(item.param2 * 100.0f) : -1;
        c.lon_e7 = item.param3 > 0.0f ? nav::round_to_int32(item.param3) : -1;
        break;
    default:
        break;
    }
    return true;
}

Item to_item(const Command& c, uint16_t seq, bool int_form) {
    Item it = {};
    it.seq = seq;
    it.command = c.id;
    it.autocontinue = 1;
    it.int_form = int_form;
    const float ccw = c.loiter_ccw ? -1.0f : 1.0f;
    if (is_nav(c.id)) {
        it.frame = c.relative_alt ? (int_form ? kFrameGlobalRelativeAltInt : kFrameGlobalRelativeAlt)
                                  : (int_form ? kFrameGlobalInt : kFrameGlobal);
        it.x = c.lat_e7;
        it.y = c.lon_e7;
        it.z = (float)c.alt_cm * 0.01f;
    } else {
        it.frame = kFrameMission;
    }
    switch (c.id) {
    case kNavLoiterUnlim:
        it.param3 = ccw * (float)c.p1;
        break;
    case kNavLoiterTurns:
        it.param1 = (float)loiter_turns(c);
        it.param3 = ccw * (float)loiter_turns_radius_m(c);
        break;
    case kNavLoiterTime:
        it.param1 = (float)c.p1;
        it.param3 = c.loiter_ccw ? -1.0f : 0.0f;
        break;
    case kNavTakeoff:
        it.param1 = (float)c.p1;
        break;
    case kDoJump:
        it.param1 = (float)c.p1;
        it.param2 = (float)c.lat_e7;
        break;
    case kDoChangeSpeed:
        it.param1 = (float)c.p1;
        it.param2 = c.lat_e7 > 0 ? (float)c.lat_e7 * 0.01f : -1.0f;
        it.param3 = c.lon_e7 > 0 ? (float)c.lon_e7 : -1.0f;
        break;
    default:
        break;
    }
    return it;
}

Item home_item(const nav::Location& home, bool int_form) {
    Command c;
    c.id = kNavWaypoint;
    c.lat_e7 = home.lat_e7;
    c.lon_e7 = home.lon_e7;
    c.alt_cm = home.alt_cm;
    c.relative_alt = false;
    return to_item(c, 0, int_form);
}

Reply MissionProtocol::request(uint16_t seq) {
    Reply r = {};
    r.kind = request_int_ ? Reply::kRequestInt : Reply::kRequest;
    r.seq = seq;
    return r;
}

Reply MissionProtocol::ack(Result result, uint8_t mission_type) {
    Reply r = {};
    r.kind = Reply::kAck;
    r.result = result;
    r.mission_type = mission_type;
    return r;
}

void MissionProtocol::finish(uint8_t commands) {
    store_.commit(commands);
    ++changes_;
    state_ = State::kIdle;
}

Reply MissionProtocol::on_count(uint16_t count, uint8_t mission_type, uint32_t now_ms) {
    if (mission_type != kTypeMission) return ack(Result::kUnsupported, mission_type);
    done_recently_ = false;
    if (count > (uint16_t)kMaxCommands + 1u) {
        state_ = State::kIdle;
        return ack(Result::kNoSpace);
    }
    store_.begin_upload();
    if (count == 0) {  // ArduPilot clears the mission on a count of 0
        finish(0);
        return ack(Result::kAccepted);
    }
    state_ = State::kReceiving;
    count_ = count;
    expected_ = 0;
    retries_ = 0;
    any_item_ = false;
    request_int_ = true;
    last_ms_ = now_ms;
    return request(0);
}

Reply MissionProtocol::on_item(const Item& item, uint32_t now_ms) {
    if (item.mission_type != kTypeMission) return ack(Result::kUnsupported, item.mission_type);
    if (state_ != State::kReceiving) {
        // The last item again: our ACK was lost. Anything else: no upload is running.
        if (done_recently_ && item.seq + 1u == last_done_) return ack(Result::kAccepted);
        return ack(Result::kError);
    }
    request_int_ = item.int_form;
    any_item_ = true;
    last_ms_ = now_ms;
    retries_ = 0;
    if (item.seq != expected_) return request(expected_);
    if (item.seq > 0) {
        Command c;
        Result why = Result::kError;
        if (!from_item(item, c, why)) {
            state_ = State::kIdle;  // the mission before stays
            return ack(why);
        }
        store_.write((uint8_t)(item.seq - 1u), c);
    }
    ++expected_;
    if (expected_ < count_) return request(expected_);
    finish((uint8_t)(count_ - 1u));
    last_done_ = count_;
    done_recently_ = true;
    return ack(Result::kAccepted);
}

Reply MissionProtocol::tick(uint32_t now_ms) {
    Reply none = {};
    if (state_ != State::kReceiving || now_ms - last_ms_ < kRetryTimeout_ms) return none;
    if (retries_ >= kRetries) {
        state_ = State::kIdle;  // the ground station went: the mission before stays
        return ack(Result::kOperationCancelled);
    }
    ++retries_;
    last_ms_ = now_ms;
    if (!any_item_) request_int_ = !request_int_;  // perhaps a station that knows only MISSION_REQUEST
    return request(expected_);
}

void MissionProtocol::on_ack(uint8_t mission_type) {
    if (mission_type == kTypeMission && state_ == State::kReceiving) state_ = State::kIdle;
}

Reply MissionProtocol::on_request_list(uint8_t mission_type) {
    Reply r = {};
    r.kind = Reply::kCount;
    r.mission_type = mission_type;
    r.seq = mission_type == kTypeMission ? (uint16_t)(store_.count() + 1u) : 0u;
    return r;
}

Reply MissionProtocol::on_request(uint16_t seq, bool int_form, uint8_t mission_type, const nav::Location& home) {
    if (mission_type != kTypeMission) return ack(Result::kUnsupported, mission_type);
    Reply r = {};
    if (seq == 0) {
        r.kind = Reply::kItem;
        r.item = home_item(home, int_form);
        return r;
    }
    Command c;
    if (seq > store_.count() || !store_.read((uint8_t)(seq - 1u), c)) return ack(Result::kInvalidSequence);
    r.kind = Reply::kItem;
    r.item = to_item(c, seq, int_form);
    return r;
}

Reply MissionProtocol::on_clear_all(uint8_t mission_type) {
    if (mission_type != kTypeMission) return ack(Result::kUnsupported, mission_type);
    state_ = State::kIdle;
    done_recently_ = false;
    store_.begin_upload();
    finish(0);
    return ack(Result::kAccepted);
}

Reply MissionProtocol::on_set_current(uint16_t seq) {
    Reply r = {};
    if (seq == 0 || seq > store_.count()) return r;
    r.kind = Reply::kCurrent;
    r.seq = seq;
    return r;
}

}  // namespace mission
