// SPDX-License-Identifier: GPL-3.0-or-later
// UBX frames from a byte stream, and the solution they carry (u-blox 6 Receiver
// Description, "UBX Protocol", "UBX-NAV", "UBX-ACK", "UBX-CFG-NAV5"), fed a byte at a
// time as they leave the receive ring.
//
// The length is checked before anything is stored: a payload goes into the buffer only
// when it fits (kMaxPayload, NAV-SOL's 52 bytes, the longest message decoded); a longer
// frame of a plausible length (<= kMaxSkip) is skipped while its checksum is still
// summed (a valid frame not decoded), and a longer length is noise: the parser looks
// for the next sync at once. Bad checksums and overlong frames are counted.
//
// The solution: NAV-POSLLH (position), NAV-VELNED (velocity), NAV-SOL and NAV-STATUS
// (fix type, fix-valid flag, satellites, pDOP) update a working copy; a fix is complete
// when POSLLH and VELNED of the same epoch (iTOW) have both arrived (the messages of
// one epoch share its iTOW, "UBX-NAV"), so position and velocity are never of two
// different epochs. It is 2D or 3D only with gpsFixOk set (NAV-STATUS/SOL flags bit 0).
#pragma once

#include <stdint.h>

#include "GpsFix.h"
#include "UbxProtocol.h"

namespace gps {

class UbxParser {
public:
    // The working solution is the caller's (the NMEA parser may share it: only one of
    // them runs once a receiver is found).
    // constexpr (the payload zeroed, as a static object's is anyway): the firmware's
    // receiver is then set up at compile time, with no start-up code.
    explicit constexpr UbxParser(Fix& work) : payload_{}, fix_(work) {}

    static constexpr uint8_t kMaxPayload = ubx::kLenNavSol;
    static constexpr uint16_t kMaxSkip = 512;  // u-blox 6's longest output (NAV-SVINFO, 16 channels) fits

    enum class Message : uint8_t {
        kNone,   // no frame ended with this byte (or a bad one)
        kFix,    // a complete fix: fix()
        kAck,    // ACK-ACK for acked_class()/acked_id()
        kNak,    // ACK-NAK for the same
        kNav5,   // CFG-NAV5 (a poll's answer): dyn_model()
        kOther,  // another valid frame (NAV-STATUS, NAV-SOL, an unknown or long one ...)
    };
    struct Counters {
        uint32_t frames = 0;        // valid frames (checksum good)
        uint16_t bad_checksum = 0;
        uint16_t too_long = 0;      // longer than kMaxPayload (skipped) or than kMaxSkip (noise)
    };

    Message feed(uint8_t byte);

    const Fix& fix() const { return fix_; }  // complete after kFix, until the next one
    uint8_t acked_class() const { return ack_[0]; }
    uint8_t acked_id() const { return ack_[1]; }
    uint8_t dyn_model() const { return dyn_model_; }
    const Counters& counters() const { return counters_; }
    void reset();  // to the search for a sync, the working solution forgotten

private:
    enum State : uint8_t { kWaitSync1, kWaitSync2, kClass, kId, kLen1, kLen2, kPayload, kCkA, kCkB };
    Message decode();

    State state_ = kWaitSync1;
    uint8_t class_ = 0, id_ = 0;
    uint16_t length_ = 0, count_ = 0;
    ubx::Checksum ck_;
    uint8_t ck_a_ = 0;
    uint8_t payload_[kMaxPayload];
    // The working solution: complete at kFix results; which of this epoch's halves came.
    Fix& fix_;
    uint32_t pos_itow_ = 0, vel_itow_ = 0;
    uint8_t gps_fix_ = 0;        // the last NAV-STATUS/SOL gpsFix ...
    bool fix_ok_ = false;        // ... and gpsFixOk
    bool have_pos_ = false, have_vel_ = false;
    uint8_t ack_[2] = {0, 0};
    uint8_t dyn_model_ = 0;
    Counters counters_;
};

// The fix type a gpsFix value and the gpsFixOk flag mean (2D or 3D only when valid).
FixType ubx_fix_type(uint8_t gps_fix, bool fix_ok);

}  // namespace gps
