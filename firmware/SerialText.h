// Text to the serial port without ever stalling the 200 Hz loop.
//
// The Arduino core's Serial has a 64-byte transmit ring (what the Arduino IDE builds
// with): a `help` reply (~330 bytes) would block Serial.write for ~30 ms, six samples.
// So every text goes into this queue first (~15 cycles a byte), and pump(), called by
// loop() between samples (thousands of times a second), hands Serial only what fits
// in Serial.availableForWrite(): a write never waits for the UART, and the sample path
// pays only for the queueing.
//
// Angle lines are written only when the whole line fits (write_line_if_room), so a
// backlog of replies delays a line rather than a sample. A message that does not fit
// waits for room while pumping: with kCapacity well above the longest reply that only
// happens when replies come faster than 115200 baud can carry them.
#pragma once

#include <stdint.h>

#include "Text.h"

namespace serial_text {

constexpr uint16_t kCapacity = 512;  // bytes; a power of two (index wrap by mask)
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
// Free bytes in the queue.
uint16_t room();

}  // namespace serial_text
