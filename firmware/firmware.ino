// apm25-attitude: roll, pitch and heading from the ArduPilot Mega 2.5's own sensors,
// printed on the serial port (115200 baud) 50 times a second:
//
//   roll:-1.23 pitch:4.56 yaw:271.80
//
// This is the sketch: set-up, the 200 Hz loop, the output. The board's pieces are the
// other files of this folder (Board: pins and buses; Imu: the MPU6000; Compass: the
// HMC5883L; SerialText: output that never blocks; SettingsStore: EEPROM); everything
// that turns samples into angles is the AttitudePipeline (lib/Pipeline), which the
// host replay tool runs too. Your own code goes in user.ino.
//
// The loop is paced by the MPU6000's data-ready (200 Hz): each sample is read,
// calibrated, checked and fed to the DCM estimator (lib/DCM); a compass sample is
// read when its DRDY pin says so. Every line that is not angle data begins with "# ".
#include <SPI.h>
#include <Wire.h>

#include "ArduinoCore.h"
#include "Board.h"
#include "Compass.h"
#include "Console.h"
#include "Format.h"
#include "Imu.h"
#include "Pipeline.h"
#include "SerialText.h"
#include "SettingsStore.h"
#include "UserCode.h"

using text::Flash;
using text::Writer;

const text::Sink* const out = &serial_text::kSink;
pipeline::AttitudePipeline pipe(out);
Imu imu(board::kSpi, out);
Compass compass(board::kI2c, out, pipe);
SettingsStore store(out);
console::LineReader reader;

// Loop load: the share of each second spent on samples (measured, shown by `status`).
uint32_t work_us = 0, window_start_us = 0;
uint8_t load_pct = 0;
pipeline::RateLimiter warn_angle;

// ---------------------------------------------------------------------------
// Output

static void say(Flash text) { Writer(out).str(text).end(); }

