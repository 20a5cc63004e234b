// SPDX-License-Identifier: GPL-3.0-or-later
// `--serial tcp:PORT`: UART0 served on a TCP port of the loopback interface, as ArduPilot's
// SITL serves its first serial port on 5760, so that MAVProxy and the ground stations
// connect to the simulated board as to a board. One client at a time; a client that
// disconnects leaves the port listening for the next. No simavr here: the harness moves
// the bytes between this and the UART, and paces simulated time to the wall clock.
#pragma once

#include <stdint.h>

#include <string>

namespace sim {

// Parses "tcp:PORT" (PORT 0..65535; 0 lets the system choose). False with `error` set.
bool parse_serial_spec(const std::string& spec, int& port, std::string& error);

class TcpSerial {
public:
    ~TcpSerial();
    // Listens on 127.0.0.1:port (loopback only). False with error() set.
    bool listen(int port);
    const std::string& error() const { return error_; }
    int port() const { return port_; }  // the port listened on (the chosen one for 0)
    bool connected() const { return client_ >= 0; }

    // Accepts a waiting client, reads what it sent (appended to `received`), writes what
    // is queued; never blocks. Returns a line for stderr when a client came or went.
    std::string poll(std::string& received);
    // Queues a byte for the client (dropped while none is connected, as on a serial line
    // with nobody listening; beyond kMaxQueued bytes unread by the client, dropped too).
    void send(uint8_t byte);
    uint64_t dropped() const { return dropped_; }

    static constexpr size_t kMaxQueued = 1u << 20;

private:
    void drop_client();

    int listener_ = -1;
    int client_ = -1;
    int port_ = 0;
    std::string out_;
    uint64_t dropped_ = 0;
    std::string error_;
};

// Keeps simulated time from running ahead of the wall clock: `speed` simulated seconds
// per wall second (0: as fast as the host runs). Behind, it never waits.
class Pacer {
public:
    explicit Pacer(double speed) : speed_(speed) {}
    void wait_until(double sim_s);

private:
    double speed_;
    bool started_ = false;
    double wall_start_s_ = 0.0, sim_start_s_ = 0.0;
};

}  // namespace sim
