// SPDX-License-Identifier: GPL-3.0-or-later
// The u-blox UBX and NMEA framing the GPS model speaks (u-blox 6 Receiver Description
// including Protocol Specification, GPS.G6-SW-10018: "UBX Protocol", "NMEA Protocol").
//
// UBX frame: 0xB5 0x62, class, id, length (uint16 little-endian), payload, CK_A, CK_B,
// the checksum an 8-bit Fletcher over class..payload (ck_a += b; ck_b += ck_a).
// NMEA sentence: '$', fields separated by ',', '*', two upper-case hex digits of the XOR
// of the characters between '$' and '*', CR LF.
// Host-only.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <string>
#include <vector>

#include "UbxProtocol.h"

namespace sim {
namespace ubx {

// The ids, payload lengths, protocol masks, the checksum and the field readers are the
// firmware's own (lib/GPS/UbxProtocol.h): one definition of the protocol.
using namespace gps::ubx;

// A whole frame.
std::vector<uint8_t> frame(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload);

// Little-endian payload building and reading.
void put_u1(std::vector<uint8_t>& p, uint32_t v);
void put_u2(std::vector<uint8_t>& p, uint32_t v);
void put_u4(std::vector<uint8_t>& p, uint32_t v);
inline void put_i4(std::vector<uint8_t>& p, int32_t v) { put_u4(p, (uint32_t)v); }

// The sentence "$" body "*hh\r\n" for a body without '$' and '*'.
std::string nmea_sentence(const std::string& body);

// Splits an input byte stream into UBX frames and NMEA sentences, as a receiver's port
// does: bytes outside either are dropped, a frame or sentence that breaks off (a bad
// checksum, a length over kMaxPayload, a sentence over kMaxSentence characters without its
// end) is counted and dropped, and the parser looks for the next start.
class StreamParser {
public:
    static constexpr size_t kMaxPayload = 1024;
    static constexpr size_t kMaxSentence = 120;  // NMEA 0183: 82; u-blox accepts longer PUBX

    struct Message {
        bool is_ubx = false;
        uint8_t cls = 0, id = 0;
        std::vector<uint8_t> payload;  // UBX
        std::string sentence;          // NMEA: between '$' and '*' (checksum checked)
    };
    struct Counters {
        uint32_t ubx_frames = 0;
        uint32_t ubx_bad_checksum = 0;
        uint32_t ubx_too_long = 0;
        uint32_t nmea_sentences = 0;
        uint32_t nmea_bad_checksum = 0;
        uint32_t nmea_malformed = 0;     // no '*hh', or too long
        uint32_t bytes_outside = 0;      // bytes that began neither
    };

    // Feeds one byte; true when it completed a valid message (in `out`).
    bool feed(uint8_t byte, Message& out);
    const Counters& counters() const { return counters_; }
    void reset() { state_ = kIdle; }

private:
    enum State { kIdle, kGotSync1, kClass, kId, kLen1, kLen2, kPayload, kCkA, kCkB, kNmea };
    bool start(uint8_t byte);

    State state_ = kIdle;
    Message msg_;
    uint16_t length_ = 0;
    uint8_t got_ck_a_ = 0;
    Counters counters_;
};

}  // namespace ubx
}  // namespace sim
