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
// backlog of replies delays a line rather than a sample. A message line (every "# " line,
// or its STATUSTEXT frames) goes in whole or not at all (line_part/end_line): its bytes
// wait behind the ones before it, uncommitted, until its end, and a part that finds no
// room once the bytes before it have moved on to Serial drops the line (its bytes taken
// back); the caller counts it (Port: "N lines held back"). So after setup() no write of a
// message ever waits for the UART. Before the loop (setup(): no sample to miss) a line
// waits for room as every write does. Frames and replies whose room was checked
// (room(), as the reply tasks do) fit, and write() never waits for them.
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
// Queues len bytes; waits (pumping) only while the queue is full (the caller checked
// room(): it never is after setup()). pump() sends them. An open line is ended first.
void write(const char* data, uint8_t len);
// A part of a message line (the line's bytes, or one of its frames): queued behind the
// line's earlier parts if it fits now, else the line is dropped and its other parts are
// ignored. Before loop_starts() it waits for room instead.
void line_part(const char* data, uint8_t len);
// The line is over: its bytes can go (true), or it was dropped (false).
bool end_line();
// The loop runs: from now on a message line that does not fit is dropped, never waited for.
void loop_starts();
// Queues the line if it fits whole; false (nothing queued) when it does not.
bool write_line_if_room(const char* line, uint8_t len);
// Blocks until everything queued has gone to Serial (set-up only).
void flush();
uint16_t queued();
// Bytes that can be written now without waiting for the UART: free in this queue and
// in Serial's transmit ring.
uint16_t room();

}  // namespace serial_text
