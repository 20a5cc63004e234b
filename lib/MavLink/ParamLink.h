// SPDX-License-Identifier: GPL-3.0-or-later
// MAVLink's parameter protocol over the parameter table (lib/Settings/Params.h), as
// ArduPilot answers it:
//
//   PARAM_REQUEST_LIST  -> PARAM_VALUE for every index 0 .. count-1, in order, paced by
//                          the caller (a few per loop as the serial queue has room)
//   PARAM_REQUEST_READ  -> PARAM_VALUE of that index, or of that name (index -1);
//                          nothing for an unknown one (ArduPilot ignores it too)
//   PARAM_SET           -> params::set, then PARAM_VALUE with the value in force: the new
//                          one, or the old one when the table refused it (out of range,
//                          not whole, end points out of order); nothing for an unknown name
//
// Values travel as floats, the types as ArduPilot's (REAL32 for floats and COMPASS_DEC,
// INT16 for 16-bit values, INT8 for bytes and reverse bits): every value of the table fits
// its type. Plain C++, host-tested.
#pragma once

#include <stdint.h>

#include "MavLink.h"
#include "Params.h"
#include "Settings.h"

namespace mav {

// MAV_PARAM_TYPE of a table type.
uint8_t param_type(params::Type t);

// PARAM_VALUE of parameter `index` (0 past the end); count: params::count() (a walk over
// the table: ParamReplies keeps it).
uint8_t pack_param_value(Packer& packer, uint8_t out[kMaxFrame], const settings::Settings& s, uint16_t index,
                         uint16_t count);

// The index a PARAM_REQUEST_READ asks for, or -1 (past the end, unknown name).
int16_t requested_index(const ParamRequest& r);

// Applies a PARAM_SET: the index to answer with (-1: unknown name, no answer); `changed`
// when the value in force is now another (worth saving).
int16_t apply_param_set(settings::Settings& s, const ParamSet& p, bool& changed);

// The PARAM_VALUE replies still to send: the whole list (after PARAM_REQUEST_LIST, from
// index 0; a new request starts it over) and single ones, those first, lowest index
// first. A single one is a bit per parameter: a burst of PARAM_SETs (or READs, or a
// parameter changed by the console, the defaults, a calibration) is each answered once,
// however many come before the link has room, in ~kMaxParams / 8 bytes of RAM.
class ParamReplies {
public:
    static constexpr uint16_t kMaxParams = 192;  // params::count() must stay below (a test holds it)
    void request_all();
    void request_one(uint16_t index);
    // Every parameter once (the defaults restored: ArduPilot resends the list too).
    void request_every_one();
    // The next index to send; false when none is pending.
    bool peek(uint16_t& index) const;
    void pop();  // the peeked one was sent
    uint16_t count() const { return count_; }  // params::count(), taken at a request

private:
    uint8_t pending_[kMaxParams / 8] = {};
    uint8_t singles_ = 0;  // bits set in pending_
    uint8_t next_of_list_ = kNone;
    uint8_t count_ = 0;
    static constexpr uint8_t kNone = 0xFF;  // params::count() < 255
};

}  // namespace mav
