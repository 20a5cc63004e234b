// SPDX-License-Identifier: GPL-3.0-or-later
// The --fault SPEC language of build/apm25sim: parsing and applying to the models.
//
//   SPEC   := TARGET ':' KIND [ '=' VALUE ] [ '@' T1 [ '-' T2 ] ]
//   T      := digits [ '.' digits ] | '.' digits        (seconds, finite, >= 0)
//   no '@': from reset to the end; '@T1': from T1 seconds to the end; '@T1-T2': [T1, T2).
// Any number of SPECs of one kind, as long as their windows do not overlap. The table of
// targets and kinds is kFaultHelp (printed by --help).
#pragma once

#include <string>

#include "Hmc5883Model.h"
#include "Mpu6000Model.h"
#include "Ms5611Model.h"
#include "TimeWindow.h"
#include "UbloxModel.h"

namespace sim {

extern const char* const kFaultHelp;

// Faults the bus itself carries (not a single chip).
struct BusFaults {
    TimeWindows i2c_sda_low;  // a slave holds SDA low: nothing on the I2C bus answers
};

// One SPEC taken apart (no check of TARGET:KIND against the table).
struct FaultSpec {
    std::string what;         // "TARGET:KIND"
    std::string value;        // after '=' (has_value)
    bool has_value = false;
    TimeWindow window = TimeWindow::always();
    bool has_window = false;  // an '@' part was given
};

// Splits SPEC by the grammar above. On error returns false and sets `error` to a
// sentence naming the SPEC.
bool parse_fault_spec(const std::string& spec, FaultSpec& out, std::string& error);

// What the faults can reach. A null GPS or barometer: that part is not on the board
// (--gps none, --baro none), and a fault aimed at it is an error.
struct FaultTargets {
    Mpu6000Model* mpu = nullptr;
    Hmc5883Model* mag = nullptr;
    BusFaults* bus = nullptr;
    UbloxFaults* gps = nullptr;
    Ms5611Faults* baro = nullptr;
};

// Parses SPEC and adds it to the models or the bus. On error (malformed SPEC, unknown
// kind, a value where none is taken or a bad one, a window that overlaps an earlier SPEC
// of the same kind, a part that is not attached) returns false, sets `error` and changes
// nothing.
bool apply_fault_spec(const std::string& spec, const FaultTargets& targets, std::string& error);
// The same for the IMU, the compass and the bus only.
bool apply_fault_spec(const std::string& spec, Mpu6000Model& mpu, Hmc5883Model& mag, BusFaults& bus,
                      std::string& error);

}  // namespace sim
