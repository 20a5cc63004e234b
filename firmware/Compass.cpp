// SPDX-License-Identifier: GPL-3.0-or-later
#include "Compass.h"

#include "Board.h"

using text::Flash;
using text::Writer;

namespace {
constexpr uint8_t kDrdySilentMs = 50;  // DRDY low this long (75 Hz = 13 ms): ask the status register
constexpr uint16_t kDeadMs = 1000;     // no good sample this long: stopped delivering
}  // namespace

void Compass::failed(Flash why, uint32_t now_ms) {
    if (health_.failed(now_ms)) {
        Writer(out_).str(TXT(TXT_ERROR TXT_HMC " ")).str(why).end();
        say_gyro_only();
    }
    pipe_.set_mag_present(false);
}

void Compass::say_gyro_only() { Writer(out_).str(TXT(TXT_WARN TXT_HMC " absent: yaw is gyro-only")).end(); }

bool Compass::start(bool self_test, uint32_t now_ms) {
    const hmc5883::InitResult r = chip_.begin(self_test);
    if (r.status != hmc5883::InitStatus::Ok) {
        if (health_.failed(now_ms)) {  // news: say what the chip answered
            Writer w(out_);
            w.str(TXT(TXT_ERROR TXT_HMC " "));
            if (r.status == hmc5883::InitStatus::WrongIdentity)
                w.str(TXT("wrong ID ")).hex8(r.id[0]).chr(' ').hex8(r.id[1]).chr(' ').hex8(r.id[2])
                    .str(TXT(", expected 48 34 33 (H43)"));
            else if (r.status == hmc5883::InitStatus::ReadbackMismatch)
                w.str(TXT("did not keep its configuration: reg 0x")).hex8(r.reg).str(TXT(" wrote 0x")).hex8(r.wrote)
                    .str(TXT(" read 0x")).hex8(r.read);
            else
                w.str(TXT("not found (no answer at 0x1E)"));
            w.end();
            say_gyro_only();
        }
        pipe_.set_mag_present(false);
        return false;
    }
    if (self_test) {
        Writer w(out_);
        if (chip_.self_test_passed()) {
            const linalg::Vector3f s = chip_.self_test_scale();
            w.str(TXT("# " TXT_HMC " self-test: scale ")).fixed2(s.x).chr(' ').fixed2(s.y).chr(' ').fixed2(s.z).end();
        } else {
            w.str(TXT(TXT_WARN TXT_HMC " self-test implausible (")).u32(chip_.self_test_good_samples())
                .str(TXT("/5 good): scale 1.0")).end();
        }
    }
    last_read_ms_ = last_ok_ms_ = now_ms;
    failures_ = 0;
    if (health_.working()) Writer(out_).str(TXT("# recovered: " TXT_HMC)).end();
    pipe_.set_mag_present(true);
    return true;
}

void Compass::retry(uint32_t now_ms) {
    if (!health_.retry_due(now_ms)) return;
    if (board::sda_low()) board::i2c_recover();
    start(false, now_ms);
}

void Compass::service(uint32_t now_ms) {
    if (!ok()) return;
    const bool by_pin = board::mag_drdy_high();
    bool due = false;
    if (by_pin) {
        due = pipe_.steps() - last_read_step_ >= pipeline::kMagReadMinSteps;
    } else if (now_ms - last_read_ms_ >= kDrdySilentMs) {
        bool ready = false;
        if (!chip_.ready_by_status(ready)) ++failures_;
        if (ready) {
            due = true;
            if (!drdy_warned_) Writer(out_).str(TXT(TXT_WARN TXT_HMC " DRDY pin silent: polling status")).end();
            drdy_warned_ = true;
        }
    }
    if (due) {
        linalg::Vector3f field;
        board::mark_begin(board::kSecMagRead);
        const hmc5883::ReadStatus st = chip_.read(field);
        board::mark_end(board::kSecMagRead);
        last_read_ms_ = now_ms;
        last_read_step_ = pipe_.steps();
        // DRDY falls when the data are read: still high afterwards, three reads in a row,
        // means the pin is stuck and the minimum spacing is what paces the reads.
        if (by_pin && board::mag_drdy_high()) {
            if (drdy_high_reads_ < 3 && ++drdy_high_reads_ == 3)
                Writer(out_).str(TXT(TXT_WARN TXT_HMC " DRDY pin stuck high: reading every 10 ms")).end();
        } else {
            drdy_high_reads_ = 0;
        }
        if (st == hmc5883::ReadStatus::Ok) {
            pipe_.on_mag_sample(field);
            last_ok_ms_ = now_ms;
            failures_ = 0;
            overflow_warned_ = false;
            if (by_pin) drdy_warned_ = false;  // the pin works (again): a new silence is news
        } else if (st == hmc5883::ReadStatus::Overflow) {
            last_ok_ms_ = now_ms;  // it answers; the field is just out of range
            if (!overflow_warned_) Writer(out_).str(TXT(TXT_WARN TXT_HMC " overflow (-4096): samples dropped")).end();
            overflow_warned_ = true;  // once until a good sample
        } else if (st != hmc5883::ReadStatus::Skipped) {
            ++failures_;
        }
    }
    const bool timed_out = board::i2c_timed_out();  // read every time: it clears the flag
    Flash why;
    if (failures_ >= 3 || (timed_out && failures_ > 0)) why = TXT("stopped answering");
    else if (now_ms - last_ok_ms_ > kDeadMs) why = TXT("stopped delivering samples");
    else return;
    failed(why, now_ms);
    board::i2c_recover();
}
