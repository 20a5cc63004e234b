// apm25-attitude: attitude (roll, pitch, heading) on the ArduPilot Mega 2.5.
//
// This file is the board's side only: set-up, the 200 Hz loop paced by the MPU6000
// data-ready, sensor health (report once, retry at 1 Hz, report recovery), the serial
// console, LEDs and EEPROM. Everything that turns samples into angles is lib/Pipeline
// (AttitudePipeline), which the host replay tool runs too.
//
// Serial: 115200 baud; angle lines per ../shared/SIM.md; every other line begins "# ".
#include "ArduinoCore.h"
#include <avr/eeprom.h>

#include "Board.h"
#include "Console.h"
#include "Format.h"
#include "Pipeline.h"
#include "Settings.h"

namespace {

using text::Flash;
using text::Writer;

constexpr uint16_t kPeriodUs = 1000000u / pipeline::kRateHz;  // 5 000
// Reading INT_STATUS clears the data-ready flag and the latched pin: a poll that races
// a new sample loses it (the early overrun seen at ~0.27 s). So INT_STATUS is asked
// only when the pin is overdue (it is silent), and every loop from 4 ms on once the pin
// has been found silent.
constexpr uint16_t kStatusPollOverdueUs = 7000;
constexpr uint16_t kStatusPollAfterUs = 4000;
constexpr uint16_t kTimerFallbackUs = 12000;   // neither: pace on the timer and say so
constexpr uint16_t kRetryMs = 1000;            // a failed sensor is tried again this often
constexpr uint16_t kWarnMs = 2000;             // rate limit of the firmware's warnings
constexpr uint8_t kMagDrdySilentMs = 50;       // DRDY low this long: ask the status register
constexpr uint16_t kMagDeadMs = 1000;          // no good sample this long: stopped answering
constexpr uint8_t kConsoleBytesPerLoop = 16;

const text::Sink* const out = &board::kSerialSink;
pipeline::AttitudePipeline pipe(&board::kSerialSink);
mpu6000::Mpu6000 mpu(board::kSpi);
hmc5883::Hmc5883 mag(board::kI2c);
console::LineReader reader;

// Sensor health.
bool mpu_ok = false;
bool mpu_reported = false;  // the current failure has been reported
bool mag_ok = false;
bool mag_reported = false;
bool mag_drdy_warned = false;
bool mag_overflow_warned = false;
uint8_t mag_drdy_high_reads = 0;  // reads after which DRDY stayed high (3: stuck, said)
uint8_t mag_failures = 0;
uint32_t mpu_retry_ms = 0, mag_retry_ms = 0;
uint32_t last_mag_read_ms = 0, last_mag_ok_ms = 0;
uint32_t last_mag_read_step = 0;

// Loop timing.
uint32_t last_sample_us = 0;
bool have_sample_time = false;
bool timer_pacing = false;
bool int_pin_ok = true;  // the INT pin paces the loop (else INT_STATUS polling)
bool pacing_warned = false;
uint32_t overruns = 0;
uint32_t work_us = 0, window_start_us = 0;
uint8_t load_pct = 0;
pipeline::RateLimiter warn_overrun, warn_angle;

// EEPROM save, one byte per loop while the EEPROM is ready (no 150 ms stall).
uint8_t save_buf[settings::kRecordSize];
uint8_t save_index = settings::kRecordSize;
bool save_verify = false;

// "<a>\n": most messages are one flash string.
void say(Flash a) { Writer(out).str(a).end(); }

// "... (reg 0xRR wrote 0xWW read 0xVV)": a register that did not keep its value.
void print_readback(Flash part, uint8_t reg, uint8_t wrote, uint8_t read) {
    Writer(out).str(TXT(TXT_ERROR)).str(part).str(TXT(" did not keep its configuration: reg 0x")).hex8(reg)
        .str(TXT(" wrote 0x")).hex8(wrote).str(TXT(" read 0x")).hex8(read).end();
}

// ---------------------------------------------------------------------------
bool mpu_start() {
    const mpu6000::InitResult r = mpu.begin();
    if (r.status == mpu6000::InitStatus::Ok) return true;
    if (!mpu_reported) {
        if (r.status == mpu6000::InitStatus::WrongIdentity)
            Writer(out).str(TXT(TXT_ERROR TXT_MPU " not found (WHO_AM_I=0x")).hex8(r.read)
                .str(TXT(", expected 0x68)")).end();
        else
            print_readback(TXT(TXT_MPU), r.reg, r.wrote, r.read);
    }
    mpu_reported = true;
    return false;
}

// The first report of a compass failure (`why` null: already said), then what it
// means for yaw; the compass is then retried every second.
void mag_failed(Flash why) {
    if (!mag_reported) {
        if (why.p != nullptr) Writer(out).str(TXT(TXT_ERROR TXT_HMC " ")).str(why).end();
        say(TXT(TXT_WARN TXT_HMC " absent: yaw is gyro-only"));
    }
    mag_reported = true;
    mag_ok = false;
    pipe.set_mag_present(false);
    mag_retry_ms = millis();
}

bool mag_start(bool self_test) {
    const hmc5883::InitResult r = mag.begin(self_test);
    if (r.status != hmc5883::InitStatus::Ok) {
        Flash why = TXT("not found (no answer at 0x1E)");
        if (!mag_reported && r.status != hmc5883::InitStatus::NoAnswer) {
            why.p = nullptr;
            if (r.status == hmc5883::InitStatus::WrongIdentity) {
                Writer(out).str(TXT(TXT_ERROR TXT_HMC " wrong ID ")).hex8(r.id[0]).chr(' ')
                    .hex8(r.id[1]).chr(' ').hex8(r.id[2]).str(TXT(", expected 48 34 33 (H43)")).end();
            } else {
                print_readback(TXT(TXT_HMC), r.reg, r.wrote, r.read);
            }
        }
        mag_failed(why);
        return false;
    }
    if (self_test) {
        if (mag.self_test_passed()) {
            const linalg::Vector3f s = mag.self_test_scale();
            Writer(out).str(TXT("# " TXT_HMC " self-test: scale ")).fixed2(s.x).chr(' ').fixed2(s.y).chr(' ')
                .fixed2(s.z).end();
        } else {
            Writer(out).str(TXT(TXT_WARN TXT_HMC " self-test implausible (")).u32(mag.self_test_good_samples())
                .str(TXT("/5 good): scale 1.0")).end();
        }
    }
    last_mag_read_ms = last_mag_ok_ms = millis();
    mag_failures = 0;
    mag_ok = true;
    pipe.set_mag_present(true);
    return true;
}

// ---------------------------------------------------------------------------
void print_settings_line() {
    const settings::Settings& s = pipe.settings();
    char buf[14];
    Writer(out).str(TXT("# settings: rate ")).u32(s.rate_hz).str(TXT(" Hz, decl "))
        .str(buf, text::format_centi(buf, s.declination_centideg)).str(TXT(" deg, mode "))
        .str(console::mode_name(s.mode)).str(TXT(", compass cal "))
        .str((s.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none")).end();
}

Flash ok_or_failed(bool ok) { return ok ? TXT("ok") : TXT("FAILED"); }

void print_status() {
    Writer w(out);
    w.str(TXT("# status: " TXT_MPU " ")).str(ok_or_failed(mpu_ok)).str(TXT(", " TXT_HMC " ")).str(ok_or_failed(mag_ok));
    if (!mag_ok) w.str(TXT(" (yaw gyro-only)"));
    const pipeline::Phase ph = pipe.phase();
    w.str(TXT(", estimator "))
        .str(ph == pipeline::Phase::Running       ? TXT("running")
             : ph == pipeline::Phase::Calibrating ? TXT("calibrating")
                                                  : TXT("waiting for " TXT_MPU))
        .end();
    char buf[14];
    w.str(TXT("# load ")).u32(load_pct).str(TXT("%, overruns ")).u32(overruns)
        .str(TXT(", spikes ")).u32(pipe.spikes()).str(TXT(", uptime "))
        .str(buf, text::format_centi(buf, (int32_t)(millis() / 10u))).str(TXT(" s")).end();
    pipe.print_bias(TXT("# gyro bias "), true);
    print_settings_line();
}

void start_save() {
    settings::encode(pipe.settings(), save_buf);
    save_index = 0;
    save_verify = true;
    say(TXT("# saving to " TXT_EEPROM));
}

void service_save() {
    if (!eeprom_is_ready()) return;
    if (save_index < settings::kRecordSize) {
        eeprom_update_byte((uint8_t*)(settings::kEepromAddress + save_index), save_buf[save_index]);
        ++save_index;
        return;
    }
    if (!save_verify) return;
    save_verify = false;
    bool same = true;
    for (uint8_t i = 0; i < settings::kRecordSize; ++i)
        same = same && eeprom_read_byte((const uint8_t*)(settings::kEepromAddress + i)) == save_buf[i];
    say(same ? TXT("# saved") : TXT(TXT_ERROR TXT_EEPROM " write did not verify: not saved"));
}

void load_settings() {
    uint8_t rec[settings::kRecordSize];
    eeprom_read_block(rec, (const void*)settings::kEepromAddress, settings::kRecordSize);
    Flash m;
    switch (settings::decode(rec, pipe.settings())) {
        case settings::LoadResult::Ok: m = TXT("# settings loaded from " TXT_EEPROM); break;
        case settings::LoadResult::Blank: m = TXT("# " TXT_EEPROM " blank" TXT_DEFAULTS); break;
        case settings::LoadResult::BadMagic: m = TXT(TXT_WARN TXT_EEPROM " holds something else" TXT_DEFAULTS); break;
        case settings::LoadResult::OldVersion: m = TXT(TXT_WARN TXT_EEPROM " from another version" TXT_DEFAULTS); break;
        case settings::LoadResult::BadCrc: m = TXT(TXT_WARN TXT_EEPROM " corrupted (CRC)" TXT_DEFAULTS); break;
        default: m = TXT(TXT_WARN TXT_EEPROM " values out of range" TXT_DEFAULTS); break;
    }
    say(m);
}

void poll_console() {
    for (uint8_t n = 0; n < kConsoleBytesPerLoop; ++n) {
        const int16_t b = board::serial_read();
        if (b < 0) return;
        const console::Command c = reader.feed((uint8_t)b);
        switch (c.id) {
            case console::CommandId::None: break;
            case console::CommandId::Error: console::print_error(c, out); break;
            case console::CommandId::Help: console::print_help(out); break;
            case console::CommandId::Status: print_status(); break;
            case console::CommandId::Save: start_save(); break;
            default: pipe.handle(c); break;
        }
    }
}

// ---------------------------------------------------------------------------
void service_mag(uint32_t now_ms) {
    if (!mag_ok) return;
    const uint32_t since = now_ms - last_mag_read_ms;
    const bool by_pin = board::mag_drdy_high();
    bool due = false;
    if (by_pin) {
        due = pipe.steps() - last_mag_read_step >= pipeline::kMagReadMinSteps;
    } else if (since >= kMagDrdySilentMs) {
        bool ready = false;
        if (!mag.ready_by_status(ready)) ++mag_failures;
        if (ready) {
            due = true;
            if (!mag_drdy_warned) say(TXT(TXT_WARN TXT_HMC " DRDY pin silent: polling status"));
            mag_drdy_warned = true;
        }
    }
    if (due) {
        linalg::Vector3f field;
        board::mark_begin(board::kSecMagRead);
        const hmc5883::ReadStatus st = mag.read(field);
        board::mark_end(board::kSecMagRead);
        last_mag_read_ms = now_ms;
        last_mag_read_step = pipe.steps();
        // DRDY falls when the data are read: still high afterwards, three reads in a row,
        // means the pin is stuck and the 10 ms minimum spacing is what paces the reads.
        if (by_pin && board::mag_drdy_high()) {
            if (mag_drdy_high_reads < 3 && ++mag_drdy_high_reads == 3)
                say(TXT(TXT_WARN TXT_HMC " DRDY pin stuck high: reading every 10 ms"));
        } else {
            mag_drdy_high_reads = 0;
        }
        if (st == hmc5883::ReadStatus::Ok) {
            pipe.on_mag_sample(field);
            last_mag_ok_ms = now_ms;
            mag_failures = 0;
            mag_overflow_warned = false;
            if (by_pin) mag_drdy_warned = false;  // the pin works (again): a new silence is news
        } else if (st == hmc5883::ReadStatus::Overflow) {
            last_mag_ok_ms = now_ms;  // it answers; the field is just out of range
            if (!mag_overflow_warned) say(TXT(TXT_WARN TXT_HMC " overflow (-4096): samples dropped"));
            mag_overflow_warned = true;  // once until a good sample
        } else if (st != hmc5883::ReadStatus::Skipped) {
            ++mag_failures;
        }
    }
    const bool timed_out = board::i2c_timed_out();  // read every time: it clears the flag
    Flash why;
    if (mag_failures >= 3 || (timed_out && mag_failures > 0)) why = TXT("stopped answering");
    else if (now_ms - last_mag_ok_ms > kMagDeadMs) why = TXT("stopped delivering samples");
    else return;
    mag_failed(why);
    board::i2c_recover();
}

void retry_sensors(uint32_t now_ms) {
    if (!mpu_ok && now_ms - mpu_retry_ms >= kRetryMs) {
        mpu_retry_ms = now_ms;
        say(TXT("# no attitude: " TXT_MPU " absent, retrying every 1 s"));
        uint8_t who = 0;
        if (mpu.probe(who) && mpu_start()) {
            say(TXT("# recovered: " TXT_MPU));
            mpu_ok = true;
            mpu_reported = false;
            have_sample_time = false;
            pipe.restart_estimator();
        }
    }
    if (!mag_ok && now_ms - mag_retry_ms >= kRetryMs) {
        mag_retry_ms = now_ms;
        if (board::sda_low()) board::i2c_recover();
        if (mag_start(false)) {
            say(TXT("# recovered: " TXT_HMC));
            mag_reported = false;
        }
    }
}

void update_leds() {
    const pipeline::Phase ph = pipe.phase();
    board::set_leds(ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating(),
                    mpu_ok && ph == pipeline::Phase::Running,
                    !mpu_ok || !mag_ok);
}

void emit_output(uint32_t now_ms) {
    const settings::Settings& s = pipe.settings();
    if (s.mode == fmt::OutputMode::Quiet) return;
    board::mark_begin(board::kSecEuler);
    const pipeline::Angles a = pipe.angles();
    board::mark_end(board::kSecEuler);
    char line[fmt::kLineMax];
    board::mark_begin(board::kSecFormat);
    const uint8_t n = s.mode == fmt::OutputMode::Csv
                          ? fmt::format_csv_line(line, now_ms, a.roll_deg, a.pitch_deg, a.heading_deg)
                          : fmt::format_plot_line(line, a.roll_deg, a.pitch_deg, a.heading_deg);
    board::mark_end(board::kSecFormat);
    if (n > 0) board::serial_write(line, n);
    else if (warn_angle.allow(now_ms, kWarnMs)) say(TXT(TXT_WARN "angle not finite: line skipped"));
}

// One 200 Hz step once the MPU6000 has a sample.
void step(uint32_t now_us) {
    board::mark_begin(board::kSecLoop);
    const uint32_t now_ms = millis();
    if (have_sample_time) {
        const uint32_t gap = now_us - last_sample_us;
        if (gap > kPeriodUs + kPeriodUs / 2u) {
            const uint16_t missed = (uint16_t)((gap + kPeriodUs / 2u) / kPeriodUs - 1u);
            overruns += missed;
            if (warn_overrun.allow(now_ms, kWarnMs))
                Writer(out).str(TXT(TXT_WARN "loop overrun: ")).u32(missed).str(TXT(" sample(s) missed, "))
                    .u32(overruns).str(TXT(" in all")).end();
        }
    }
    last_sample_us = now_us;
    have_sample_time = true;

    mpu6000::Sample sample;
    board::mark_begin(board::kSecMpuRead);
    const mpu6000::BurstStatus st = mpu.read(sample);
    board::mark_end(board::kSecMpuRead);
    if (st != mpu6000::BurstStatus::Ok) {
        mpu_ok = false;
        if (!mpu_reported) say(TXT(TXT_ERROR TXT_MPU " stopped answering (burst all 0x00 or 0xFF)"));
        mpu_reported = true;
        mpu_retry_ms = now_ms;
    } else {
        service_mag(now_ms);
        board::mark_begin(board::kSecEstimator);
        pipe.on_imu_sample(sample);
        board::mark_end(board::kSecEstimator);
        if (pipe.output_due()) emit_output(now_ms);
    }
    board::mark_end(board::kSecLoop);
    work_us += micros() - now_us;
}

}  // namespace

// The set-up runs on a fixed timeline (pipeline::kMpuStartMs ...): the same
// instants of a trajectory are sampled here and in the host replay tool.
static void wait_until_ms(uint16_t ms) {
    while (millis() < ms) {
    }
}

void setup() {
    board::init_pins();  // every chip select high before any SPI traffic
    board::set_leds(true, false, false);
    board::serial_begin();
    say(TXT("# apm25-attitude 0.1.0: APM 2.5, 200 Hz loop\n"
            "# " TXT_MPU " 200 Hz, DLPF 42 Hz, 2000 deg/s, 8 g; " TXT_HMC " 75 Hz, 8-sample average, 1.3 Ga"));
    load_settings();
    print_settings_line();

    board::spi_begin();
    wait_until_ms(pipeline::kMpuStartMs);
    mpu_ok = mpu_start();
    mpu_retry_ms = millis();

    board::wire_begin();
    if (board::sda_low()) board::i2c_recover();
    wait_until_ms(pipeline::kMagStartMs);
    mag_start(true);
    say(TXT("# type help for commands"));
    if (pipe.settings().mode == fmt::OutputMode::Csv) Writer(out).str(console::csv_header());
    board::serial_drain();  // the banner out before the 200 Hz loop starts: no overrun
    wait_until_ms(pipeline::kLoopStartMs);
    window_start_us = micros();
    update_leds();
}

void loop() {
    poll_console();
    service_save();
    retry_sensors(millis());

    const uint32_t now_us = micros();
    if (now_us - window_start_us >= 1000000u) {  // load over the last second
        load_pct = (uint8_t)(work_us / ((now_us - window_start_us) / 100u));
        work_us = 0;
        window_start_us = now_us;
        update_leds();
    }
    if (!mpu_ok) return;

    // Data ready: the INT pin (latched until the burst read), else INT_STATUS when a
    // sample is due, else the timer (said once): the loop never waits forever.
    const uint32_t since = now_us - last_sample_us;
    bool ready = board::mpu_int_high();
    if (ready) {
        int_pin_ok = true;
        pacing_warned = false;
    } else if (since >= (int_pin_ok ? kStatusPollOverdueUs : kStatusPollAfterUs) || !have_sample_time) {
        ready = mpu.data_ready();
        if (ready && have_sample_time && int_pin_ok) {
            int_pin_ok = false;
            have_sample_time = false;  // this gap is not an overrun
            say(TXT(TXT_WARN TXT_MPU " INT pin silent: polling INT_STATUS"));
        }
    }
    if (ready) {
        timer_pacing = false;
    } else if (have_sample_time && since >= (timer_pacing ? kPeriodUs : kTimerFallbackUs)) {
        if (!timer_pacing) {
            if (!pacing_warned) say(TXT(TXT_WARN TXT_MPU " data-ready not seen: pacing on the timer"));
            pacing_warned = true;      // once until the INT pin works again
            have_sample_time = false;  // this gap is not an overrun
        }
        timer_pacing = true;
        ready = true;
    }
    if (!ready) return;
    step(now_us);
    if (pipe.steps() % 50u == 0u) update_leds();
}

// Our own entry point instead of the core's main(): its init() also starts timers 1..5
// for PWM and the ADC, which this board does not use.
int main() {
    board::start_clock();
    setup();
    for (;;) loop();
}
