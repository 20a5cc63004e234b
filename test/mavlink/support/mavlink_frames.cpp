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
    put(nullptr, buf, p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Stabilize));
    put(nullptr, buf, p.attitude(buf, 123456u, -30.0f, 45.0f, 270.0f, linalg::Vector3f(0.5f, -0.25f, 1.5f)));
    put(nullptr, buf, p.sys_status(buf, mav::health(true, true, true, false), 593u, 12u));
    mav::StatusText st(p, mav::FrameSink{nullptr, &put});
    const char lines[] =
        "roll:1.00 pitch:2.00 yaw:3.00\n"  // not a "# " line: dropped
        "# warn: compass overflow\n"
        "# error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68); retrying every second\n"
        "# status: ok\n";
    st.write(lines, (uint8_t)(sizeof lines - 1));
    put(nullptr, buf, p.heartbeat(buf, mav::State::Critical, mav::PlaneMode::FlyByWireA));
    put(nullptr, buf, p.param_value(buf, "RLL2SRV_P", 0.4f, mav::kParamTypeReal32, 97u, 1u));
    put(nullptr, buf, p.command_ack(buf, mav::kCmdPreflightCalibration, mav::Result::Accepted, 255u, 190u));
    const uint16_t rc[8] = {1100, 1200, 1300, 1400, 1500, 1600, 1700, 1800};
    put(nullptr, buf, p.rc_channels(buf, 4000u, rc, 8u));
    const uint16_t servo[8] = {1000, 1100, 1200, 1300, 1400, 1500, 1600, 2000};
    put(nullptr, buf, p.servo_output_raw(buf, 4000000u, servo));
    return 0;
}
