// SPDX-License-Identifier: GPL-3.0-or-later
// The serial output lines (../shared/SIM.md contract), formatted with integers only:
// Serial.print(float, 2) does float divisions a digit on the 2560 (docs/performance.md).
//
//   plot:  "roll:-1.23 pitch:4.56 yaw:271.80\n"   (degrees; yaw = heading 0..360)
//   csv:   header "t_ms,roll,pitch,yaw\n", rows "1234,-1.23,4.56,271.80\n"
//   quat:  "qw:0.7071 qx:0.0000 qy:0.7071 qz:0.0000\n"   (body -> earth, scalar first)
//   raw:   "gx:0.12 gy:-0.06 gz:0.00 ax:0.012 ay:-0.003 az:-1.001 mx:20.1 my:0.3 mz:45.2\n"
//          calibrated: gyro deg/s (2 decimals: one LSB at 2000 deg/s is 0.06), accel g
//          (3 decimals: one LSB at 16 g is 0.0005 g), field uT (1 decimal: one LSB at
//          1.3 Ga is 0.09 uT); body axes x forward, y right, z down
//
// Angles are rounded to the nearest hundredth (half away from zero); a heading that
// rounds to 360.00 is written 0.00. An angle that is not finite is never printed:
// the formatter returns 0 and the caller writes a "# warn:" line instead (the DCM
// guarantees finite angles; this is the last line of defence).
#pragma once

#include <stdint.h>

#include "LinAlg.h"
#include "OutputMode.h"

namespace fmt {

// Longest line: "roll:-180.00 pitch:-90.00 yaw:359.99\n" or a csv row with a 10-digit
// time stamp; 48 leaves room.
constexpr uint8_t kLineMax = 48;

// Returns the line length including the '\n' (no NUL written), or 0 if an angle is
// not finite or out of range.
uint8_t format_plot_line(char buf[kLineMax], float roll_deg, float pitch_deg, float heading_deg);
uint8_t format_csv_line(char buf[kLineMax], uint32_t t_ms, float roll_deg, float pitch_deg,
                        float heading_deg);
// The same from angles already in hundredths (the firmware's integer path): 0 beyond
// +-36000; a heading of 36000 is written 0.00.
uint8_t format_plot_line_centideg(char buf[kLineMax], int32_t roll_centideg, int32_t pitch_centideg,
                                  int32_t heading_centideg);
uint8_t format_csv_line_centideg(char buf[kLineMax], uint32_t t_ms, int32_t roll_centideg, int32_t pitch_centideg,
                                 int32_t heading_centideg);

// Returns the length including the '\n', or 0 if a component is not finite or beyond
// +-1.0001 (not a unit quaternion: a bug upstream, never printed).
uint8_t format_quat_line(char buf[kLineMax], const linalg::Quaternion& q);

// Longest raw line: nine fields at their bounds below, eight spaces and the '\n'.
constexpr uint8_t kRawLineMax = 104;
// Returns the length including the '\n', or 0 if a value is not finite or beyond what
// the sensors can report, with margin: 9999 deg/s and 40 g (5x the configured 2000 deg/s,
// 2.5x the 16 g), 999.9 uT (the HMC5883L's widest range is 8.1 Ga = 810 uT). Beyond is a
// decoding bug, never a reading. Longest line: 99 characters.
uint8_t format_raw_line(char buf[kRawLineMax], const linalg::Vector3f& gyro_dps, const linalg::Vector3f& accel_g,
                        const linalg::Vector3f& field_uT);

}  // namespace fmt
