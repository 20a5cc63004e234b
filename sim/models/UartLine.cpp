// SPDX-License-Identifier: GPL-3.0-or-later
#include "UartLine.h"

#include <cmath>
#include <limits>

namespace sim {

namespace {

// The bit (0..9) of frame f at time t, or -1 outside it: 0 start (low), 1..8 data LSB
// first, 9 stop (high).
int frame_bit(const UartFrame& f, double t_s) {
    if (t_s < f.start_s || t_s >= f.end_s()) return -1;
    int index = (int)std::floor((t_s - f.start_s) / f.bit_s);
    if (index > 9) index = 9;
    if (index == 0) return 0;
    if (index == 9) return 1;
    return (f.byte >> (index - 1)) & 1;
}

}  // namespace

double usart_bit_s(uint32_t cpu_hz, unsigned ubrr, bool u2x) {
    return (double)((u2x ? 8u : 16u) * (ubrr + 1u)) / (double)cpu_hz;
}

void UartReceiver::push(const UartFrame& frame) {
    UartFrame f = frame;
    if (!frames_.empty() && f.start_s < frames_.back().end_s()) f.start_s = frames_.back().end_s();
    frames_.push_back(f);
}

void UartReceiver::reset() {
    frames_.clear();
    search_from_s_ = 0.0;
}

int UartReceiver::level_at(double t_s) const {
    for (const UartFrame& f : frames_) {
        if (f.start_s > t_s) break;
        const int bit = frame_bit(f, t_s);
        if (bit >= 0) return bit;
    }
    return 1;
}

bool UartReceiver::next_edge(double t_s, double& edge_s, const UartFrame** frame) const {
    for (const UartFrame& f : frames_) {
        if (f.end_s() <= t_s) continue;
        // A frame's start is a falling edge: before it the line is idle or a stop bit.
        if (f.start_s >= t_s) {
            edge_s = f.start_s;
            *frame = &f;
            return true;
        }
        // Inside the frame: data bit k-1 high then data bit k low (k = 1..7), at bit k+1.
        for (int bit = 2; bit <= 8; ++bit) {
            const double at = f.start_s + bit * f.bit_s;
            if (at < t_s) continue;
            const int before = (f.byte >> (bit - 2)) & 1, now = (f.byte >> (bit - 1)) & 1;
            if (before == 1 && now == 0) {
                edge_s = at;
                *frame = nullptr;
                return true;
            }
        }
    }
    return false;
}

bool UartReceiver::matched(const UartFrame& f) const {
    const double ratio = bit_s_ / f.bit_s;
    return ratio >= 0.95 && ratio < 1.05;
}

double UartReceiver::next_ready_s() const {
    double edge_s = 0.0;
    const UartFrame* frame = nullptr;
    if (!next_edge(search_from_s_, edge_s, &frame)) return std::numeric_limits<double>::infinity();
    if (frame && frame->start_s == edge_s && matched(*frame)) return edge_s;
    return edge_s + 9.5 * bit_s_;
}

void UartReceiver::decode(double t_s, std::vector<UartChar>& out) {
    for (;;) {
        double edge_s = 0.0;
        const UartFrame* frame = nullptr;
        if (!next_edge(search_from_s_, edge_s, &frame)) break;
        UartChar c;
        c.edge_s = edge_s;
        if (frame && frame->start_s == edge_s && matched(*frame)) {
            // Every sample falls in its own bit of this frame: the frame's byte.
            if (edge_s > t_s) break;
            c.ready_s = edge_s;
            c.byte = frame->byte;
            c.framing_ok = true;
        } else {
            c.ready_s = edge_s + 9.5 * bit_s_;
            if (c.ready_s > t_s) break;  // a frame still to come may change the samples
            if (level_at(edge_s + 0.5 * bit_s_) != 0) {  // a false start bit
                search_from_s_ = edge_s + 0.5 * bit_s_;
                continue;
            }
            uint8_t byte = 0;
            for (int k = 0; k < 8; ++k)
                if (level_at(edge_s + (1.5 + k) * bit_s_)) byte = (uint8_t)(byte | (1u << k));
            c.byte = byte;
            c.framing_ok = level_at(edge_s + 9.5 * bit_s_) == 1;
        }
        search_from_s_ = edge_s + 9.5 * bit_s_;
        out.push_back(c);
        // Frames wholly before the next search cannot matter any more.
        while (!frames_.empty() && frames_.front().end_s() <= search_from_s_) frames_.pop_front();
    }
}

}  // namespace sim
