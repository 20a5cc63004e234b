#include "Imu.h"

#include "Board.h"

using text::Writer;

namespace {
// Reading INT_STATUS clears the data-ready flag and the latched pin: a poll that races
// a new sample loses it. So INT_STATUS is asked only when the pin is overdue (it is
// silent), and every loop from 4 ms on once the pin has been found silent.
constexpr uint16_t kStatusPollOverdueUs = 7000;
constexpr uint16_t kStatusPollAfterUs = 4000;
constexpr uint16_t kTimerFallbackUs = 12000;  // neither answers: pace on the timer
constexpr uint16_t kWarnMs = 2000;            // rate limit of the missed-sample warning
}  // namespace

bool Imu::start(uint32_t now_ms) {
    const mpu6000::InitResult r = chip_.begin();
    if (r.status == mpu6000::InitStatus::Ok) {
        have_sample_time_ = false;
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
    bool ready = board::mpu_int_high();
    if (ready) {
        int_pin_ok_ = true;
        pacing_warned_ = false;
    } else if (since >= (int_pin_ok_ ? kStatusPollOverdueUs : kStatusPollAfterUs) || !have_sample_time_) {
        ready = chip_.data_ready();
        if (ready && have_sample_time_ && int_pin_ok_) {
            int_pin_ok_ = false;
            have_sample_time_ = false;  // this gap is not a missed sample
            Writer(out_).str(TXT(TXT_WARN TXT_MPU " INT pin silent: polling INT_STATUS")).end();
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
    if (have_sample_time_) {
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
    last_sample_us_ = now_us;
    have_sample_time_ = true;

    board::mark_begin(board::kSecMpuRead);
    const mpu6000::BurstStatus st = chip_.read(out);
    board::mark_end(board::kSecMpuRead);
    if (st == mpu6000::BurstStatus::Ok) return true;
    if (health_.failed(now_ms))
        Writer(out_).str(TXT(TXT_ERROR TXT_MPU " stopped answering (burst all 0x00 or 0xFF)")).end();
    return false;
}
