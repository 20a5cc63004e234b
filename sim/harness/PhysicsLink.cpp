// SPDX-License-Identifier: GPL-3.0-or-later
#include "PhysicsLink.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "WallClock.h"

namespace sim {


bool parse_physics_spec(const std::string& spec, PhysicsOptions& options, std::string& error) {
    if (spec.compare(0, 4, "json") != 0 || (spec.size() > 4 && spec[4] != ':')) {
        error = "--physics '" + spec + "': only json[:HOST[:PORT]] is known";
        return false;
    }
    if (spec.size() == 4) return true;
    const std::string rest = spec.substr(5);
    const size_t colon = rest.find(':');
    options.host = rest.substr(0, colon);
    if (options.host.empty()) {
        error = "--physics '" + spec + "': HOST is empty";
        return false;
    }
    if (colon != std::string::npos) {
        const std::string digits = rest.substr(colon + 1);
        char* end = nullptr;
        const long port = digits.empty() ? 0 : std::strtol(digits.c_str(), &end, 10);
        if (digits.empty() || *end != '\0' || port < 1 || port > 65535) {
            error = "--physics '" + spec + "': the port must be a number 1..65535";
            return false;
        }
        options.port = (int)port;
    }
    return true;
}

PhysicsLink::~PhysicsLink() {
    if (fd_ >= 0) close(fd_);
}

bool PhysicsLink::open() {
    addrinfo hints;
    std::memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_DGRAM;
    addrinfo* found = nullptr;
    if (getaddrinfo(options_.host.c_str(), nullptr, &hints, &found) != 0 || !found) {
        error_ = "cannot resolve the physics backend's host '" + options_.host + "'";
        return false;
    }
    std::memcpy(&address_, found->ai_addr, sizeof address_);
    freeaddrinfo(found);
    address_.sin_port = htons((uint16_t)options_.port);
    fd_ = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd_ < 0) {
        error_ = std::string("cannot open a UDP socket: ") + std::strerror(errno);
        return false;
    }
    // Any free port: the backend answers to where the packet came from (the readme). A
    // backend on this machine is answered on loopback only.
    sockaddr_in local;
    std::memset(&local, 0, sizeof local);
    local.sin_family = AF_INET;
    const bool loopback = (ntohl(address_.sin_addr.s_addr) >> 24) == 127;
    local.sin_addr.s_addr = htonl(loopback ? INADDR_LOOPBACK : INADDR_ANY);
    if (bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0) {
        error_ = std::string("cannot bind the physics socket: ") + std::strerror(errno);
        return false;
    }
    return true;
}

bool PhysicsLink::exchange(uint32_t frame_count, const uint16_t pwm_us[kSitlServoChannels], PhysicsState& state) {
    // Whatever is waiting answers an earlier send (a resent frame answered twice, or a
    // backend that steps on every packet): dropped, so that the answer taken is this
    // frame's. What comes later is told by its timestamp (ReplyClock).
    char buffer[65536];
    while (recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT) > 0) ++drained_;
    const std::string packet = encode_servo_packet((uint16_t)options_.frame_rate_hz, frame_count, pwm_us);
    const double start_s = wall_clock_s();
    double sent_s = -1e9;
    uint32_t stale = 0;  // stale replies in this wait
    double stale_last_s = 0.0;
    for (;;) {
        if (stop_ && stop_()) {  // SIGINT/SIGTERM while the backend is silent
            stopped_ = true;
            error_ = "stopped while waiting for the physics backend";
            return false;
        }
        const double now_s = wall_clock_s();
        if (now_s - start_s >= options_.give_up_s) {
            char why[320];
            if (stale == 0) {
                std::snprintf(why, sizeof why, "no answer from the physics backend at %s:%d to frame %u for %.0f s",
                              options_.host.c_str(), options_.port, (unsigned)frame_count, options_.give_up_s);
            } else {
                std::snprintf(why, sizeof why,
                              "no new state from the physics backend at %s:%d for frame %u in %.0f s: %u "
                              "replies, none after %.6f s (the last at %.6f s): its time stands still or went "
                              "back",
                              options_.host.c_str(), options_.port, (unsigned)frame_count, options_.give_up_s,
                              (unsigned)stale, clock_.last_s(), stale_last_s);
            }
            error_ = why;
            return false;
        }
        if (now_s - sent_s >= options_.resend_s) {
            if (sent_s > -1e9) {
                ++resends_;
                std::fprintf(stderr,
                             "apm25sim: the physics backend at %s:%d has not answered frame %u for %.0f s: "
                             "sending it again\n",
                             options_.host.c_str(), options_.port, (unsigned)frame_count, now_s - start_s);
            }
            // An unreachable port (ICMP) only delays the answer: sendto's errors are not fatal.
            sendto(fd_, packet.data(), packet.size(), 0, reinterpret_cast<const sockaddr*>(&address_), sizeof address_);
            sent_s = now_s;
        }
        double wait_s = sent_s + options_.resend_s - now_s;
        if (start_s + options_.give_up_s - now_s < wait_s) wait_s = start_s + options_.give_up_s - now_s;
        pollfd p{fd_, POLLIN, 0};
        const int ready = poll(&p, 1, (int)(wait_s * 1000.0) + 1);
        if (ready <= 0) continue;
        const ssize_t n = recv(fd_, buffer, sizeof buffer, 0);
        if (n <= 0) continue;  // e.g. ECONNREFUSED reported for an earlier send
        std::string why;
        PhysicsState reply;
        if (!parse_physics_state(std::string(buffer, (size_t)n), reply, why)) {
            error_ = "the physics backend's answer to frame " + std::to_string(frame_count) + ": " + why;
            return false;
        }
        if (!clock_.take(reply.timestamp_s)) {  // an earlier send's answer: wait on
            ++stale;
            stale_last_s = reply.timestamp_s;
            continue;
        }
        state = reply;
        return true;
    }
}

std::string PhysicsLink::summary() const {
    char text[160];
    std::snprintf(text, sizeof text, "%u frames, %u sent again, %u late or duplicate replies dropped",
                  (unsigned)clock_.taken(), (unsigned)resends_, (unsigned)dropped_replies());
    return text;
}

}  // namespace sim
