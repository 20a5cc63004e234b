// SPDX-License-Identifier: GPL-3.0-or-later
#include "GpsPort.h"

#include <avr/interrupt.h>

#include "ArduinoCore.h"
#include "GpsReceiver.h"
#include "Vehicle.h"

namespace gps_port {

namespace uart {

constexpr uint8_t kRxSize = 128;
constexpr uint8_t kTxSize = 48;  // CFG-NAV5, the longest message sent, is 44 bytes
static_assert((kRxSize & (kRxSize - 1u)) == 0, "the receive ring's index wraps by a mask");
static_assert(kTxSize > gps::ubx::kLenCfgNav5 + gps::ubx::kFrameOverhead, "the longest message fits");
inline uint8_t tx_next(uint8_t i) { return i + 1u == kTxSize ? 0u : (uint8_t)(i + 1u); }

// Receive: the interrupt writes at rx_head, the loop reads at rx_tail; one byte each, so
// either side reads the other's index in one instruction.
volatile uint8_t rx_ring[kRxSize];
volatile uint8_t rx_head = 0, rx_tail = 0;
volatile uint16_t rx_dropped = 0;  // ring full, or DOR1
// Transmit: the loop writes at tx_head, the interrupt sends from tx_tail.
volatile uint8_t tx_ring[kTxSize];
volatile uint8_t tx_head = 0, tx_tail = 0;

// ATmega2560 datasheet 22.3.1 (double speed, U2X1 = 1): UBRR = f / (8 baud) - 1, rounded
// as the Arduino core rounds it (38400: 51, +0.2 %; 115200: 16, +2.1 %).
void set_baud(void*, uint32_t baud) {
    UCSR1B = 0;  // receiver, transmitter and their interrupts off while it changes
    rx_head = rx_tail = 0;
    tx_head = tx_tail = 0;
    UBRR1 = (uint16_t)((F_CPU / 4u / baud - 1u) / 2u);
    UCSR1A = _BV(U2X1);
    UCSR1C = _BV(UCSZ11) | _BV(UCSZ10);  // 8N1
    UCSR1B = _BV(RXEN1) | _BV(TXEN1) | _BV(RXCIE1);
}

uint8_t room(void*) {
    const uint8_t head = tx_head, tail = tx_tail;
    const uint8_t used = head >= tail ? (uint8_t)(head - tail) : (uint8_t)(head + kTxSize - tail);
    return (uint8_t)(kTxSize - 1u - used);
}

void write(void*, const uint8_t* data, uint8_t len) {
    uint8_t head = tx_head;
    for (uint8_t i = 0; i < len; ++i) {  // the caller checked room()
        tx_ring[head] = data[i];
        head = tx_next(head);
    }
    tx_head = head;
    UCSR1B |= _BV(UDRIE1);  // the interrupt sends them
}

void off() { UCSR1B = 0; }

}  // namespace uart

}  // namespace gps_port

// A received byte into the ring (datasheet 22.7: read UCSR1A before UDR1). DOR1 says
// bytes were lost before this one (the ring's reader is never that late, but an
// interrupt held off long enough would be); a full ring drops the new one.
ISR(USART1_RX_vect) {
    using namespace gps_port::uart;
    const uint8_t status = UCSR1A;
    const uint8_t byte = UDR1;
    if (status & _BV(DOR1)) ++rx_dropped;
    const uint8_t next = (uint8_t)((rx_head + 1u) & (kRxSize - 1u));
    if (next == rx_tail) {
        ++rx_dropped;
        return;
    }
    rx_ring[rx_head] = byte;
    rx_head = next;
}

ISR(USART1_UDRE_vect) {
    using namespace gps_port::uart;
    if (tx_head == tx_tail) {
        UCSR1B &= (uint8_t)~_BV(UDRIE1);
        return;
    }
    UDR1 = tx_ring[tx_tail];
    tx_tail = tx_next(tx_tail);
}

