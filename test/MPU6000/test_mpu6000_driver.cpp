// SPDX-License-Identifier: GPL-3.0-or-later
// The MPU6000 bus driver against fake buses (lib/MPU6000/Mpu6000): the same seam the
// firmware fills with SPI and the replay tool with the simulator's register model.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "Mpu6000.h"
#include "Mpu6000Model.h"

namespace {

// ---------------------------------------------------------------------------
// A register-level MPU6000 on SPI: first byte = address (bit 7 read), then auto-increment.
struct FakeMpu {
    uint8_t reg[128] = {};
    bool present = true;
    bool selected = false;
    bool have_addr = false;
    bool reading = false;
    uint8_t addr = 0;
    uint32_t clock = 0;
    std::vector<uint32_t> write_clocks, burst_clocks;
    uint16_t delayed_ms = 0;
    uint8_t ignore_reg = 0xFF;  // a register that does not keep writes (read-back test)

    FakeMpu() { power_on(); }
    void power_on() {
        std::memset(reg, 0, sizeof reg);
        reg[mpu6000::REG_WHO_AM_I] = 0x68;
        reg[mpu6000::REG_PWR_MGMT_1] = 0x40;  // sleeping
    }
    static void select(void* ctx, bool on, uint32_t hz) {
        FakeMpu* m = static_cast<FakeMpu*>(ctx);
        m->selected = on;
        m->have_addr = false;
        m->clock = hz;
    }
    static uint8_t transfer(void* ctx, uint8_t out) {
        FakeMpu* m = static_cast<FakeMpu*>(ctx);
        EXPECT_TRUE(m->selected);
        if (!m->present) return 0x00;
        if (!m->have_addr) {
            m->have_addr = true;
            m->reading = (out & 0x80) != 0;
            m->addr = out & 0x7F;
            if (m->reading && m->addr == mpu6000::REG_ACCEL_XOUT_H) m->burst_clocks.push_back(m->clock);
            if (!m->reading) m->write_clocks.push_back(m->clock);
            return 0;
        }
        const uint8_t a = m->addr++;
        if (m->reading) {
            const uint8_t v = m->reg[a];
            if (a == mpu6000::REG_INT_STATUS) m->reg[a] = 0;  // clear on read
            return v;
        }
        if (a == mpu6000::REG_PWR_MGMT_1 && (out & 0x80)) {
            m->power_on();
            return 0;
        }
        if (a != m->ignore_reg && a != mpu6000::REG_WHO_AM_I) m->reg[a] = out;
        return 0;
    }
    static void delay(void* ctx, uint16_t ms) { static_cast<FakeMpu*>(ctx)->delayed_ms += ms; }
    mpu6000::SpiDevice device() { return mpu6000::SpiDevice{this, select, transfer, delay}; }

    void set_sample(int16_t ax, int16_t ay, int16_t az, int16_t t, int16_t gx, int16_t gy, int16_t gz) {
        const int16_t v[7] = {ax, ay, az, t, gx, gy, gz};
        for (int i = 0; i < 7; ++i) {
            reg[0x3B + 2 * i] = (uint8_t)((uint16_t)v[i] >> 8);
            reg[0x3B + 2 * i + 1] = (uint8_t)(v[i] & 0xFF);
        }
        reg[mpu6000::REG_INT_STATUS] = 0x01;
    }
};

}  // namespace

