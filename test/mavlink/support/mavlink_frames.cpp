// SPDX-License-Identifier: GPL-3.0-or-later
// Writes a fixed set of frames from lib/MavLink to stdout for decode_frames.py, which
// decodes them with pymavlink (a real ground-station parser) and checks every field.
// The values here and the expectations there are one list: change both together.
#include <stdio.h>

#include "MavLink.h"
#include "MissionProtocol.h"

namespace {

void put(void*, const uint8_t* frame, uint8_t len) { fwrite(frame, 1, len, stdout); }

}  // namespace

int main() {
    mav::Packer p;
    uint8_t buf[mav::kMaxFrame];
    put(nullptr, buf, p.heartbeat(buf, mav::State::Active, mav::PlaneMode::Stabilize, true));
    put(nullptr, buf, p.attitude(buf, 123456u, -30.0f, 45.0f, 270.0f, linalg::Vector3f(0.5f, -0.25f, 1.5f)));
    put(nullptr, buf, p.sys_status(buf, mav::health(true, true, true, false), 593u, 12u));
    mav::StatusText st(p, mav::FrameSink{nullptr, &put});
    const char lines[] =
        "roll:1.00 pitch:2.00 yaw:3.00\n"  // not a "# " line: dropped
        "# warn: compass overflow\n"
        "# error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68); retrying every second\n"
        "# status: ok\n";
    st.write(lines, (uint8_t)(sizeof lines - 1));
    put(nullptr, buf, p.heartbeat(buf, mav::State::Critical, mav::PlaneMode::FlyByWireA, false));  // disarmed
    put(nullptr, buf, p.param_value(buf, "RLL2SRV_P", 0.4f, mav::kParamTypeReal32, 97u, 1u));
    put(nullptr, buf, p.command_ack(buf, mav::kCmdPreflightCalibration, mav::Result::Accepted, 255u, 190u));
    const uint16_t rc[8] = {1100, 1200, 1300, 1400, 1500, 1600, 1700, 1800};
    put(nullptr, buf, p.rc_channels(buf, 4000u, rc, 8u));
    const uint16_t servo[8] = {1000, 1100, 1200, 1300, 1400, 1500, 1600, 2000};
    put(nullptr, buf, p.servo_output_raw(buf, 4000000u, servo));
    gps::Fix fix;
    fix.received_ms = 61234u;
    fix.lat_e7 = 71350450;
    fix.lon_e7 = -731194210;
    fix.alt_msl_mm = 1028123;
    fix.ground_speed_cm_s = 1834u;
    fix.course_e5 = 27012345;
    fix.h_acc_mm = 2100u;
    fix.hdop_cm = 90u;
    fix.sats = 10u;
    fix.fix = gps::FixType::k3D;
    put(nullptr, buf, p.gps_raw_int(buf, fix));
    mav::PositionReport r{};
    r.time_boot_ms = 61300u;
    r.lat_e7 = 71351450;
    r.lon_e7 = -731193210;
    r.alt_msl_mm = 1078500;
    r.relative_alt_mm = 50500;
    r.vel_ned_m_s[0] = 12.0f;
    r.vel_ned_m_s[1] = -16.0f;
    r.vel_ned_m_s[2] = -1.5f;
    r.heading_deg = 306.87f;
    r.airspeed_m_s = 19.5f;
    r.climb_m_s = 1.5f;
    r.throttle_pct = 65u;
    put(nullptr, buf, p.global_position_int(buf, r));
    put(nullptr, buf, p.vfr_hud(buf, r));
    put(nullptr, buf, p.home_position(buf, 71350450, -731194210, 1028000));
    // The conversation.
    const mav::Version v{1, 2, 3, {'0', '1', '2', '3', 'a', 'b', 'c', 'd'}};
    put(nullptr, buf, p.autopilot_version(buf, v));
    put(nullptr, buf, p.mission_count(buf, 255u, 190u, 0u, 1u));
    put(nullptr, buf, p.mission_ack(buf, 255u, 190u, mav::MissionResult::Unsupported, 2u));
    put(nullptr, buf, p.timesync(buf, 61234000000ll, -5ll));
    put(nullptr, buf, p.system_time(buf, 1380812400370000ull, 61300u));
    // The mission protocol.
    mission::Item it = {};
    it.seq = 5;
    it.command = 18;  // NAV_LOITER_TURNS
    it.frame = 6;     // GLOBAL_RELATIVE_ALT_INT
    it.autocontinue = 1;
    it.param1 = 2.0f;
    it.param3 = -60.0f;
    it.x = 71350450;
    it.y = -731194210;
    it.z = 90.5f;
    it.int_form = true;
    put(nullptr, buf, p.mission_item(buf, 255u, 190u, it));
    it.int_form = false;
    it.frame = 3;     // GLOBAL_RELATIVE_ALT
    put(nullptr, buf, p.mission_item(buf, 255u, 190u, it));
    put(nullptr, buf, p.mission_request(buf, 255u, 190u, 7u, true, 0u));
    put(nullptr, buf, p.mission_request(buf, 255u, 190u, 8u, false, 0u));
    put(nullptr, buf, p.mission_current(buf, 4u, 10u));
    put(nullptr, buf, p.mission_item_reached(buf, 3u));
    return 0;
}
