// SPDX-License-Identifier: GPL-3.0-or-later
#include "Imu.h"

#include "Board.h"

using text::Writer;

namespace {
// The pin is overdue this long after a sample (the period is 5 ms): ask INT_STATUS once.
// If a sample is there, the pin is silent: from then on the FIFO holds every sample,
// and its count (read without side effects) is polled from kFifoPollAfterUs on.
constexpr uint16_t kPinOverdueUs = 7000;
constexpr uint16_t kFifoPollAfterUs = 4000;
constexpr uint16_t kTimerFallbackUs = 12000;  // nothing delivers: pace on the timer
constexpr uint16_t kFifoFullSamples = 70;     // of 73: about to drop the oldest, start over
constexpr uint16_t kWarnMs = 2000;            // rate limit of the missed-sample warning
}  // namespace

bool Imu::start(uint32_t now_ms) {
    const mpu6000::InitResult r = chip_.begin();
    if (r.status == mpu6000::InitStatus::Ok) {
        have_sample_time_ = false;
        int_pin_ok_ = true;  // the reset turned the FIFO off
        if (health_.working()) Writer(out_).str(TXT("# recovered: " TXT_MPU)).end();
        return true;
    }
    if (health_.failed(now_ms)) {
        Writer w(out_);
        if (r.status == mpu6000::InitStatus::WrongIdentity)
            w.str(TXT(TXT_ERROR TXT_MPU " not found (WHO_AM_I=0x")).hex8(r.read).str(TXT(", expected 0x68)")).end();
        else
            w.str(TXT(TXT_ERROR TXT_MPU " did not keep its configuration: reg 0x")).hex8(r.reg)
                .str(TXT(" wrote 0x")).hex8(r.wrote).str(TXT(" read 0x")).hex8(r.read).end();
    }
    return false;
}

bool Imu::retry(uint32_t now_ms) {
    if (!health_.retry_due(now_ms)) return false;
    Writer(out_).str(TXT("# no attitude: " TXT_MPU " absent, retrying every 1 s")).end();
    uint8_t who = 0;
    return chip_.probe(who) && start(now_ms);
}

bool Imu::sample_ready(uint32_t now_us) {
    if (!health_.ok()) return false;
    const uint32_t since = now_us - last_sample_us_;
    from_fifo_ = false;
    bool ready = board::mpu_int_high();
    if (ready) {
        if (!int_pin_ok_) chip_.stop_fifo();  // the pin works again
        int_pin_ok_ = true;
        pacing_warned_ = false;
    } else if (!int_pin_ok_) {
        if (since >= kFifoPollAfterUs || timer_pacing_) {
            const uint16_t queued = chip_.fifo_samples();
            if (queued >= kFifoFullSamples) {
                chip_.start_fifo();  // empties it: those samples are lost, and counted
                missed_ += queued;
            } else {
                ready = from_fifo_ = queued > 0;
            }
        }
    } else if (since >= kPinOverdueUs || !have_sample_time_) {
        ready = chip_.data_ready();  // this sample is read from the registers
        if (ready && have_sample_time_) {
            int_pin_ok_ = false;
            chip_.start_fifo();
            Writer(out_).str(TXT(TXT_WARN TXT_MPU " INT pin silent: reading its FIFO")).end();
        }
    }
    if (ready) {
        timer_pacing_ = false;
    } else if (have_sample_time_ && since >= (timer_pacing_ ? kPeriodUs : kTimerFallbackUs)) {
        if (!timer_pacing_) {
            if (!pacing_warned_)
                Writer(out_).str(TXT(TXT_WARN TXT_MPU " data-ready not seen: pacing on the timer")).end();
            pacing_warned_ = true;      // once until the INT pin works again
            have_sample_time_ = false;  // this gap is not a missed sample
        }
        timer_pacing_ = true;
        ready = true;
    }
    return ready;
}

bool Imu::read(mpu6000::Sample& out, uint32_t now_us, uint32_t now_ms) {
    // A sample from the FIFO was queued when it was taken: a late read loses nothing.
    if (have_sample_time_ && !from_fifo_) {
        const uint32_t gap = now_us - last_sample_us_;
        if (gap > kPeriodUs + kPeriodUs / 2u) {
            const uint16_t missed = (uint16_t)((gap + kPeriodUs / 2u) / kPeriodUs - 1u);
            missed_ += missed;
            if (warn_missed_.allow(now_ms, kWarnMs)) {
                Writer(out_).str(TXT(TXT_WARN "loop overrun: ")).u32(missed).str(TXT(" sample(s) missed, "))
                    .u32(missed_).str(TXT(" in all")).end();
            }
        }
    }
    // Overruns the rate limit held back, told once its time is over.
    const uint16_t held = warn_missed_.deferred(now_ms, kWarnMs);
    if (held != 0)
        Writer(out_).str(TXT(TXT_WARN "loop overrun: ")).u32(held).str(TXT(" more time(s), "))
            .u32(missed_).str(TXT(" sample(s) missed in all")).end();
    last_sample_us_ = now_us;
    have_sample_time_ = true;

    board::mark_begin(board::kSecMpuRead);
    const mpu6000::BurstStatus st = from_fifo_ ? chip_.read_fifo(out) : chip_.read(out);
    board::mark_end(board::kSecMpuRead);
    if (st == mpu6000::BurstStatus::Ok) return true;
    if (health_.failed(now_ms))
        Writer(out_).str(TXT(TXT_ERROR TXT_MPU " stopped answering (burst all 0x00 or 0xFF)")).end();
    return false;
}
