// SPDX-License-Identifier: GPL-3.0-or-later
// The radio side of the simulated APM 2.5 (../shared/APM25.md, "Flying"), host-only and
// without simavr so that the unit tests cover it:
// - RcScript: the `--rc FILE` stick script (CSV `t,ch1,...,ch8`, seconds and us): a row
//   holds from its time until the next; a row with every channel empty is a dead
//   receiver (no PPM); before the first row there is no signal.
// - PpmEncoder: the PPM sum the board's ATmega32U2 encoder (ArduPPM) puts on ICP5 (PL1):
//   8 channels in a 22.5 ms frame, each channel a 400 us low pre-pulse then the line
//   high until the next pre-pulse, so consecutive rising edges are one channel width
//   apart; between frames the line stays high (the sync gap). This is ArduPPM's default
//   (negative) frame: its output starts low and toggles, the period segment is high.
//   ArduPilot's APM2 HAL captures rising edges (ICES5) and takes rising-to-rising
//   intervals as the widths, a gap over 4 ms as the frame sync.
// - ServoPulseLog: pulses measured from the servo output pins' edges (`--servo-log`).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <string>
#include <vector>

namespace sim {

constexpr int kRcChannels = 8;
constexpr int kServoOutputs = 8;

struct RcRow {
    double t_s = 0.0;
    bool signal = false;                 // false: the receiver is dead (no PPM)
    double width_us[kRcChannels] = {};   // valid when signal
};

class RcScript {
public:
    // The channel widths a script may ask for: the pre-pulse (400 us) must fit inside
    // a channel, and the encoder cannot send more than its frame holds.
    static constexpr double kMinWidth_us = 500.0;
    static constexpr double kMaxWidth_us = 3000.0;

    // Parses the CSV text. False with error() naming `name` and the line on bad input
    // (wrong header, a row with some but not all channels, a width out of range, a
    // non-numeric value, times not strictly increasing or negative).
    bool parse(const std::string& text, const std::string& name);
    bool load(const std::string& path);
    const std::string& error() const { return error_; }

    // Appends a row at or after the last one's time (the physics backend's `rc`);
    // false (nothing added) when it goes back in time or a width is out of range.
    bool push(const RcRow& row);

    const std::vector<RcRow>& rows() const { return rows_; }
    // Forgets the rows before t_s but the one in force at t_s (a long flight's history).
    void drop_before(double t_s);
    // The row in force at t (nullptr before the first row).
    const RcRow* at(double t_s) const;

private:
    std::vector<RcRow> rows_;
    std::string error_;
};

// One level change of the PPM line.
struct PpmEdge {
    double t_s = 0.0;
    bool high = true;
};

class PpmEncoder {
public:
    static constexpr double kFrame_us = 22500.0;
    static constexpr double kPrePulse_us = 400.0;
    // The shortest sync interval (rising edge to rising edge) the encoder leaves: a
    // frame of very long widths is stretched rather than losing its sync. 8 channels of
    // 2200 us leave 4.9 ms in 22.5 ms, so any plausible frame keeps its 22.5 ms.
    static constexpr double kMinSync_us = 4500.0;

    // The line idles high (no signal).
    explicit PpmEncoder(const RcScript& script) : script_(script) {}

    // The next level change after the last one returned, in time order. False when none
    // is due from the rows known so far (the receiver is dead, or no row yet): call
    // again after RcScript::push. A frame, once begun, is sent whole with the widths in
    // force at its start; a dead row stops the signal after the frame in progress.
    bool next_edge(PpmEdge& edge);

    // Frames begun so far.
    unsigned long frames() const { return frames_; }

private:
    bool start_frame();

    const RcScript& script_;
    bool in_frame_ = false;
    int edge_index_ = 0;            // 0..17 within the frame: even = falling, odd = rising
    double frame_start_s_ = 0.0;
    double frame_length_s_ = 0.0;
    double widths_us_[kRcChannels] = {};
    double resume_s_ = 0.0;         // no frame starts before this
    unsigned long frames_ = 0;
};

// One servo pulse measured from its pin.
struct ServoPulse {
    double rise_s = 0.0;
    int output = 0;          // 1..8
    double width_us = 0.0;
};

// Turns the outputs' pin levels into pulses, handed out in the order of their rising
// edges (ties by output number), each once it has ended and no pulse still high on
// another output began before it.
class ServoPulseLog {
public:
    // The level of output 1..8 at t_s (repeats of the same level are ignored).
    void level(int output, double t_s, bool high);
    // Pulses ready in order; with `all`, every ended pulse (the run's end: a pulse
    // still high is not a pulse yet and is dropped).
    void take(std::vector<ServoPulse>& out, bool all = false);
    // The width of the last pulse that ended on the output (0 before any).
    double last_width_us(int output) const;
    // The width a servo on the output is being sent at t_s, rounded to the microsecond: the
    // last pulse's while pulses keep coming (one ended within `stale_s`), else 0 (no
    // signal, as ArduPilot sends for an output that is off).
    uint16_t width_now_us(int output, double t_s, double stale_s) const;
    // "t,out,width_us" and one row: rise time (s, six decimals), output, width (us,
    // two decimals).
    static const char* header() { return "t,out,width_us\n"; }
    static std::string format(const ServoPulse& pulse);

private:
    bool high_[kServoOutputs] = {};
    double rise_s_[kServoOutputs] = {};
    double last_width_us_[kServoOutputs] = {};
    double last_end_s_[kServoOutputs] = {};
    std::vector<ServoPulse> ended_;
};

}  // namespace sim
