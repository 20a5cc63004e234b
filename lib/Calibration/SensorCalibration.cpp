// SPDX-License-Identifier: GPL-3.0-or-later
#include "SensorCalibration.h"

#include "CalibMath.h"

namespace calib {

using linalg::Matrix3f;
using linalg::Vector3f;

Calibration default_calibration() {
    Calibration c;
    c.gyro_bias_rad_s = Vector3f();
    c.mag_offset_uT = Vector3f();
    c.mag_scale = Vector3f(1.0f, 1.0f, 1.0f);
    c.mag_cross = Vector3f();
    c.mag_learned_uT = Vector3f();
    return c;
}

// W rows: (sx, xy, xz), (xy, sy, yz), (xz, yz, sz).
static Matrix3f soft_iron(const Calibration& c) {
    return Matrix3f(Vector3f(c.mag_scale.x, c.mag_cross.x, c.mag_cross.y),
                    Vector3f(c.mag_cross.x, c.mag_scale.y, c.mag_cross.z),
                    Vector3f(c.mag_cross.y, c.mag_cross.z, c.mag_scale.z));
}

Vector3f apply_mag(const Calibration& c, const Vector3f& field_uT) {
    return soft_iron(c) * (field_uT - c.mag_offset_uT) - c.mag_learned_uT;
}

bool is_plausible(const Calibration& c) {
    // Bias, offset, diagonal, cross terms, learned offset: fifteen packed floats.
    static_assert(sizeof(Calibration) == 15 * sizeof(float), "Calibration is fifteen floats");
    const float* v = &c.gyro_bias_rad_s.x;
    for (uint8_t i = 0; i < 15; ++i) {
        const uint8_t k = (uint8_t)(i / 3u);
        const float lo = k == 0 ? -kGyroBiasMax_rad_s : k == 2 ? 0.5f : k == 3 ? -0.5f : -200.0f;
        const float hi = k == 0 ? kGyroBiasMax_rad_s : k == 2 ? 2.0f : k == 3 ? 0.5f : 200.0f;
        if (!within(v[i], lo, hi)) return false;
    }
    return true;
}

}  // namespace calib
