// A span of simulated time [start_s, end_s) during which a fault is active.
// Shared by the sensor register models and the simavr harness's fault parser.
#pragma once

#include <limits>

namespace sim {

struct TimeWindow {
    double start_s = std::numeric_limits<double>::infinity();  // never, by default
    double end_s = std::numeric_limits<double>::infinity();

    static TimeWindow always() { return TimeWindow{0.0, std::numeric_limits<double>::infinity()}; }
    static TimeWindow between(double t1_s, double t2_s) { return TimeWindow{t1_s, t2_s}; }
    bool active(double t_s) const { return t_s >= start_s && t_s < end_s; }
    bool ever() const { return start_s < end_s && start_s < std::numeric_limits<double>::infinity(); }
};

}  // namespace sim
