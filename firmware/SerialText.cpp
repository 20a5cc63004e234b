// SPDX-License-Identifier: GPL-3.0-or-later
#include "SerialText.h"

#include "ArduinoCore.h"

namespace serial_text {

static char ring[kCapacity];
static uint16_t head = 0, tail = 0;  // head: next write, tail: next byte for Serial

static uint16_t next(uint16_t i) { return i + 1u == kCapacity ? 0u : (uint16_t)(i + 1u); }
uint16_t queued() { return head >= tail ? (uint16_t)(head - tail) : (uint16_t)(head + kCapacity - tail); }
static uint16_t ring_room() { return (uint16_t)(kCapacity - 1u - queued()); }
uint16_t room() { return (uint16_t)(ring_room() + (uint16_t)Serial.availableForWrite()); }

void begin() { Serial.begin(kBaud); }

void pump() {
    int free_bytes = Serial.availableForWrite();
    while (free_bytes-- > 0 && tail != head) {
        Serial.write((uint8_t)ring[tail]);
        tail = next(tail);
    }
}

static void put(char c) {
    while (ring_room() == 0) pump();
    ring[head] = c;
    head = next(head);
}

void write(const char* data, uint8_t len) {
    for (uint8_t i = 0; i < len; ++i) put(data[i]);
}

bool write_line_if_room(const char* line, uint8_t len) {
    if (room() < len) return false;
    write(line, len);
    return true;
}

void flush() {
    while (tail != head) pump();
    Serial.flush();
}

}  // namespace serial_text