static void print_settings_line() {
    const settings::Settings& s = pipe.settings();
    char buf[14];
    Writer(out).str(TXT("# settings: rate ")).u32(s.rate_hz).str(TXT(" Hz, decl "))
        .str(buf, text::format_centi(buf, s.declination_centideg)).str(TXT(" deg, mode "))
        .str(console::mode_name(s.mode)).str(TXT(", compass cal "))
        .str((s.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none")).end();
}

static Flash ok_or_failed(bool ok) { return ok ? TXT("ok") : TXT("FAILED"); }

static void print_status() {
    Writer w(out);
    w.str(TXT("# status: " TXT_MPU " ")).str(ok_or_failed(imu.ok())).str(TXT(", " TXT_HMC " "))
        .str(ok_or_failed(compass.ok()));
    if (!compass.ok()) w.str(TXT(" (yaw gyro-only)"));
    const pipeline::Phase ph = pipe.phase();
    w.str(TXT(", estimator "))
        .str(ph == pipeline::Phase::Running       ? TXT("running")
             : ph == pipeline::Phase::Calibrating ? TXT("calibrating")
                                                  : TXT("waiting for " TXT_MPU))
        .end();
    char buf[14];
    w.str(TXT("# load ")).u32(load_pct).str(TXT("%, overruns ")).u32(imu.missed_samples())
        .str(TXT(", spikes ")).u32(pipe.spikes()).str(TXT(", uptime "))
        .str(buf, text::format_centi(buf, (int32_t)(millis() / 10u))).str(TXT(" s")).end();
    pipe.print_bias(TXT("# gyro bias "), true);
    print_settings_line();
}

// One angle line in the chosen mode (none in quiet mode).
static void emit_output(uint32_t now_ms) {
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
    if (n > 0) serial_text::write_line_if_room(line, n);  // a backlog of replies delays a line, not a sample
    else if (warn_angle.allow(now_ms, 2000)) say(TXT(TXT_WARN "angle not finite: line skipped"));
}

// ---------------------------------------------------------------------------
// Console: each complete line is one command (lib/Console parses; help in README.md).
//
// Nothing typed or pasted is lost: bytes are taken from Serial's 64-byte receive ring
// and parsed at once, every loop iteration and again inside the step after the
// estimator (at 115200 baud the ring fills in 5.6 ms; the longest step is ~4.5 ms), and
// the parsed commands wait in a queue. A command runs only when the output queue has
// room for its longest reply (help, 300 bytes): a paste is answered line by line as
// fast as the UART carries the replies, and a reply never blocks the loop.
constexpr uint16_t kLongestReplyBytes = 320;
console::CommandQueue commands;

static void execute(const console::Command& c) {
    switch (c.id) {
        case console::CommandId::None: break;
        case console::CommandId::Error: console::print_error(c, out); break;
        case console::CommandId::Help: console::print_help(out); break;
        case console::CommandId::Status: print_status(); break;
        case console::CommandId::Save: store.start_save(pipe.settings()); break;
        case console::CommandId::CalGyro: pipe.start_gyro_calibration(); break;
        case console::CommandId::CalMag: pipe.start_mag_calibration(); break;
        case console::CommandId::Defaults:
            pipe.restore_defaults();
            console::print_defaults(out);
            break;
        default: console::apply_setting(c, pipe.settings(), out); break;  // rate, decl, mode
    }
}

// Received bytes -> parsed commands, while the command queue has room (when it has none,
// the bytes wait in Serial's ring).
static void take_console_input() {
    while (!commands.full()) {
        const int b = Serial.read();
        if (b < 0) return;
        const console::Command c = reader.feed((uint8_t)b);
        if (c.id != console::CommandId::None) commands.push(c);
    }
}

static void run_console_command() {
    if (!commands.empty() && serial_text::room() >= kLongestReplyBytes) execute(commands.pop());
}

// ---------------------------------------------------------------------------
// The 200 Hz step, once the MPU6000 has a sample.

static void step(uint32_t now_us) {
    board::mark_begin(board::kSecLoop);
    const uint32_t now_ms = millis();
    mpu6000::Sample sample;
    if (imu.read(sample, now_us, now_ms)) {
        compass.service(now_ms);
        board::mark_begin(board::kSecEstimator);
        pipe.on_imu_sample(sample);
        board::mark_end(board::kSecEstimator);
        take_console_input();
        if (pipe.phase() == pipeline::Phase::Running) user_attitude_step(pipe);
        if (pipe.output_due()) emit_output(now_ms);
    }
    board::mark_end(board::kSecLoop);
    work_us += micros() - now_us;
}

static void update_leds() {
    const pipeline::Phase ph = pipe.phase();
    board::set_leds(ph == pipeline::Phase::Calibrating || pipe.gyro_calibrating() || pipe.mag_calibrating(),
                    imu.ok() && ph == pipeline::Phase::Running, !imu.ok() || !compass.ok());
}

// The set-up runs on a fixed timeline (pipeline::kMpuStartMs ...): the same instants of
// a trajectory are sampled here and in the host replay tool.
static void wait_until_ms(uint16_t ms) {
    while (millis() < ms) serial_text::pump();
}

// ---------------------------------------------------------------------------

void setup() {
    board::init_pins();  // every chip select high before any SPI traffic
    board::set_leds(true, false, false);
    serial_text::begin();
    say(TXT("# apm25-attitude 0.2.0: APM 2.5, 200 Hz loop\n"
            "# " TXT_MPU " 200 Hz, DLPF 42 Hz, 2000 deg/s, 8 g; " TXT_HMC " 75 Hz, 8-sample average, 1.3 Ga"));
    store.load(pipe.settings());
    print_settings_line();

    board::spi_begin();
    wait_until_ms(pipeline::kMpuStartMs);
    imu.start(millis());

    board::wire_begin();
    if (board::sda_low()) board::i2c_recover();
    wait_until_ms(pipeline::kMagStartMs);
    compass.start(true, millis());
    say(TXT("# type help for commands"));
    if (pipe.settings().mode == fmt::OutputMode::Csv) Writer(out).str(console::csv_header());
    serial_text::flush();  // the banner out before the 200 Hz loop starts: no missed sample
    user_setup();
    wait_until_ms(pipeline::kLoopStartMs);
    window_start_us = micros();
    update_leds();
}

void loop() {
    serial_text::pump();
    take_console_input();
    run_console_command();
    store.service();
    const uint32_t now_ms = millis();
    if (imu.retry(now_ms)) pipe.restart_estimator();
    compass.retry(now_ms);
    user_loop();

    const uint32_t now_us = micros();
    if (now_us - window_start_us >= 1000000u) {  // load over the last second
        load_pct = (uint8_t)(work_us / ((now_us - window_start_us) / 100u));
        work_us = 0;
        window_start_us = now_us;
        update_leds();
    }
    if (!imu.sample_ready(now_us)) return;
    step(now_us);
    if (pipe.steps() % 50u == 0u) update_leds();
}
