// The APM 2.5 board seen by the firmware: pins, the bus seams filled with the AVR's
// own SPI, TWI and USART0 at register level (the Arduino SPI, Wire and HardwareSerial
// cost ~4 KB of flash and 370 B of RAM for what this board needs), the LEDs
// and the benchmark markers. The only place (with main.cpp) that includes Arduino.h;
// the Arduino core is used for millis(), micros() and delay() only (its init() sets up
// every timer and the ADC for PWM and analogRead: start_clock() does what we use).
#pragma once

#include "ArduinoCore.h"

#include "Hmc5883.h"
#include "Mpu6000.h"
#include "Text.h"

namespace board {

// Pins (../shared/APM25.md): MPU6000 CS = pin 53 = PB0 (also the AVR's SS: an output
// keeps SPI master), barometer CS = pin 40 = PG1 (high forever), SDA/SCL = pins 20/21 =
// PD1/PD0, HMC5883L DRDY = pin 31 = PC6 (no interrupt: polled), MPU6000 INT = PE6,
// LEDs A/B/C = pins 27/26/25 = PA5/PA4/PA3, active low (calibrating / running / fault).
constexpr uint32_t kI2cClockHz = 400000;

// Cycle markers read by the simulator's benchmark: a section id written to GPIOR0 when
// it starts and to GPIOR1 when it ends (one OUT instruction each).
enum Section : uint8_t {
    kSecEstimator = 1,  // the pipeline's step: guard, calibration, Dcm::update (+ heading)
    kSecEuler = 2,
    kSecFormat = 3,     // one output line, not the UART send
    kSecMpuRead = 4,
    kSecMagRead = 5,
    kSecLoop = 6,       // one loop iteration's work, from data-ready seen to work done
};
inline void mark_begin(uint8_t id) { GPIOR0 = id; }
inline void mark_end(uint8_t id) { GPIOR1 = id; }

inline bool mpu_int_high() { return (PINE & _BV(PE6)) != 0; }
inline bool mag_drdy_high() { return (PINC & _BV(PC6)) != 0; }
inline bool sda_low() { return (PIND & _BV(PD1)) == 0; }

// Timer 0 as the Arduino core's init() sets it (fast PWM, clock/64, overflow interrupt:
// what millis(), micros() and delay() count), then interrupts on.
void start_clock();
void init_pins();           // LEDs off, every SPI chip select high (53 then 40), inputs
void set_leds(bool calibrating, bool running, bool fault);
void spi_begin();           // after init_pins: SPI master, mode 0
void wire_begin();          // the TWI at 400 kHz, pull-ups on; every call bounded by 3 ms
// Frees the I2C bus when a slave holds SDA low: up to 16 SCL pulses until SDA is
// released (>= 9 clocks finish any byte), then a STOP, then the TWI again.
void i2c_recover();
// True (and clears it) if an I2C call timed out since the last call.
bool i2c_timed_out();

extern const mpu6000::SpiDevice kSpi;
extern const hmc5883::I2cBus kI2c;

// Serial: USART0 at 115200 (U2X, as the Arduino core sets it). Output goes through a
// 256-byte ring drained by the data-register-empty interrupt; a full ring waits for
// the UART (87 us a byte), so text is never lost. Input: a 32-byte ring filled by the
// receive interrupt.
void serial_begin();
extern const text::Sink kSerialSink;
void serial_drain();  // blocks until the ring is empty (set-up only)
void serial_write(const char* data, uint8_t len);
// The next received byte, or -1.
int16_t serial_read();

}  // namespace board
