// SPDX-License-Identifier: GPL-3.0-or-later
// The simulator's sensor register models (sim/models): their bytes, decoded with the
// firmware's own decoders (lib/MPU6000, lib/HMC5883), give back the trajectory's
// body-frame values within one count; ranges, saturation, overflow, identity, timing.
#include <gtest/gtest.h>

#include <cmath>

#include "Hmc5883Model.h"
#include "Hmc5883Registers.h"
#include "Mpu6000Model.h"
#include "Mpu6000Registers.h"
#include "Trajectory.h"

namespace {

using linalg::Vector3f;

// A trajectory holding constant body-frame values from 0 to 10 s.
sim::Trajectory constant_trajectory(const double gyro_rad_s[3], const double accel_m_s2[3],
                                    const double mag_uT[3]) {
    sim::Trajectory trajectory;
    for (double t_s : {0.0, 10.0}) {
        sim::TrajectorySample s{};
        s.t_s = t_s;
        for (int i = 0; i < 3; ++i) {
            s.gyro_rad_s[i] = gyro_rad_s[i];
            s.accel_m_s2[i] = accel_m_s2[i];
            s.mag_uT[i] = mag_uT[i];
        }
        s.quat[0] = 1.0;
        s.movement = true;
        trajectory.samples().push_back(s);
    }
    return trajectory;
}

const double kGyro_rad_s[3] = {0.30, -0.70, 1.10};
const double kAccel_m_s2[3] = {1.5, -2.5, -9.0};
const double kMag_uT[3] = {18.0, -6.0, 42.0};

// Brings the MPU6000 up as the APM2 driver does (APM25.md): reset, wake, SPI only,
// 200 Hz, DLPF 42 Hz, ranges as given, data-ready interrupt latched.
void bring_up(sim::Mpu6000Model& mpu, uint8_t gyro_config, uint8_t accel_config) {
    mpu.write_register(mpu6000::REG_PWR_MGMT_1, mpu6000::kPwrDeviceReset);
    mpu.advance_to(mpu.time_s() + 0.1);
    mpu.write_register(mpu6000::REG_PWR_MGMT_1, mpu6000::kPwrClockPllGyroZ);
    mpu.write_register(mpu6000::REG_USER_CTRL, mpu6000::kUserCtrlI2cIfDis);
    mpu.write_register(mpu6000::REG_SMPLRT_DIV, 4);
    mpu.write_register(mpu6000::REG_CONFIG, (uint8_t)mpu6000::Dlpf::Hz42);
    mpu.write_register(mpu6000::REG_GYRO_CONFIG, gyro_config);
    mpu.write_register(mpu6000::REG_ACCEL_CONFIG, accel_config);
    mpu.write_register(mpu6000::REG_INT_PIN_CFG, 0x30);
    mpu.write_register(mpu6000::REG_INT_ENABLE, mpu6000::kIntEnableDataReady);
}

mpu6000::BurstStatus read_sample(sim::Mpu6000Model& mpu, uint8_t gyro_config, uint8_t accel_config,
                                 mpu6000::Sample& out) {
    uint8_t raw[mpu6000::kBurstLength];
    mpu.read_registers(mpu6000::REG_ACCEL_XOUT_H, raw, sizeof raw);
    return mpu6000::decode_burst(raw, (mpu6000::GyroRange)gyro_config, (mpu6000::AccelRange)accel_config, out);
}

TEST(Mpu6000Model, WhoAmIAnswers0x68AndTheFaultChangesIt) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    uint8_t who = 0;
    mpu.read_registers(mpu6000::REG_WHO_AM_I, &who, 1);
    EXPECT_EQ(who, mpu6000::kWhoAmIValue);
    mpu.faults().who_am_i = 0x70;
    mpu.read_registers(mpu6000::REG_WHO_AM_I, &who, 1);
    EXPECT_EQ(who, 0x70);
}

