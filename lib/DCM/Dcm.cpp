#include "Dcm.h"

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {
constexpr float kGravity_m_s2 = 9.80665f;
constexpr float kInvGravity_s2_m = 1.0f / kGravity_m_s2;
// Beyond any MEMS gyro's range (the MPU6000 stops at 2000 deg/s = 35 rad/s): such a
// sample is garbage, not a rotation, and is not integrated.
constexpr float kMaxCredibleRate_rad_s = 50.0f;
// A mag correction stands for the time since the previous sample, but never more
// than this (after an outage the first sample must not make a jump).
constexpr float kMaxMagInterval_s = 0.1f;
}  // namespace

// Gains tuned on the BROAD recordings through the replay tool (see README,
// "Performance"): one set for every recording and scenario.
const DcmSettings kDefaultDcmSettings = {
    0.005f,                         // step_s: 200 Hz
    1.0f,                           // kp_rp_1_s
    0.1f,                           // ki_rp_1_s2
    1.0f,                           // kp_yaw_1_s
    0.1f,                           // ki_yaw_1_s2
    5.0f,                           // kp_startup_1_s
    1.0f,                           // startup_s
    0.15f,                          // accel_reject_g
    20.0f * linalg::kRadPerDeg,     // integrator_hold_rate_rad_s (ArduPilot's 20 deg/s)
    10.0f * linalg::kRadPerDeg,     // bias_limit_rad_s
    30.0f * linalg::kRadPerDeg,     // mag_reject_rad
    10.0f,                          // mag_recover_s
};

Dcm::Dcm(const DcmSettings& settings)
    : settings_(settings),
      mag_disturbed_s_(0.0f),
      steps_(0),
      steps_since_mag_(0),
      recoveries_(0),
      status_(kStatusNoHeading) {}

void Dcm::set_gyro_bias_rad_s(const Vector3f& bias) {
    if (!bias.is_finite()) return;
    const float limit = settings_.bias_limit_rad_s;
    bias_rad_s_ = Vector3f(linalg::constrain(bias.x, -limit, limit),
                           linalg::constrain(bias.y, -limit, limit),
                           linalg::constrain(bias.z, -limit, limit));
}

// TRIAD (Shuster & Oh 1981, as in the thesis): the rows of R are the earth axes
// in body coordinates, so they are built directly from the two observations.
bool Dcm::init(const Vector3f& accel_m_s2, const Vector3f& mag_field) {
    if (!accel_m_s2.is_finite()) return false;
    const Vector3f down = (-accel_m_s2).normalized();  // specific force points up
    if (down.is_zero()) return false;
    last_accel_m_s2_ = accel_m_s2;

    // North: the field's component perpendicular to down. Without a usable field,
    // the body x axis projected on the horizontal (yaw 0), or body y at pitch 90.
    Vector3f north;
    if (mag_field.is_finite()) north = (down.cross(mag_field)).cross(down).normalized();
    if (north.is_zero()) {
        status_ |= kStatusNoHeading;
        north = (down.cross(Vector3f(1.0f, 0.0f, 0.0f))).cross(down).normalized();
        if (north.is_zero()) north = (down.cross(Vector3f(0.0f, 1.0f, 0.0f))).cross(down).normalized();
    } else {
        status_ &= (uint8_t)~kStatusNoHeading;
        last_mag_field_ = mag_field;
        mag_ref_norm_ = mag_field.length();
        mag_ref_down_ = mag_field.dot(down) / mag_ref_norm_;
    }
    const Vector3f east = down.cross(north);
    r_ = Matrix3f(north, east, down);
    omega_yaw_rad_s_ = Vector3f();
    mag_disturbed_s_ = 0.0f;
    steps_ = 0;
    status_ |= kStatusInitialised;
    return true;
}

float Dcm::proportional_gain(float steady_gain_1_s) const {
    // Start-up: a higher gain that ramps down linearly to the steady one, so a
    // poor first sample is forgotten within startup_s (Fusion does the same).
    const float startup_steps = settings_.startup_s / settings_.step_s;
    if ((float)steps_ >= startup_steps) return steady_gain_1_s;
    const float left = 1.0f - (float)steps_ / startup_steps;
    const float boosted = settings_.kp_startup_1_s > steady_gain_1_s ? settings_.kp_startup_1_s : steady_gain_1_s;
    return steady_gain_1_s + (boosted - steady_gain_1_s) * left;
}

