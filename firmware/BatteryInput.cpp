// SPDX-License-Identifier: GPL-3.0-or-later
#include "BatteryInput.h"

#include "Adc.h"
#include "ArduinoCore.h"
#include "BatteryMonitor.h"
#include "GcsLink.h"
#include "Port.h"
#include "Vehicle.h"

namespace battery_input {

using vehicle::pipe;

static battery::Monitor monitor;
// Low 16 bits of millis(): the intervals measured are well under 65 s.
static uint16_t last_update_ms = 0;
static bool updated_before = false;  // the first update has no interval to integrate

static const battery::Settings& settings() { return pipe.settings().vehicle.battery; }

static uint16_t now16() { return (uint16_t)millis(); }

bool due() { return (uint16_t)(now16() - last_update_ms) >= battery::kUpdatePeriodMs; }

// The low-battery failsafe's action: ArduPlane's (low_battery_event), RTL; without a 3D
// fix or home the mode is kept, and said so (FlightIo::failsafe_rtl).
static void failsafe_action() { vehicle::flight_io.failsafe_rtl(TXT("low battery")); }

static void say_failsafe() {
    // ArduPlane's words: "Low battery %.2fV used %.0f mAh" (a WARNING).
    const float used = monitor.consumed_mah();
    text::Writer(vehicle::out)
        .str(TXT("# warn: Low battery "))
        .fixed2(monitor.voltage_v())
        .str(TXT("V used "))
        .u32(used > 0.0f ? (uint32_t)(used + 0.5f) : 0u)
        .str(monitor.failsafe() == battery::Failsafe::kCapacity ? TXT(" mAh (FS_BATT_MAH)") : TXT(" mAh"))
        .end();
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) void update() {
    const uint32_t now_ms = millis();
    const float dt_s = updated_before ? (float)(uint16_t)((uint16_t)now_ms - last_update_ms) * 0.001f : 0.0f;
    last_update_ms = (uint16_t)now_ms;
    updated_before = true;
    const battery::Settings& s = settings();
    adc::Sums sums;
    adc::take_battery_sums(sums);
    // The pins to convert from now on (a changed BATT_*_PIN or BATT_MONITOR takes effect here).
    const bool on = battery::Monitor::enabled(s);
    adc::set_battery_pins(on ? s.volt_pin : adc::kNoPin,
                          on && battery::Monitor::has_current(s) ? s.curr_pin : adc::kNoPin);
    if (on && sums.volt_n == 0u) {
        // No conversion in 100 ms: just switched on, or no sample flows (nobody takes A0's
        // conversion, so the battery's never start): the pins converted here, the failsafe
        // rule still kept.
        adc::convert_battery_pins_now();
        adc::take_battery_sums(sums);
        if (sums.volt_n == 0u) return;
    }
    if (monitor.update(s, battery::pin_volts(sums.volt_counts, sums.volt_n),
                       battery::pin_volts(sums.curr_counts, sums.curr_n), dt_s, now_ms)) {
        say_failsafe();
        failsafe_action();
    }
}

bool enabled() { return battery::Monitor::enabled(settings()); }
bool healthy() { return enabled() && monitor.failsafe() == battery::Failsafe::kNone; }
bool failsafe() { return monitor.failsafe() != battery::Failsafe::kNone; }
mav::BatteryReport report() { return mav::battery_report(monitor, settings()); }

bool status_due() {
    return enabled() && gcs_link::stream_due(mav::kStreamBatteryStatus) && gcs_link::room_for(mav::kBatteryStatusFrame);
}

void send_status() {
    gcs_link::take_stream(mav::kStreamBatteryStatus, millis());  // SR0_EXTRA3's rate
    uint8_t frame[mav::kMaxFrame];
    port::send_frame(frame, port::mavlink.battery_status(frame, report()));
}

void print_status_line(const text::Sink* out) {
    const battery::Settings& s = settings();
    text::Writer w(out);
    w.str(TXT("# battery: "));
    if (!battery::Monitor::enabled(s)) {
        w.str(TXT("off (BATT_MONITOR ")).u32(s.monitor).chr(')').end();
        return;
    }
    w.fixed2(monitor.voltage_v()).str(TXT(" V"));
    if (battery::Monitor::has_current(s)) {
        const float used = monitor.consumed_mah();
        w.str(TXT(", ")).fixed2(monitor.current_a()).str(TXT(" A, "))
            .u32(used > 0.0f ? (uint32_t)(used + 0.5f) : 0u).str(TXT(" mAh used"));
        const int8_t left = monitor.remaining_pct(s);
        if (left >= 0) w.str(TXT(", ")).u32((uint32_t)left).str(TXT("% left"));
    }
    switch (monitor.failsafe()) {
        case battery::Failsafe::kVoltage: w.str(TXT(", FAILSAFE (low voltage)")); break;
        case battery::Failsafe::kCapacity: w.str(TXT(", FAILSAFE (FS_BATT_MAH)")); break;
        default:
            if (monitor.voltage_low()) w.str(TXT(", below FS_BATT_VOLTAGE"));
            break;
    }
    w.end();
}

}  // namespace battery_input
