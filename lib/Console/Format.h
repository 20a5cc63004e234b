// The serial output lines (../shared/SIM.md contract), formatted with integers only:
// Serial.print(float, 2) costs ~6 700 cycles a value on the 2560, this ~1/10 of it.
//
//   plot:  "roll:-1.23 pitch:4.56 yaw:271.80\n"   (degrees; yaw = heading 0..360)
//   csv:   header "t_ms,roll,pitch,yaw\n", rows "1234,-1.23,4.56,271.80\n"
//
// Angles are rounded to the nearest hundredth (half away from zero); a heading that
// rounds to 360.00 is written 0.00. An angle that is not finite is never printed:
// the formatter returns 0 and the caller writes a "# warn:" line instead (the DCM
// guarantees finite angles; this is the last line of defence).
#pragma once

#include <stdint.h>

namespace fmt {

enum class OutputMode : uint8_t { Plot = 0, Csv = 1, Quiet = 2 };

// Longest line: "roll:-180.00 pitch:-90.00 yaw:359.99\n" or a csv row with a 10-digit
// time stamp; 48 leaves room.
constexpr uint8_t kLineMax = 48;

// Returns the line length including the '\n' (no NUL written), or 0 if an angle is
// not finite or out of range.
uint8_t format_plot_line(char buf[kLineMax], float roll_deg, float pitch_deg, float heading_deg);
uint8_t format_csv_line(char buf[kLineMax], uint32_t t_ms, float roll_deg, float pitch_deg,
                        float heading_deg);

}  // namespace fmt
