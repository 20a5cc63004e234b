// SPDX-License-Identifier: GPL-3.0-or-later
// An asynchronous serial line (8 data bits, no parity, 1 stop bit: 8N1) between two ends
// that need not agree on the baud rate, as the GPS port between the ATmega2560's USART1
// and the GPS module.
//
// The sender puts frames on the line: a start bit (low), 8 data bits LSB first, a stop
// bit (high), each bit lasting the sender's bit time; the line idles high. The receiver
// decodes the line at its own bit time as a UART does (ATmega2560 datasheet 22.8,
// "Asynchronous Data Reception", simplified to one sample per bit): a high-to-low edge
// starts a character, the start bit is checked at its middle (still low, else a false
// start and the edge is forgotten), then data bit k is sampled at (1.5 + k) receiver bit
// times after the edge and the stop bit at 9.5; a low stop bit is a framing error. The
// receiver then waits for the next high-to-low edge.
//
// At equal baud rates (within the 5 % that keeps every sample inside its own bit) each
// frame decodes to its own byte; at any other rate the receiver sees what a real one
// would: other bytes, framing errors, or nothing while the line is idle. The datasheet's
// three-sample majority vote and the clock-recovery fine points are not modelled.
//
// Host-only: the simavr harness feeds it the frames the USART1 and the GPS model send.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <deque>
#include <vector>

namespace sim {

struct UartFrame {
    double start_s = 0.0;  // the start bit's falling edge
    double bit_s = 0.0;    // the sender's bit time (1 / baud)
    uint8_t byte = 0;
    double end_s() const { return start_s + 10.0 * bit_s; }
};

struct UartChar {
    double edge_s = 0.0;   // the falling edge the receiver started on
    double ready_s = 0.0;  // when the receiver could know it (see UartReceiver::decode)
    uint8_t byte = 0;
    bool framing_ok = true;
};

// The bit time of a USART at UBRR with U2X (ATmega2560 datasheet table 22-1), seconds.
double usart_bit_s(uint32_t cpu_hz, unsigned ubrr, bool u2x);

class UartReceiver {
public:
    explicit UartReceiver(double bit_s = 1.0 / 9600.0) : bit_s_(bit_s) {}
    // The receiver's bit time from the next character on.
    void set_bit_s(double bit_s) { bit_s_ = bit_s; }
    double bit_s() const { return bit_s_; }

    // A frame put on the line. Frames come in the order of their start, each when (or
    // before) the line reaches its start; a frame starting before the previous one ends
    // starts when it ends instead (one sender, one line).
    void push(const UartFrame& frame);

    // Appends the characters the receiver has decoded by time t_s, in order. A character
    // is known once the line up to its stop-bit sample is known: at that sample (ready_s)
    // in general, or already at its edge when the edge is a frame's start at a bit time
    // within 5 % of the receiver's (the frame alone then decides every sample).
    void decode(double t_s, std::vector<UartChar>& out);
    // The earliest time a character can be ready given the frames pushed so far
    // (infinity when none is pending).
    double next_ready_s() const;

    // Forgets the frames and any character in progress (a receiver switched off).
    void reset();

private:
    int level_at(double t_s) const;  // 1 idle/high, 0 low
    // The first falling edge at or after t_s among the frames known; false if none.
    bool next_edge(double t_s, double& edge_s, const UartFrame** frame) const;
    bool matched(const UartFrame& f) const;

    double bit_s_;
    std::deque<UartFrame> frames_;
    double search_from_s_ = 0.0;
};

}  // namespace sim
