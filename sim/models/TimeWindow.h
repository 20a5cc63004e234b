// SPDX-License-Identifier: GPL-3.0-or-later
// Spans of simulated time during which a fault is active.
// Shared by the sensor register models and the simavr harness's fault parser.
#pragma once

#include <limits>
#include <vector>

namespace sim {

// One span [start_s, end_s).
struct TimeWindow {
    double start_s = std::numeric_limits<double>::infinity();  // never, by default
    double end_s = std::numeric_limits<double>::infinity();

    static TimeWindow always() { return TimeWindow{0.0, std::numeric_limits<double>::infinity()}; }
    static TimeWindow between(double t1_s, double t2_s) { return TimeWindow{t1_s, t2_s}; }
    bool active(double t_s) const { return t_s >= start_s && t_s < end_s; }
    bool ever() const { return start_s < end_s && start_s < std::numeric_limits<double>::infinity(); }
    // Two half-open spans share an instant.
    bool overlaps(const TimeWindow& o) const { return start_s < o.end_s && o.start_s < end_s; }
};

// Any number of disjoint windows of one fault kind (empty: never active).
class TimeWindows {
public:
    TimeWindows() = default;
    TimeWindows(const TimeWindow& w) { windows_.push_back(w); }  // one window (tests, defaults)

    // Adds `w`; false (nothing added) when it shares an instant with one already held:
    // two windows of one kind that overlap are a mistake in the fault list, not a union.
    bool add(const TimeWindow& w) {
        for (const TimeWindow& o : windows_)
            if (o.overlaps(w)) return false;
        windows_.push_back(w);
        return true;
    }
    bool active(double t_s) const {
        for (const TimeWindow& w : windows_)
            if (w.active(t_s)) return true;
        return false;
    }
    bool ever() const {
        for (const TimeWindow& w : windows_)
            if (w.ever()) return true;
        return false;
    }
    const std::vector<TimeWindow>& windows() const { return windows_; }

private:
    std::vector<TimeWindow> windows_;
};

// Disjoint windows of one fault kind that each carry a value (a glitch's metres, a
// satellite count).
struct ValueWindow {
    TimeWindow window;
    double value = 0.0;
};

class ValueWindows {
public:
    // Adds `w` with `value`; false (nothing added) when it overlaps one already held.
    bool add(const TimeWindow& w, double value) {
        for (const ValueWindow& o : windows_)
            if (o.window.overlaps(w)) return false;
        windows_.push_back(ValueWindow{w, value});
        return true;
    }
    // The window active at t_s, or nullptr.
    const ValueWindow* active(double t_s) const {
        for (const ValueWindow& w : windows_)
            if (w.window.active(t_s)) return &w;
        return nullptr;
    }
    const std::vector<ValueWindow>& windows() const { return windows_; }

private:
    std::vector<ValueWindow> windows_;
};

}  // namespace sim
