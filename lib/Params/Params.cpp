// SPDX-License-Identifier: GPL-3.0-or-later
#include "Params.h"

#include <stddef.h>
#include <string.h>

#ifdef __AVR__
#include <avr/pgmspace.h>
#define PARAM_TABLE PROGMEM
#define COPY_ROW(dst, src) memcpy_P((dst), (src), sizeof(Row))
#else
#define PARAM_TABLE
#define COPY_ROW(dst, src) memcpy((dst), (src), sizeof(Row))
#endif

namespace params {

namespace {

using settings::Settings;

// One row: a parameter, or `count` numbered ones whose name has '#' for the number
// (first, first+1, ...) and whose values lie `stride` bytes apart (Bit: bit i of the
// byte at offset).
struct Row {
    char name[kNameMax + 1];
    Type type;
    uint8_t first;
    uint8_t count;
    uint8_t stride;
    uint16_t offset;
    float min, max, def;
};

#define AT(member) ((uint16_t)offsetof(Settings, member))
constexpr uint8_t kEp = (uint8_t)sizeof(flight::EndPoints);
constexpr uint8_t kN = flight::kChannels;

// The ranges are ArduPilot's where it documents one (RLL2SRV_TCONST 0.4..1.0, P 0.1..4,
// I 0..1, D 0..0.2, IMAX 0..4500, PTCH2SRV_RLL 0.7..1.5), widths the PPM decoder's
// plausible ones. Defaults: ArduPlane's P (1.0) and D (roll 0.08, pitch 0.04), TCONST 0.5,
// IMAX 3000; I ArduPlane 3's 0.04, not the 0.3 of its later releases: the integrator
// trims steady moments, and 0.3 also stores an upset's rate error (a 20 N m roll upset of
// the simulated Rascal left -15 deg of aileron that banked it 5 deg the other way for
// 2 s; 0.04: 2.5 deg). LIM_ROLL_CD 4500, LIM_PITCH_MAX/MIN +-2500 as issue 21 asks;
// end points 1000..2000 around 1500.
const Row kRows[] PARAM_TABLE = {
    {"RLL2SRV_TCONST", Type::Float, 0, 1, 0, AT(flight.roll.tconst_s), 0.4f, 1.0f, 0.5f},
    {"RLL2SRV_P", Type::Float, 0, 1, 0, AT(flight.roll.p), 0.1f, 4.0f, 1.0f},
    {"RLL2SRV_I", Type::Float, 0, 1, 0, AT(flight.roll.i), 0.0f, 1.0f, 0.04f},
    {"RLL2SRV_D", Type::Float, 0, 1, 0, AT(flight.roll.d), 0.0f, 0.2f, 0.08f},
    {"RLL2SRV_IMAX", Type::Int16, 0, 1, 0, AT(flight.roll.imax_cd), 0.0f, 4500.0f, 3000.0f},
    {"PTCH2SRV_TCONST", Type::Float, 0, 1, 0, AT(flight.pitch.tconst_s), 0.4f, 1.0f, 0.5f},
    {"PTCH2SRV_P", Type::Float, 0, 1, 0, AT(flight.pitch.p), 0.1f, 4.0f, 1.0f},
    {"PTCH2SRV_I", Type::Float, 0, 1, 0, AT(flight.pitch.i), 0.0f, 1.0f, 0.04f},
    {"PTCH2SRV_D", Type::Float, 0, 1, 0, AT(flight.pitch.d), 0.0f, 0.2f, 0.04f},
    {"PTCH2SRV_IMAX", Type::Int16, 0, 1, 0, AT(flight.pitch.imax_cd), 0.0f, 4500.0f, 3000.0f},
    {"PTCH2SRV_RLL", Type::Float, 0, 1, 0, AT(flight.pitch_roll_ff), 0.7f, 1.5f, 1.0f},
    {"LIM_ROLL_CD", Type::Int16, 0, 1, 0, AT(flight.lim_roll_cd), 0.0f, 9000.0f, 4500.0f},
    {"LIM_PITCH_MAX", Type::Int16, 0, 1, 0, AT(flight.lim_pitch_max_cd), 0.0f, 9000.0f, 2500.0f},
    {"LIM_PITCH_MIN", Type::Int16, 0, 1, 0, AT(flight.lim_pitch_min_cd), -9000.0f, 0.0f, -2500.0f},
    {"FS_GLIDE_PITCH", Type::Int16, 0, 1, 0, AT(flight.fs_pitch_cd), -3000.0f, 0.0f, -500.0f},
    {"THR_FS_VALUE", Type::UInt16, 0, 1, 0, AT(flight.thr_fs_value_us), 800.0f, 1100.0f, 950.0f},
    {"THR_FS_OUT", Type::UInt8, 0, 1, 0, AT(flight.thr_fs_pct), 0.0f, 100.0f, 0.0f},
    {"ARSPD_FBW_MIN", Type::UInt8, 0, 1, 0, AT(flight.arspd_min_m_s), 5.0f, 50.0f, 9.0f},
    {"ARSPD_FBW_MAX", Type::UInt8, 0, 1, 0, AT(flight.arspd_max_m_s), 5.0f, 50.0f, 22.0f},
    {"TRIM_ARSPD_CM", Type::UInt16, 0, 1, 0, AT(flight.trim_arspd_cm), 0.0f, 5000.0f, 0.0f},
    {"FLTMODE_CH", Type::UInt8, 0, 1, 0, AT(flight.fltmode_ch), 0.0f, 8.0f, 8.0f},
    {"FLTMODE1", Type::UInt8, 0, 1, 0, AT(flight.fltmode[0]), 0.0f, 2.0f, 0.0f},
    {"FLTMODE#", Type::UInt8, 2, 5, 1, AT(flight.fltmode[1]), 0.0f, 2.0f, 2.0f},
    {"RCMAP_ROLL", Type::UInt8, 0, 1, 0, AT(flight.rcmap[0]), 1.0f, 8.0f, 1.0f},
    {"RCMAP_PITCH", Type::UInt8, 0, 1, 0, AT(flight.rcmap[1]), 1.0f, 8.0f, 2.0f},
    {"RCMAP_THROTTLE", Type::UInt8, 0, 1, 0, AT(flight.rcmap[2]), 1.0f, 8.0f, 3.0f},
    {"RCMAP_YAW", Type::UInt8, 0, 1, 0, AT(flight.rcmap[3]), 1.0f, 8.0f, 4.0f},
    {"ELEVON_OUTPUT", Type::UInt8, 0, 1, 0, AT(flight.elevon_output), 0.0f, 1.0f, 0.0f},
    {"VTAIL_OUTPUT", Type::UInt8, 0, 1, 0, AT(flight.vtail_output), 0.0f, 1.0f, 0.0f},
    {"RC#_MIN", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].min_us), 800.0f, 2200.0f, 1000.0f},
    {"RC#_MAX", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].max_us), 800.0f, 2200.0f, 2000.0f},
    {"RC#_TRIM", Type::UInt16, 1, kN, kEp, AT(flight.rc[0].trim_us), 800.0f, 2200.0f, 1500.0f},
    {"RC#_REVERSED", Type::Bit, 1, kN, 0, AT(flight.rc_reversed), 0.0f, 1.0f, 0.0f},
    {"SERVO#_MIN", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].min_us), 800.0f, 2200.0f, 1000.0f},
    {"SERVO#_MAX", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].max_us), 800.0f, 2200.0f, 2000.0f},
    {"SERVO#_TRIM", Type::UInt16, 1, kN, kEp, AT(flight.servo[0].trim_us), 800.0f, 2200.0f, 1500.0f},
    {"SERVO#_REVERSED", Type::Bit, 1, kN, 0, AT(flight.servo_reversed), 0.0f, 1.0f, 0.0f},
    {"COMPASS_DEC", Type::DeclRad, 0, 1, 0, AT(declination_centideg), -3.1416f, 3.1416f, 0.0f},
};
#undef AT
constexpr uint8_t kRowCount = (uint8_t)(sizeof kRows / sizeof kRows[0]);