TEST(Mpu6000Model, AsleepAtPowerOnDataReadsZero) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    mpu.advance_to(0.5);
    EXPECT_TRUE(mpu.asleep());
    mpu6000::Sample sample{};
    EXPECT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::NoSensor);
    EXPECT_GT(mpu.counters().data_read_while_asleep, 0u);
}

TEST(Mpu6000Model, ResetRestoresRegistersAndIsDeafForAWhile) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    mpu.write_register(mpu6000::REG_PWR_MGMT_1, 0x03);
    mpu.write_register(mpu6000::REG_SMPLRT_DIV, 9);
    mpu.write_register(mpu6000::REG_PWR_MGMT_1, mpu6000::kPwrDeviceReset);
    uint8_t who = 0xAA;
    mpu.read_registers(mpu6000::REG_WHO_AM_I, &who, 1);
    EXPECT_EQ(who, 0x00);  // still resetting
    EXPECT_GT(mpu.counters().access_during_reset, 0u);
    mpu.advance_to(0.1);
    mpu.read_registers(mpu6000::REG_WHO_AM_I, &who, 1);
    EXPECT_EQ(who, 0x68);
    EXPECT_EQ(mpu.peek_register(mpu6000::REG_SMPLRT_DIV), 0);
    EXPECT_EQ(mpu.peek_register(mpu6000::REG_PWR_MGMT_1), 0x40);  // asleep again
}

// Every gyro and accel range: bytes decode back to the body-frame truth within one count.
TEST(Mpu6000Model, BurstDecodesToTheTrajectoryInEveryRange) {
    const uint8_t ranges[4] = {0x00, 0x08, 0x10, 0x18};
    for (uint8_t gyro_config : ranges) {
        for (uint8_t accel_config : ranges) {
            // 1.1 rad/s = 63 deg/s fits +-250 deg/s; 9 m/s^2 fits +-2 g.
            sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
            bring_up(mpu, gyro_config, accel_config);
            mpu.advance_to(0.5);
            mpu6000::Sample sample{};
            ASSERT_EQ(read_sample(mpu, gyro_config, accel_config, sample), mpu6000::BurstStatus::Ok);
            const float gyro_res = linalg::kRadPerDeg / mpu6000::gyro_lsb_per_dps((mpu6000::GyroRange)gyro_config);
            const float accel_res = mpu6000::kStandardGravity_m_s2 /
                                    mpu6000::accel_lsb_per_g((mpu6000::AccelRange)accel_config);
            const float gyro[3] = {sample.gyro_rad_s().x, sample.gyro_rad_s().y, sample.gyro_rad_s().z};
            const float accel[3] = {sample.accel_m_s2().x, sample.accel_m_s2().y, sample.accel_m_s2().z};
            for (int i = 0; i < 3; ++i) {
                EXPECT_NEAR(gyro[i], kGyro_rad_s[i], gyro_res) << "gyro axis " << i << " cfg " << (int)gyro_config;
                EXPECT_NEAR(accel[i], kAccel_m_s2[i], accel_res) << "accel axis " << i << " cfg " << (int)accel_config;
            }
            EXPECT_NEAR(sample.temperature_c(), 30.0f, 0.01f);
            EXPECT_FALSE(sample.gyro_saturated);
            EXPECT_FALSE(sample.accel_saturated);
        }
    }
}

