// SPDX-License-Identifier: GPL-3.0-or-later
// MS5611-01BA03 arithmetic (Measurement Specialties datasheet, "Pressure and temperature
// calculation" and "Second order temperature compensation"; AN520 for the PROM's CRC-4),
// shared by the firmware's driver and the simulator's register model (sim/models), so the
// chip's numbers are worked out one way only.
//
// Units as the datasheet: D1 and D2 the 24-bit ADC codes, TEMP in 0.01 degC, P in Pa
// (0.01 mbar), PROM words C1..C6 at prom[1..6], word 7's low 4 bits the CRC.
// Integer results exactly as printed: OFF, SENS and D1 * SENS need 64 bits (the
// datasheet's own variable sizes), every division truncates toward zero as C's does;
// the .cpp keeps to 32 bits what fits (test/MS5611/test_ms5611_exact.cpp holds it to an
// int64_t transcription). The temperature terms change slowly: they are worked out once
// per D2, and each D1 then costs one 32 x 32 -> 64 product (terms() and pressure_pa()).
#pragma once

#include <stdint.h>

namespace ms5611 {

constexpr uint8_t kPromWords = 8;

// AN520's CRC-4 of the 8 PROM words, word 7's low byte taken as 0.
uint8_t crc4(const uint16_t prom[kPromWords]);

enum class PromStatus : uint8_t {
    Ok,
    Blank,    // every word 0x0000 or every word 0xFFFF: nobody answering (MISO held low or high)
    BadCrc,   // word 7's low 4 bits are not the CRC-4 of the words
};
PromStatus check_prom(const uint16_t prom[kPromWords]);

// The temperature's terms of the compensation, from D2 (second order included).
struct Terms {
    int32_t temp_c100;  // TEMP - T2: the compensated temperature, 0.01 degC
    int64_t off;        // OFF - OFF2: offset at that temperature
    int64_t sens;       // SENS - SENS2: sensitivity at that temperature
};
// Exact (the datasheet's integers) for D2 < 2^24 and TEMP (first order) within the
// datasheet's -4000..8500; below -4000 temp_c100 stays exact (so the sequencer rejects
// it) and off, sens take the -40 degC second-order terms.
Terms terms(const uint16_t prom[kPromWords], uint32_t d2);

// P = (D1 * SENS / 2^21 - OFF) / 2^15, Pa.
int32_t pressure_pa(const Terms& t, uint32_t d1);

}  // namespace ms5611
