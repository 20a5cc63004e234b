// SPDX-License-Identifier: GPL-3.0-or-later
// One sensor's health as the user sees it: a failure is reported once, the sensor is
// tried again once a second while it is down, and its return is reported.
#pragma once

#include <stdint.h>

class SensorHealth {
public:
    static constexpr uint16_t kRetryMs = 1000;

    bool ok() const { return ok_; }
    // The sensor failed at now_ms. True when this failure is news: report it (once).
    bool failed(uint32_t now_ms) {
        ok_ = false;
        retry_ms_ = now_ms;
        const bool news = !reported_;
        reported_ = true;
        return news;
    }
    // True once a second while the sensor is down: time to try it again.
    bool retry_due(uint32_t now_ms) {
        if (ok_ || now_ms - retry_ms_ < kRetryMs) return false;
        retry_ms_ = now_ms;
        return true;
    }
    // The sensor works. True when it had failed and been reported: report the recovery.
    bool working() {
        const bool back = !ok_ && reported_;
        ok_ = true;
        reported_ = false;
        return back;
    }

private:
    bool ok_ = false;
    bool reported_ = false;
    uint32_t retry_ms_ = 0;
};
