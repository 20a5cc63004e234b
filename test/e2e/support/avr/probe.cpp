// SPDX-License-Identifier: GPL-3.0-or-later
// A tiny AVR program that exercises the simulated board (sim/apm25sim) without the
// firmware: MPU6000 over SPI, HMC5883L over Wire, the INT and DRDY lines, the serial
// console input and the GPIOR profiling markers. Built by test/e2e/support/avr/build.sh.
//
// -DPROBE_BUS_VIOLATION: drives the barometer chip select (pin 40) low while the
// MPU6000 chip select (pin 53) is low, which the harness must flag.
#include <Arduino.h>
#include <SPI.h>
#include <Wire.h>

static const uint8_t kMpuCs = 53;
static const uint8_t kBaroCs = 40;
static const uint8_t kMagDrdy = 31;

static uint8_t mpu_read(uint8_t reg) {
    digitalWrite(kMpuCs, LOW);
    SPI.transfer(reg | 0x80);
    uint8_t v = SPI.transfer(0);
    digitalWrite(kMpuCs, HIGH);
    return v;
}

static void mpu_write(uint8_t reg, uint8_t v) {
    digitalWrite(kMpuCs, LOW);
    SPI.transfer(reg);
    SPI.transfer(v);
    digitalWrite(kMpuCs, HIGH);
}

static bool mag_write(uint8_t reg, uint8_t v) {
    Wire.beginTransmission(0x1E);
    Wire.write(reg);
    Wire.write(v);
    return Wire.endTransmission() == 0;
}

static uint8_t mag_read(uint8_t reg, uint8_t* out, uint8_t n) {
    Wire.beginTransmission(0x1E);
    Wire.write(reg);
    if (Wire.endTransmission() != 0) return 0;
    uint8_t got = Wire.requestFrom((uint8_t)0x1E, n);
    for (uint8_t i = 0; i < got; ++i) out[i] = Wire.read();
    return got;
}

static int16_t be16(const uint8_t* p) { return (int16_t)(uint16_t)(((uint16_t)p[0] << 8) | p[1]); }

void setup() {
    digitalWrite(kMpuCs, HIGH);
    pinMode(kMpuCs, OUTPUT);
    digitalWrite(kBaroCs, HIGH);
    pinMode(kBaroCs, OUTPUT);
    Serial.begin(115200);
    Serial.println(F("# probe: simulated board check"));
    SPI.begin();
    SPI.setClockDivider(SPI_CLOCK_DIV16);  // 1 MHz for register writes
    Serial.print(F("# whoami 0x"));
    Serial.println(mpu_read(0x75), HEX);
    mpu_write(0x6B, 0x80);
    delay(100);
    mpu_write(0x6B, 0x03);
    mpu_write(0x6A, 0x10);
    mpu_write(0x19, 4);
    mpu_write(0x1A, 3);
    mpu_write(0x1B, 0x18);
    mpu_write(0x1C, 0x08);
    mpu_write(0x37, 0x10);
    mpu_write(0x38, 0x01);
    SPI.setClockDivider(SPI_CLOCK_DIV2);  // 8 MHz for sensor reads

    Wire.begin();
    Wire.setClock(400000);
    uint8_t id[3] = {0, 0, 0};
    uint8_t got = mag_read(10, id, 3);
    Serial.print(F("# magid "));
    Serial.print(got);
    Serial.print(' ');
    Serial.write(id, 3);
    Serial.println();
    mag_write(0, 0x78);
    mag_write(1, 0x20);
    mag_write(2, 0x00);
}

static uint32_t last_ms = 0;
static uint16_t mpu_int_seen = 0;
static uint8_t last_int = 0;

void loop() {
    const uint8_t int_level = (PINE >> 6) & 1;
    if (int_level && !last_int) ++mpu_int_seen;
    last_int = int_level;

    if (Serial.available()) {
        Serial.print(F("# echo "));
        while (Serial.available()) Serial.write(Serial.read());
    }
    const uint32_t now = millis();
    if (now - last_ms < 100) return;
    last_ms = now;

    GPIOR0 = 4;
    uint8_t raw[14];
    digitalWrite(kMpuCs, LOW);
#ifdef PROBE_BUS_VIOLATION
    if (now > 500) digitalWrite(kBaroCs, LOW);
#endif
    SPI.transfer(0x3B | 0x80);
    for (uint8_t i = 0; i < 14; ++i) raw[i] = SPI.transfer(0);
    digitalWrite(kMpuCs, HIGH);
    GPIOR1 = 4;

    uint8_t m[6] = {0, 0, 0, 0, 0, 0};
    const uint8_t drdy = digitalRead(kMagDrdy);
    GPIOR0 = 5;
    const uint8_t got = mag_read(3, m, 6);
    GPIOR1 = 5;

    Serial.print(F("ax:"));
    Serial.print(be16(raw));
    Serial.print(F(" ay:"));
    Serial.print(be16(raw + 2));
    Serial.print(F(" az:"));
    Serial.print(be16(raw + 4));
    Serial.print(F(" gx:"));
    Serial.print(be16(raw + 8));
    Serial.print(F(" gy:"));
    Serial.print(be16(raw + 10));
    Serial.print(F(" gz:"));
    Serial.print(be16(raw + 12));
    Serial.print(F(" ints:"));
    Serial.print(mpu_int_seen);
    Serial.print(F(" drdy:"));
    Serial.print(drdy);
    Serial.print(F(" mag:"));
    Serial.print(got);
    Serial.print(F(" mx:"));
    Serial.print(be16(m));
    Serial.print(F(" mz:"));
    Serial.print(be16(m + 2));
    Serial.print(F(" my:"));
    Serial.println(be16(m + 4));
}
