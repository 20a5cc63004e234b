#include "SerialText.h"

#include "ArduinoCore.h"

namespace serial_text {

static_assert((kCapacity & (kCapacity - 1u)) == 0, "kCapacity must be a power of two");
constexpr uint16_t kMask = kCapacity - 1u;

static char ring[kCapacity];
static uint16_t head = 0, tail = 0;  // head: next write, tail: next byte for Serial

uint16_t queued() { return (uint16_t)((head - tail) & kMask); }
uint16_t room() { return (uint16_t)(kMask - queued()); }

void begin() { Serial.begin(kBaud); }

void pump() {
    int free_bytes = Serial.availableForWrite();
    while (free_bytes-- > 0 && tail != head) {
        Serial.write((uint8_t)ring[tail]);
        tail = (uint16_t)((tail + 1u) & kMask);
    }
}

static void put(char c) {
    while (room() == 0) pump();
    ring[head] = c;
    head = (uint16_t)((head + 1u) & kMask);
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
