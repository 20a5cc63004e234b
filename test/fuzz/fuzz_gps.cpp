// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: lib/GPS's receiver (detection, configuration, the UBX and NMEA parsers)
// on arbitrary bytes, as the GPS port would deliver them, with the clock moved on by the
// input too. Built by mk/fuzz.mk with clang -fsanitize=fuzzer,address,undefined: a crash,
// an out-of-bounds access, undefined behaviour or a broken invariant below aborts.
//
// Invariants checked (GpsReceiver.h):
// - nothing is written beyond the room the port offers, and only whole UBX frames with
//   a right checksum or the $PUBX,41 sentence;
// - GPS_TYPE 0 writes nothing and sets no baud; the bauds are the five of the detection;
// - a 2D or 3D fix is on the earth, its course within 0..360 deg, its speed plausible;
// - the fix count moves by at most one per byte fed or update.
#include <stddef.h>
#include <stdint.h>

#include <cstring>

#include "FuzzAssert.h"
#include "GpsReceiver.h"

namespace {

struct FakePort {
    uint8_t room = 255;
    bool silent = false;  // GPS_TYPE 0: any call is a failure
};

void set_baud(void* ctx, uint32_t baud) {
    fuzz_assert(!static_cast<FakePort*>(ctx)->silent);
    fuzz_assert(baud == 4800 || baud == 9600 || baud == 38400 || baud == 57600 || baud == 115200);
}
uint8_t room(void* ctx) { return static_cast<FakePort*>(ctx)->room; }
void write(void* ctx, const uint8_t* data, uint8_t len) {
    const FakePort* port = static_cast<FakePort*>(ctx);
    fuzz_assert(!port->silent && len <= port->room && len >= gps::ubx::kFrameOverhead);
    if (data[0] == '$') {
        fuzz_assert(std::strlen(gps::kPubx41) == len && std::memcmp(data, gps::kPubx41, len) == 0);
        return;
    }
    fuzz_assert(data[0] == gps::ubx::kSync1 && data[1] == gps::ubx::kSync2);
    fuzz_assert((uint16_t)(data[4] | data[5] << 8) + gps::ubx::kFrameOverhead == len);
    gps::ubx::Checksum ck;
    ck.add(data + 2, (size_t)len - 4u);
    fuzz_assert(ck.a == data[len - 2] && ck.b == data[len - 1]);
}

void check_fix(const gps::Fix& f) {
    if (f.fix < gps::FixType::k2D) return;
    fuzz_assert(f.lat_e7 >= -900000000 && f.lat_e7 <= 900000000);
    fuzz_assert(f.lon_e7 >= -1800000000 && f.lon_e7 <= 1800000000);
    fuzz_assert(f.course_e5 >= 0 && f.course_e5 <= 36000000);
    fuzz_assert(f.ground_speed_cm_s <= gps::Receiver::kMaxSpeedCmS);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size < 2) return 0;
    // The first byte: the GPS_TYPE and the transmit room; then every 16th byte moves the clock.
    static const gps::Type kTypes[] = {gps::Type::kNone, gps::Type::kAuto, gps::Type::kUblox, gps::Type::kNmea};
    FakePort port;
    port.room = (uint8_t)(data[0] & 0xF0u) == 0 ? 255u : (uint8_t)(data[0] & 0xF0u);
    gps::Config config;
    config.type = kTypes[data[0] & 3u];
    port.silent = config.type == gps::Type::kNone;
    const gps::Port seam{&port, set_baud, room, write};
    gps::Receiver rx(seam);
    uint32_t now_ms = 0;
    rx.begin(config, now_ms);
    for (size_t i = 1; i < size; ++i) {
        uint16_t before = rx.fix_count();
        if (i % 16u == 0u) {
            now_ms += (uint32_t)data[i] * 20u;  // up to 5 s
            rx.update(now_ms);
            fuzz_assert((uint16_t)(rx.fix_count() - before) <= 1u);
            before = rx.fix_count();
        }
        rx.feed(data[i], now_ms);
        fuzz_assert((uint16_t)(rx.fix_count() - before) <= 1u);
        check_fix(rx.fix());
        (void)rx.take_events();
    }
    return 0;
}
