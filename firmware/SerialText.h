// SPDX-License-Identifier: GPL-3.0-or-later
// Text to the serial port without ever stalling the 200 Hz loop.
//
// The Arduino core's Serial has a 64-byte transmit ring (what the Arduino IDE builds
// with): a `help` reply (~330 bytes) would block Serial.write for ~30 ms, six samples.
// So every text goes into this queue first (a byte copied into a ring), and pump(),
// called by every loop() iteration (each interrupt wakes one), hands Serial only what fits
// in Serial.availableForWrite(): a write never waits for the UART, and the sample path
// pays only for the queueing.
//
// Angle lines are written only when the whole line fits (write_line_if_room), so a
// backlog of replies delays a line rather than a sample. A message that does not fit
// waits for room while pumping: console replies go out a part (a line or two) at a time,
// each only when room() holds it and an output line after it (firmware.ino), so that
// only happens when the sensors' own messages come faster than 115200 baud carries them.
//
// Size: 192 bytes here and Serial's 64 behind them (room() counts both: pump() moves
// bytes on as soon as Serial has space) hold a reply part (a line of up to 96 bytes, or
// its two STATUSTEXT frames, 132 bytes, in `mode mavlink`) with an output line after it
// (a 104-byte raw line, a 40-byte ATTITUDE frame) and some 50 bytes of the sensors' own
// messages; at 115200 baud they drain in 22 ms.
#pragma once

#include <stdint.h>

#include "Text.h"

namespace serial_text {

constexpr uint16_t kCapacity = 192;  // bytes
constexpr uint32_t kBaud = 115200;

void begin();
// Moves queued bytes into Serial's transmit ring, as many as it has room for.
void pump();
// Queues len bytes; waits (pumping) only while the queue is full. pump() sends them.
void write(const char* data, uint8_t len);
// Queues the line if it fits whole; false (nothing queued) when it does not.
bool write_line_if_room(const char* line, uint8_t len);
// Blocks until everything queued has gone to Serial (set-up only).
void flush();
uint16_t queued();
// Bytes that can be written now without waiting for the UART: free in this queue and
// in Serial's transmit ring.
uint16_t room();

}  // namespace serial_text
