// SPDX-License-Identifier: GPL-3.0-or-later
#include "Modes.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define MODE_TABLE PROGMEM
#define MODE_BYTE(p) pgm_read_byte(p)
#else
#define MODE_TABLE
#define MODE_BYTE(p) (*(p))
#endif

namespace flight {

namespace {

struct Row {
    uint8_t number;  // ArduPlane's
    Law law;
    char name[kModeNameMax + 1];
};

// ArduPlane's FBWA is what STABILIZE flies here (the sticks demand a bank within
// LIM_ROLL_CD and a pitch within LIM_PITCH_MAX/MIN, centred sticks hold the wings level):
// ArduPlane's own STABILIZE levels the wings but adds the stick to the surfaces. Both
// numbers are taken, for a ground station's `mode FBWA` and for the mode switch set
// up as for ArduPlane.
const Row kModes[kModeCount] MODE_TABLE = {
    {(uint8_t)Mode::Manual, Law::PassThrough, "MANUAL"},
    {(uint8_t)Mode::Stabilize, Law::Attitude, "STABILIZE"},
    {(uint8_t)Mode::FlyByWireA, Law::Attitude, "FBWA"},
    // The navigation's modes (the firmware's NavModes composes lib/Nav and lib/Mission).
    {(uint8_t)Mode::Circle, Law::NavigateOn, "CIRCLE"},
    {(uint8_t)Mode::FlyByWireB, Law::Navigate, "FBWB"},
    {(uint8_t)Mode::Cruise, Law::Navigate, "CRUISE"},
    {(uint8_t)Mode::Auto, Law::NavigateOn, "AUTO"},
    {(uint8_t)Mode::Rtl, Law::NavigateOn, "RTL"},
    {(uint8_t)Mode::Loiter, Law::NavigateOn, "LOITER"},
    {(uint8_t)Mode::Guided, Law::NavigateOn, "GUIDED"},
};

char upper(char c) { return (c >= 'a' && c <= 'z') ? (char)(c - 'a' + 'A') : c; }

}  // namespace

int8_t mode_index(uint8_t number) {
    for (uint8_t i = 0; i < kModeCount; ++i)
        if (MODE_BYTE(&kModes[i].number) == number) return (int8_t)i;
    return -1;
}

uint8_t mode_number(uint8_t index) { return MODE_BYTE(&kModes[index < kModeCount ? index : 0].number); }

Law mode_law(uint8_t index) {
    return (Law)MODE_BYTE((const uint8_t*)&kModes[index < kModeCount ? index : 0].law);
}

void mode_name(uint8_t index, char out[kModeNameMax + 1]) {
    const char* p = kModes[index < kModeCount ? index : 0].name;
    uint8_t i = 0;
    for (; i < kModeNameMax && MODE_BYTE(p + i) != 0; ++i) out[i] = (char)MODE_BYTE(p + i);
    out[i] = '\0';
}

int8_t mode_by_name(const char* name) {
    for (uint8_t r = 0; r < kModeCount; ++r) {
        const char* p = kModes[r].name;
        uint8_t i = 0;
        while (i < kModeNameMax && MODE_BYTE(p + i) != 0 && upper(name[i]) == (char)MODE_BYTE(p + i)) ++i;
        if ((i == kModeNameMax || MODE_BYTE(p + i) == 0) && name[i] == '\0') return (int8_t)r;
    }
    return -1;
}

}  // namespace flight
