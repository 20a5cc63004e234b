// SPDX-License-Identifier: GPL-3.0-or-later
// Seeded noise for the sensor models: the same seed gives the same numbers on every host
// (splitmix64 and Box-Muller written out, where the standard library's distributions are
// free to differ between implementations).
#pragma once

#include <stdint.h>

#include <cmath>

namespace sim {

class NoiseSource {
public:
    explicit NoiseSource(uint64_t seed = 1) : state_(seed) {}

    // splitmix64 (Steele, Lea, Flood 2014): a full-period 64-bit sequence.
    uint64_t next_u64() {
        uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // Uniform in [0, 1), 53 bits.
    double uniform() { return (double)(next_u64() >> 11) * (1.0 / 9007199254740992.0); }
    // Standard normal (Box-Muller, the second value of each pair kept for the next call).
    double gauss() {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        double u1 = uniform();
        if (u1 < 1e-300) u1 = 1e-300;
        const double u2 = uniform();
        const double r = std::sqrt(-2.0 * std::log(u1));
        spare_ = r * std::sin(2.0 * M_PI * u2);
        has_spare_ = true;
        return r * std::cos(2.0 * M_PI * u2);
    }

private:
    uint64_t state_;
    double spare_ = 0.0;
    bool has_spare_ = false;
};

// A first-order Gauss-Markov process: x <- a x + sqrt(1 - a^2) sigma w, a = exp(-dt/tau),
// w standard normal. Stationary standard deviation sigma, correlation time tau: a slow
// random walk that does not wander off (a GPS position error).
class GaussMarkov {
public:
    GaussMarkov(double sigma, double tau_s) : sigma_(sigma), tau_s_(tau_s) {}
    // Starts from a draw of the stationary distribution.
    void start(NoiseSource& noise) { x_ = sigma_ * noise.gauss(); }
    double step(double dt_s, NoiseSource& noise) {
        const double a = tau_s_ > 0.0 ? std::exp(-dt_s / tau_s_) : 0.0;
        x_ = a * x_ + std::sqrt(1.0 - a * a) * sigma_ * noise.gauss();
        return x_;
    }
    double value() const { return x_; }

private:
    double sigma_, tau_s_;
    double x_ = 0.0;
};

}  // namespace sim