void Dcm::update(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2) {
    if (!initialised()) {
        init(accel_m_s2, last_mag_field_);
        return;
    }
    status_ &= (uint8_t)~(kStatusAccelIgnored | kStatusBiasHeld | kStatusGyroRejected);
    if (steps_since_mag_ < 0xFFFF) ++steps_since_mag_;
    const float dt = settings_.step_s;

    const bool gyro_ok = gyro_rad_s.is_finite() &&
                         gyro_rad_s.length_squared() < kMaxCredibleRate_rad_s * kMaxCredibleRate_rad_s;
    if (!gyro_ok) status_ |= kStatusGyroRejected;
    const float hold2 = settings_.integrator_hold_rate_rad_s * settings_.integrator_hold_rate_rad_s;
    const bool hold_integrator = !gyro_ok || gyro_rad_s.length_squared() > hold2;
    if (hold_integrator) status_ |= kStatusBiasHeld;
    rotating_fast_ = hold_integrator;

    // Roll/pitch error (Premerlani & Bizard eq. 27): measured down x estimated down.
    // |a|^2 against g^2 gives the weight without a square root: gravity counts fully
    // at 1 g and not at all accel_reject_g away from it (linear accelerations and
    // vibration make |a| differ from 1 g, and then a is not gravity).
    Vector3f correction_rad_s;
    if (accel_m_s2.is_finite()) {
        const float ratio2 = accel_m_s2.length_squared() * (kInvGravity_s2_m * kInvGravity_s2_m);
        const float deviation = 0.5f * (ratio2 > 1.0f ? ratio2 - 1.0f : 1.0f - ratio2);  // ~ | |a|/g - 1 |
        const float weight = 1.0f - deviation / settings_.accel_reject_g;
        if (weight > 0.0f) {
            last_accel_m_s2_ = accel_m_s2;
            // -a/g is the measured down direction (unit length to within the weight's
            // tolerance, so no normalisation is needed).
            const Vector3f error = (accel_m_s2 * -kInvGravity_s2_m).cross(r_.c);
            correction_rad_s = error * (proportional_gain(settings_.kp_rp_1_s) * weight);
            if (!hold_integrator) bias_rad_s_ -= error * (settings_.ki_rp_1_s2 * weight * dt);
        } else {
            status_ |= kStatusAccelIgnored;
        }
    } else {
        status_ |= kStatusAccelIgnored;
    }
    // Yaw correction from the last magnetometer sample, applied once.
    correction_rad_s += omega_yaw_rad_s_;
    omega_yaw_rad_s_ = Vector3f();
    clamp_bias();

    // Gyro integration (eq. 17): R <- R (I + [w x] dt); row_i [w x] = row_i x w.
    if (gyro_ok) {
        const Vector3f omega_dt = (gyro_rad_s - bias_rad_s_ + correction_rad_s) * dt;
        r_.a += r_.a.cross(omega_dt);
        r_.b += r_.b.cross(omega_dt);
        r_.c += r_.c.cross(omega_dt);
    }
    // One pass leaves ~(X.Y)^2: a second one, needed only at high rates (a step of
    // more than ~3 deg), keeps the matrix orthonormal to 1e-5 up to the gyro's range.
    const float skew_before = r_.a.dot(r_.b);
    bool ok = renormalise();
    if (ok && (skew_before > 2e-3f || skew_before < -2e-3f)) ok = renormalise();
    if (!ok) recover();
    if (steps_ < 0xFFFFFFFFu) ++steps_;
}

