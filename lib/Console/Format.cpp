#include "Format.h"

#include "Text.h"

namespace fmt {

namespace {

// Hundredths of the three angles; false if any is not representable.
bool angles_centi(float roll_deg, float pitch_deg, float heading_deg, int32_t c[3]) {
    if (!text::to_centi(roll_deg, c[0]) || !text::to_centi(pitch_deg, c[1]) ||
        !text::to_centi(heading_deg, c[2]))
        return false;
    // Attitude angles never exceed a full turn; anything else is not an angle.
    for (uint8_t i = 0; i < 3; ++i)
        if (c[i] > 36000 || c[i] < -36000) return false;
    if (c[2] == 36000) c[2] = 0;  // 359.996 rounds to 360.00: the same heading as 0.00
    return true;
}

uint8_t put(char* buf, uint8_t at, const char* s) {
    while (*s != '\0') buf[at++] = *s++;
    return at;
}

}  // namespace

uint8_t format_plot_line(char buf[kLineMax], float roll_deg, float pitch_deg, float heading_deg) {
    int32_t c[3];
    if (!angles_centi(roll_deg, pitch_deg, heading_deg, c)) return 0;
    uint8_t n = put(buf, 0, "roll:");
    n = (uint8_t)(n + text::format_centi(buf + n, c[0]));
    n = put(buf, n, " pitch:");
    n = (uint8_t)(n + text::format_centi(buf + n, c[1]));
    n = put(buf, n, " yaw:");
    n = (uint8_t)(n + text::format_centi(buf + n, c[2]));
    buf[n++] = '\n';
    return n;
}

uint8_t format_csv_line(char buf[kLineMax], uint32_t t_ms, float roll_deg, float pitch_deg,
                        float heading_deg) {
    int32_t c[3];
    if (!angles_centi(roll_deg, pitch_deg, heading_deg, c)) return 0;
    // t_ms as unsigned: split so that the int32 formatter never sees a wrapped value.
    uint8_t n = 0;
    if (t_ms >= 1000000000u) {
        n = text::format_int(buf, (int32_t)(t_ms / 1000000000u));
        const uint32_t rest = t_ms % 1000000000u;
        for (uint32_t p = 100000000u; p > 0u; p /= 10u) buf[n++] = (char)('0' + (uint8_t)((rest / p) % 10u));
    } else {
        n = text::format_int(buf, (int32_t)t_ms);
    }
    for (uint8_t i = 0; i < 3; ++i) {
        buf[n++] = ',';
        n = (uint8_t)(n + text::format_centi(buf + n, c[i]));
    }
    buf[n++] = '\n';
    return n;
}

}  // namespace fmt