TEST(Mpu6000Driver, BeginConfiguresAndReadsBack) {
    FakeMpu chip;
    mpu6000::Mpu6000 mpu(chip.device());
    const mpu6000::InitResult r = mpu.begin();
    ASSERT_EQ(r.status, mpu6000::InitStatus::Ok);
    EXPECT_GE(chip.delayed_ms, 100);  // waited for the reset
    EXPECT_EQ(chip.reg[mpu6000::REG_PWR_MGMT_1], 0x03);
    EXPECT_EQ(chip.reg[mpu6000::REG_USER_CTRL], 0x10);
    EXPECT_EQ(chip.reg[mpu6000::REG_SMPLRT_DIV], 4);   // 1 kHz / 5 = 200 Hz
    EXPECT_EQ(chip.reg[mpu6000::REG_CONFIG], 0x03);    // DLPF 42 Hz
    EXPECT_EQ(chip.reg[mpu6000::REG_GYRO_CONFIG], 0x18);
    EXPECT_EQ(chip.reg[mpu6000::REG_ACCEL_CONFIG], 0x18);  // +-16 g
    EXPECT_EQ(chip.reg[mpu6000::REG_INT_ENABLE], 0x01);
    EXPECT_EQ(chip.reg[mpu6000::REG_INT_PIN_CFG], 0x30);
    for (uint32_t hz : chip.write_clocks) EXPECT_LE(hz, 1000000u);  // writes at <= 1 MHz
}

TEST(Mpu6000Driver, AbsentOrWrongIdentity) {
    FakeMpu chip;
    chip.present = false;
    mpu6000::Mpu6000 mpu(chip.device());
    mpu6000::InitResult r = mpu.begin();
    EXPECT_EQ(r.status, mpu6000::InitStatus::WrongIdentity);
    EXPECT_EQ(r.read, 0x00);
    EXPECT_EQ(r.wrote, 0x68);
    EXPECT_EQ(chip.delayed_ms, 0);  // no reset wait when nobody answers

    FakeMpu other;
    other.reg[mpu6000::REG_WHO_AM_I] = 0x70;  // an MPU6500
    mpu6000::Mpu6000 mpu2(other.device());
    uint8_t who = 0;
    EXPECT_FALSE(mpu2.probe(who));
    EXPECT_EQ(who, 0x70);
}

TEST(Mpu6000Driver, ReadbackMismatchIsReported) {
    FakeMpu chip;
    chip.ignore_reg = mpu6000::REG_GYRO_CONFIG;
    mpu6000::Mpu6000 mpu(chip.device());
    const mpu6000::InitResult r = mpu.begin();
    EXPECT_EQ(r.status, mpu6000::InitStatus::ReadbackMismatch);
    EXPECT_EQ(r.reg, mpu6000::REG_GYRO_CONFIG);
    EXPECT_EQ(r.wrote, 0x18);
    EXPECT_EQ(r.read, 0x00);
}

TEST(Mpu6000Driver, BurstAt8MHzDecodesToBodyFrame) {
    FakeMpu chip;
    mpu6000::Mpu6000 mpu(chip.device());
    ASSERT_EQ(mpu.begin().status, mpu6000::InitStatus::Ok);
    // Level, at rest: chip z reads +1 g (2048 LSB at 16 g; body z = -chip z = -1 g). Gyro chip x = 16.4 LSB = 1 deg/s.
    chip.set_sample(0, 0, 2048, 0, 164, 0, -328);
    EXPECT_TRUE(mpu.data_ready());
    EXPECT_FALSE(mpu.data_ready());  // cleared by the read
    mpu6000::Sample s{};
    uint8_t raw[14];
    ASSERT_EQ(mpu.read(s, raw), mpu6000::BurstStatus::Ok);
    ASSERT_EQ(chip.burst_clocks.size(), 1u);
    EXPECT_EQ(chip.burst_clocks[0], 8000000u);
    EXPECT_EQ(raw[4], 0x08);
    EXPECT_NEAR(s.accel_m_s2().z, -9.80665f, 1e-3f);
    EXPECT_NEAR(s.accel_m_s2().x, 0.0f, 1e-6f);
    EXPECT_NEAR(s.gyro_rad_s().y, 10.0f * linalg::kRadPerDeg, 1e-4f);   // body y = chip x
    EXPECT_NEAR(s.gyro_rad_s().z, 20.0f * linalg::kRadPerDeg, 1e-4f);   // body z = -chip z
    EXPECT_NEAR(s.temperature_c(), 36.53f, 1e-3f);
    EXPECT_FALSE(s.gyro_saturated);
}

