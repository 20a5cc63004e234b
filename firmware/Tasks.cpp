// SPDX-License-Identifier: GPL-3.0-or-later
// The task table: every periodic job of the firmware, how often it runs, the time it may
// take and the profiling section that measures it (lib/Scheduler/Scheduler.h says how
// the scheduler runs the two tables). `make bench` prints each task's cycles against its
// budget; `status` says which ran over it.
//
// The budgets: a sample's tasks must leave the loop time to see the next sample, 5 ms
// after this one; a sample is missed when it is read more than 1.5 periods (7.5 ms)
// after the previous one, so a loop task must end by kDeadlineUs after the last sample,
// and it starts only when its budget says it will. Each budget is what the task takes at
// most (apm25sim --profile: make bench) with a margin; the MAVLink rows' include packing
// the "# " lines into STATUSTEXT frames. The gps row's is for a slice of at most
// gps_port::kSliceBytes received bytes parsed, the receiver's step (a fix, its glitch test)
// and a "# gps:" line (packed as STATUSTEXT for a ground station: 2.0 ms): a pass is
// bounded whatever arrives, the rest waits in the ring.
#include "Tasks.h"

#include "AirspeedInput.h"
#include "ArduinoCore.h"
#include "Adc.h"
#include "Baro.h"
#include "BatteryInput.h"
#include "Board.h"
#include "ConsoleLink.h"
#include "GcsLink.h"
#include "GpsPort.h"
#include "LoopLoad.h"
#include "MissionLink.h"
#include "NavModes.h"
#include "OutputLine.h"
#include "Port.h"
#include "Position.h"
#include "Scheduler.h"
#include "SerialText.h"
#include "UserCode.h"
#include "Vehicle.h"

extern volatile unsigned long timer0_overflow_count;  // the Arduino core's millis() clock (wiring.c)

