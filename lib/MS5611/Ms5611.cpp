// SPDX-License-Identifier: GPL-3.0-or-later
#include "Ms5611.h"

#include "Profile.h"

namespace ms5611 {

bool Sequencer::due(uint32_t now_us) const {
    const uint32_t since = now_us - since_us_;
    switch (state_) {
        case State::Start: return true;
        case State::WaitReset: return since >= kResetUs;
        case State::Converting: return since >= kConversionUs;
        case State::WaitRetry: return since >= kRetryUs;
    }
    return false;
}

void Sequencer::start_conversion(uint32_t now_us) {
    spi_.transaction(spi_.ctx, phase_ == 0 ? kCmdConvertD2Osr4096 : kCmdConvertD1Osr4096, nullptr, 0);
    since_us_ = now_us;
    state_ = State::Converting;
}

Event Sequencer::read_prom(uint32_t now_us) {
    for (uint8_t w = 0; w < kPromWords; ++w) {
        uint8_t b[2];
        spi_.transaction(spi_.ctx, (uint8_t)(kCmdPromRead + 2u * w), b, 2);
        prom_[w] = (uint16_t)((uint16_t)b[0] << 8 | b[1]);
    }
    const PromStatus st = check_prom(prom_);
    if (st != PromStatus::Ok) {
        since_us_ = now_us;
        state_ = State::WaitRetry;
        if (failed_) return Event::None;  // said already
        failed_ = true;
        return st == PromStatus::Blank ? Event::Blank : Event::BadCrc;
    }
    // A new start: the temperature first, the stuck and spike tests afresh.
    phase_ = 0;
    missed_run_ = spike_run_ = same_d1_ = 0;
    have_terms_ = have_pa_ = stuck_ = false;
    start_conversion(now_us);
    const bool back = failed_;
    failed_ = false;
    return back ? Event::Back : Event::Found;
}

Event Sequencer::service(uint32_t now_us) {
    switch (state_) {
        case State::Start:
        case State::WaitRetry:
            spi_.transaction(spi_.ctx, kCmdReset, nullptr, 0);
            since_us_ = now_us;
            state_ = State::WaitReset;
            return Event::None;
        case State::WaitReset: return read_prom(now_us);
        case State::Converting: break;
    }
    uint8_t b[3];
    spi_.transaction(spi_.ctx, kCmdAdcRead, b, 3);
    const uint32_t code = (uint32_t)b[0] << 16 | (uint32_t)b[1] << 8 | b[2];
    if (code == 0) {
        // Read before the end, or a conversion spoiled: 0 (datasheet "ADC read"). The
        // same conversion again, and after kLostAfter of them the chip is gone.
        ++missed_;
        if (++missed_run_ >= kLostAfter) {
            since_us_ = now_us;
            state_ = State::WaitRetry;
            failed_ = true;
            return Event::Lost;
        }
        start_conversion(now_us);
        return Event::None;
    }
    missed_run_ = 0;
    ++conversions_;
    const uint8_t was = phase_;
    phase_ = (uint8_t)(phase_ == kD1PerD2 ? 0 : phase_ + 1u);
    start_conversion(now_us);
    return was == 0 ? take_d2(code) : take_d1(code);
}

Event Sequencer::reject() {
    ++rejected_;
    return spike_run_++ == 0 ? Event::Rejected : Event::None;
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) Event Sequencer::take_d2(uint32_t d2) {
    profile::begin(profile::kBaroCompensation);
    const Terms t = terms(prom_, d2);
    profile::end(profile::kBaroCompensation);
    if (t.temp_c100 < kMinTempC100 || t.temp_c100 > kMaxTempC100) return reject();
    terms_ = t;
    have_terms_ = true;
    return Event::None;
}

Event Sequencer::take_d1(uint32_t d1) {
    // Stuck: the same code again and again.
    Event said = Event::None;
    if (d1 == last_d1_) {
        if (same_d1_ < 255u) ++same_d1_;
        if (same_d1_ >= kStuckReadings && !stuck_) {
            stuck_ = true;
            said = Event::Stuck;
        }
    } else {
        same_d1_ = 0;
        if (stuck_) said = Event::Unstuck;
        stuck_ = false;
    }
    last_d1_ = d1;
    if (!have_terms_) return said;
    profile::begin(profile::kBaroCompensation);
    const int32_t p = pressure_pa(terms_, d1);
    profile::end(profile::kBaroCompensation);
    const bool absurd = p < kMinPressurePa || p > kMaxPressurePa;
    const bool jump = have_pa_ && (p > last_pa_ + kSpikePa || p < last_pa_ - kSpikePa);
    if (absurd || (jump && spike_run_ < kSpikeRun)) {
        const Event e = reject();
        return said != Event::None ? said : e;
    }
    spike_run_ = 0;
    last_pa_ = p;
    have_pa_ = true;
    if (count_ == 255u) {  // nobody took the average for long: keep its mean as one reading
        sum_pa_ /= count_;
        count_ = 1;
    }
    sum_pa_ += p;
    ++count_;
    return said != Event::None ? said : Event::Pressure;
}

bool Sequencer::take_average(float& mean_pa) {
    if (count_ == 0) return false;
    mean_pa = (float)sum_pa_ / (float)count_;
    sum_pa_ = 0;
    count_ = 0;
    return true;
}

}  // namespace ms5611
