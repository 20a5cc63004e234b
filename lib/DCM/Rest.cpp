// SPDX-License-Identifier: GPL-3.0-or-later
#include "Rest.h"

#include <string.h>

#include "Fixed.h"

namespace dcm {

using linalg::Vector3l;

namespace {
// The field may move this much in body axes during a rest: the HMC5883L's noise is
// ~0.2 uT with its 8-sample average; a turn of 3 deg moves a 20 uT horizontal field by
// 1 uT, so a steady turn of more than 2 deg/s ends a rest within its first 1.5 s, and
// a slower one before it has lasted 1 uT / (20 uT x rate).
constexpr float kRestFieldMove_uT = 1.0f;
constexpr int16_t kRestFieldMoveQ5 = (int16_t)(kRestFieldMove_uT * (float)(1 << kFieldQ));

// |a - b| > kRestFieldMove_uT for two fields in uT Q5: an axis beyond it decides at
// once; else the squares of the differences.
bool moved(const linalg::Vector3i& a, const linalg::Vector3i& b) {
    const int16_t d[3] = {(int16_t)(a.x - b.x), (int16_t)(a.y - b.y), (int16_t)(a.z - b.z)};
    int32_t sum = 0;
    for (uint8_t i = 0; i < 3; ++i) {
        if (d[i] >= kRestFieldMoveQ5 || d[i] <= -kRestFieldMoveQ5) return true;
        sum += linalg::mul_s16(d[i], d[i]);
    }
    return sum > linalg::mul_s16(kRestFieldMoveQ5, kRestFieldMoveQ5);
}

// A mean in units (counts * 2^8) to counts: its middle two bytes, read as such (the
// AVR and the host are little-endian; a shift would load all four), truncated: the
// resolution, 0.06 deg/s, is an eighth of what a rest may move. Within 16 bits but for
// a gyro at full scale less a bias, which wraps: a move beyond any limit, no rest (and
// none there is).
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "counts_of reads bytes 1 and 2 of a little-endian int32");
inline int16_t counts_of(const int32_t& units) {
    int16_t counts;
    memcpy(&counts, reinterpret_cast<const uint8_t*>(&units) + 1, sizeof counts);
    return counts;
}
}  // namespace

FIXED_COLD void RestDetector::restart_at_mean() {
    start_counts_ = linalg::Vector3i(counts_of(gyro_mean_.x), counts_of(gyro_mean_.y), counts_of(gyro_mean_.z));
}

void RestDetector::watch_field(const linalg::Vector3i& field_q5) {
    if (moved(field_q5, field_q5_)) {
        field_q5_ = field_q5;
        corrections_ = 0;
    }
}

// (At 50 Hz, off the step's hot path: an ordinary call.)
FIXED_COLD bool RestDetector::mean_moved(const DcmCoefficients& k) {
    if (corrections_ == 0) restart_at_mean();
    // kRestMeanMove_rad_s in counts (units / 2^8; a float multiply at 50 Hz).
    const int16_t limit = (int16_t)(k.units_per_rad_s * (kRestMeanMove_rad_s / 256.0f));
    const int16_t moved[3] = {(int16_t)(counts_of(gyro_mean_.x) - start_counts_.x),
                              (int16_t)(counts_of(gyro_mean_.y) - start_counts_.y),
                              (int16_t)(counts_of(gyro_mean_.z) - start_counts_.z)};
    for (uint8_t i = 0; i < 3; ++i)
        if (moved[i] > limit || moved[i] < -limit) return true;
    return false;
}

bool RestDetector::update(const Vector3l& gyro_mean_units, const Vector3l& accel_mean_units,
                          const Vector3l& mean_off_bias_units, bool whole_window, bool compass_watching,
                          const DcmCoefficients& k) {
    // A steady turn passes the deviation test too. The compass tells (watch_field).
    // Without a compass delivering, the mean must be within the tremor bound of the bias
    // estimate instead (VQF's rule, its 2 deg/s bias clip): a larger vertical bias is
    // then not told from a slow turn.
    const Vector3l gyro_change = gyro_mean_units - gyro_mean_, accel_change = accel_mean_units - accel_mean_;
    const bool still = !exceeds(gyro_change, k.rest_gyro_dev) &&
                       (compass_watching || !exceeds(mean_off_bias_units, k.rest_gyro_dev)) &&
                       !exceeds(accel_change, k.rest_accel_dev);
    // mean += alpha (sample - mean): the factor in 16 bits (two 16x16 products an axis),
    // the step rounded to the unit (the changes are counts * 2^8, far below 2^29).
    // The first window after reset() is the gyro mean (a factor of 1), as reset() takes
    // the accelerometer's: from zero the mean would move toward the bias for a second,
    // and a moving mean is no rest (mean_moved).
    using linalg::hot::mul_q14_unit;
    const bool first_window = start_counts_.x == kMeanUnknown;
    const int16_t gyro_alpha_q14 = first_window ? (int16_t)(1 << 14) : k.rest_alpha_q14;
    gyro_mean_ += Vector3l(mul_q14_unit(gyro_alpha_q14, gyro_change.x), mul_q14_unit(gyro_alpha_q14, gyro_change.y),
                           mul_q14_unit(gyro_alpha_q14, gyro_change.z));
    if (first_window) start_counts_.x = 0;
    accel_mean_ += Vector3l(mul_q14_unit(k.rest_alpha_q14, accel_change.x), mul_q14_unit(k.rest_alpha_q14, accel_change.y),
                            mul_q14_unit(k.rest_alpha_q14, accel_change.z));
    // A bias does not move within a rest (the MPU6000 drifts 0.2 deg/s a minute as it
    // warms: 0.005 deg/s in 1.5 s), but a slow turn does, and a slowly changing one
    // passes the deviation test (a ramp of 2 deg/s^2 deviates by 1 deg/s from the 0.5 s
    // mean) and the compass's (a 20 uT horizontal field turned at 0.5 deg/s moves 0.26 uT
    // in 1.5 s, below what its noise lets kRestFieldMove_uT see): a pendulum's twist
    // turning back through zero, a turntable starting. So the mean may not move from
    // where the rest began by kRestMeanMove_rad_s, 100 times the bias's own change;
    // beyond, the rest begins again from there.
    if (!still || !whole_window || mean_moved(k)) {
        corrections_ = 0;
        return false;
    }
    if (corrections_ < k.rest_min_corrections) {
        ++corrections_;
        return false;
    }
    return true;
}

}  // namespace dcm
