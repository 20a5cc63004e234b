// SPDX-License-Identifier: GPL-3.0-or-later
// The HMC5883L bus driver against a fake bus (lib/HMC5883/Hmc5883): the same seam the
// firmware fills with Wire and the replay tool with the simulator's register model.
#include <gtest/gtest.h>

#include "Hmc5883.h"

namespace {

// ---------------------------------------------------------------------------
// A register-level HMC5883L: the ambient field, or the bias field alone in self-test
// (the chip subtracts the ambient itself), single and continuous modes, RDY in the
// status register.
struct FakeHmc {
    uint8_t reg[16] = {};
    bool present = true;
    bool ready_works = true;
    int16_t ambient[3] = {100, -50, 200};  // chip x, y, z counts at the current gain
    int16_t bias[3] = {740, 700, 690};     // positive bias counts at gain 0x60
    int reads = 0;

    FakeHmc() {
        reg[0x0A] = 'H';
        reg[0x0B] = '4';
        reg[0x0C] = '3';
        reg[hmc5883::REG_MODE] = 0x01;
    }
    void measure() {
        int16_t v[3];
        const bool positive = (reg[0] & 0x03) == 0x01;
        for (int i = 0; i < 3; ++i) v[i] = positive ? bias[i] : ambient[i];
        // Data order X, Z, Y.
        const int16_t order[3] = {v[0], v[2], v[1]};
        for (int i = 0; i < 3; ++i) {
            reg[3 + 2 * i] = (uint8_t)((uint16_t)order[i] >> 8);
            reg[4 + 2 * i] = (uint8_t)(order[i] & 0xFF);
        }
        if (ready_works) reg[hmc5883::REG_STATUS] |= 0x01;
    }
    static bool write_reg(void* ctx, uint8_t addr7, uint8_t r, uint8_t v) {
        FakeHmc* h = static_cast<FakeHmc*>(ctx);
        if (!h->present || addr7 != 0x1E) return false;
        if (r <= 2) h->reg[r] = v;
        if (r == hmc5883::REG_MODE && (v & 0x03) == hmc5883::kModeSingle) h->measure();
        if (r == hmc5883::REG_MODE && (v & 0x03) == hmc5883::kModeContinuous) h->measure();
        return true;
    }
    static bool read_regs(void* ctx, uint8_t addr7, uint8_t r, uint8_t* d, uint8_t n) {
        FakeHmc* h = static_cast<FakeHmc*>(ctx);
        if (!h->present || addr7 != 0x1E) return false;
        for (uint8_t i = 0; i < n; ++i) d[i] = h->reg[(r + i) & 0x0F];
        if (r == hmc5883::REG_DATA_X_MSB) {
            h->reg[hmc5883::REG_STATUS] &= (uint8_t)~0x01;
            ++h->reads;
        }
        return true;
    }
    static void delay(void*, uint16_t) {}
    hmc5883::I2cBus bus() { return hmc5883::I2cBus{this, write_reg, read_regs, delay}; }
};

}  // namespace

TEST(Hmc5883Driver, SelfTestScaleAndContinuousConfig) {
    FakeHmc chip;
    hmc5883::Hmc5883 mag(chip.bus());
    const hmc5883::InitResult r = mag.begin(true);
    ASSERT_EQ(r.status, hmc5883::InitStatus::Ok);
    EXPECT_TRUE(mag.self_test_passed());
    // scale = expected (datasheet bias field at 660 LSB/Ga) / measured.
    EXPECT_NEAR(mag.self_test_scale().x, 1.16f * 660.0f / 740.0f, 1e-4f);
    EXPECT_NEAR(mag.self_test_scale().y, 1.16f * 660.0f / 700.0f, 1e-4f);
    EXPECT_NEAR(mag.self_test_scale().z, 1.08f * 660.0f / 690.0f, 1e-4f);
    EXPECT_EQ(chip.reg[hmc5883::REG_CONFIG_A], 0x78);
    EXPECT_EQ(chip.reg[hmc5883::REG_CONFIG_B], 0x20);
    EXPECT_EQ(chip.reg[hmc5883::REG_MODE], 0x00);
}

TEST(Hmc5883Driver, ImplausibleSelfTestFallsBackToUnitScale) {
    FakeHmc chip;
    chip.bias[1] = 200;  // y far too weak: ratio 3.6
    hmc5883::Hmc5883 mag(chip.bus());
    ASSERT_EQ(mag.begin(true).status, hmc5883::InitStatus::Ok);
    EXPECT_FALSE(mag.self_test_passed());
    EXPECT_TRUE(mag.self_test_scale() == linalg::Vector3f(1.0f, 1.0f, 1.0f));

    FakeHmc no_ready;
    no_ready.ready_works = false;  // never says ready: bounded, then unit scale
    hmc5883::Hmc5883 mag2(no_ready.bus());
    ASSERT_EQ(mag2.begin(true).status, hmc5883::InitStatus::Ok);
    EXPECT_FALSE(mag2.self_test_passed());
}

TEST(Hmc5883Driver, AbsentAndWrongIdentity) {
    FakeHmc chip;
    chip.present = false;
    hmc5883::Hmc5883 mag(chip.bus());
    EXPECT_EQ(mag.begin(true).status, hmc5883::InitStatus::NoAnswer);
    linalg::Vector3f f;
    EXPECT_EQ(mag.read(f), hmc5883::ReadStatus::BusError);

    FakeHmc other;
    other.reg[0x0B] = '5';
    hmc5883::Hmc5883 mag2(other.bus());
    const hmc5883::InitResult r = mag2.begin(true);
    EXPECT_EQ(r.status, hmc5883::InitStatus::WrongIdentity);
    EXPECT_EQ(r.id[1], '5');
}

TEST(Hmc5883Driver, ReadsBodyFrameDropsFirstAndOverflow) {
    FakeHmc chip;
    hmc5883::Hmc5883 mag(chip.bus());
    ASSERT_EQ(mag.begin(false).status, hmc5883::InitStatus::Ok);
    linalg::Vector3f f(7.0f, 7.0f, 7.0f);
    EXPECT_EQ(mag.read(f), hmc5883::ReadStatus::Skipped);  // first sample after the gain change
    chip.ambient[0] = 109;  // 0.1 Ga = 10 uT on chip x at 1090 LSB/Ga
    chip.ambient[1] = 218;
    chip.ambient[2] = -545;
    chip.measure();
    ASSERT_EQ(mag.read(f), hmc5883::ReadStatus::Ok);
    // body = (-chip_y, -chip_x, -chip_z)
    EXPECT_NEAR(f.x, -20.0f, 1e-3f);
    EXPECT_NEAR(f.y, -10.0f, 1e-3f);
    EXPECT_NEAR(f.z, 50.0f, 1e-3f);
    chip.ambient[2] = -4096;
    chip.measure();
    const linalg::Vector3f before = f;
    EXPECT_EQ(mag.read(f), hmc5883::ReadStatus::Overflow);
    EXPECT_TRUE(f == before);
}
