// SPDX-License-Identifier: GPL-3.0-or-later
// `--physics json[:HOST[:PORT]]`: apm25sim plays ArduPilot's side of ArduPilot's SITL JSON
// interface (sim/models/SitlJson.h for the formats): one UDP servo packet a physics frame to
// the backend (default 127.0.0.1:9002), which answers to the address the packet came from
// with the state after its step. Lock-step: the next frame goes only after the answer.
#pragma once

#include <netinet/in.h>
#include <stdint.h>

#include <string>

#include "SitlJson.h"

namespace sim {

struct PhysicsOptions {
    std::string host = "127.0.0.1";
    int port = 9002;
    int frame_rate_hz = 1000;     // asked of the backend in every packet
    double resend_s = 1.0;        // a frame not answered within this is sent again, same count
    double give_up_s = 30.0;      // no answer for this long: the run stops with an error
};

// Parses "json", "json:HOST" or "json:HOST:PORT" into `options`. False with `error` set.
bool parse_physics_spec(const std::string& spec, PhysicsOptions& options, std::string& error);

class PhysicsLink {
public:
    explicit PhysicsLink(const PhysicsOptions& options) : options_(options) {}
    ~PhysicsLink();
    bool open();  // false with error() set
    const std::string& error() const { return error_; }

    // Sends frame `frame_count` with the widths and waits for the backend's state: resends
    // the same frame every resend_s and says so on stderr. A reply that answers an earlier
    // send (waiting before this frame is sent, or a timestamp not after the last state
    // taken: ReplyClock) is dropped and counted, and the wait goes on. False with error()
    // set when no new state came within give_up_s (a silent backend, or one whose time
    // does not move or went back), or an answer is not a state.
    bool exchange(uint32_t frame_count, const uint16_t pwm_us[kSitlServoChannels], PhysicsState& state);
    uint32_t resends() const { return resends_; }
    uint32_t frames_taken() const { return clock_.taken(); }
    // Replies dropped: late or duplicate answers to earlier sends.
    uint32_t dropped_replies() const { return drained_ + clock_.stale(); }
    // "FRAMES frames, R sent again, D late or duplicate replies dropped" for the summary.
    std::string summary() const;
    // Checked while waiting: when it says so, exchange returns false with stopped() true.
    void set_stop_check(bool (*stop)()) { stop_ = stop; }
    bool stopped() const { return stopped_; }

private:
    PhysicsOptions options_;
    int fd_ = -1;
    sockaddr_in address_{};  // the backend
    std::string error_;
    uint32_t resends_ = 0;
    uint32_t drained_ = 0;  // replies waiting before a frame was sent
    ReplyClock clock_;
    bool (*stop_)() = nullptr;
    bool stopped_ = false;
};

}  // namespace sim
