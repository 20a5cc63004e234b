#include "Dcm.h"

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {
constexpr float kGravity_m_s2 = 9.80665f;
// Beyond any MEMS gyro's range (the MPU6000 stops at 2000 deg/s = 35 rad/s): such a
// sample is garbage, not a rotation, and is not integrated.
constexpr float kMaxCredibleRate_rad_s = 50.0f;
// A mag correction stands for the time since the previous sample, but never more
// than this (after an outage the first sample must not make a jump).
constexpr float kMaxMagInterval_s = 0.1f;
// The accel low-pass during start-up: a 0.25 s time constant at 200 Hz.
constexpr float kStartupAccelAlpha = 0.02f;
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
    3.0f,                           // startup_s
    16.0f,                          // accel_max_g
    3.0f,                           // accel_lowpass_s
    20.0f * linalg::kRadPerDeg,     // integrator_hold_rate_rad_s (ArduPilot's 20 deg/s)
    10.0f * linalg::kRadPerDeg,     // bias_limit_rad_s
    0.2f,                           // mag_norm_tolerance
    0.1f,                           // mag_dip_tolerance
    20.0f,                          // mag_recover_s
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
        mag_candidate_norm_ = mag_ref_norm_;
        mag_candidate_down_ = mag_ref_down_;
    }
    const Vector3f east = down.cross(north);
    r_ = Matrix3f(north, east, down);
    accel_lp_ef_ = Vector3f(0.0f, 0.0f, -kGravity_m_s2);
    accel_alpha_ = settings_.step_s / (settings_.accel_lowpass_s + settings_.step_s);
    omega_yaw_rad_s_ = Vector3f();
    mag_disturbed_s_ = 0.0f;
    steps_ = 0;
    status_ |= kStatusInitialised;
    return true;
}

// Start-up: a faster response that ramps down linearly to the steady one over
// startup_s, so a poor first sample is forgotten quickly (Fusion does the same).
float Dcm::startup_boost(float steady, float boosted) const {
    const float startup_steps = settings_.startup_s / settings_.step_s;
    if ((float)steps_ >= startup_steps || boosted <= steady) return steady;
    return steady + (boosted - steady) * (1.0f - (float)steps_ / startup_steps);
}

