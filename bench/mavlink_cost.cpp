// SPDX-License-Identifier: GPL-3.0-or-later
// Cost of lib/MavLink on the ATmega2560: a bare program (no Arduino core) that packs
// each message between the cycle markers apm25sim --profile counts (section id to GPIOR0
// at the start, GPIOR1 at the end). Built twice by `make mavlink-cost`: with
// -DMAV_COST_EMPTY the same program without the packing, so the flash difference is
// what the MavLink code costs in a linked image (LTO, --gc-sections, as the firmware).
//
//   section 1  HEARTBEAT             (1 Hz)
//   section 2  ATTITUDE              (every output line)
//   section 3  SYS_STATUS            (1 Hz)
//   section 4  a 30-character "# " line through StatusText (one STATUSTEXT)
//   section 5  a 70-character "# error:" line (two chunks)
//   section 7  Parser over one 21-byte HEARTBEAT frame from a GCS (CRC-checked)
//   section 8  RC_CHANNELS and SERVO_OUTPUT_RAW (the 5 Hz pair)
//   section 9  Parser over one 35-byte PARAM_SET frame from a GCS (CRC-checked), decoded
//   section 10 GPS_RAW_INT, 11 GLOBAL_POSITION_INT, 12 VFR_HUD (the position streams), 13 HOME_POSITION
//   section 6  the whole run
#include <avr/io.h>
#include <stdint.h>

#ifndef MAV_COST_EMPTY
#include "MavLink.h"
#endif

namespace {

volatile uint8_t g_sink;
volatile float g_angle = 12.5f;

#ifndef MAV_COST_EMPTY
void sink(void*, const uint8_t* frame, uint8_t len) {
    uint8_t s = 0;
    for (uint8_t i = 0; i < len; ++i) s = (uint8_t)(s + frame[i]);
    g_sink = s;
}
#endif

inline void begin(uint8_t id) { GPIOR0 = id; }
inline void end(uint8_t id) { GPIOR1 = id; }

}  // namespace

int main() {
    begin(6);
#ifndef MAV_COST_EMPTY
    mav::Packer packer;
    mav::StatusText text(packer, mav::FrameSink{nullptr, &sink});
    mav::Parser filter;
    uint8_t frame[mav::kMaxFrame];
    uint8_t gcs[mav::kMaxFrame];
    mav::Packer gcs_packer;
    const uint8_t gcs_len = gcs_packer.heartbeat(gcs, mav::State::Active, mav::PlaneMode::Manual, false);
    // A PARAM_SET as QGroundControl sends it (MAVLink 2, system 255, component 190).
    static const uint8_t kParamSet[] = {0xFD, 0x17, 0x00, 0x00, 0x07, 0xFF, 0xBE, 0x17, 0x00, 0x00, 0x00, 0x00,
                                        0xA0, 0x3F, 0x01, 0x01, 'R',  'L',  'L',  '2',  'S',  'R',  'V',  '_',
                                        'P',  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x09, 0x00, 0x00};
    uint8_t param_set[sizeof kParamSet];
    for (uint8_t i = 0; i < sizeof kParamSet; ++i) param_set[i] = kParamSet[i];
    const uint16_t widths[8] = {1500, 1500, 1100, 1500, 1520, 1480, 1500, 1900};
    static const char kShort[] = "# mode mavlink: MAVLink 2 now\n";
    static const char kLong[] = "# error: MPU6000 not found (WHO_AM_I=0x00, expected 0x68), retrying each s\n";
    gps::Fix fix;
    fix.lat_e7 = 71350450;
    fix.lon_e7 = -731194210;
    fix.alt_msl_mm = 1028000;
    fix.ground_speed_cm_s = 1800u;
    fix.course_e5 = 9000000;
    fix.hdop_cm = 90u;
    fix.sats = 10u;
    fix.fix = gps::FixType::k3D;
    mav::PositionReport report{};
    report.lat_e7 = fix.lat_e7;
    report.lon_e7 = fix.lon_e7;
    report.alt_msl_mm = fix.alt_msl_mm;
    report.heading_deg = 90.0f;
    report.airspeed_m_s = 18.0f;
#endif
    for (uint8_t k = 0; k < 20; ++k) {
#ifndef MAV_COST_EMPTY
        begin(1);
        uint8_t n = packer.heartbeat(frame, mav::State::Active, mav::PlaneMode::Stabilize, true);
        end(1);
        sink(nullptr, frame, n);
        begin(2);
        n = packer.attitude(frame, 1000u * k, g_angle, -g_angle, 359.0f - g_angle,
                            linalg::Vector3f(0.01f, -0.02f, g_angle * 0.001f));
        end(2);
        sink(nullptr, frame, n);
        begin(3);
        n = packer.sys_status(frame, mav::health(true, true, true, k & 1u), 593u, k);
        end(3);
        sink(nullptr, frame, n);
        begin(4);
        text.write(kShort, (uint8_t)(sizeof kShort - 1));
        end(4);
        begin(5);
        text.write(kLong, (uint8_t)(sizeof kLong - 1));
        end(5);
        begin(7);
        for (uint8_t i = 0; i < gcs_len; ++i) g_sink = filter.consume(gcs[i]);
        filter.release();
        end(7);
        begin(8);
        n = packer.rc_channels(frame, 1000u * k, widths, 8u);
        sink(nullptr, frame, n);
        n = packer.servo_output_raw(frame, 1000000u * k, widths);
        end(8);
        sink(nullptr, frame, n);
        begin(9);
        mav::ParamSet ps;
        for (uint8_t i = 0; i < sizeof param_set; ++i) filter.consume(param_set[i]);
        g_sink = filter.ready() && mav::decode_param_set(filter.frame(), ps);
        filter.release();
        end(9);
        fix.received_ms = 200u * k;
        report.time_boot_ms = 200u * k;
        report.vel_ned_m_s[1] = g_angle;
        begin(10);
        n = packer.gps_raw_int(frame, fix);
        end(10);
        sink(nullptr, frame, n);
        begin(11);
        n = packer.global_position_int(frame, report);
        end(11);
        sink(nullptr, frame, n);
        begin(12);
        n = packer.vfr_hud(frame, report);
        end(12);
        sink(nullptr, frame, n);
        begin(13);
        n = packer.home_position(frame, fix.lat_e7, fix.lon_e7, fix.alt_msl_mm);
        end(13);
        sink(nullptr, frame, n);
#else
        begin(1);
        g_sink = (uint8_t)(g_sink + (uint8_t)g_angle);
        end(1);
#endif
    }
    end(6);
    for (;;) {
    }
}
