// SPDX-License-Identifier: GPL-3.0-or-later
// The GPS port (UART1: RXD1 PD2, TXD1 PD3) and the receiver on it (lib/GPS Receiver):
// detection, the u-blox configuration, the latest fix for the rest of the firmware, and
// the "# gps: ..." lines (STATUSTEXT in MAVLink).
//
// USART1 is driven here, not by the Arduino core's Serial1 (a 64-byte ring that drops
// bytes silently): its receive interrupt puts each byte into a 128-byte ring (0.33 s of
// 5 Hz u-blox output at 38400 baud, 33 ms of a continuous stream), counting the bytes a
// full ring drops and those the USART itself lost (its data-overrun flag DOR1); its
// data-register-empty interrupt sends from a 64-byte ring (the longest message, CFG-NAV5,
// is 44 bytes). The loop task `gps` takes at most kSliceBytes a pass from the ring into
// the parsers, so a pass is bounded whatever arrives.
//
// GPS_TYPE 0: USART1 is never enabled; nothing is sent or read.
#pragma once

#include <stdint.h>

#include "GpsFix.h"
#include "Text.h"

namespace gps_port {

constexpr uint8_t kSliceBytes = 64;  // bytes parsed a pass at most

// After the settings are loaded: detection starts (or nothing, GPS_TYPE 0).
void begin();
// Loop task: received bytes parsed, the receiver's time-outs and next message, its
// events said; once a second the settings checked (GPS_TYPE, GPS_NAVFILTER changed:
// detection again) and a receive overflow reported.
void service();

// The latest solution, and a count incremented on each new one (also when the receiver
// is lost: fix().fix is then kNoGps). fix().received_ms is millis() at its last byte.
const gps::Fix& fix();
uint16_t fix_count();

// Bytes lost on receive: the ring full, or the USART's overrun (DOR1).
uint16_t rx_dropped();

// The `gps` command: two lines (part 0 the position, 1 speed, course, age, counters);
// false past the last.
bool print(uint8_t part, const text::Sink* out);
// `status`: "# gps: u-blox at 38400 baud, 3D fix, 10 satellites" and the like.
void print_status_line(const text::Sink* out);

}  // namespace gps_port