TEST(Mpu6000Driver, SilentBusIsNoSensor) {
    FakeMpu chip;
    mpu6000::Mpu6000 mpu(chip.device());
    ASSERT_EQ(mpu.begin().status, mpu6000::InitStatus::Ok);
    chip.present = false;
    mpu6000::Sample s{};
    s.temperature_raw = 1234;
    EXPECT_EQ(mpu.read(s), mpu6000::BurstStatus::NoSensor);
    EXPECT_EQ(s.temperature_raw, 1234);  // untouched
}

// The FIFO path the firmware takes when the INT pin is silent, against the simulator's
// register model: start_fifo, the count in whole samples, and each queued sample read
// and decoded as the burst would be.
namespace {
struct ModelBus {
    sim::Mpu6000Model* mpu;
    static void select(void* ctx, bool on, uint32_t) { static_cast<ModelBus*>(ctx)->mpu->set_chip_select(on); }
    static uint8_t transfer(void* ctx, uint8_t out) { return static_cast<ModelBus*>(ctx)->mpu->transfer(out, 1e6); }
    static void delay(void* ctx, uint16_t ms) {
        sim::Mpu6000Model* m = static_cast<ModelBus*>(ctx)->mpu;
        m->advance_to(m->time_s() + ms * 1e-3);
    }
};
}  // namespace

TEST(Mpu6000Driver, FifoDeliversEverySampleInOrder) {
    sim::Trajectory t;
    for (int k = 0; k <= 10; ++k) {
        sim::TrajectorySample s{};
        s.t_s = k;
        s.gyro_rad_s[2] = 2.0 * k;  // a ramp of ~9 counts a sample: each sample differs
        s.accel_m_s2[2] = -9.81;
        s.mag_uT[0] = 20;
        s.quat[0] = 1;
        s.movement = true;
        t.samples().push_back(s);
    }
    sim::Mpu6000Model model(t);
    ModelBus bus{&model};
    mpu6000::Mpu6000 mpu(mpu6000::SpiDevice{&bus, ModelBus::select, ModelBus::transfer, ModelBus::delay});
    ASSERT_EQ(mpu.begin().status, mpu6000::InitStatus::Ok);
    model.advance_to(1.0);
    EXPECT_EQ(mpu.fifo_samples(), 0u);  // off until started
    mpu.start_fifo();
    model.advance_to(1.0 + 5 * 0.005 + 0.001);
    ASSERT_EQ(mpu.fifo_samples(), 5u);
    mpu6000::Sample s{}, prev{};
    for (int i = 0; i < 5; ++i) {
        ASSERT_EQ(mpu.read_fifo(s), mpu6000::BurstStatus::Ok);
        EXPECT_NEAR(s.accel_m_s2().z, -9.81f, 0.01f);
        if (i > 0) {
            EXPECT_GT(s.gyro_rad_s().z, prev.gyro_rad_s().z) << i;
        }
        prev = s;
    }
    EXPECT_EQ(mpu.fifo_samples(), 0u);
    mpu6000::Sample latest{};
    ASSERT_EQ(mpu.read(latest), mpu6000::BurstStatus::Ok);
    EXPECT_EQ(latest.gyro_rad_s().z, prev.gyro_rad_s().z);  // the last queued sample is the registers'
    mpu.stop_fifo();
    model.advance_to(model.time_s() + 0.05);
    EXPECT_EQ(mpu.fifo_samples(), 0u);
}

TEST(Mpu6000Driver, FifoCountFromASilentBusIsZero) {
    FakeMpu fake;
    fake.present = false;
    mpu6000::Mpu6000 mpu(fake.device());
    EXPECT_EQ(mpu.fifo_samples(), 0u);
}
