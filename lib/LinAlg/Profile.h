// SPDX-License-Identifier: GPL-3.0-or-later
// Cycle markers for the simulator's profiler (apm25sim --profile, ../shared/SIM.md):
// a section id written to GPIOR0 where the section starts and to GPIOR1 where it
// ends, one OUT instruction each on the AVR and nothing on the host. The firmware's
// own sections are in firmware/Board.h (the numbers not used here); the parts of the
// estimator step, which lives in lib/, are these, so that `make bench` shows where its
// cycles go.
#pragma once

#include <stdint.h>

namespace profile {

enum Part : uint8_t {
    kIntegration = 7,     // the gyro's rotation applied to the matrix (Dcm::update)
    kRenormalisation = 8, // orthonormalisation (Dcm::update)
    kGravity = 9,         // accel low-pass, rest test, roll/pitch correction (every 4th step)
    kCompass = 10,        // heading correction from a field sample (Dcm::correct_heading)
    kLearner = 11,        // the compass offset learner's pair update (Pipeline)
    kChecks = 12,         // the pipeline's sample checks and calibration before the DCM
    // 13 is the firmware's flight control step (firmware/Board.h).
    kMagFit = 14,         // one part of the `cal mag` fit (Pipeline), outside the estimator step
    // 15..39 are the firmware's (firmware/Board.h).
    kGpsAid = 40,         // a GPS fix into the estimator (Pipeline::on_gps_fix, 5 Hz)
    kBaroCompensation = 46,  // lib/MS5611: a D2's temperature terms or a D1's pressure (in the baro task)
    kBoardFrame = 41,     // the accelerometer's calibration and the board's orientation on a sample (Pipeline)
};

// The byte the firmware paints its free RAM with at start-up (firmware/StackPaint.cpp):
// apm25sim --profile reports how much of it the stack overwrote (its high-water mark).
constexpr uint8_t kStackPaint = 0xC5;

#if defined(__AVR__)
// GPIOR0 and GPIOR1 are I/O registers 0x1E and 0x2A on the ATmega2560 (datasheet 31).
inline void begin(uint8_t part) { __asm__ __volatile__("out 0x1e, %0" ::"r"(part)); }
inline void end(uint8_t part) { __asm__ __volatile__("out 0x2a, %0" ::"r"(part)); }
#else
inline void begin(uint8_t) {}
inline void end(uint8_t) {}
#endif

}  // namespace profile