TEST(Mpu6000Model, ARangeTooSmallSaturatesAtTheInt16Ends) {
    const double fast_rad_s[3] = {6.0, -6.0, 0.1};     // 344 deg/s: beyond +-250
    const double hard_m_s2[3] = {30.0, -30.0, -9.8};  // 3 g: beyond +-2 g
    sim::Mpu6000Model mpu(constant_trajectory(fast_rad_s, hard_m_s2, kMag_uT));
    bring_up(mpu, 0x00, 0x00);
    mpu.advance_to(0.5);
    uint8_t raw[mpu6000::kBurstLength];
    mpu.read_registers(mpu6000::REG_ACCEL_XOUT_H, raw, sizeof raw);
    // chip = (body y, body x, -body z)
    EXPECT_EQ(linalg::int16_from_be(raw[0], raw[1]), -32768);  // accel chip x = body y
    EXPECT_EQ(linalg::int16_from_be(raw[2], raw[3]), 32767);
    EXPECT_EQ(linalg::int16_from_be(raw[8], raw[9]), -32768);  // gyro chip x = body y
    EXPECT_EQ(linalg::int16_from_be(raw[10], raw[11]), 32767);
    mpu6000::Sample sample{};
    ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps250, mpu6000::AccelRange::G2, sample),
              mpu6000::BurstStatus::Ok);
    EXPECT_TRUE(sample.gyro_saturated);
    EXPECT_TRUE(sample.accel_saturated);
}

TEST(Mpu6000Model, AWrongRangeGivesWrongValues) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x00, 0x00);  // chip at +-250 deg/s, +-2 g
    mpu.advance_to(0.5);
    mpu6000::Sample sample{};
    ASSERT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::Ok);  // decoded as 2000 / 4 g
    EXPECT_NEAR(sample.gyro_rad_s().z, kGyro_rad_s[2] * 131.0 / 16.4, 0.01);
    EXPECT_NEAR(sample.accel_m_s2().z, kAccel_m_s2[2] * 2.0, 0.01);
}

TEST(Mpu6000Model, DataReadyAtTheConfiguredRateOnTheIntPin) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x18, 0x08);  // SMPLRT_DIV 4 -> 200 Hz, latched INT
    mpu.advance_to(0.2);
    const uint32_t before = mpu.counters().samples;
    mpu.advance_to(1.2);
    EXPECT_NEAR((double)(mpu.counters().samples - before), 200.0, 1.0);
    EXPECT_TRUE(mpu.int_pin_high());
    uint8_t status = 0;
    mpu.read_registers(mpu6000::REG_INT_STATUS, &status, 1);
    EXPECT_EQ(status & mpu6000::kIntStatusDataReady, mpu6000::kIntStatusDataReady);
    EXPECT_FALSE(mpu.int_pin_high());  // cleared by the read (latched mode)
    mpu.advance_to(mpu.next_event_s());
    EXPECT_TRUE(mpu.int_pin_high() || mpu.next_event_s() > mpu.time_s());
    mpu.advance_to(1.2 + 0.0051);
    EXPECT_TRUE(mpu.int_pin_high());
}

TEST(Mpu6000Model, UnlatchedIntIsA50usPulse) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x18, 0x08);
    mpu.write_register(mpu6000::REG_INT_PIN_CFG, 0x10);
    mpu.advance_to(0.3);
    double t_s = mpu.next_event_s();
    while (!mpu.int_pin_high()) {
        mpu.advance_to(t_s);
        t_s = mpu.next_event_s();
    }
    const double rise_s = mpu.time_s();
    mpu.advance_to(rise_s + 40e-6);
    EXPECT_TRUE(mpu.int_pin_high());
    mpu.advance_to(rise_s + 60e-6);
    EXPECT_FALSE(mpu.int_pin_high());
}

TEST(Mpu6000Model, LowerDlpfBandwidthIsSlower) {
    // A gyro step at t = 1 s; after 10 ms the 5 Hz filter has moved less than the 42 Hz one.
    auto step_response = [](uint8_t dlpf) {
        sim::Trajectory trajectory;
        for (double t_s : {0.0, 0.9999, 1.0, 5.0}) {
            sim::TrajectorySample s{};
            s.t_s = t_s;
            s.gyro_rad_s[2] = t_s >= 1.0 ? 1.0 : 0.0;
            s.accel_m_s2[2] = -9.8;
            trajectory.samples().push_back(s);
        }
        sim::Mpu6000Model mpu(trajectory);
        bring_up(mpu, 0x18, 0x08);
        mpu.write_register(mpu6000::REG_CONFIG, dlpf);
        mpu.advance_to(1.010);
        mpu6000::Sample sample{};
        read_sample(mpu, 0x18, 0x08, sample);
        return sample.gyro_rad_s().z;
    };
    const float slow = step_response((uint8_t)mpu6000::Dlpf::Hz5);
    const float fast = step_response((uint8_t)mpu6000::Dlpf::Hz42);
    EXPECT_GT(fast, 0.8f);
    EXPECT_LT(slow, 0.4f);
    EXPECT_GT(slow, 0.05f);
}

