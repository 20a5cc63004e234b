// SPDX-License-Identifier: GPL-3.0-or-later
// Byte helpers shared by the sensor drivers and the simulator's register models.
#pragma once

#include <stdint.h>

namespace linalg {

// Two big-endian bytes as a signed 16-bit value, assembled as uint16_t first: on
// AVR `hi << 8` is an int (16-bit) shift of a value >= 0x80 and overflows.
inline int16_t int16_from_be(uint8_t hi, uint8_t lo) {
    return (int16_t)(uint16_t)(((uint16_t)hi << 8) | (uint16_t)lo);
}
inline uint8_t high_byte(int16_t v) { return (uint8_t)((uint16_t)v >> 8); }
inline uint8_t low_byte(int16_t v) { return (uint8_t)((uint16_t)v & 0xFFu); }

// Nearest int16 to x, saturating at the ends of the range (as a sensor ADC does).
inline int16_t saturate_int16(float x) {
    if (!(x == x)) return 0;
    if (x >= 32767.0f) return 32767;
    if (x <= -32768.0f) return -32768;
    return (int16_t)(x >= 0.0f ? x + 0.5f : x - 0.5f);
}

}  // namespace linalg
