// SPDX-License-Identifier: GPL-3.0-or-later
// The u-blox UBX protocol's framing, message ids and payload layout (u-blox 6 Receiver
// Description including Protocol Specification, GPS.G6-SW-10018, "UBX Protocol"): one
// definition that the firmware's parser and configuration and the simulator's u-blox
// model (sim/models/Ubx.h) share. Plain C++, no Arduino.
//
// Frame: 0xB5 0x62, class, id, length (uint16 little-endian), payload, CK_A, CK_B; the
// checksum is the 8-bit Fletcher algorithm over class..payload ("UBX Checksum").
// NMEA sentence: '$', fields, '*', two hex digits of the XOR of the characters between
// '$' and '*', CR LF ("NMEA Protocol").
#pragma once

#include <stddef.h>
#include <stdint.h>

namespace gps {
namespace ubx {

constexpr uint8_t kSync1 = 0xB5;
constexpr uint8_t kSync2 = 0x62;
constexpr uint8_t kFrameOverhead = 8;  // sync 2, class, id, length 2, checksum 2

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

// Payload lengths ("UBX-NAV", "UBX-ACK", "UBX-CFG").
constexpr uint16_t kLenNavPosllh = 28;
constexpr uint16_t kLenNavStatus = 16;
constexpr uint16_t kLenNavDop = 18;
constexpr uint16_t kLenNavSol = 52;
constexpr uint16_t kLenNavVelned = 36;
constexpr uint16_t kLenAck = 2;
constexpr uint16_t kLenCfgPrt = 20;
constexpr uint16_t kLenCfgMsg = 3;  // the current port's rate only
constexpr uint16_t kLenCfgRate = 6;
constexpr uint16_t kLenCfgNav5 = 36;
constexpr uint16_t kLenCfgSbas = 8;

// Payload offsets of the fields decoded (the same sections).
constexpr uint8_t kPosllhItow = 0, kPosllhLon = 4, kPosllhLat = 8, kPosllhHmsl = 16, kPosllhHacc = 20;
constexpr uint8_t kStatusItow = 0, kStatusFix = 4, kStatusFlags = 5;
constexpr uint8_t kSolItow = 0, kSolWeek = 8, kSolFix = 10, kSolFlags = 11, kSolPdop = 44, kSolNumSv = 47;
constexpr uint8_t kVelnedItow = 0, kVelnedN = 4, kVelnedGspeed = 20, kVelnedHeading = 24, kVelnedSacc = 28;
constexpr uint8_t kNav5Mask = 0, kNav5DynModel = 2;
constexpr uint8_t kFlagFixOk = 0x01;  // NAV-STATUS and NAV-SOL flags bit 0: gpsFixOk
constexpr uint8_t kGpsFix2D = 2, kGpsFix3D = 3, kGpsFixGpsDr = 4;  // gpsFix values
constexpr uint16_t kNav5MaskDyn = 0x0001;  // CFG-NAV5 mask bit 0: apply dynModel

// Port protocol masks (CFG-PRT inProtoMask / outProtoMask, PUBX,41).
constexpr uint16_t kProtoUbx = 0x0001;
constexpr uint16_t kProtoNmea = 0x0002;
constexpr uint16_t kProtoRtcm = 0x0004;

// The 8-bit Fletcher checksum, a byte at a time.
struct Checksum {
    uint8_t a = 0, b = 0;
    void add(uint8_t byte) {
        a = (uint8_t)(a + byte);
        b = (uint8_t)(b + a);
    }
    void add(const uint8_t* data, size_t n) {
        for (size_t i = 0; i < n; ++i) add(data[i]);
    }
};

// Little-endian fields of a payload.
inline uint16_t get_u2(const uint8_t* p) { return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8)); }
inline uint32_t get_u4(const uint8_t* p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
inline int32_t get_i4(const uint8_t* p) { return (int32_t)get_u4(p); }

// Writes the frame class/id/payload into out (payload_len + kFrameOverhead bytes);
// returns its length.
uint8_t write_frame(uint8_t* out, uint8_t cls, uint8_t id, const uint8_t* payload, uint8_t payload_len);

}  // namespace ubx

namespace nmea {

// The XOR of the characters of a sentence between '$' and '*'.
inline uint8_t checksum(const char* body, size_t n) {
    uint8_t x = 0;
    for (size_t i = 0; i < n; ++i) x = (uint8_t)(x ^ (uint8_t)body[i]);
    return x;
}
// The value of a hex digit (either case), or -1.
inline int8_t hex_value(uint8_t c) {
    if (c >= '0' && c <= '9') return (int8_t)(c - '0');
    if (c >= 'A' && c <= 'F') return (int8_t)(c - 'A' + 10);
    if (c >= 'a' && c <= 'f') return (int8_t)(c - 'a' + 10);
    return -1;
}

}  // namespace nmea
}  // namespace gps