constexpr float kRadPerCentideg = 3.14159265f / 18000.0f;

// The row holding index, and the instance within it; false past the end.
bool locate(uint16_t index, Row& row, uint8_t& instance) {
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        if (index < row.count) {
            instance = (uint8_t)index;
            return true;
        }
        index = (uint16_t)(index - row.count);
    }
    return false;
}

uint8_t* where(Settings& s, const Row& row, uint8_t instance) {
    return reinterpret_cast<uint8_t*>(&s) + row.offset + (uint16_t)row.stride * instance;
}

float read(const Settings& s, const Row& row, uint8_t instance) {
    const uint8_t* p = where(const_cast<Settings&>(s), row, instance);
    switch (row.type) {
        case Type::Float: { float v; memcpy(&v, p, sizeof v); return v; }
        case Type::Int16: { int16_t v; memcpy(&v, p, sizeof v); return (float)v; }
        case Type::UInt16: { uint16_t v; memcpy(&v, p, sizeof v); return (float)v; }
        case Type::UInt8: return (float)*p;
        case Type::Bit: return (float)((*p >> instance) & 1u);
        case Type::DeclRad: { int16_t v; memcpy(&v, p, sizeof v); return (float)v * kRadPerCentideg; }
    }
    return 0.0f;
}

// Stores a value already checked against the row's range.
void write(Settings& s, const Row& row, uint8_t instance, float value) {
    uint8_t* p = where(s, row, instance);
    const int32_t whole = (int32_t)(value >= 0.0f ? value + 0.5f : value - 0.5f);
    switch (row.type) {
        case Type::Float: memcpy(p, &value, sizeof value); break;
        case Type::Int16: { const int16_t v = (int16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt16: { const uint16_t v = (uint16_t)whole; memcpy(p, &v, sizeof v); break; }
        case Type::UInt8: *p = (uint8_t)whole; break;
        case Type::Bit:
            *p = whole != 0 ? (uint8_t)(*p | (1u << instance)) : (uint8_t)(*p & ~(1u << instance));
            break;
        case Type::DeclRad: {
            const float cd = value / kRadPerCentideg;
            int16_t v = (int16_t)(cd >= 0.0f ? cd + 0.5f : cd - 0.5f);
            if (v > settings::kDeclMaxCentideg) v = settings::kDeclMaxCentideg;
            if (v < settings::kDeclMinCentideg) v = settings::kDeclMinCentideg;
            memcpy(p, &v, sizeof v);
            break;
        }
    }
}

bool in_range(const Row& row, float v) {
    if (!(v >= row.min && v <= row.max)) return false;  // NaN fails too
    return !is_integer(row.type) || v == (float)(int32_t)v;
}

bool ends_in_order(const flight::EndPoints* eps) {
    for (uint8_t i = 0; i < flight::kChannels; ++i)
        if (!(eps[i].min_us <= eps[i].trim_us && eps[i].trim_us <= eps[i].max_us)) return false;
    return true;
}

char upper(char c) { return (c >= 'a' && c <= 'z') ? (char)(c - 'a' + 'A') : c; }

}  // namespace

bool is_integer(Type t) { return t != Type::Float && t != Type::DeclRad; }

uint16_t count() {
    uint16_t n = 0;
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        n = (uint16_t)(n + row.count);
    }
    return n;
}

