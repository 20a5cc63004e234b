// SPDX-License-Identifier: GPL-3.0-or-later
#include "Mpu6000.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define MPU6000_PROGMEM PROGMEM
#else
#define MPU6000_PROGMEM
#endif

namespace mpu6000 {

namespace {
// The register writes of begin(), in flash on the AVR (a const table is copied to SRAM).
struct Write {
    uint8_t reg, value;
};
const Write kConfig[] MPU6000_PROGMEM = {
    {REG_PWR_MGMT_1, kPwrClockPllGyroZ},
    {REG_USER_CTRL, kUserCtrlI2cIfDis},
    {REG_SMPLRT_DIV, smplrt_div_for_hz(kRateHz)},
    {REG_CONFIG, (uint8_t)kDlpf},
    {REG_GYRO_CONFIG, (uint8_t)kGyroRange},
    {REG_ACCEL_CONFIG, (uint8_t)kAccelRange},
    {REG_INT_PIN_CFG, kIntPinCfgLatchClearOnRead},
    {REG_INT_ENABLE, kIntEnableDataReady},
};
Write config(uint8_t i) {
#ifdef __AVR__
    return Write{pgm_read_byte(&kConfig[i].reg), pgm_read_byte(&kConfig[i].value)};
#else
    return kConfig[i];
#endif
}
constexpr uint8_t kConfigWrites = sizeof kConfig / sizeof kConfig[0];
}  // namespace

uint8_t Mpu6000::read_register(uint8_t reg, uint32_t clock_hz) {
    dev_.select(dev_.ctx, true, clock_hz);
    dev_.transfer(dev_.ctx, (uint8_t)(reg | kReadFlag));
    const uint8_t v = dev_.transfer(dev_.ctx, 0x00);
    dev_.select(dev_.ctx, false, clock_hz);
    return v;
}

void Mpu6000::write_register(uint8_t reg, uint8_t value) {
    dev_.select(dev_.ctx, true, kConfigClockHz);
    dev_.transfer(dev_.ctx, (uint8_t)(reg & (uint8_t)~kReadFlag));
    dev_.transfer(dev_.ctx, value);
    dev_.select(dev_.ctx, false, kConfigClockHz);
}

bool Mpu6000::probe(uint8_t& who) {
    who = read_register(REG_WHO_AM_I);
    return who == kWhoAmIValue;
}

InitResult Mpu6000::begin() {
    uint8_t who = 0;
    if (!probe(who)) return InitResult{InitStatus::WrongIdentity, REG_WHO_AM_I, kWhoAmIValue, who};

    write_register(REG_PWR_MGMT_1, kPwrDeviceReset);
    dev_.delay_ms(dev_.ctx, kResetWaitMs);  // the reset takes up to 100 ms
    write_register(REG_PWR_MGMT_1, kPwrClockPllGyroZ);
    dev_.delay_ms(dev_.ctx, 5);             // PLL settles
    // After a reset the I2C interface is back on: SPI only again before anything else.
    write_register(REG_USER_CTRL, kUserCtrlI2cIfDis);

    for (uint8_t i = 0; i < kConfigWrites; ++i) write_register(config(i).reg, config(i).value);
    for (uint8_t i = 0; i < kConfigWrites; ++i) {
        const Write w = config(i);
        const uint8_t got = read_register(w.reg);
        if (got != w.value) return InitResult{InitStatus::ReadbackMismatch, w.reg, w.value, got};
    }
    read_register(REG_INT_STATUS);  // clear a stale interrupt
    return InitResult{InitStatus::Ok, REG_WHO_AM_I, kWhoAmIValue, who};
}

bool Mpu6000::data_ready() {
    return (read_register(REG_INT_STATUS, kReadClockHz) & kIntStatusDataReady) != 0;
}

void Mpu6000::read_burst(uint8_t first_reg, uint8_t* buf) {
    dev_.select(dev_.ctx, true, kReadClockHz);
    dev_.transfer(dev_.ctx, (uint8_t)(first_reg | kReadFlag));
    for (uint8_t i = 0; i < kBurstLength; ++i) buf[i] = dev_.transfer(dev_.ctx, 0x00);
    dev_.select(dev_.ctx, false, kReadClockHz);
}

BurstStatus Mpu6000::read(Sample& out, uint8_t* raw) {
    uint8_t buf[kBurstLength];
    read_burst(REG_ACCEL_XOUT_H, buf);
    if (raw != nullptr)
        for (uint8_t i = 0; i < kBurstLength; ++i) raw[i] = buf[i];
    return decode_burst(buf, kGyroRange, kAccelRange, out);
}

void Mpu6000::start_fifo() {
    write_register(REG_FIFO_EN, kFifoEnBurstSample);
    write_register(REG_USER_CTRL, (uint8_t)(kUserCtrlI2cIfDis | kUserCtrlFifoEn | kUserCtrlFifoReset));
}

void Mpu6000::stop_fifo() {
    write_register(REG_USER_CTRL, kUserCtrlI2cIfDis);
    write_register(REG_FIFO_EN, 0x00);
}

uint16_t Mpu6000::fifo_samples() {
    dev_.select(dev_.ctx, true, kReadClockHz);
    dev_.transfer(dev_.ctx, (uint8_t)(REG_FIFO_COUNTH | kReadFlag));
    const uint8_t high = dev_.transfer(dev_.ctx, 0x00);
    const uint8_t low = dev_.transfer(dev_.ctx, 0x00);
    dev_.select(dev_.ctx, false, kReadClockHz);
    const uint16_t bytes = (uint16_t)linalg::int16_from_be(high, low);
    return bytes > kFifoSize ? 0 : (uint16_t)(bytes / kBurstLength);
}

BurstStatus Mpu6000::read_fifo(Sample& out) {
    uint8_t buf[kBurstLength];
    read_burst(REG_FIFO_R_W, buf);
    return decode_burst(buf, kGyroRange, kAccelRange, out);
}

}  // namespace mpu6000
