// SPDX-License-Identifier: GPL-3.0-or-later
// apm25sim --serial tcp:PORT: the firmware's UART0 served on a loopback TCP port, as
// ArduPilot's SITL serves 5760. A client reads the firmware's lines, types a command and
// reads the reply, leaves, and another connects; SIGTERM ends the run cleanly.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>

#include <cstring>
#include <regex>

#include "harness_live.h"

namespace {

int connect_to(int port) {
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr;
    std::memset(&addr, 0, sizeof addr);
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons((uint16_t)port);
    if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

// Reads from the client socket until `done(text so far)` or the guard; returns the text.
template <typename Done>
std::string read_until(int fd, Done done) {
    std::string text;
    while (!done(text)) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, e2e::kGuard_ms) <= 0) break;
        char buffer[4096];
        const ssize_t n = recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) break;
        text.append(buffer, (size_t)n);
    }
    return text;
}

int count_angle_lines(const std::string& text) {
    int n = 0;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("roll:", 0) == 0 && in.good()) ++n;  // whole lines only
    return n;
}

TEST(HarnessSerial, AClientOverTcpReadsTheBoardAndTypesCommands) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario", "firmware.elf");
    const std::string out_path = e2e::work_dir() + "/serial_stdout." + std::to_string(getpid()) + ".txt";
    e2e::LiveProcess sim;
    ASSERT_TRUE(sim.start({e2e::tool("apm25sim"), "--elf", e2e::firmware_elf(), "--trajectory",
                           e2e::scenario_csv("rest", 30), "--serial", "tcp:0", "--seconds", "60"},
                          2, out_path));
    const std::string port_text = sim.wait_line("serving UART0 on tcp:127\\.0\\.0\\.1:([0-9]+)");
    ASSERT_FALSE(port_text.empty()) << sim.text;
    const int port = std::atoi(port_text.c_str());

    // First client: the board's lines, then `rate 10` and its reply.
    int fd = connect_to(port);
    ASSERT_GE(fd, 0);
    const std::string boot = read_until(fd, [](const std::string& t) { return count_angle_lines(t) >= 3; });
    EXPECT_GE(count_angle_lines(boot), 3) << boot;
    EXPECT_NE(boot.find("# calibrating gyro"), std::string::npos) << boot.substr(0, 2000);
    ASSERT_EQ(send(fd, "rate 10\n", 8, 0), 8);
    const std::string reply = read_until(fd, [](const std::string& t) { return t.find("# rate 10 Hz\n") != std::string::npos; });
    EXPECT_NE(reply.find("# rate 10 Hz\n"), std::string::npos) << reply.substr(0, 2000);
    close(fd);
    EXPECT_FALSE(sim.wait_line("tcp:[0-9]+ client disconnected").empty()) << sim.text;

    // A second client gets the port, the lines and the console.
    fd = connect_to(port);
    ASSERT_GE(fd, 0);
    const std::string again = read_until(fd, [](const std::string& t) { return count_angle_lines(t) >= 2; });
    EXPECT_GE(count_angle_lines(again), 2) << again;
    ASSERT_EQ(send(fd, "rate 25\n", 8, 0), 8);
    const std::string reply2 = read_until(fd, [](const std::string& t) { return t.find("# rate 25 Hz\n") != std::string::npos; });
    EXPECT_NE(reply2.find("# rate 25 Hz\n"), std::string::npos) << reply2.substr(0, 2000);

    // Another apm25sim cannot take the same port: a clear error, exit 1.
    const e2e::CommandResult busy = e2e::run_command(e2e::tool("apm25sim") + " --elf " + e2e::firmware_elf() +
                                                     " --trajectory " + e2e::scenario_csv("rest", 30) +
                                                     " --serial tcp:" + port_text + " --seconds 1");
    EXPECT_EQ(busy.exit_code, 1);
    EXPECT_NE(busy.err.find("cannot listen on 127.0.0.1:" + port_text), std::string::npos) << busy.err;

    close(fd);
    // SIGTERM: a clean end; stdout carried the same bytes, both replies included.
    EXPECT_EQ(sim.stop(), 0) << sim.text;
    const std::string out = e2e::read_text(out_path);
    unlink(out_path.c_str());
    EXPECT_NE(out.find("# rate 10 Hz\n"), std::string::npos);
    EXPECT_NE(out.find("# rate 25 Hz\n"), std::string::npos);
    EXPECT_NE(out.find(reply.substr(0, reply.find('\n') + 1)), std::string::npos);
}

TEST(HarnessSerial, BadSerialSpecsAreRefused) {
    E2E_REQUIRE_TOOLS("apm25sim", "scenario", "firmware.elf");
    for (const std::string& spec : {"udp:5760", "tcp:", "tcp:70000", "tcp:57x"}) {
        const e2e::CommandResult r = e2e::run_command(e2e::tool("apm25sim") + " --elf " + e2e::firmware_elf() +
                                                      " --trajectory " + e2e::scenario_csv("rest", 1) +
                                                      " --serial " + spec + " --seconds 0.1");
        EXPECT_EQ(r.exit_code, 1) << spec;
        EXPECT_NE(r.err.find(spec), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << spec;
    }
}

}  // namespace