TEST(Mpu6000Model, FaultsAbsentSaturateSpike) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    mpu.faults().absent = sim::TimeWindow::between(1.0, 2.0);
    mpu.faults().gyro_saturate = sim::TimeWindow::between(3.0, 4.0);
    mpu.faults().spike = sim::TimeWindow::between(5.0, 6.0);
    bring_up(mpu, 0x18, 0x08);
    mpu6000::Sample sample{};
    mpu.advance_to(1.5);
    EXPECT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::NoSensor);
    EXPECT_FALSE(mpu.int_pin_high());
    mpu.advance_to(2.5);
    EXPECT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::Ok);
    EXPECT_FALSE(sample.gyro_saturated);
    mpu.advance_to(3.5);
    EXPECT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::Ok);
    EXPECT_TRUE(sample.gyro_saturated);
    EXPECT_FALSE(sample.accel_saturated);
    mpu.advance_to(5.5);
    EXPECT_EQ(read_sample(mpu, 0x18, 0x08, sample), mpu6000::BurstStatus::Ok);
    EXPECT_GT(sample.gyro_rad_s().length(), 20.0f);   // > 1000 deg/s
    EXPECT_GT(sample.accel_m_s2().length(), 50.0f);   // > 5 g
}

// --- HMC5883L ------------------------------------------------------------------

void start_continuous(sim::Hmc5883Model& mag, uint8_t gain) {
    ASSERT_TRUE(mag.write_register(hmc5883::REG_CONFIG_A, hmc5883::kConfigA_Avg8_75Hz));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_CONFIG_B, gain));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_MODE, hmc5883::kModeContinuous));
}

TEST(Hmc5883Model, IdReadsH43) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    uint8_t id[3] = {0, 0, 0};
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_ID_A, id, 3));
    EXPECT_TRUE(hmc5883::id_matches(id));
    uint8_t after_wrap[2];
    ASSERT_TRUE(mag.read_registers(12, after_wrap, 2));  // 12 then wraps to 0 (Config A)
    EXPECT_EQ(after_wrap[0], '3');
    EXPECT_EQ(after_wrap[1], 0x10);
}

TEST(Hmc5883Model, DataDecodesToTheTrajectoryAtEveryGain) {
    const uint8_t gains[] = {0x20, 0x40, 0x60, 0x80, 0xA0, 0xC0, 0xE0};
    for (uint8_t gain : gains) {
        sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
        start_continuous(mag, gain);
        mag.advance_to(0.1);
        uint8_t raw[hmc5883::kDataLength];
        ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
        Vector3f field_uT;
        ASSERT_EQ(hmc5883::decode_data(raw, (hmc5883::Gain)gain, field_uT), hmc5883::DataStatus::Ok);
        const float res_uT = 100.0f / hmc5883::lsb_per_gauss((hmc5883::Gain)gain);
        EXPECT_NEAR(field_uT.x, kMag_uT[0], res_uT) << "gain " << (int)gain;
        EXPECT_NEAR(field_uT.y, kMag_uT[1], res_uT) << "gain " << (int)gain;
        EXPECT_NEAR(field_uT.z, kMag_uT[2], res_uT) << "gain " << (int)gain;
    }
}

