// SPDX-License-Identifier: GPL-3.0-or-later
// Writes a fixed set of frames from lib/MavLink to stdout for decode_frames.py, which
// decodes them with pymavlink (a real ground-station parser) and checks every field.
// The values here and the expectations there are one list: change both together.
#include <stdio.h>

#include "MavLink.h"

namespace {

void put(void*, const uint8_t* frame, uint8_t len) { fwrite(frame, 1, len, stdout); }

}  // namespace

int main() {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    put(nullptr, buf, p.heartbeat(buf, mav::State::Active));
    put(nullptr, buf, p.attitude(buf, 123456u, -30.0f, 45.0f, 270.0f, linalg::Vector3f(0.5f, -0.25f, 1.5f)));
    put(nullptr, buf, p.sys_status(buf, mav::health(true, true, true, false), 593u, 12u));
    mav::StatusText st(p, mav::FrameSink{nullptr, &put});
    const char lines[] =
        "roll:1.00 pitch:2.00 yaw:3.00\n"  // not a "# " line: dropped
        "# warn: compass overflow\n"
        "# error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68); retrying every second\n"
        "# status: ok\n";
    st.write(lines, (uint8_t)(sizeof lines - 1));
    put(nullptr, buf, p.heartbeat(buf, mav::State::Critical));
    return 0;
}
