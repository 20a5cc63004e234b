#include "Board.h"


namespace board {

void init_pins() {
    // Outputs written high before they are outputs: no low glitch on a chip select.
    const uint8_t high_outputs[] = {kPinLedA, kPinLedB, kPinLedC, kPinMpuCs, kPinBaroCs};
    for (uint8_t pin : high_outputs) {
        digitalWrite(pin, HIGH);
        pinMode(pin, OUTPUT);
    }
    pinMode(kPinMagDrdy, INPUT);
    DDRE &= (uint8_t)~_BV(PE6);  // MPU6000 INT
}

void set_leds(bool calibrating, bool running, bool fault) {
    digitalWrite(kPinLedA, calibrating ? LOW : HIGH);
    digitalWrite(kPinLedB, running ? LOW : HIGH);
    digitalWrite(kPinLedC, fault ? LOW : HIGH);
}

// ---------------------------------------------------------------------------
// SPI: mode 0, MSB first. SPISettings built in place from constants folds to two
// register values; as global objects they cost a ~1 KB run-time constructor.

void spi_begin() { SPI.begin(); }

static void spi_select(void*, bool on, uint32_t clock_hz) {
    if (on) {
        if (clock_hz >= mpu6000::kReadClockHz) SPI.beginTransaction(SPISettings(mpu6000::kReadClockHz, MSBFIRST, SPI_MODE0));
        else SPI.beginTransaction(SPISettings(mpu6000::kConfigClockHz, MSBFIRST, SPI_MODE0));
        PORTB &= (uint8_t)~_BV(PB0);  // pin 53 low; pin 40 (barometer) is never touched
    } else {
        PORTB |= _BV(PB0);
        SPI.endTransaction();
    }
}
static uint8_t spi_transfer(void*, uint8_t out) { return SPI.transfer(out); }
static void wait_ms(void*, uint16_t ms) { delay(ms); }

mpu6000::SpiDevice spi_device() { return mpu6000::SpiDevice{nullptr, spi_select, spi_transfer, wait_ms}; }

// ---------------------------------------------------------------------------
// I2C through Wire: every call bounded by Wire's timeout.
void wire_begin() {
    Wire.begin();
    Wire.setClock(kI2cClockHz);
    Wire.setWireTimeout(kI2cTimeoutUs, true);
}

bool i2c_timed_out() {
    if (!Wire.getWireTimeoutFlag()) return false;
    Wire.clearWireTimeoutFlag();
    return true;
}

void i2c_recover() {
    Wire.end();
    pinMode(kPinSda, INPUT_PULLUP);
    pinMode(kPinScl, INPUT_PULLUP);
    delayMicroseconds(5);
    for (uint8_t i = 0; i < 16 && digitalRead(kPinSda) == LOW; ++i) {
        digitalWrite(kPinScl, LOW);  // open drain: drive low, release to the pull-up
        pinMode(kPinScl, OUTPUT);
        delayMicroseconds(5);
        pinMode(kPinScl, INPUT_PULLUP);
        delayMicroseconds(5);
    }
    // STOP: SDA rises while SCL is high.
    digitalWrite(kPinSda, LOW);
    pinMode(kPinSda, OUTPUT);
    delayMicroseconds(5);
    pinMode(kPinSda, INPUT_PULLUP);
    delayMicroseconds(5);
    wire_begin();
}

static bool i2c_write_reg(void*, uint8_t addr7, uint8_t reg, uint8_t value) {
    Wire.beginTransmission(addr7);
    Wire.write(reg);
    Wire.write(value);
    return Wire.endTransmission() == 0;
}

static bool i2c_read_regs(void*, uint8_t addr7, uint8_t reg, uint8_t* data, uint8_t len) {
    Wire.beginTransmission(addr7);
    Wire.write(reg);
    if (Wire.endTransmission() != 0) return false;
    if (Wire.requestFrom(addr7, len) != len) return false;
    for (uint8_t i = 0; i < len; ++i) data[i] = (uint8_t)Wire.read();
    return true;
}

hmc5883::I2cBus i2c_bus() { return hmc5883::I2cBus{nullptr, i2c_write_reg, i2c_read_regs, wait_ms}; }

// ---------------------------------------------------------------------------
// Serial output ring: the angle lines and messages queue here and leave as the UART
// has room, so a status or help reply does not stall the 200 Hz loop.
static constexpr uint16_t kRingSize = 256;
static char ring[kRingSize];
static uint16_t ring_head = 0, ring_tail = 0;  // head: next write, tail: next read

static uint16_t ring_used() { return (uint16_t)((ring_head - ring_tail) & (kRingSize - 1u)); }

void serial_pump() {
    int room = Serial.availableForWrite();
    while (room-- > 0 && ring_tail != ring_head) {
        Serial.write((uint8_t)ring[ring_tail]);
        ring_tail = (uint16_t)((ring_tail + 1u) & (kRingSize - 1u));
    }
}

void serial_drain() {
    while (ring_tail != ring_head) serial_pump();
}

static void ring_put(char c) {
    while (ring_used() >= kRingSize - 1u) {  // full: wait for the UART (bounded: 87 us a byte)
        Serial.write((uint8_t)ring[ring_tail]);
        ring_tail = (uint16_t)((ring_tail + 1u) & (kRingSize - 1u));
    }
    ring[ring_head] = c;
    ring_head = (uint16_t)((ring_head + 1u) & (kRingSize - 1u));
}

void serial_write(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) ring_put(data[i]);
}

static void sink_write(void*, const char* data, uint8_t len) { serial_write(data, len); }
static void sink_write_flash(void*, const char* p) {
    for (char c = (char)pgm_read_byte(p); c != '\0'; c = (char)pgm_read_byte(++p)) ring_put(c);
}

static const text::Sink kSerialSink = {nullptr, sink_write, sink_write_flash};

void serial_begin(uint32_t baud) { Serial.begin(baud); }
const text::Sink* serial_sink() { return &kSerialSink; }

}  // namespace board
