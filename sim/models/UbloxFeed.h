// SPDX-License-Identifier: GPL-3.0-or-later
// The u-blox model (UbloxModel.h) as the host replay tool's GPS: configured as ArduPilot
// configured the module on the APM 2 and the firmware does (PUBX,41 at 9600 baud for UBX at
// 38400, then NAV-POSLLH, -STATUS, -SOL and -VELNED at rate 1 and a 200 ms measurement
// period), its bytes decoded when their
// stop bit has left the line, and each solution (NAV-SOL and NAV-VELNED of one iTOW) given
// as the gps::Fix the firmware's driver delivers: the model's noise, latency, fix and
// satellites, and the line's time, without simavr.
// Host-only.
#pragma once

#include <stdint.h>

#include <deque>

#include "GpsFix.h"
#include "Trajectory.h"
#include "UbloxModel.h"
#include "Ubx.h"

namespace sim {

class UbloxFeed {
public:
    // The configuration is sent at kConfigure_s (the firmware's GPS detection runs from
    // its set-up on).
    static constexpr double kConfigure_s = 0.6;
    // path: its n,e,d positions and velocities (Trajectory::at).
    UbloxFeed(const Trajectory& path, const UbloxOptions& options);
    // Runs the module and the line to t_s; true with the next solution complete by then
    // (call again for another: at 5 Hz there is at most one).
    bool poll(double t_s, gps::Fix& fix);
    UbloxModel& model() { return model_; }

private:
    void send(double t_s, const std::vector<uint8_t>& bytes, uint32_t baud);
    bool take(const ubx::StreamParser::Message& m, double t_s, gps::Fix& fix);

    UbloxModel model_;
    ubx::StreamParser parser_;
    std::deque<UartFrame> line_;  // the module's frames not yet complete
    double now_s_ = 0.0;
    bool configured_ = false;
    uint32_t sol_itow_ = 0;
    uint8_t sol_fix_ = 0, sol_flags_ = 0, sol_sats_ = 0;
    uint16_t sol_pdop_ = 9999;
    bool have_sol_ = false;
};

}  // namespace sim