namespace tasks {

using sched::kAlways;
using vehicle::pipe;
using vehicle::tick;

constexpr uint16_t kDeadlineUs = 7300;

// The sample tasks' own steps.
static void compass_service() { vehicle::compass.service(tick.now_ms); }
static void estimator_step() {
    if (vehicle::imu.pacing_on_timer()) pipe.imu_doubtful();
    // A new GPS solution goes into the estimator before the sample (its velocity
    // aids the gravity correction, its course the heading without a compass); its ~13k
    // cycles come five times a second (`make bench` section 40).
    static uint16_t gps_fixes_seen = 0;
    if (gps_port::fix_count() != gps_fixes_seen) {
        gps_fixes_seen = gps_port::fix_count();
        pipe.on_gps_fix(gps_port::fix());
    }
    pipe.on_imu_sample(tick.sample);
}
static bool estimator_running() { return pipe.phase() == pipeline::Phase::Running; }
static void user_step() { user_attitude_step(pipe); }
static bool control_due() { return vehicle::flight_io.control_due(tick.output); }
static void control_run() {
    vehicle::flight_io.control_run(tick.now_us, tick.now_ms, tick.sample, tick.have_angles ? &tick.angles : nullptr);
}
// ... and the loop tasks'.
// The settings' save and the mission's writes (MissionLink), each only when the EEPROM is ready.
static void store_service() {
    vehicle::store.service();
    mission_link::service();
}
static void sensor_retries() {
    const uint32_t now_ms = millis();
    if (vehicle::imu.retry(now_ms)) pipe.restart_estimator();
    vehicle::compass.retry(now_ms);
}
static void flight_poll() { vehicle::flight_io.poll(micros(), millis()); }
static bool prearm_due() { return vehicle::flight_io.prearm_due(); }
static void say_prearm() { vehicle::flight_io.say_prearm(); }
static void once_a_second() {
    loop_load::new_second();
    vehicle::update_leds();
    gcs_link::send_heartbeat_and_status();
    output_line::say_skipped();
}

// On each sample, in this order (5 ms for all of them, with the read).
//     name         due test                         run                          period budget_us section
#define SAMPLE_TASKS(X)                                                                                          \
    X(compass,      nullptr,                         compass_service,                  1, 1400, kSecCompassTask)  \
    X(estimator,    nullptr,                         estimator_step,                   1, 2300, kSecEstimator)    \
    X(airspeed,     nullptr,                         airspeed_input::step,             1,  800, kSecAirspeed)     \
    X(input_step,   nullptr,                         console_link::take_input_in_step, 1, 1000, kSecInputInStep)  \
    X(user,         estimator_running,               user_step,                        1,  200, kSecUser)         \
    X(output,       output_line::due,                output_line::run,                 1, 1800, kSecOutput)       \
    X(control,      control_due,                     control_run,                      1, 1200, kSecControl)      \
    X(leds,         nullptr,                         vehicle::update_leds,            50,  100, kSecLeds)

// Between samples, on each pass of the loop, in this order, each when due and when it
// ends before kDeadlineUs (kAlways: whenever due).
//     name         due test                         run                             budget_us section         flags
#define LOOP_TASKS(X)                                                                                            \
    X(pump,         nullptr,                         serial_text::pump,                 800, kSecPump,         kAlways) \
    X(held_back,    port::held_back_due,             port::say_held_back,              2000, kSecHeldBack,     0)       \
    X(input,        nullptr,                         console_link::take_input,         2000, kSecInput,        kAlways) \
    X(command,      console_link::command_due,       console_link::reply,              5800, kSecCommand,      0)       \
    X(reply,        console_link::reply_due_text,    console_link::reply,              3200, kSecConsoleReply, 0)       \
    X(statustext,   console_link::reply_due_mavlink, console_link::reply,              3000, kSecStatusText,   0)       \
    X(gcs_request,  gcs_link::request_due,           gcs_link::take_request,           1500, kSecGcsRequest,   0)       \
    X(gcs_command,  gcs_link::command_due,           gcs_link::run_pending_command,    5800, kSecGcsCommand,   0)       \
    X(gcs_defaults, gcs_link::defaults_due,          gcs_link::run_defaults,           5800, kSecGcsDefaults,  0)       \
    X(prearm,       prearm_due,                      say_prearm,                       2300, kSecPreArm,       0)       \
    X(gcs_save,     gcs_link::save_due,              gcs_link::save,                   5800, kSecGcsSave,      0)       \
    X(param_value,  gcs_link::param_value_due,       gcs_link::send_param_value,       3300, kSecGcsReply,     0)       \
    X(gcs_reply,    gcs_link::reply_due,             gcs_link::send_reply,             2000, kSecGcsAnswer,    0)       \
    X(gcs_reboot,   gcs_link::reboot_due,            gcs_link::reboot,                 6000, kSecGcsAnswer,    0)       \
    X(gcs_streams,  gcs_link::streams_due,           gcs_link::send_streams,           3300, kSecGcsStreams,   0)       \
    X(gcs_position, gcs_link::position_due,          gcs_link::send_position,          2000, kSecGcsPosition,  0)       \
    X(gcs_battery,  battery_input::status_due,       battery_input::send_status,       1000, kSecGcsBattery,   0)       \
    X(nav,          position::due,                   position::run,                    3600, kSecNav,          0)       \
    X(guide,        nav_modes::due,                  nav_modes::run,                   4000, kSecGuide,        0)       \
    X(tecs,         nav_modes::filters_due,          nav_modes::filters_run,            700, kSecTecsFilter,   0)       \
    X(store,        nullptr,                         store_service,                    1800, kSecStore,        0)       \
    X(baro,         baro::due,                       baro::service,                    2600, kSecBaro,         0)       \
    X(adc,          adc::battery_conversion_due,     adc::take_battery_conversion,      100, kSecAdc,          kAlways) \
    X(battery,      battery_input::due,              battery_input::update,            2800, kSecBattery,      0)       \
    X(retries,      nullptr,                         sensor_retries,                 150000, kSecRetry,        kAlways) \
    X(user_loop,    nullptr,                         user_loop,                         200, kSecUserLoop,     kAlways) \
    X(flight,       nullptr,                         flight_poll,                       800, kSecFlightPoll,   kAlways) \
    X(gps,          nullptr,                         gps_port::service,                2400, kSecGps,          0)       \
    X(second,       loop_load::second_due,           once_a_second,                    1000, kSecSecond,       kAlways)

// The rows' ids (stats[]), names (`status`) and the periodic rows' counters.
#define SAMPLE_ID(name, ...) kTask_##name,
#define LOOP_ID(name, ...) kTask_##name,
enum TaskId : uint8_t { SAMPLE_TASKS(SAMPLE_ID) LOOP_TASKS(LOOP_ID) kTasks };
#define TASK_NAME(name, ...) #name "\0"
static const char kNames[] PROGMEM = SAMPLE_TASKS(TASK_NAME) LOOP_TASKS(TASK_NAME);
#define PHASE(name, ...) uint8_t name;
static struct { SAMPLE_TASKS(PHASE) } phase;
static sched::TaskStats stats[kTasks];

// The scheduler's clock: timer0 (the core's millis() timer: 4 us a count at 16 MHz / 64)
// with its overflow count's low byte above it, read with interrupts held as micros()
// does: 4 us ticks over 262 ms, a few cycles a read.
struct Clock {
    static constexpr uint8_t kUsPerTick = 4;
    __attribute__((always_inline)) static uint16_t ticks() {
        const uint8_t sreg = SREG;
        cli();
        uint8_t overflows = (uint8_t)timer0_overflow_count;
        const uint8_t count = TCNT0;
        if ((TIFR0 & _BV(TOV0)) && count < 255u) ++overflows;  // an overflow not yet counted
        SREG = sreg;
        return (uint16_t)((uint16_t)overflows << 8 | count);
    }
    // No sample can be late while the MPU6000 is down: nothing waits then.
    // Before the first sample (or the first after pacing changed) only the kAlways rows run:
    // the sample may come any moment, and a late first read would take a later sample and
    // start the estimator off the fixed timeline (pipeline::kLoopStartMs).
    static uint32_t us_since_sample() {
        if (!vehicle::imu.ok()) return 0u;
        return vehicle::imu.awaiting_sample() ? kDeadlineUs : vehicle::imu.us_since_sample(micros());
    }
};
using Timing = sched::Timing<Clock>;

static void run_sample_tasks() {
    uint16_t start = Clock::ticks();
#define SAMPLE_ROW(name, due, run, period, budget_us, section) \
    SCHED_SAMPLE_TASK(name, due, run, period, budget_us, board::section)
    SAMPLE_TASKS(SAMPLE_ROW)
    (void)start;
}

static void run_loop_tasks() {
    const uint32_t since_sample_us = Clock::us_since_sample();
    const uint16_t pass_start = Clock::ticks();
    constexpr uint16_t deadline_us = kDeadlineUs;
#define LOOP_ROW(name, due, run, budget_us, section, flags) \
    SCHED_LOOP_TASK(name, due, run, budget_us, board::section, flags)
    LOOP_TASKS(LOOP_ROW)
}

void loop_starts() {
    const uint32_t now_us = micros();
    loop_load::start(now_us);
    serial_text::loop_starts();  // a message that does not fit now is held back, never waited for
    vehicle::flight_io.loop_starts(now_us);
    vehicle::update_leds();
}

void loop_pass() {
    run_loop_tasks();
    const uint32_t now_us = micros();
    if (!vehicle::imu.sample_ready(now_us)) {
        board::idle_until_interrupt();  // until the next sample, a byte, a tick
        return;
    }
    board::mark_begin(board::kSecLoop);
    tick.now_us = now_us;
    tick.now_ms = millis();
    tick.output = tick.have_angles = false;
    if (vehicle::imu.read(tick.sample, now_us, tick.now_ms)) run_sample_tasks();
    board::mark_end(board::kSecLoop);
    loop_load::add_sample_work(now_us, micros());
}

// "# tasks: N runs over budget (NAME Kx, max M us)": the task with the most, a line that
// fits a reply part (console::kPartReply); `make bench` gives each task's figures.
void print_status_line(const text::Sink* out) {
    uint32_t total = 0;
    uint8_t worst = 0;
    for (uint8_t i = 0; i < kTasks; ++i) {
        total += stats[i].overruns;
        if (stats[i].overruns > stats[worst].overruns) worst = i;
    }
    text::Writer w(out);
    w.str(TXT("# tasks: ")).u32(total).str(TXT(" runs over budget"));
    if (total != 0) {
        const char* name = kNames;
        for (uint8_t i = 0; i < worst; ++i) name += strlen_P(name) + 1;
        w.str(TXT(" (")).str(text::flash(name)).chr(' ').u32(stats[worst].overruns).str(TXT("x, max "))
            .u32((uint32_t)stats[worst].max_ticks * Clock::kUsPerTick).str(TXT(" us)"));
    }
    w.end();
}

}  // namespace tasks
