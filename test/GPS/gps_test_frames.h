// SPDX-License-Identifier: GPL-3.0-or-later
// UBX NAV frames and NMEA sentences for the GPS tests, built field by field as the u-blox 6
// Protocol Specification lays them out.
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "UbxProtocol.h"

namespace gpstest {

using Bytes = std::vector<uint8_t>;

inline void put(Bytes& p, uint32_t v, int n) {
    for (int i = 0; i < n; ++i) p.push_back((uint8_t)(v >> (8 * i)));
}

inline Bytes frame(uint8_t cls, uint8_t id, const Bytes& payload) {
    Bytes f = {gps::ubx::kSync1, gps::ubx::kSync2, cls, id};
    put(f, (uint32_t)payload.size(), 2);
    f.insert(f.end(), payload.begin(), payload.end());
    gps::ubx::Checksum ck;
    ck.add(f.data() + 2, f.size() - 2);
    f.push_back(ck.a);
    f.push_back(ck.b);
    return f;
}

inline Bytes posllh(uint32_t itow, int32_t lat_e7, int32_t lon_e7, int32_t hmsl_mm, uint32_t hacc_mm = 1500) {
    Bytes p;
    put(p, itow, 4);
    put(p, (uint32_t)lon_e7, 4);
    put(p, (uint32_t)lat_e7, 4);
    put(p, (uint32_t)(hmsl_mm + 10000), 4);  // height above the ellipsoid
    put(p, (uint32_t)hmsl_mm, 4);
    put(p, hacc_mm, 4);
    put(p, 2500, 4);
    return frame(gps::ubx::kClassNav, gps::ubx::kNavPosllh, p);
}

inline Bytes velned(uint32_t itow, int32_t n, int32_t e, int32_t d, uint32_t gspeed, int32_t heading_e5) {
    Bytes p;
    put(p, itow, 4);
    put(p, (uint32_t)n, 4);
    put(p, (uint32_t)e, 4);
    put(p, (uint32_t)d, 4);
    put(p, gspeed + 1, 4);  // 3D speed
    put(p, gspeed, 4);
    put(p, (uint32_t)heading_e5, 4);
    put(p, 30, 4);          // sAcc
    put(p, 100000, 4);      // cAcc
    return frame(gps::ubx::kClassNav, gps::ubx::kNavVelned, p);
}

inline Bytes sol(uint32_t itow, uint8_t gps_fix, uint8_t flags, uint8_t num_sv, uint16_t pdop, uint16_t week = 0) {
    Bytes p(gps::ubx::kLenNavSol, 0);
    for (int i = 0; i < 4; ++i) p[(size_t)i] = (uint8_t)(itow >> (8 * i));
    p[gps::ubx::kSolWeek] = (uint8_t)week;
    p[gps::ubx::kSolWeek + 1] = (uint8_t)(week >> 8);
    p[gps::ubx::kSolFix] = gps_fix;
    p[gps::ubx::kSolFlags] = flags;
    p[gps::ubx::kSolPdop] = (uint8_t)pdop;
    p[gps::ubx::kSolPdop + 1] = (uint8_t)(pdop >> 8);
    p[gps::ubx::kSolNumSv] = num_sv;
    return frame(gps::ubx::kClassNav, gps::ubx::kNavSol, p);
}

inline Bytes status(uint32_t itow, uint8_t gps_fix, uint8_t flags) {
    Bytes p(gps::ubx::kLenNavStatus, 0);
    for (int i = 0; i < 4; ++i) p[(size_t)i] = (uint8_t)(itow >> (8 * i));
    p[gps::ubx::kStatusFix] = gps_fix;
    p[gps::ubx::kStatusFlags] = flags;
    return frame(gps::ubx::kClassNav, gps::ubx::kNavStatus, p);
}

inline Bytes ack(bool ok, uint8_t cls, uint8_t id) {
    return frame(gps::ubx::kClassAck, ok ? gps::ubx::kAckAck : gps::ubx::kAckNak, Bytes{cls, id});
}

inline Bytes nav5(uint8_t dyn_model) {
    Bytes p(gps::ubx::kLenCfgNav5, 0);
    p[0] = 0xFF;
    p[1] = 0xFF;
    p[gps::ubx::kNav5DynModel] = dyn_model;
    p[3] = 3;  // fixMode auto
    return frame(gps::ubx::kClassCfg, gps::ubx::kCfgNav5, p);
}

// One epoch as the configured u-blox sends it: POSLLH, STATUS, SOL, VELNED.
inline Bytes epoch(uint32_t itow, int32_t lat_e7, int32_t lon_e7, int32_t vel_n_cm_s = 0, uint8_t sats = 10,
                   uint8_t gps_fix = 3, uint8_t flags = 0x0D) {
    Bytes out = posllh(itow, lat_e7, lon_e7, 1028000);
    for (const Bytes& b : {status(itow, gps_fix, flags), sol(itow, gps_fix, flags, sats, 166),
                           velned(itow, vel_n_cm_s, 0, 0, (uint32_t)(vel_n_cm_s < 0 ? -vel_n_cm_s : vel_n_cm_s), 0)})
        out.insert(out.end(), b.begin(), b.end());
    return out;
}

// "$body*hh\r\n".
inline std::string sentence(const std::string& body, bool lower_case_hex = false) {
    char tail[8];
    std::snprintf(tail, sizeof tail, lower_case_hex ? "*%02x\r\n" : "*%02X\r\n",
                  gps::nmea::checksum(body.data(), body.size()));
    return "$" + body + tail;
}

}  // namespace gpstest