TEST(Hmc5883Model, FieldBeyondTheGainReadsMinus4096) {
    // 1.6 Ga on z: 2192 counts at 1370 LSB/Ga, beyond the 12-bit ADC's 2047.
    const double strong_uT[3] = {10.0, 10.0, 160.0};
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, strong_uT));
    start_continuous(mag, 0x00);
    mag.advance_to(0.1);
    uint8_t raw[hmc5883::kDataLength];
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    const hmc5883::Counts counts = hmc5883::counts_from_data(raw);
    EXPECT_EQ(counts.z, hmc5883::kOverflow);
    EXPECT_NE(counts.x, hmc5883::kOverflow);
    Vector3f field_uT;
    EXPECT_EQ(hmc5883::decode_data(raw, hmc5883::Gain::Ga0_88, field_uT), hmc5883::DataStatus::Overflow);
}

TEST(Hmc5883Model, DrdyRisesAbout6msAfterAModeWriteAndFallsOnRead) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    mag.advance_to(1.0);
    EXPECT_FALSE(mag.drdy_pin_high());
    start_continuous(mag, 0x20);
    mag.advance_to(1.005);
    EXPECT_FALSE(mag.drdy_pin_high());
    mag.advance_to(1.0065);
    EXPECT_TRUE(mag.drdy_pin_high());
    uint8_t status = 0;
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_STATUS, &status, 1));
    EXPECT_EQ(status & hmc5883::kStatusReady, hmc5883::kStatusReady);
    uint8_t raw[hmc5883::kDataLength];
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    EXPECT_FALSE(mag.drdy_pin_high());
    // Then 75 Hz on the grid anchored at t = 0 (k / 75 s), at least half a period on:
    // 76/75 = 1.01333 s, then 77/75 = 1.02667 s.
    mag.advance_to(1.0130);
    EXPECT_FALSE(mag.drdy_pin_high());
    mag.advance_to(1.0134);
    EXPECT_TRUE(mag.drdy_pin_high());
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    mag.advance_to(1.0265);
    EXPECT_FALSE(mag.drdy_pin_high());
    mag.advance_to(1.0267);
    EXPECT_TRUE(mag.drdy_pin_high());
}

TEST(Hmc5883Model, SingleModeMeasuresOnceThenIdles) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_MODE, hmc5883::kModeSingle));
    mag.advance_to(0.5);
    EXPECT_EQ(mag.counters().samples, 1u);
    EXPECT_EQ(mag.peek_register(hmc5883::REG_MODE) & 0x03, 0x03);
}

TEST(Hmc5883Model, PointerReturnsTo3AfterRegister8) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    start_continuous(mag, 0x20);
    mag.advance_to(0.1);
    uint8_t twelve[12];
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, twelve, sizeof twelve));
    for (int i = 0; i < 6; ++i) EXPECT_EQ(twelve[i], twelve[i + 6]) << i;
}

TEST(Hmc5883Model, PositiveBiasReadsTheSelfTestFieldAlone) {
    // The external field does not show: the chip subtracts it (datasheet).
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_CONFIG_A, 0x70 | hmc5883::kConfigA_PositiveBias));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_CONFIG_B, (uint8_t)hmc5883::kSelfTestGain));
    ASSERT_TRUE(mag.write_register(hmc5883::REG_MODE, hmc5883::kModeSingle));
    mag.advance_to(0.1);
    uint8_t raw[hmc5883::kDataLength];
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    const hmc5883::Counts counts = hmc5883::counts_from_data(raw);
    EXPECT_NEAR(counts.x, 1.16 * 660, 1);
    EXPECT_NEAR(counts.y, 1.16 * 660, 1);
    EXPECT_NEAR(counts.z, 1.08 * 660, 1);
    // A perfect chip's self-test gives unit scale on every axis.
    hmc5883::SelfTest self_test;
    for (int i = 0; i < 5; ++i) EXPECT_TRUE(self_test.add_sample(counts));
    ASSERT_TRUE(self_test.done());
    EXPECT_NEAR(self_test.scale().x, 1.0f, 0.002f);
    EXPECT_NEAR(self_test.scale().y, 1.0f, 0.002f);
    EXPECT_NEAR(self_test.scale().z, 1.0f, 0.002f);
}