float Dcm::proportional_gain(float steady_gain_1_s) const {
    return startup_boost(steady_gain_1_s, settings_.kp_startup_1_s);
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
    // The bias is not learned from start-up transients nor while rotating fast
    // (where gyro scale errors look like bias: ArduPilot's rule).
    const bool starting = (float)steps_ < settings_.startup_s / dt;
    const bool hold_integrator = !gyro_ok || starting || gyro_rad_s.length_squared() > hold2;
    if (hold_integrator) status_ |= kStatusBiasHeld;
    rotating_fast_ = hold_integrator;

    // Roll/pitch error (Premerlani & Bizard eq. 27): measured down x estimated down.
    // The measurement is the specific force low-passed in the (estimated) earth
    // frame, as VQF does: there a linear acceleration averages out over the filter's
    // time, since velocity stays bounded, while in body axes it does not. Samples
    // are not weighted by how close |a| is to 1 g: dropping the large ones biases
    // that average (BROAD's fast translation, up to 10 g, shows it: 16 deg RMSE with
    // weighting, 0.7 without). Only a sample beyond any accelerometer's range is
    // garbage and skipped.
    Vector3f correction_rad_s;
    const float accel_max_m_s2 = settings_.accel_max_g * kGravity_m_s2;
    if (accel_m_s2.is_finite() && accel_m_s2.length_squared() < accel_max_m_s2 * accel_max_m_s2) {
        last_accel_m_s2_ = accel_m_s2;
        accel_lp_ef_ += (r_ * accel_m_s2 - accel_lp_ef_) * startup_boost(accel_alpha_, kStartupAccelAlpha);
    } else {
        status_ |= kStatusAccelIgnored;
    }
    {
        // Earth-frame error: measured down (-lp/|lp|) x earth down (0, 0, 1).
        const float lp2 = accel_lp_ef_.length_squared();
        if (lp2 > 0.25f * kGravity_m_s2 * kGravity_m_s2) {
            const float inv = 1.0f / sqrtf(lp2);
            const Vector3f error_ef(-accel_lp_ef_.y * inv, accel_lp_ef_.x * inv, 0.0f);
            const Vector3f error = r_.mul_transpose(error_ef);
            const float kp = proportional_gain(settings_.kp_rp_1_s);
            correction_rad_s = error * kp;
            if (!hold_integrator) bias_rad_s_ -= error * (settings_.ki_rp_1_s2 * dt);
            // The correction turns the estimated earth frame by kp dt error_ef: the
            // filter state, kept in that frame, turns with it.
            accel_lp_ef_ += (error_ef * (kp * dt)).cross(accel_lp_ef_);
        }
    }
    // Yaw correction from the last magnetometer sample, applied once.
    correction_rad_s += omega_yaw_rad_s_;
    omega_yaw_rad_s_ = Vector3f();
    clamp_bias();

    // Gyro integration (eq. 17, to second order): R <- R exp([theta x]), theta = w dt,
    // row_i [theta x] = row_i x theta. The paper's first-order R (I + [theta x]) is not
    // a rotation: renormalising it shrinks each row's component along the axis by
    // theta^2/2 a step, which at 640 deg/s tilts the matrix by 50 deg in 10 s at
    // 200 Hz. The second-order term (row x theta) x theta / 2 and the first term's
    // (1 - |theta|^2/6) make the step exact to O(theta^4). Row c need not be
    // integrated: renormalisation rebuilds it as a x b.
    if (gyro_ok) {
        const Vector3f theta = (gyro_rad_s - bias_rad_s_ + correction_rad_s) * dt;
        const float first_order = 1.0f - (1.0f / 6.0f) * theta.length_squared();
        const Vector3f da = r_.a.cross(theta);
        const Vector3f db = r_.b.cross(theta);
        r_.a += da * first_order + da.cross(theta) * 0.5f;
        r_.b += db * first_order + db.cross(theta) * 0.5f;
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

    // Disturbance rejection (as VQF does): a field whose strength or dip differs
    // from the learned earth field is a magnet or iron nearby, not north, and is not
    // used; the heading then runs on the gyro. A different field that stays the same
    // for mag_recover_s is a new environment (the board was moved): it becomes the
    // reference, and its heading is taken at once. A magnet fixed to a rotating
    // board never looks the same twice, so it never gets in.
    const float norm = norm2 * inv_norm;
    const float down_component = field_ef.z * inv_norm;
    if (!field_matches(norm, down_component, mag_ref_norm_, mag_ref_down_, 1.0f)) {
        if (field_matches(norm, down_component, mag_candidate_norm_, mag_candidate_down_, 0.5f)) {
            mag_disturbed_s_ += interval_s;
        } else {
            mag_disturbed_s_ = 0.0f;
        }
        mag_candidate_norm_ += 0.2f * (norm - mag_candidate_norm_);
        mag_candidate_down_ += 0.2f * (down_component - mag_candidate_down_);
        if (mag_disturbed_s_ < settings_.mag_recover_s) return;
        // A new steady field: learn it and take its heading at once, R <- Rz(-error) R
        // (the rotation that puts the field's horizontal part on north).
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
    mag_candidate_norm_ = norm;
    mag_candidate_down_ = down_component;
    status_ &= (uint8_t)~kStatusMagIgnored;
    // Track slow changes of the local field (temperature, location): ~2 s at 75 Hz.
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

bool Dcm::field_matches(float norm, float down_component, float ref_norm, float ref_down,
                        float tolerance_scale) const {
    const float norm_tolerance = settings_.mag_norm_tolerance * tolerance_scale * ref_norm;
    const float dip_tolerance = settings_.mag_dip_tolerance * tolerance_scale;
    const float norm_error = norm - ref_norm;
    const float dip_error = down_component - ref_down;
    return norm_error < norm_tolerance && norm_error > -norm_tolerance && dip_error < dip_tolerance &&
           dip_error > -dip_tolerance;
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