bool info(uint16_t index, Info& out) {
    Row row;
    uint8_t instance;
    if (!locate(index, row, instance)) return false;
    uint8_t o = 0;
    for (uint8_t i = 0; row.name[i] != '\0' && o < kNameMax; ++i)
        out.name[o++] = row.name[i] == '#' ? (char)('0' + row.first + instance) : row.name[i];
    out.name[o] = '\0';
    out.type = row.type;
    out.min = row.min;
    out.max = row.max;
    out.def = row.def;
    return true;
}

// One pass over the rows (a numbered row matched by its prefix, one digit, its suffix),
// not info() for every index: MAVLink's PARAM_SET and PARAM_REQUEST_READ look names up
// between samples.
int16_t find(const char* name) {
    Row row;
    uint16_t index = 0;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        uint8_t i = 0, j = 0;  // row.name, name
        int16_t instance = 0;
        bool match = true;
        while (match && row.name[i] != '\0') {
            if (row.name[i] == '#') {
                const char c = name[j++];
                instance = (int16_t)(c - '0' - (char)row.first);
                match = c >= '0' && c <= '9' && instance >= 0 && instance < row.count;
            } else {
                match = upper(name[j++]) == row.name[i];
            }
            ++i;
        }
        if (match && name[j] == '\0') return (int16_t)(index + instance);
        index = (uint16_t)(index + row.count);
    }
    return -1;
}