TEST(Hmc5883Model, FaultsAbsentOverflowDrdyStuck) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    mag.faults().absent = sim::TimeWindow::between(1.0, 2.0);
    mag.faults().overflow = sim::TimeWindow::between(3.0, 4.0);
    mag.faults().drdy_stuck_low = sim::TimeWindow::between(5.0, 6.0);
    start_continuous(mag, 0x20);
    uint8_t raw[hmc5883::kDataLength];
    Vector3f field_uT;
    mag.advance_to(1.5);
    EXPECT_FALSE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    EXPECT_GT(mag.counters().nacked_while_absent, 0u);
    mag.advance_to(2.5);
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    EXPECT_EQ(hmc5883::decode_data(raw, hmc5883::Gain::Ga1_3, field_uT), hmc5883::DataStatus::Ok);
    mag.advance_to(3.5);
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, raw, sizeof raw));
    EXPECT_EQ(hmc5883::decode_data(raw, hmc5883::Gain::Ga1_3, field_uT), hmc5883::DataStatus::Overflow);
    mag.advance_to(5.5);
    EXPECT_FALSE(mag.drdy_pin_high());
    mag.advance_to(6.5);
    EXPECT_TRUE(mag.drdy_pin_high());
}

TEST(Hmc5883Model, DataLockDropsSamplesUntilAllSixAreRead) {
    sim::Hmc5883Model mag(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    start_continuous(mag, 0x20);
    mag.advance_to(0.1);
    uint8_t two[2];
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_DATA_X_MSB, two, 2));
    uint8_t status = 0;
    ASSERT_TRUE(mag.read_registers(hmc5883::REG_STATUS, &status, 1));
    EXPECT_EQ(status & 0x02, 0x02);  // LOCK
    const uint32_t samples = mag.counters().samples;
    mag.advance_to(0.2);
    EXPECT_EQ(mag.counters().samples, samples);
    EXPECT_GT(mag.counters().samples_dropped_by_lock, 0u);
}

}  // namespace

// FIFO (Register Map 4.6, 4.29-4.31): with FIFO_EN = accel, temp and gyro, each output
// sample is queued as the 14 bytes of the burst, in the same order; the count says how
// many bytes wait, reads of FIFO_R_W pop them (a burst stays on FIFO_R_W), FIFO_RESET
// empties it, and a full FIFO drops its oldest bytes and flags FIFO_OFLOW.
namespace {
uint16_t fifo_count(sim::Mpu6000Model& mpu) {
    uint8_t c[2];
    mpu.read_registers(mpu6000::REG_FIFO_COUNTH, c, 2);
    return (uint16_t)((c[0] << 8) | c[1]);
}
void start_fifo(sim::Mpu6000Model& mpu) {
    mpu.write_register(mpu6000::REG_FIFO_EN, mpu6000::kFifoEnBurstSample);
    mpu.write_register(mpu6000::REG_USER_CTRL, mpu6000::kUserCtrlI2cIfDis | mpu6000::kUserCtrlFifoEn |
                                                   mpu6000::kUserCtrlFifoReset);
}
}  // namespace

TEST(Mpu6000Model, FifoIsOffUntilEnabled) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x18, 0x08);
    mpu.advance_to(0.5);
    EXPECT_EQ(fifo_count(mpu), 0u);
}

