// SPDX-License-Identifier: GPL-3.0-or-later
// The MS5611 barometer's sequencer: a state machine that moves the chip through reset,
// PROM, and conversions, one short bus transaction group per call, never waiting. The
// caller (the firmware's loop task, a host test's fake bus, the simulator's model) calls
// service() whenever due() says so; nothing here reads a clock or blocks.
//
//   reset 0x1E ... >= 3 ms (datasheet: 2.8 ms reload) ... PROM 0xA0..0xAE, checked
//   (Ms5611Math.h: blank or bad CRC-4: no barometer) ... then, in rotation,
//   D2 (0x58), D1 (0x48) x 4: each conversion started in one call and read (ADC 0x00)
//   in a later one >= kConversionUs after it (OSR 4096: 9.04 ms max), the next one
//   started at once. One D2 for every four D1: the temperature changes slowly, the
//   pressure carries the height (ArduPilot's AP_Baro_MS5611 on APM2 did the same).
//
// What goes wrong, and what is done:
//   - an ADC result of 0: the conversion was missed (read early, or spoiled): counted,
//     the conversion started again; kLostAfter in a row: the chip is lost (Event::Lost),
//     and a reset and PROM read are tried every kRetryUs until it answers (Event::Back);
//   - a temperature outside the chip's -40..85 degC or a pressure outside its
//     10..1200 mbar: rejected and counted;
//   - a pressure further than kSpikePa from the last one taken (a jump no aircraft
//     makes in 10 ms: 5 hPa is ~40 m): rejected and counted; kSpikeRun such in a row
//     and the new level is believed (the chip is right and the air did change);
//   - kStuckReadings identical D1 codes in a row: stuck (Event::Stuck) until a D1
//     differs (Event::Unstuck); the chip's own noise (~50 codes at OSR 4096) makes a
//     repeat by chance rare, and a long run of them impossible.
// The accepted pressures are summed for the caller, who averages them at its own rate
// (take_average()).
#pragma once

#include <stdint.h>

#include "Ms5611Math.h"

namespace ms5611 {

// Commands (datasheet "Commands").
constexpr uint8_t kCmdReset = 0x1E;
constexpr uint8_t kCmdAdcRead = 0x00;
constexpr uint8_t kCmdConvertD1Osr4096 = 0x48;
constexpr uint8_t kCmdConvertD2Osr4096 = 0x58;
constexpr uint8_t kCmdPromRead = 0xA0;  // + 2 * word

constexpr uint16_t kResetUs = 3000;       // datasheet: 2.8 ms reload after reset
constexpr uint16_t kConversionUs = 9100;  // OSR 4096: 9.04 ms at most, + a clock tick's margin
constexpr uint8_t kD1PerD2 = 4;
constexpr uint8_t kLostAfter = 10;        // missed conversions in a row (~0.1 s)
constexpr uint32_t kRetryUs = 1000000;    // a lost or absent chip tried again once a second
constexpr int32_t kMinPressurePa = 1000;  // the chip's range, 10..1200 mbar
constexpr int32_t kMaxPressurePa = 120000;
constexpr int32_t kMinTempC100 = -4000;   // ... and -40..85 degC
constexpr int32_t kMaxTempC100 = 8500;
constexpr int32_t kSpikePa = 500;
constexpr uint8_t kSpikeRun = 25;         // ~0.3 s of readings
constexpr uint8_t kStuckReadings = 50;    // ~0.6 s of identical D1

// The bus seam: one transaction, chip select low, `cmd` sent, `len` bytes clocked in
// (0x00 sent), chip select high.
struct SpiDevice {
    void* ctx;
    void (*transaction)(void* ctx, uint8_t cmd, uint8_t* in, uint8_t len);
};

enum class Event : uint8_t {
    None,
    Found,     // PROM good: converting
    Blank,     // PROM all 0 or all 1: nobody answers (said once; retried)
    BadCrc,    // PROM's CRC-4 wrong (said once; retried)
    Lost,      // kLostAfter conversions missed in a row (retried)
    Back,      // found again after Lost, Blank or BadCrc
    Stuck,     // kStuckReadings identical D1
    Unstuck,   // a D1 differs again
    Rejected,  // the first of a run of rejected readings (absurd or a spike)
    Pressure,  // a pressure was accepted
};

class Sequencer {
public:
    // constexpr: a static sequencer needs no start-up code.
    explicit constexpr Sequencer(const SpiDevice& spi) : spi_(spi) {}

    // True when service() has work at now_us (a conversion ended, the reset's wait is
    // over, a retry is due); call service() then, and only then has the bus been used.
    bool due(uint32_t now_us) const;
    // One step: at most the PROM's 8 reads, or an ADC read and the next conversion's start.
    Event service(uint32_t now_us);

    bool converting() const { return state_ == State::Converting; }
    bool stuck() const { return stuck_; }
    bool have_temperature() const { return have_terms_; }
    int32_t temperature_c100() const { return terms_.temp_c100; }
    int32_t last_pressure_pa() const { return last_pa_; }  // the last accepted
    // The mean of the pressures accepted since the last call (Pa); false when none.
    bool take_average(float& mean_pa);

    uint16_t missed() const { return missed_; }      // conversions read as 0
    uint16_t rejected() const { return rejected_; }  // absurd readings and spikes
    uint32_t conversions() const { return conversions_; }  // read and non-zero
    const uint16_t* prom() const { return prom_; }

private:
    enum class State : uint8_t { Start, WaitReset, Converting, WaitRetry };
    void start_conversion(uint32_t now_us);
    Event read_prom(uint32_t now_us);
    Event take_d2(uint32_t d2);
    Event take_d1(uint32_t d1);
    Event reject();

    SpiDevice spi_;
    uint16_t prom_[kPromWords] = {};
    Terms terms_ = {0, 0, 0};
    int32_t last_pa_ = 0;
    int32_t sum_pa_ = 0;      // accepted since take_average(): <= ~20 readings of < 2^17
    uint32_t last_d1_ = 0;
    uint32_t since_us_ = 0;   // the state's start: conversion, reset or retry wait
    uint32_t conversions_ = 0;
    uint16_t missed_ = 0, rejected_ = 0;
    uint8_t count_ = 0;       // accepted readings in sum_pa_
    uint8_t phase_ = 0;       // 0: D2 converting, 1..kD1PerD2: D1
    uint8_t missed_run_ = 0, spike_run_ = 0, same_d1_ = 0;
    State state_ = State::Start;
    bool have_terms_ = false, have_pa_ = false, stuck_ = false;
    bool failed_ = false;     // said Blank, BadCrc or Lost: the next Found is Back
};

}  // namespace ms5611
