// SPDX-License-Identifier: GPL-3.0-or-later
#include "SerialText.h"

#include "ArduinoCore.h"

namespace serial_text {

static_assert(kCapacity <= 256u, "the ring's indices are bytes");
static char ring[kCapacity];
// head: next write; tail: next byte for Serial; done: the end of what may go (the start of
// an open line's bytes, head when none is open).
static uint8_t head = 0, tail = 0, done = 0;
enum : uint8_t { kDropped = 1, kInLoop = 2 };
static uint8_t flags = 0;

static uint8_t next(uint8_t i) { return i + 1u == kCapacity ? 0u : (uint8_t)(i + 1u); }
uint16_t queued() { return head >= tail ? (uint16_t)(head - tail) : (uint16_t)(head + kCapacity - tail); }
static uint16_t ring_room() { return (uint16_t)(kCapacity - 1u - queued()); }
uint16_t room() { return (uint16_t)(ring_room() + (uint16_t)Serial.availableForWrite()); }

void begin() { Serial.begin(kBaud); }
void loop_starts() { flags = (uint8_t)(flags | kInLoop); }

void pump() {
    int free_bytes = Serial.availableForWrite();
    while (free_bytes-- > 0 && tail != done) {
        Serial.write((uint8_t)ring[tail]);
        tail = next(tail);
    }
}

// A frame or line at a time, copied in runs up to the ring's end or its room (a byte at
// a time with the room worked out for each, a PARAM_VALUE's 37 cost ~1 000 cycles).
void write(const char* data, uint8_t len) {
    done = head;  // an open line goes as it is: its bytes stay before these
    while (len > 0u) {
        uint16_t run = ring_room();
        if (run == 0u) {
            pump();  // setup(): wait for Serial's room (write_line_if_room never gets here)
            continue;
        }
        if (run > (uint16_t)(kCapacity - head)) run = (uint16_t)(kCapacity - head);
        if (run > len) run = len;
        memcpy(&ring[head], data, run);
        data += run;
        len = (uint8_t)(len - run);
        head = (uint8_t)(head + run == kCapacity ? 0u : head + run);
        done = head;
    }
}

bool write_line_if_room(const char* line, uint8_t len) {
    if (room() < len) return false;
    write(line, len);
    return true;
}

void line_part(const char* data, uint8_t len) {
    if (flags & kDropped) return;
    for (uint8_t i = 0; i < len; ++i) {
        if (ring_room() == 0) pump();  // the bytes before the line, as Serial has room now
        while (ring_room() == 0) {
            if (flags & kInLoop) {
                head = done;  // the line taken back, whole
                flags = (uint8_t)(flags | kDropped);
                return;
            }
            if (tail == done) done = head;  // setup(): a line longer than the ring goes as it is
            pump();
        }
        ring[head] = data[i];
        head = next(head);
    }
}

bool end_line() {
    const bool said = !(flags & kDropped);
    flags = (uint8_t)(flags & ~kDropped);
    done = head;
    return said;
}

void flush() {
    done = head;
    while (tail != head) pump();
    Serial.flush();
}

}  // namespace serial_text
