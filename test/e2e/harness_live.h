// SPDX-License-Identifier: GPL-3.0-or-later
// A process the simulator's e2e tests run in the background (apm25sim serving TCP, a
// physics backend): one of its output streams on a pipe the test reads, the other to a file.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <signal.h>

#include <regex>

#include "e2e_support.h"

namespace e2e {

// Guards against a hang only (never asserted as a duration): the reads below wait at
// most this long for something the simulated board must send.
constexpr int kGuard_ms = 90000;

struct LiveProcess {
    pid_t pid = -1;
    int pipe_fd = -1;
    std::string text;  // what the piped stream said so far

    // Runs args[0] (searched in PATH) with args; `piped_fd` (1 stdout or 2 stderr) comes
    // to this process (read with wait_line), the other stream goes to `other_path`.
    bool start(const std::vector<std::string>& args, int piped_fd, const std::string& other_path) {
        int fds[2];
        if (pipe(fds) != 0) return false;
        pid = fork();
        if (pid == 0) {
            dup2(fds[1], piped_fd);
            const int other = open(other_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (other >= 0) dup2(other, piped_fd == 1 ? 2 : 1);
            close(fds[0]);
            std::vector<char*> argv;
            for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
            argv.push_back(nullptr);
            execvp(argv[0], argv.data());
            _exit(127);
        }
        close(fds[1]);
        pipe_fd = fds[0];
        return pid > 0;
    }
    // Reads the piped stream until a line matches `pattern` (its first group returned) or EOF.
    std::string wait_line(const std::string& pattern) {
        const std::regex re(pattern);
        for (;;) {
            std::smatch m;
            size_t start = 0;
            for (size_t nl; (nl = text.find('\n', start)) != std::string::npos; start = nl + 1) {
                const std::string line = text.substr(start, nl - start);
                if (std::regex_search(line, m, re)) return m.size() > 1 ? m[1].str() : line;
            }
            pollfd p{pipe_fd, POLLIN, 0};
            if (::poll(&p, 1, kGuard_ms) <= 0) return "";
            char buffer[512];
            const ssize_t n = read(pipe_fd, buffer, sizeof buffer);
            if (n <= 0) return "";
            text.append(buffer, (size_t)n);
        }
    }
    // SIGTERM, then its exit status (-1 when a signal ended it).
    int stop() {
        if (pid <= 0) return -1;
        kill(pid, SIGTERM);
        int status = 0;
        waitpid(pid, &status, 0);
        pid = -1;
        char buffer[512];
        ssize_t n;
        while ((n = read(pipe_fd, buffer, sizeof buffer)) > 0) text.append(buffer, (size_t)n);
        close(pipe_fd);
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    ~LiveProcess() {
        if (pid > 0) stop();
    }
};

}  // namespace e2e