float get(const Settings& s, uint16_t index) {
    Row row;
    uint8_t instance;
    return locate(index, row, instance) ? read(s, row, instance) : 0.0f;
}

bool set(Settings& s, uint16_t index, float value) {
    Row row;
    uint8_t instance;
    if (!locate(index, row, instance) || !in_range(row, value)) return false;
    const float before = read(s, row, instance);
    write(s, row, instance, value);
    if (ends_in_order(s.flight.rc) && ends_in_order(s.flight.servo)) return true;
    write(s, row, instance, before);
    return false;
}

void apply_defaults(Settings& s) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        for (uint8_t i = 0; i < row.count; ++i) write(s, row, i, row.def);
    }
}

bool all_valid(const Settings& s) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        for (uint8_t i = 0; i < row.count; ++i)
            if (!in_range(row, read(s, row, i))) return false;
    }
    return ends_in_order(s.flight.rc) && ends_in_order(s.flight.servo);
}

namespace {

uint8_t stored_bytes(Type t) {
    switch (t) {
        case Type::Float: return 4;
        case Type::Int16:
        case Type::UInt16:
        case Type::DeclRad: return 2;
        default: return 1;
    }
}

// Calls f(pointer to the value's bytes, their count) for every stored value of the
// flight settings, in the record's order.
template <typename F>
void each_flight_value(const Settings& s, F f) {
    Row row;
    for (uint8_t r = 0; r < kRowCount; ++r) {
        COPY_ROW(&row, &kRows[r]);
        if (row.offset < offsetof(Settings, flight)) continue;
        const uint8_t n = row.type == Type::Bit ? 1 : row.count;
        for (uint8_t i = 0; i < n; ++i) f(where(const_cast<Settings&>(s), row, i), stored_bytes(row.type));
    }
}

}  // namespace

// The AVR and every host this builds on are little-endian: a value's bytes are its
// record bytes.
void encode_flight(const Settings& s, uint8_t out[settings::kFlightBytes]) {
    flight_part(s, 0, settings::kFlightBytes, out);
}

void decode_flight(const uint8_t in[settings::kFlightBytes], Settings& s) {
    uint16_t at = 0;
    each_flight_value(s, [&](uint8_t* p, uint8_t n) {
        if (at + n <= settings::kFlightBytes) memcpy(p, in + at, n);
        at = (uint16_t)(at + n);
    });
}

void flight_part(const Settings& s, uint8_t from, uint8_t n, uint8_t* out) {
    uint16_t at = 0;
    const uint16_t to = (uint16_t)(from + n);
    each_flight_value(s, [&](uint8_t* p, uint8_t len) {
        for (uint8_t j = 0; j < len; ++j) {
            const uint16_t k = (uint16_t)(at + j);
            if (k >= from && k < to) out[k - from] = p[j];
        }
        at = (uint16_t)(at + len);
    });
}

uint16_t flight_bytes() {
    uint16_t at = 0;
    const Settings s{};
    each_flight_value(s, [&](uint8_t*, uint8_t n) { at = (uint16_t)(at + n); });
    return at;
}

}  // namespace params
