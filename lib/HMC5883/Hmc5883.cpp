// SPDX-License-Identifier: GPL-3.0-or-later
#include "Hmc5883.h"

#ifdef __AVR__
#include <avr/pgmspace.h>
#define HMC5883_PROGMEM PROGMEM
#else
#define HMC5883_PROGMEM
#endif

namespace hmc5883 {

using linalg::Vector3f;

namespace {
float absf(float v) { return v < 0.0f ? -v : v; }

// The register writes of begin() and the bits they are checked on, in flash on the AVR
// (a const table is copied to SRAM).
struct Write {
    uint8_t reg, value, mask;
};
const Write kConfig[] HMC5883_PROGMEM = {
    {REG_CONFIG_A, kConfigA, 0x7F},  // bit 7 is reserved
    {REG_CONFIG_B, (uint8_t)kGain, 0xE0},
    {REG_MODE, kModeContinuous, 0x03},
};
Write config(uint8_t i) {
#ifdef __AVR__
    return Write{pgm_read_byte(&kConfig[i].reg), pgm_read_byte(&kConfig[i].value), pgm_read_byte(&kConfig[i].mask)};
#else
    return kConfig[i];
#endif
}
constexpr uint8_t kConfigWrites = sizeof kConfig / sizeof kConfig[0];
}  // namespace

bool Hmc5883::ready_by_status(bool& ready) {
    uint8_t st = 0;
    if (!read_regs(REG_STATUS, &st, 1)) return false;
    ready = (st & kStatusReady) != 0;
    return true;
}

// One single-mode measurement with the given Config A; false on a bus error or when
// the chip never said ready.
bool Hmc5883::single_measurement(uint8_t config_a, Counts& out) {
    if (!write(REG_CONFIG_A, config_a) || !write(REG_MODE, kModeSingle)) return false;
    bus_.delay_ms(bus_.ctx, kSingleWaitMs);
    bool ready = false;
    for (uint8_t waited = kSingleWaitMs; !ready; ++waited) {
        if (!ready_by_status(ready)) return false;
        if (ready) break;
        if (waited >= kReadyTimeoutMs) return false;
        bus_.delay_ms(bus_.ctx, 1);
    }
    uint8_t raw[kDataLength];
    if (!read_regs(REG_DATA_X_MSB, raw, kDataLength)) return false;
    out = counts_from_data(raw);
    return true;
}

void Hmc5883::run_self_test() {
    SelfTest st;
    Counts biased;
    // The first measurement after a gain change is still at the old gain: drop it.
    if (write(REG_CONFIG_B, (uint8_t)kSelfTestGain)) single_measurement(kSelfTestConfigA, biased);
    while (!st.done() && !st.failed()) {
        // The chip subtracts the external field itself: the reading is the bias field.
        // A bus error or a missing ready counts as a bad try (add_sample counts tries).
        if (!single_measurement((uint8_t)(kSelfTestConfigA | kConfigA_PositiveBias), biased)) biased = Counts{0, 0, 0};
        st.add_sample(biased);
    }
    self_test_good_ = st.good_samples();
    self_test_passed_ = st.done();
    scale_chip_ = st.scale();  // 1.0 per axis unless done
}

InitResult Hmc5883::begin(bool run_self_test_now) {
    InitResult r{InitStatus::Ok, {0, 0, 0}, 0, 0, 0};
    if (!read_regs(REG_ID_A, r.id, kIdLength)) {
        r.status = InitStatus::NoAnswer;
        return r;
    }
    if (!id_matches(r.id)) {
        r.status = InitStatus::WrongIdentity;
        return r;
    }
    if (run_self_test_now) run_self_test();
    // The chip axes' scale seen in body axes (the mapping is a signed permutation).
    const Vector3f b = chip_to_body(scale_chip_);
    scale_body_ = Vector3f(absf(b.x), absf(b.y), absf(b.z));

    for (uint8_t i = 0; i < kConfigWrites; ++i) {
        const Write w = config(i);
        if (!write(w.reg, w.value)) {
            r.status = InitStatus::NoAnswer;
            return r;
        }
    }
    for (uint8_t i = 0; i < kConfigWrites; ++i) {
        const Write w = config(i);
        uint8_t got = 0;
        if (!read_regs(w.reg, &got, 1)) {
            r.status = InitStatus::NoAnswer;
            return r;
        }
        if ((got & w.mask) != w.value) {
            r.status = InitStatus::ReadbackMismatch;
            r.reg = w.reg;
            r.wrote = w.value;
            r.read = got;
            return r;
        }
    }
    discard_next_ = true;
    return r;
}

ReadStatus Hmc5883::read(Vector3f& field_uT) {
    uint8_t raw[kDataLength];
    if (!read_regs(REG_DATA_X_MSB, raw, kDataLength)) return ReadStatus::BusError;
    Vector3f f;
    const DataStatus s = decode_data(raw, kGain, f);
    if (s == DataStatus::NoSensor) return ReadStatus::NoSensor;
    if (discard_next_) {
        discard_next_ = false;
        return ReadStatus::Skipped;
    }
    if (s == DataStatus::Overflow) return ReadStatus::Overflow;
    field_uT = Vector3f(f.x * scale_body_.x, f.y * scale_body_.y, f.z * scale_body_.z);
    return ReadStatus::Ok;
}

}  // namespace hmc5883
