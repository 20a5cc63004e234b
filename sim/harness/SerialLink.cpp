// SPDX-License-Identifier: GPL-3.0-or-later
#include "SerialLink.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "WallClock.h"

namespace sim {

bool parse_serial_spec(const std::string& spec, int& port, std::string& error) {
    const std::string prefix = "tcp:";
    if (spec.compare(0, prefix.size(), prefix) != 0) {
        error = "--serial '" + spec + "': only tcp:PORT is known";
        return false;
    }
    const std::string digits = spec.substr(prefix.size());
    char* end = nullptr;
    const long value = digits.empty() ? -1 : std::strtol(digits.c_str(), &end, 10);
    if (digits.empty() || *end != '\0' || value < 0 || value > 65535) {
        error = "--serial '" + spec + "': the port must be a number 0..65535";
        return false;
    }
    port = (int)value;
    return true;
}

TcpSerial::~TcpSerial() {
    drop_client();
    if (listener_ >= 0) close(listener_);
}

bool TcpSerial::listen(int port) {
    listener_ = socket(AF_INET, SOCK_STREAM, 0);
    if (listener_ < 0) {
        error_ = std::string("cannot open a TCP socket: ") + std::strerror(errno);
        return false;
    }
    const int yes = 1;
    setsockopt(listener_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in addr;
    std::memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons((uint16_t)port);
    if (bind(listener_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listener_, 1) != 0) {
        char what[64];
        std::snprintf(what, sizeof what, "cannot listen on 127.0.0.1:%d: ", port);
        error_ = what + std::string(std::strerror(errno));
        return false;
    }
    socklen_t len = sizeof addr;
    getsockname(listener_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    fcntl(listener_, F_SETFL, fcntl(listener_, F_GETFL) | O_NONBLOCK);
    return true;
}

void TcpSerial::drop_client() {
    if (client_ >= 0) close(client_);
    client_ = -1;
    out_.clear();
}

std::string TcpSerial::poll(std::string& received) {
    std::string event;
    if (client_ < 0 && listener_ >= 0) {
        const int fd = accept(listener_, nullptr, nullptr);
        if (fd >= 0) {
            fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
            const int yes = 1;
            setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);  // a byte goes when it leaves the UART
            client_ = fd;
            event = "client connected";
        }
    }
    if (client_ < 0) return event;
    char buffer[4096];
    for (;;) {
        const ssize_t n = recv(client_, buffer, sizeof buffer, 0);
        if (n > 0) {
            received.append(buffer, (size_t)n);
            continue;
        }
        if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
            drop_client();
            return "client disconnected";
        }
        break;
    }
    while (!out_.empty()) {
        const ssize_t n = ::send(client_, out_.data(), out_.size(), MSG_NOSIGNAL);
        if (n > 0) {
            out_.erase(0, (size_t)n);
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) break;
        drop_client();
        return "client disconnected";
    }
    return event;
}

void TcpSerial::send(uint8_t byte) {
    if (client_ < 0) return;
    if (out_.size() >= kMaxQueued) {
        ++dropped_;
        return;
    }
    out_.push_back((char)byte);
}


void Pacer::wait_until(double sim_s) {
    if (speed_ <= 0.0) return;
    if (!started_) {
        started_ = true;
        wall_start_s_ = wall_clock_s();
        sim_start_s_ = sim_s;
        return;
    }
    const double ahead_s = (sim_s - sim_start_s_) / speed_ - (wall_clock_s() - wall_start_s_);
    if (ahead_s <= 0.0) return;
    timespec ts;
    ts.tv_sec = (time_t)ahead_s;
    ts.tv_nsec = (long)((ahead_s - (double)ts.tv_sec) * 1e9);
    nanosleep(&ts, nullptr);
}

}  // namespace sim
