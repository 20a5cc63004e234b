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

namespace sim {
namespace ubx {

constexpr uint8_t kSync1 = 0xB5;
constexpr uint8_t kSync2 = 0x62;

constexpr uint8_t kClassNav = 0x01;
constexpr uint8_t kClassAck = 0x05;
constexpr uint8_t kClassCfg = 0x06;
constexpr uint8_t kClassMon = 0x0A;
constexpr uint8_t kClassNmea = 0xF0;  // NMEA standard messages in CFG-MSG
constexpr uint8_t kClassPubx = 0xF1;  // u-blox proprietary NMEA in CFG-MSG

constexpr uint8_t kNavPosllh = 0x02;
constexpr uint8_t kNavStatus = 0x03;
constexpr uint8_t kNavDop = 0x04;
constexpr uint8_t kNavSol = 0x06;
constexpr uint8_t kNavVelned = 0x12;
constexpr uint8_t kAckNak = 0x00;
constexpr uint8_t kAckAck = 0x01;
constexpr uint8_t kCfgPrt = 0x00;
constexpr uint8_t kCfgMsg = 0x01;
constexpr uint8_t kCfgRst = 0x04;
constexpr uint8_t kCfgRate = 0x08;
constexpr uint8_t kCfgCfg = 0x09;
constexpr uint8_t kCfgSbas = 0x16;
constexpr uint8_t kCfgNav5 = 0x24;
constexpr uint8_t kMonVer = 0x04;

// NMEA message ids in class 0xF0 (CFG-MSG).
constexpr uint8_t kNmeaGga = 0x00;
constexpr uint8_t kNmeaGll = 0x01;
constexpr uint8_t kNmeaGsa = 0x02;
constexpr uint8_t kNmeaGsv = 0x03;
constexpr uint8_t kNmeaRmc = 0x04;
constexpr uint8_t kNmeaVtg = 0x05;

// Payload lengths (Protocol Specification, "UBX-NAV" and "UBX-ACK").
constexpr uint16_t kLenNavPosllh = 28;
constexpr uint16_t kLenNavStatus = 16;
constexpr uint16_t kLenNavDop = 18;
constexpr uint16_t kLenNavSol = 52;
constexpr uint16_t kLenNavVelned = 36;
constexpr uint16_t kLenAck = 2;
constexpr uint16_t kLenCfgPrt = 20;
constexpr uint16_t kLenCfgRate = 6;
constexpr uint16_t kLenCfgNav5 = 36;
constexpr uint16_t kLenCfgSbas = 8;

// Port protocol masks (CFG-PRT inProtoMask / outProtoMask, PUBX,41).
constexpr uint16_t kProtoUbx = 0x0001;
constexpr uint16_t kProtoNmea = 0x0002;
constexpr uint16_t kProtoRtcm = 0x0004;

// CK_A, CK_B over `n` bytes (class, id, length, payload).
void checksum(const uint8_t* data, size_t n, uint8_t& ck_a, uint8_t& ck_b);

// A whole frame.
std::vector<uint8_t> frame(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload);

// Little-endian payload building and reading.
void put_u1(std::vector<uint8_t>& p, uint32_t v);
void put_u2(std::vector<uint8_t>& p, uint32_t v);
void put_u4(std::vector<uint8_t>& p, uint32_t v);
inline void put_i4(std::vector<uint8_t>& p, int32_t v) { put_u4(p, (uint32_t)v); }
uint16_t get_u2(const uint8_t* p);
uint32_t get_u4(const uint8_t* p);
inline int32_t get_i4(const uint8_t* p) { return (int32_t)get_u4(p); }

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
    uint8_t ck_a_ = 0, ck_b_ = 0, got_ck_a_ = 0;
    Counters counters_;
};

}  // namespace ubx
}  // namespace sim
