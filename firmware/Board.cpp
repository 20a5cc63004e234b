// SPDX-License-Identifier: GPL-3.0-or-later
#include "Board.h"

#include <avr/sleep.h>
#include <avr/wdt.h>

#include <SPI.h>
// Wire's TWI driver under it, called directly (see "I2C" below); firmware.ino still
// includes <Wire.h>, which makes the Arduino IDE and PlatformIO build the library.
extern "C" {
#include <utility/twi.h>
}

// MPU6000 INT (wake_on_data_ready): a bare RETI.
EMPTY_INTERRUPT(INT6_vect)

namespace board {

// Written high before it is an output: no low glitch on a chip select.
static void high_output(uint8_t pin) {
    digitalWrite(pin, HIGH);
    pinMode(pin, OUTPUT);
}

void init_pins() {
    // One call per pin, not a loop over a table: a const table is copied to SRAM.
    high_output(kPinLedA);
    high_output(kPinLedB);
    high_output(kPinLedC);
    high_output(kPinMpuCs);
    high_output(kPinBaroCs);
    pinMode(kPinMagDrdy, INPUT);
    DDRE &= (uint8_t)~_BV(PE6);  // MPU6000 INT
}

// Nothing to do in the handler: waking the core is the point; the loop reads the pin.
// The registers attachInterrupt(6, f, RISING) sets (INT6 on the 2560's core), with an
// empty vector of our own: attachInterrupt's table of eight handlers was 16 bytes of RAM
// (and its eight vectors flash) for this one, whose handler did nothing.
void wake_on_data_ready() {
    EICRB = (uint8_t)((EICRB & ~(_BV(ISC60) | _BV(ISC61))) | (RISING << ISC60));
    EIMSK |= _BV(INT6);
}

void idle_until_interrupt() {
    set_sleep_mode(SLEEP_MODE_IDLE);
    // Checked with interrupts off: an edge after the check sets INTF6, and the interrupt
    // then wakes the SLEEP that follows SEI (the instruction after SEI always runs first).
    cli();
    if (!mpu_int_high()) {
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
    }
    sei();
}

void set_leds(bool calibrating, bool running, bool fault) {
    digitalWrite(kPinLedA, calibrating ? LOW : HIGH);  // active low
    digitalWrite(kPinLedB, running ? LOW : HIGH);
    digitalWrite(kPinLedC, fault ? LOW : HIGH);
}

// ---------------------------------------------------------------------------
// SPI: mode 0, MSB first. The settings are built in place from constants, so the
// library computes the clock divider at compile time.
void spi_begin() { SPI.begin(); }

void seam::spi_select(void*, bool on, uint32_t clock_hz) {
    if (on) {
        if (clock_hz >= mpu6000::kReadClockHz)
            SPI.beginTransaction(SPISettings(mpu6000::kReadClockHz, MSBFIRST, SPI_MODE0));
        else
            SPI.beginTransaction(SPISettings(mpu6000::kConfigClockHz, MSBFIRST, SPI_MODE0));
        // Chip select on its port (one instruction, where digitalWrite looks the pin up
        // in tables, and this runs twice per sample); pin 40 (barometer) is never touched.
        PORTB &= (uint8_t)~_BV(PB0);
    } else {
        PORTB |= _BV(PB0);
        SPI.endTransaction();
    }
}
uint8_t seam::spi_transfer(void*, uint8_t out) { return SPI.transfer(out); }
void seam::wait_ms(void*, uint16_t ms) { delay(ms); }

// ---------------------------------------------------------------------------
// I2C on Wire's TWI driver (utility/twi.c), the calls Wire's own methods make, without
// Wire: its TwoWire object (a Stream, with its vtable) and its two 32-byte buffers, which
// <Wire.h> fixes at 32, were 94 bytes of RAM for transfers of at most 7 bytes (twi.c's
// own buffers, TWI_BUFFER_LENGTH, hold them). The Makefile links the core as an archive:
// with no reference left, Wire.cpp's object stays out. Register writes are one
// transmission; reads set the register pointer, then read with a STOP in between (the
// HMC5883L's protocol, datasheet "I2C Communication Protocol").

// The slave events Wire.begin() attaches (twi.c's interrupt calls them unchecked if the
// TWI is ever addressed as a slave): without a user callback Wire's do nothing.
static void on_slave_receive(uint8_t*, int) {}
static void on_slave_transmit() {}

void wire_begin() {
    twi_init();  // pull-ups on
    twi_attachSlaveTxEvent(on_slave_transmit);
    twi_attachSlaveRxEvent(on_slave_receive);
    twi_setFrequency(kI2cClockHz);
    twi_setTimeoutInMicros(kI2cTimeoutUs, true);
}

bool i2c_timed_out() {
    const bool t = twi_manageTimeoutFlag(false);
    twi_manageTimeoutFlag(true);  // clear it
    return t;
}

bool seam::i2c_write_reg(void*, uint8_t addr7, uint8_t reg, uint8_t value) {
    uint8_t bytes[2] = {reg, value};
    return twi_writeTo(addr7, bytes, 2, 1, 1) == 0;  // wait, STOP
}

bool seam::i2c_read_regs(void*, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len) {
    if (twi_writeTo(addr7, &reg, 1, 1, 1) != 0) return false;
    // Read into a buffer of its own as Wire did: data is left alone by a short read.
    // Longer than TWI_BUFFER_LENGTH: twi_readFrom reads nothing (so did Wire).
    uint8_t got[TWI_BUFFER_LENGTH];
    if (len > TWI_BUFFER_LENGTH || twi_readFrom(addr7, got, len, 1) != len) return false;
    for (uint8_t i = 0; i < len; ++i) data[i] = got[i];
    return true;
}

// Open drain by hand: a line is driven low as an output, released as an input with
// its pull-up.
static void line_low(uint8_t pin) {
    digitalWrite(pin, LOW);
    pinMode(pin, OUTPUT);
    delayMicroseconds(5);
}
static void line_release(uint8_t pin) {
    pinMode(pin, INPUT_PULLUP);
    delayMicroseconds(5);
}

void i2c_recover() {
    twi_disable();  // the pins back to the port (Wire.end())
    line_release(kPinSda);
    line_release(kPinScl);
    for (uint8_t i = 0; i < 16 && sda_low(); ++i) {
        line_low(kPinScl);
        line_release(kPinScl);
    }
    // STOP: SDA rises while SCL is high.
    line_low(kPinSda);
    line_release(kPinSda);
    wire_begin();
}

void reset_by_watchdog() {
    cli();
    wdt_enable(WDTO_15MS);
    for (;;) {}
}

}  // namespace board

// After a watchdog reset WDRF keeps the watchdog on at its shortest period: off before
// the start-up's waits (avr-libc's wdt.h: in .init3, MCUSR cleared first). The APM 2.5's
// bootloader does it too; an ELF run without one (apm25sim) needs this.
extern "C" __attribute__((naked, used, section(".init3"))) void apm25_stop_watchdog() {
    MCUSR = 0;
    wdt_disable();
}
