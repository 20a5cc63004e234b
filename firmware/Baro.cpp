// SPDX-License-Identifier: GPL-3.0-or-later
#include "Baro.h"

#include <SPI.h>

#include "ArduinoCore.h"
#include "Board.h"
#include "BaroHeight.h"
#include "GcsLink.h"
#include "LinAlg.h"
#include "Ms5611.h"
#include "Vehicle.h"

namespace baro {

using text::Writer;

// The ground: the means of the 10 Hz periods kGroundFirst .. kGroundFirst + kGroundPeriods - 1
// after the chip is found (the first tenth left out: the first D1s follow the reset).
constexpr uint8_t kGroundFirst = 1;
constexpr uint8_t kGroundPeriods = 5;
constexpr uint32_t kHeightPeriodUs = 100000;  // 10 Hz
constexpr uint16_t kStaleMs = 500;            // no pressure for this long: not healthy
constexpr uint16_t kRejectSayMs = 2000;       // at most one "rejected" line this often

// One transaction on the shared bus: mode 0 at 8 MHz (the AVR's fastest; the chip takes 20),
// its chip select on its port (PG1, one instruction). Only the loop task calls it, never
// while the MPU6000's select (PB0) is low: the burst reads are in the sample path.
static void transaction(void*, uint8_t cmd, uint8_t* in, uint8_t len) {
    SPI.beginTransaction(SPISettings(8000000, MSBFIRST, SPI_MODE0));
    PORTG &= (uint8_t)~_BV(PG1);
    SPI.transfer(cmd);
    for (uint8_t i = 0; i < len; ++i) in[i] = SPI.transfer(0x00);
    PORTG |= _BV(PG1);
    SPI.endTransaction();
}
static_assert(board::kPinBaroCs == 40, "pin 40 is PG1 on the Mega 2560");

static ms5611::Sequencer chip(ms5611::SpiDevice{nullptr, transaction});
static ms5611::BaroHeight height;
static float mean_pa = 0.0f;
static float ground_sum_pa = 0.0f;
static float ground_pa = 0.0f, ground_c = 0.0f;  // as set in `height`
static float ground_chip_c = 0.0f;  // the chip's temperature when the ground was taken
static bool ground_unsaid = false;  // the ground taken, its line not said yet
static uint32_t period_start_us = 0, last_pressure_ms = 0, last_reject_said_ms = 0;
static uint8_t periods = 0;  // 10 Hz periods since found (saturates)
static bool found = false, lost = false, absent = false;

float height_m() { return height.height_m(); }
float climb_m_s() { return height.climb_m_s(); }
float pressure_pa() { return mean_pa; }
float temperature_c() { return chip.have_temperature() ? (float)chip.temperature_c100() * 0.01f : 0.0f; }
bool present() { return found; }
bool healthy() {
    return chip.converting() && !chip.stuck() && height.have_ground() && millis() - last_pressure_ms < kStaleMs;
}

bool due() { return ground_unsaid || chip.due(micros()); }

static void say(ms5611::Event e) {
    Writer w(vehicle::out);
    switch (e) {
        case ms5611::Event::Blank:
            w.str(TXT(TXT_WARN "baro: MS5611 not found (PROM blank), retrying every 1 s")).end();
            absent = true;
            break;
        case ms5611::Event::BadCrc:
            w.str(TXT(TXT_WARN "baro: MS5611 not found (bad PROM CRC), retrying every 1 s")).end();
            absent = true;
            break;
        case ms5611::Event::Lost:
            w.str(TXT(TXT_WARN "baro: MS5611 lost (")).u32(ms5611::kLostAfter)
                .str(TXT(" conversions read 0), height held, retrying every 1 s")).end();
            lost = true;
            break;
        case ms5611::Event::Back:
            w.str(TXT("# baro: MS5611 back")).end();
            lost = absent = false;
            break;
        case ms5611::Event::Stuck:
            w.str(TXT(TXT_WARN "baro: MS5611 stuck (")).u32(ms5611::kStuckReadings)
                .str(TXT(" identical readings), height held")).end();
            break;
        case ms5611::Event::Unstuck: w.str(TXT("# baro: MS5611 readings move again")).end(); break;
        case ms5611::Event::Rejected: {
            const uint32_t now_ms = millis();
            if (now_ms - last_reject_said_ms < kRejectSayMs) break;
            last_reject_said_ms = now_ms;
            w.str(TXT(TXT_WARN "baro: a reading rejected (a jump over 5 hPa or out of range), "))
                .u32(chip.rejected()).str(TXT(" in all")).end();
            break;
        }
        default: break;
    }
}

// The ground, once (GND_ABS_PRESS), then the height at 10 Hz; GND_ABS_PRESS or GND_TEMP
// changed (a ground station's PARAM_SET) moves the reference with them.
static void new_period(uint32_t now_us) {
    const float dt_s = (float)(now_us - period_start_us) * 1e-6f;
    period_start_us = now_us;
    float p;
    if (!chip.take_average(p)) return;
    mean_pa = p;
    if (periods < 255u) ++periods;
    settings::Settings& s = vehicle::pipe.settings();
    if (!height.have_ground()) {
        if (periods <= kGroundFirst) return;
        ground_sum_pa += p;
        if (periods < kGroundFirst + kGroundPeriods) return;
        s.gnd_abs_press_pa = ground_sum_pa / (float)kGroundPeriods;
        // The ground air's temperature is the chip's now: later it warms in the fuselage
        // and cools aloft, neither of which is the ground air's.
        ground_chip_c = temperature_c();
        ground_unsaid = true;
        gcs_link::announce_calibration(gcs_link::Calibrated::kBaroGround);
    }
    const float t_c = s.flight.gnd_temp_c != 0.0f ? s.flight.gnd_temp_c : ground_chip_c;
    if (!height.have_ground() || s.gnd_abs_press_pa != ground_pa || t_c != ground_c) {
        if (!(s.gnd_abs_press_pa > 0.0f)) return;  // GND_ABS_PRESS 0: none to measure from
        ground_pa = s.gnd_abs_press_pa;
        ground_c = t_c;
        height.set_ground(ground_pa, ground_c);
    }
    board::mark_begin(board::kSecBaroHeight);
    height.update(p, dt_s);
    board::mark_end(board::kSecBaroHeight);
}

// The ground's line in a run of its own: with the ground's maths and a conversion it
// would take more than the task's budget in MAVLink (two STATUSTEXT frames packed).
static void say_ground() {
    ground_unsaid = false;
    Writer(vehicle::out).str(TXT("# baro: MS5611, ground ")).u32((uint32_t)(vehicle::pipe.settings().gnd_abs_press_pa + 0.5f))
        .str(TXT(" Pa (GND_ABS_PRESS), ")).fixed2(ground_chip_c).str(TXT(" C")).end();
}

void service() {
    if (ground_unsaid) {
        say_ground();  // the conversion waits for the next pass (due() still true)
        return;
    }
    const uint32_t now_us = micros();
    const ms5611::Event e = chip.service(now_us);
    if (e == ms5611::Event::Found || e == ms5611::Event::Back) {
        found = true;
        period_start_us = now_us;
    }
    if (e == ms5611::Event::Pressure) last_pressure_ms = millis();
    else if (e != ms5611::Event::None) say(e);
    if (chip.converting() && now_us - period_start_us >= kHeightPeriodUs) new_period(now_us);
}

text::Flash state_word() {
    if (absent) return TXT("absent");
    if (lost) return TXT("lost");
    if (chip.stuck()) return TXT("stuck");
    return healthy() ? TXT("ok") : TXT("starting");
}

// Within console::kPartReply (96) whatever the numbers: at most "# baro starting: " (17),
// "120000 Pa, " (11), "-40.00 C, " (10), "-99999.99 m, " (13), "-99999.99 m/s, " (15),
// "65535 missed, " (14), "65535 rejected" (14): 94 characters.
void print_line(const text::Sink* out) {
    constexpr float kShownMax = 99999.99f;  // the height and climb printed within +-kShownMax
    Writer w(out);
    w.str(TXT("# baro ")).str(state_word());
    if (found) {
        char buf[14];
        w.str(TXT(": ")).u32((uint32_t)(mean_pa + 0.5f)).str(TXT(" Pa, "))
            .str(buf, text::format_centi(buf, chip.temperature_c100())).str(TXT(" C, "))
            .fixed2(linalg::constrain(height.height_m(), -kShownMax, kShownMax)).str(TXT(" m, "))
            .fixed2(linalg::constrain(height.climb_m_s(), -kShownMax, kShownMax)).str(TXT(" m/s, "))
            .u32(chip.missed()).str(TXT(" missed, ")).u32(chip.rejected()).str(TXT(" rejected"));
    }
    w.end();
}

}  // namespace baro