void Dcm::correct_heading(const Vector3f& mag_field) {
    const float interval_s = (float)steps_since_mag_ * settings_.step_s;
    steps_since_mag_ = 0;
    status_ |= kStatusMagIgnored;
    if (!mag_field.is_finite() || mag_field.is_zero()) return;
    last_mag_field_ = mag_field;
    if (!initialised()) return;
    if (status_ & kStatusNoHeading) {
        // The first field sample after a start without one: take its heading as is.
        init(last_accel_m_s2_, mag_field);
        return;
    }

    // Tilt compensation: the field in earth axes; its horizontal part points to
    // magnetic north when the heading is right (eq. 31-33 in vector form).
    const Vector3f field_ef = r_ * mag_field;
    const float norm2 = mag_field.length_squared();
    const float horizontal2 = field_ef.x * field_ef.x + field_ef.y * field_ef.y;
    if (!(horizontal2 > 0.01f * norm2)) return;  // field within ~6 deg of vertical: no heading
    const float inv_norm = 1.0f / sqrtf(norm2);
    const float inv_horizontal = 1.0f / sqrtf(horizontal2);
    // sin of the heading error, saturated to +-1 beyond 90 deg so it stays monotonic.
    const float sin_error = field_ef.y * inv_horizontal;
    const float heading_error = field_ef.x >= 0.0f ? sin_error : (sin_error >= 0.0f ? 1.0f : -1.0f);

    // Disturbance rejection: a field whose strength or dip differs from the one
    // learned, or that disagrees with the gyro-propagated heading, is not the
    // earth's. A disagreement that lasts mag_recover_s is accepted (the heading
    // was wrong, not the field), as Fusion's recovery trigger does.
    const float norm = norm2 * inv_norm;
    const float down_component = field_ef.z * inv_norm;
    const bool odd_field = norm > 1.25f * mag_ref_norm_ || norm < 0.8f * mag_ref_norm_ ||
                           (down_component - mag_ref_down_) > 0.1f || (mag_ref_down_ - down_component) > 0.1f;
    const float reject_sin = sinf(settings_.mag_reject_rad);
    const bool disagrees = heading_error > reject_sin || heading_error < -reject_sin;
    if ((odd_field || disagrees) && mag_disturbed_s_ < settings_.mag_recover_s) {
        mag_disturbed_s_ += interval_s;
        return;
    }
    if (mag_disturbed_s_ >= settings_.mag_recover_s) {
        // Recovery: the field has been steady in its new form for mag_recover_s.
        // Learn it and take its heading at once (R <- Rz(-error) R, the rotation
        // that puts the field's horizontal part on north; no trigonometry needed).
        mag_ref_norm_ = norm;
        mag_ref_down_ = down_component;
        mag_disturbed_s_ = 0.0f;
        const float cos_error = field_ef.x * inv_horizontal;
        const Vector3f north = r_.a * cos_error + r_.b * sin_error;
        const Vector3f east = r_.b * cos_error - r_.a * sin_error;
        r_.a = north;
        r_.b = east;
        status_ &= (uint8_t)~kStatusMagIgnored;
        return;
    }
    mag_disturbed_s_ = 0.0f;
    status_ &= (uint8_t)~kStatusMagIgnored;
    // Track slow changes of the local field (temperature, location) 1 %/sample.
    mag_ref_norm_ += 0.01f * (norm - mag_ref_norm_);
    mag_ref_down_ += 0.01f * (down_component - mag_ref_down_);

    // The correction is a rotation about earth down by -error: in body axes that
    // is the third row of R. It stands for the whole interval since the last sample.
    const float interval = interval_s > kMaxMagInterval_s ? kMaxMagInterval_s : interval_s;
    const Vector3f error = r_.c * -heading_error;
    omega_yaw_rad_s_ = error * (proportional_gain(settings_.kp_yaw_1_s) * interval / settings_.step_s);
    if (!rotating_fast_) bias_rad_s_ -= error * (settings_.ki_yaw_1_s2 * interval);
    clamp_bias();
}

void Dcm::clamp_bias() {
    const float limit = settings_.bias_limit_rad_s;
    bias_rad_s_.x = linalg::constrain(bias_rad_s_.x, -limit, limit);
    bias_rad_s_.y = linalg::constrain(bias_rad_s_.y, -limit, limit);
    bias_rad_s_.z = linalg::constrain(bias_rad_s_.z, -limit, limit);
}

// Orthonormalisation (eq. 18-21): share the X.Y error between the two rows, make
// Z their cross product, then bring each row to unit length. Near unit length the
// first-order Taylor factor (3 - r.r)/2 replaces a square root and a division.
bool Dcm::renormalise() {
    const float error = r_.a.dot(r_.b);
    const Vector3f x = r_.a - r_.b * (0.5f * error);
    const Vector3f y = r_.b - r_.a * (0.5f * error);
    const Vector3f z = x.cross(y);
    return rescale(x, r_.a) && rescale(y, r_.b) && rescale(z, r_.c);
}

bool Dcm::rescale(const Vector3f& row, Vector3f& out) {
    const float length2 = row.length_squared();
    // Taylor's residual is 3/8 (r.r - 1)^2: below 2e-6 in this window.
    if (length2 > 0.998f && length2 < 1.002f) {
        out = row * (0.5f * (3.0f - length2));
        return true;
    }
    // Far from unit length: the exact factor, unless the matrix is hopeless.
    if (!(length2 > 0.25f && length2 < 4.0f)) return false;
    out = row * (1.0f / sqrtf(length2));
    return true;
}

// A matrix that renormalisation cannot save (NaN, or rows far from unit length)
// is rebuilt from the last good gravity and field, as at start-up; the bias
// estimate survives. ArduPilot's check_matrix() does the same.
void Dcm::recover() {
    ++recoveries_;
    status_ |= kStatusRecovered;
    if (!init(last_accel_m_s2_, last_mag_field_)) r_ = Matrix3f::identity();
}

}  // namespace dcm