TEST(Mpu6000Model, FifoQueuesEachSampleAsTheBurst) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x18, 0x08);
    mpu.advance_to(0.3);
    start_fifo(mpu);
    EXPECT_EQ(mpu.peek_register(mpu6000::REG_USER_CTRL) & mpu6000::kUserCtrlFifoReset, 0);  // self-clearing
    const uint32_t before = mpu.counters().samples;
    mpu.advance_to(0.3 + 3 * 0.005 + 0.001);
    const uint32_t queued = mpu.counters().samples - before;
    ASSERT_EQ(queued, 3u);
    EXPECT_EQ(fifo_count(mpu), 3u * mpu6000::kBurstLength);
    uint8_t latest[mpu6000::kBurstLength];
    mpu.read_registers(mpu6000::REG_ACCEL_XOUT_H, latest, sizeof latest);
    uint8_t popped[mpu6000::kBurstLength] = {};
    for (int i = 0; i < 3; ++i) mpu.read_registers(mpu6000::REG_FIFO_R_W, popped, sizeof popped);
    // A constant trajectory: every queued sample equals the registers' (the last one is them).
    for (int i = 0; i < mpu6000::kBurstLength; ++i) EXPECT_EQ(popped[i], latest[i]) << "byte " << i;
    EXPECT_EQ(fifo_count(mpu), 0u);
    EXPECT_EQ(mpu.counters().fifo_underruns, 0u);
    mpu.read_registers(mpu6000::REG_FIFO_R_W, popped, 1);
    EXPECT_EQ(mpu.counters().fifo_underruns, 1u);
}

TEST(Mpu6000Model, FifoKeepsTheOrderOfChangingSamples) {
    // A rate ramp: each queued sample differs, and they come out oldest first.
    sim::Trajectory t;
    for (int k = 0; k <= 10; ++k) {
        sim::TrajectorySample s{};
        s.t_s = k;
        s.gyro_rad_s[0] = 0.2 * k;
        s.accel_m_s2[2] = -9.81;
        s.mag_uT[0] = 20;
        s.quat[0] = 1;
        s.movement = true;
        t.samples().push_back(s);
    }
    sim::Mpu6000Model mpu(t);
    bring_up(mpu, 0x18, 0x08);
    mpu.advance_to(1.0);
    start_fifo(mpu);
    mpu.advance_to(1.0 + 10 * 0.005 + 0.001);
    mpu6000::Sample prev{}, s{};
    uint8_t raw[mpu6000::kBurstLength];
    for (int i = 0; i < 10; ++i) {
        mpu.read_registers(mpu6000::REG_FIFO_R_W, raw, sizeof raw);
        ASSERT_EQ(mpu6000::decode_burst(raw, mpu6000::GyroRange::Dps2000, mpu6000::AccelRange::G4, s),
                  mpu6000::BurstStatus::Ok);
        if (i > 0) {
            EXPECT_GT(s.gyro_rad_s().x, prev.gyro_rad_s().x) << i;
        }
        prev = s;
    }
}

TEST(Mpu6000Model, FifoResetEmptiesAndOverflowDropsTheOldest) {
    sim::Mpu6000Model mpu(constant_trajectory(kGyro_rad_s, kAccel_m_s2, kMag_uT));
    bring_up(mpu, 0x18, 0x08);
    mpu.advance_to(0.3);
    start_fifo(mpu);
    mpu.advance_to(0.35);
    EXPECT_GT(fifo_count(mpu), 0u);
    mpu.write_register(mpu6000::REG_USER_CTRL, mpu6000::kUserCtrlI2cIfDis | mpu6000::kUserCtrlFifoEn |
                                                   mpu6000::kUserCtrlFifoReset);
    EXPECT_EQ(fifo_count(mpu), 0u);
    mpu.advance_to(0.35 + 0.5);  // 100 samples of 14 bytes: more than 1024
    EXPECT_EQ(fifo_count(mpu), mpu6000::kFifoSize);
    EXPECT_GT(mpu.counters().fifo_overflows, 0u);
    uint8_t status = 0;
    mpu.read_registers(mpu6000::REG_INT_STATUS, &status, 1);
    EXPECT_EQ(status & mpu6000::kIntStatusFifoOverflow, mpu6000::kIntStatusFifoOverflow);
}
