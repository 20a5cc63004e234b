// The APM 2.5 board seen by the firmware: pins, the bus seams filled with the Arduino
// core's SPI and Wire, the serial output ring, the LEDs and the benchmark markers.
// The only place (with main.cpp) that includes Arduino.h.
#pragma once

#include "ArduinoCore.h"

#include "Hmc5883.h"
#include "Mpu6000.h"
#include "Text.h"

namespace board {

// Pins (../shared/APM25.md).
constexpr uint8_t kPinMpuCs = 53;    // PB0, also the AVR's SS: an output keeps SPI master
constexpr uint8_t kPinBaroCs = 40;   // PG1, MS5611: high forever
constexpr uint8_t kPinSda = 20;      // PD1
constexpr uint8_t kPinScl = 21;      // PD0
constexpr uint8_t kPinMagDrdy = 31;  // PC6, HMC5883L DRDY (no interrupt: polled)
constexpr uint8_t kPinLedA = 27;     // PA5, active low: calibrating
constexpr uint8_t kPinLedB = 26;     // PA4, active low: running
constexpr uint8_t kPinLedC = 25;     // PA3, active low: sensor fault
constexpr uint32_t kI2cClockHz = 400000;
constexpr uint32_t kI2cTimeoutUs = 3000;  // any Wire call returns within ~3 ms

// Cycle markers read by the simulator's benchmark: a section id written to GPIOR0 when
// it starts and to GPIOR1 when it ends (one OUT instruction each).
enum Section : uint8_t {
    kSecEstimator = 1,  // Dcm::update (+ correct_heading when a field sample came in)
    kSecEuler = 2,
    kSecFormat = 3,     // one output line, not the UART send
    kSecMpuRead = 4,
    kSecMagRead = 5,
    kSecLoop = 6,       // one loop iteration's work, from data-ready seen to work done
};
inline void mark_begin(uint8_t id) { GPIOR0 = id; }
inline void mark_end(uint8_t id) { GPIOR1 = id; }

// MPU6000 INT (data ready) on PE6, not an Arduino pin: read the port directly.
inline bool mpu_int_high() { return (PINE & _BV(PE6)) != 0; }
inline bool mag_drdy_high() { return (PINC & _BV(PC6)) != 0; }

void init_pins();           // LEDs off, every SPI chip select high (53 then 40), DRDY input
void set_leds(bool calibrating, bool running, bool fault);
void spi_begin();           // after init_pins
void wire_begin();          // Wire at 400 kHz with the timeout
// Frees the I2C bus when a slave holds SDA low: up to 16 SCL pulses until SDA is
// released (>= 9 clocks finish any byte), then a STOP, then Wire again.
void i2c_recover();
// True (and clears it) if a Wire call timed out since the last call.
bool i2c_timed_out();

mpu6000::SpiDevice spi_device();
hmc5883::I2cBus i2c_bus();

// Serial output through a ring drained without blocking (pump() each loop); a full
// ring blocks until the UART makes room, so text is never lost.
void serial_begin(uint32_t baud);
const text::Sink* serial_sink();
void serial_pump();
void serial_drain();  // blocks until the ring is empty (set-up only)
void serial_write(const char* data, uint8_t len);

}  // namespace board
