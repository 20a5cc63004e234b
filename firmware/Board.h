// SPDX-License-Identifier: GPL-3.0-or-later
// The APM 2.5 board as the sketch sees it: its pins, the two sensor buses on the
// Arduino core's SPI library and Wire's TWI driver (twi.c), the LEDs and the benchmark markers.
// Everything here is a small named piece; the sketch (firmware.ino) composes them.
//
// Pins (../shared/APM25.md): MPU6000 CS = pin 53 (PB0, also the AVR's SS: an output keeps
// SPI master), barometer CS = pin 40 (PG1, high but in the barometer's transactions: Baro.cpp), SDA/SCL = pins 20/21,
// HMC5883L DRDY = pin 31 (PC6, no interrupt: polled), MPU6000 INT = PE6 (INT6, not an
// Arduino pin number: read from its port), LEDs A/B/C = pins 27/26/25, active low
// (calibrating / running / fault).
#pragma once

#include "ArduinoCore.h"

#include "Hmc5883.h"
#include "Mpu6000.h"

namespace board {

constexpr uint8_t kPinMpuCs = 53;
constexpr uint8_t kPinBaroCs = 40;
constexpr uint8_t kPinMagDrdy = 31;
constexpr uint8_t kPinLedA = 27;  // calibrating
constexpr uint8_t kPinLedB = 26;  // running
constexpr uint8_t kPinLedC = 25;  // a sensor fault
constexpr uint8_t kPinSda = 20;
constexpr uint8_t kPinScl = 21;
constexpr uint32_t kI2cClockHz = 400000;
// Any I2C call returns within this bound (twi.c's timeout, the bus reset with it):
// a compass read is ~250 us at 400 kHz, so 3 ms is ten reads' worth.
constexpr uint32_t kI2cTimeoutUs = 3000;

// Cycle markers read by the simulator's benchmark (apm25sim --profile): a section id
// written to GPIOR0 when it starts and to GPIOR1 when it ends (one OUT instruction each).
// The task table (Tasks.cpp) brackets each task with its section; some tasks mark parts
// of their work too. 7..12 and 14 are the estimator's parts (lib/LinAlg/Profile.h).
enum Section : uint8_t {
    kSecEstimator = 1,  // the pipeline's step: guard, calibration, Dcm::update (+ heading)
    kSecEuler = 2,
    kSecFormat = 3,     // one output line, not the UART send
    kSecMpuRead = 4,
    kSecMagRead = 5,
    kSecLoop = 6,       // one sample's work, from data-ready seen to its tasks done
    kSecControl = 13,   // the flight control step (50 Hz, the servo frame)
    kSecConsoleReply = 15,  // one part of a console reply, as text
    kSecGcsRequest = 16,  // a ground station's MAVLink frame taken (PARAM_SET applied, a command set aside ...)
    kSecGcsReply = 17,    // one PARAM_VALUE packed and queued
    kSecCompassTask = 18,  // the compass task: DRDY watched, a read when due (5 inside)
    kSecAirspeed = 19,
    kSecInputInStep = 20,  // the console's received bytes, on a sample
    kSecUser = 21,         // user_attitude_step
    kSecOutput = 22,       // the output line task: Euler (2), formatting (3), queueing
    kSecLeds = 23,
    kSecPump = 24,         // queued text handed to Serial
    kSecHeldBack = 62,     // "# N line(s) held back" packed and queued (Port)
    kSecInput = 25,        // the console's received bytes, between samples
    kSecGcsStreams = 26,   // RC_CHANNELS + SERVO_OUTPUT_RAW packed and queued
    kSecGcsSave = 27,      // a save started after a PARAM_SET
    kSecStore = 28,        // the settings store's and the mission's EEPROM work
    kSecRetry = 29,        // the sensors' retries while down
    kSecUserLoop = 30,     // user_loop
    kSecFlightPoll = 31,   // the receiver's frames; the control step without samples (13)
    kSecSecond = 32,       // once a second: load, LEDs, HEARTBEAT, held-back warnings
    kSecStatusText = 33,   // one part of a console reply, as STATUSTEXT frames
    kSecCommand = 34,      // the work of `save`, `defaults` or `set` typed at the console
    kSecGcsDefaults = 35,  // a ground station's PREFLIGHT_STORAGE defaults: restored, then their line
    kSecPreArm = 48,       // one "# PreArm: ..." line of a refused arming
    kSecGps = 36,          // the GPS task: received bytes parsed, the u-blox configuration sent
    kSecBaro = 37,         // the barometer task: a conversion read and the next one started
    kSecNav = 38,          // position and home from a new fix, the position moved on between fixes
    kSecGcsPosition = 39,  // GPS_RAW_INT, GLOBAL_POSITION_INT, VFR_HUD ... packed and queued
    // 46 is lib/MS5611's compensation (lib/LinAlg/Profile.h), inside 37.
    kSecBaroHeight = 47,   // the barometer's 10 Hz height and climb (inside 37)
    kSecAdc = 52,          // a battery pin's conversion taken, A0's next started
    kSecBattery = 53,      // the battery monitor's 10 Hz update (and its failsafe line)
    kSecGcsBattery = 54,   // BATTERY_STATUS packed and queued
    kSecGcsCommand = 55,   // a ground station's COMMAND_LONG run and ACKed
    kSecGcsAnswer = 56,    // TIMESYNC, AUTOPILOT_VERSION, a mission reply or SYSTEM_TIME packed and queued
    kSecGuide = 57,        // the navigation modes' 10 Hz step: the executor, L1, TECS (NavModes)
    kSecTecsFilter = 58,   // TECS's 50 Hz height and acceleration filters (NavModes)
};
inline void mark_begin(uint8_t id) { GPIOR0 = id; }
inline void mark_end(uint8_t id) { GPIOR1 = id; }

// Read from the ports directly: one IN instruction, called every loop iteration.
inline bool mpu_int_high() { return (PINE & _BV(PE6)) != 0; }
inline bool mag_drdy_high() { return (PINC & _BV(PC6)) != 0; }
inline bool sda_low() { return (PIND & _BV(PD1)) == 0; }

// Idle until an interrupt: the MPU6000's data-ready (INT6, rising edge, enabled by
// wake_on_data_ready()), timer0's millis() tick (1.024 ms), a UART byte, a receiver edge.
// Returns at once when the data-ready line is already high. Idle keeps every timer and
// peripheral running (datasheet 11.1): the servo pulses and the PPM capture go on.
void wake_on_data_ready();
void idle_until_interrupt();

// LEDs off, every SPI chip select high (53 before 40, as ArduPilot brought the bus
// up on APM2) before any SPI traffic, the data-ready lines as inputs.
void init_pins();
// Resets the board with the watchdog (15 ms) and never returns; the next start stops the
// watchdog before the C runtime's set-up (a watchdog reset leaves it running).
[[noreturn]] void reset_by_watchdog();
void set_leds(bool calibrating, bool running, bool fault);

// SPI.begin() (after init_pins). Transactions: 1 MHz for the MPU6000's register
// writes (datasheet limit), 8 MHz (the AVR's fastest) for sensor reads.
void spi_begin();
// The TWI at 400 kHz with a bounded timeout that resets it (as Wire.begin() would).
void wire_begin();
// Frees the I2C bus when a slave holds SDA low: up to 16 SCL pulses until SDA is
// released (>= 9 clocks finish any byte), then a STOP, then wire_begin() again.
void i2c_recover();
// True (and clears it) if an I2C call timed out since the last call.
bool i2c_timed_out();

// The drivers' bus seams, filled with SPI and twi.c (Board.cpp's functions), as constant
// expressions: the sensors' static objects (Vehicle.cpp) copy them with no start-up code.
namespace seam {
void spi_select(void*, bool on, uint32_t clock_hz);
uint8_t spi_transfer(void*, uint8_t out);
void wait_ms(void*, uint16_t ms);
bool i2c_write_reg(void*, uint8_t addr7, uint8_t reg, uint8_t value);
bool i2c_read_regs(void*, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len);
}  // namespace seam
constexpr mpu6000::SpiDevice kSpi = {nullptr, seam::spi_select, seam::spi_transfer, seam::wait_ms};
constexpr hmc5883::I2cBus kI2c = {nullptr, seam::i2c_write_reg, seam::i2c_read_regs, seam::wait_ms};

}  // namespace board
