// The --fault SPEC language of build/apm25sim: parsing and applying to the models.
//
//   SPEC   := TARGET ':' KIND [ '=' VALUE ] [ '@' T1 [ '-' T2 ] ]
//   no '@': from reset to the end; '@T1': from T1 seconds to the end; '@T1-T2': [T1, T2).
// The table of targets and kinds is kFaultHelp (printed by --help).
#pragma once

#include <string>

#include "Hmc5883Model.h"
#include "Mpu6000Model.h"
#include "TimeWindow.h"

namespace sim {

extern const char* const kFaultHelp;

// Faults the bus itself carries (not a single chip).
struct BusFaults {
    TimeWindow i2c_sda_low;  // a slave holds SDA low: nothing on the I2C bus answers
};

// Parses SPEC and applies it to the models or the bus. On error returns false and sets
// `error` to a sentence naming the SPEC.
bool apply_fault_spec(const std::string& spec, Mpu6000Model& mpu, Hmc5883Model& mag, BusFaults& bus,
                      std::string& error);

}  // namespace sim