namespace gps_port {

using text::Writer;

static const gps::Port kPort = {nullptr, uart::set_baud, uart::room, uart::write};
static gps::Receiver receiver(kPort);
static uint32_t second_ms = 0;
static uint16_t dropped_said = 0;
static uint16_t bad_said = 0;          // bad frames and sentences counted when last said ...
static uint8_t bad_quiet_seconds = 0;  // ... and the seconds since (said at most every kBadQuietS)
constexpr uint8_t kBadQuietS = 10;

static gps::Config settings_config() {
    const flight::FlightSettings& fs = vehicle::pipe.settings().flight;
    gps::Config c;
    c.type = (gps::Type)fs.gps_type;
    c.nav_filter = fs.gps_navfilter;
    c.min_sats = fs.ahrs_gps_minsats;
    return c;
}

void begin() {
    const gps::Config c = settings_config();
    uart::off();
    receiver.begin(c, millis());
    second_ms = millis();
}

const gps::Fix& fix() { return receiver.fix(); }
uint16_t fix_count() { return receiver.fix_count(); }

uint16_t rx_dropped() {
    const uint8_t sreg = SREG;
    cli();
    const uint16_t n = uart::rx_dropped;
    SREG = sreg;
    return n;
}

static Writer& baud_and_protocol(Writer& w) {
    return w.str(receiver.protocol() == gps::Protocol::kUbx ? TXT("u-blox at ") : TXT("NMEA at "))
        .u32(receiver.baud()).str(TXT(" baud"));
}

static Writer& quality(Writer& w) {
    const gps::Fix& f = receiver.fix();
    switch (receiver.quality()) {
        case gps::Quality::k3D:
        case gps::Quality::k3DFewSats: w.str(TXT("3D fix, ")); break;
        case gps::Quality::k2D: w.str(TXT("2D fix, ")); break;
        case gps::Quality::kNoFix: w.str(TXT("no fix, ")); break;
    }
    return w.u32(f.sats).str(TXT(" satellites"));
}

// The receiver's news as "# gps: " lines.
static void say_events(uint8_t e) {
    const text::Sink* out = vehicle::out;
    if (e & gps::kEventFound) baud_and_protocol(Writer(out).str(TXT("# gps: found, "))).end();
    if (e & gps::kEventConfigured)
        Writer(out).str(TXT("# gps: configured: 5 Hz, POSLLH STATUS SOL VELNED, dynamic model "))
            .u32(receiver.config().nav_filter).end();
    if (e & gps::kEventNoGpsFound) Writer(out).str(TXT("# gps: no GPS found (4800-115200 baud); still looking")).end();
    if (e & gps::kEventLost) {
        Writer(out).str(TXT("# gps: lost: nothing for 4 s; looking again")).end();
    } else if (e & gps::kEventQuality) {
        Writer w(out);
        w.str(TXT("# gps: "));
        if (receiver.quality() == gps::Quality::kNoFix)
            w.str(TXT("fix lost, ")).u32(receiver.fix().sats).str(TXT(" satellites"));
        else
            quality(w);
        if (receiver.quality() == gps::Quality::k3DFewSats)
            w.str(TXT(": too few (AHRS_GPS_MINSATS ")).u32(receiver.config().min_sats).chr(')');
        w.end();
    }
    if (e & gps::kEventGlitch)
        Writer(out).str(TXT("# gps: glitch: ")).fixed2(receiver.glitch_m())
            .str(TXT(" m from where the velocity says; position rejected")).end();
    if (e & gps::kEventGlitchOver) Writer(out).str(TXT("# gps: glitch over")).end();
}

void service() {
    const uint32_t now_ms = millis();
    for (uint8_t n = 0; n < kSliceBytes; ++n) {
        const uint8_t tail = uart::rx_tail;
        if (tail == uart::rx_head) break;
        const uint8_t byte = uart::rx_ring[tail];
        uart::rx_tail = (uint8_t)((tail + 1u) & (uart::kRxSize - 1u));
        receiver.feed(byte, now_ms);
    }
    receiver.update(now_ms);
    const uint8_t events = receiver.take_events();
    if (events != 0) say_events(events);
    if (now_ms - second_ms < 1000u) return;
    second_ms = now_ms;
    const gps::Config c = settings_config();
    const gps::Config& was = receiver.config();
    if (c.type != was.type || c.nav_filter != was.nav_filter || c.min_sats != was.min_sats) {
        begin();
        return;
    }
    const uint16_t dropped = rx_dropped();
    if (dropped != dropped_said) {
        Writer(vehicle::out).str(TXT("# gps: receive overflow, ")).u32((uint16_t)(dropped - dropped_said))
            .str(TXT(" bytes lost")).end();
        dropped_said = dropped;
    }
    // Bad checksums from a receiver found (not the wrong bauds of detection): garbage on
    // the line, said at most every kBadQuietS seconds.
    const uint16_t bad = (uint16_t)(receiver.ubx_counters().bad_checksum + receiver.nmea_counters().bad_checksum);
    if (bad_quiet_seconds < kBadQuietS) ++bad_quiet_seconds;
    if (!receiver.found()) {
        bad_said = bad;
    } else if (bad != bad_said && bad_quiet_seconds >= kBadQuietS) {
        Writer(vehicle::out).str(TXT("# gps: garbage on the line: ")).u32((uint16_t)(bad - bad_said))
            .str(TXT(" bad frames")).end();
        bad_said = bad;
        bad_quiet_seconds = 0;
    }
}

static void centi(Writer& w, int32_t v) {
    char buf[14];
    w.str(buf, text::format_centi(buf, v));
}

bool print(uint8_t part, const text::Sink* out) {
    const gps::Fix& f = receiver.fix();
    Writer w(out);
    if (part == 0) {
        w.str(TXT("# gps: "));
        if (!receiver.found()) {
            w.str(receiver.config().type == gps::Type::kNone ? TXT("off (GPS_TYPE 0)") : TXT("searching")).end();
            return true;
        }
        quality(w).str(TXT(", hdop "));
        centi(w, f.hdop_cm);
        w.str(TXT(", "));
        w.degrees_e7(f.lat_e7).chr(' ').degrees_e7(f.lon_e7).str(TXT(", "));
        centi(w, f.alt_msl_mm / 10);
        w.str(TXT(" m")).end();
        return true;
    }
    if (part == 1 && receiver.found()) {
        w.str(TXT("# gps: "));
        centi(w, (int32_t)f.ground_speed_cm_s);
        w.str(TXT(" m/s, course "));
        centi(w, f.course_e5 / 1000);
        w.str(TXT(", age ")).u32(millis() - f.received_ms).str(TXT(" ms, frames "))
            .u32(receiver.protocol() == gps::Protocol::kNmea ? receiver.nmea_counters().sentences
                                                             : receiver.ubx_counters().frames)
            .str(TXT(", bad ")).u32(receiver.ubx_counters().bad_checksum + receiver.nmea_counters().bad_checksum)
            .str(TXT(", lost ")).u32(rx_dropped()).end();
        return true;
    }
    return false;
}

void print_status_line(const text::Sink* out) {
    Writer w(out);
    w.str(TXT("# gps: "));
    if (receiver.config().type == gps::Type::kNone) {
        w.str(TXT("off (GPS_TYPE 0)"));
    } else if (!receiver.found()) {
        w.str(TXT("searching"));
    } else {
        baud_and_protocol(w).str(receiver.configured() ? TXT(", ") : TXT(", configuring, "));
        quality(w);
        if (receiver.fix().glitching) w.str(TXT(", glitch"));
    }
    w.end();
}

}  // namespace gps_port
