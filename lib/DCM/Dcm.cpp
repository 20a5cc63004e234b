#include "Dcm.h"

#include "Fixed.h"
#include "Profile.h"

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;

namespace {
// A mag correction stands for the time since the previous sample, but never more
// than this many steps (after an outage the first sample must not make a jump).
constexpr uint16_t kMaxMagIntervalSteps = 20;
// The accel low-pass during start-up, per correction (50 Hz): a 0.25 s time constant.
constexpr float kStartupAccelAlpha = 0.074f;
// The field may move this much in body axes during a rest: the HMC5883L's noise is
// ~0.2 uT with its 8-sample average; a turn of 3 deg moves a 20 uT horizontal field by
// 1 uT, so a steady turn of more than 2 deg/s ends a rest within its first 1.5 s, and
// a slower one before it has lasted 1 uT / (20 uT x rate).
constexpr float kRestFieldMove_uT = 1.0f;
// A compass sample at least this recent (steps) watches the rest (75 Hz: 2-3 steps).
constexpr uint16_t kRestCompassSteps = 20;
// 1/n for the means of n samples (no division on the AVR).
constexpr uint8_t kMaxWindow = 8;
constexpr float kInverse[kMaxWindow] = {1.0f, 0.5f, 1.0f / 3.0f, 0.25f, 0.2f, 1.0f / 6.0f, 1.0f / 7.0f, 0.125f};
}  // namespace

void Dcm::set_gyro_bias_rad_s(const Vector3f& bias) {
    if (!bias.is_finite()) return;
    bias_rad_s_ = bias;
    clamp_bias();
    offset_rad_s_ = bias_rad_s_ - correction_rad_s_;
}

// Each axis within the range of any accelerometer (16 g): three comparisons where
// |a|^2 would cost five float operations. NaN fails them too.
bool Dcm::accel_plausible(const Vector3f& a) const {
    const float m = accel_max_m_s2_;
    return a.x < m && a.x > -m && a.y < m && a.y > -m && a.z < m && a.z > -m;
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
        learn_field(mag_field.length(), down.dot(mag_field.normalized()));
    }
    r_ = Matrix3f(north, down.cross(north), down);
    accel_lp_ef_ = Vector3f(0.0f, 0.0f, -kGravity_m_s2);
    correction_rad_s_ = Vector3f();
    offset_rad_s_ = bias_rad_s_;
    yaw_pending_ = false;
    mag_steady_steps_ = 0;
    rest_corrections_ = 0;
    gyro_sum_rad_s_ = Vector3f();
    accel_sum_m_s2_ = Vector3f();
    window_samples_ = 0;
    accel_sum_of_sums_ = Vector3f();
    first_half_rad_s_ = Vector3f();
    turn_sum_rad_s_ = Vector3f();
    pending_steps_ = 0;
    rest_accel_mean_m_s2_ = accel_m_s2;
    steps_ = 0;
    status_ |= kStatusInitialised;
    return true;
}

void Dcm::learn_field(float norm, float down_component) {
    mag_ref_norm_ = mag_candidate_norm_ = norm;
    mag_ref_down_ = mag_candidate_down_ = down_component;
}

void Dcm::update(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2, bool line_due) {
    if (!initialised()) {
        init(accel_m_s2, last_mag_field_);
        return;
    }
    status_ &= (uint8_t)~(kStatusAccelIgnored | kStatusBiasHeld | kStatusGyroRejected);
    if (steps_since_mag_ < 0xFFFF) ++steps_since_mag_;
    // Start-up: a faster response that ramps down linearly to the steady one over
    // startup_s, so a poor first sample is forgotten quickly (Fusion does the same);
    // the bias is not learned from those transients.
    const bool starting = steps_ < startup_steps_;
    const float startup_left = starting ? 1.0f - (float)steps_ * inv_startup_steps_ : 0.0f;

    // NaN and infinity fail these comparisons too: such samples are rejected.
    const float rate2 = gyro_rad_s.length_squared();
    const bool gyro_ok = rate2 < max_rate2_;
    if (!gyro_ok) status_ |= kStatusGyroRejected;
    // No bias learning while rotating fast either: gyro scale errors look like bias
    // there (ArduPilot's rule). What counts is the turn that lasts, the 0.5 s mean rate
    // of the rest test: a scale error on a vibration (an 8 Hz wobble at 50 deg/s) makes
    // an error that averages out, while a hand's or a vehicle's turn does not (shake,
    // a board never still since power-on with a 2 deg/s bias: 17.8 -> 12.6 deg, VQF 14.4;
    // BROAD 1.57 -> 1.58).
    rotating_fast_ = !gyro_ok || (rest_gyro_mean_rad_s_ - bias_rad_s_).length_squared() > hold_rate2_;
    const bool hold_integrator = rotating_fast_ || starting;
    if (hold_integrator) status_ |= kStatusBiasHeld;

    // Gravity. The specific force is low-passed in the (estimated) earth frame, as
    // VQF does: there a linear acceleration averages out over the filter's time,
    // since velocity stays bounded, while in body axes it does not. Samples are
    // not weighted by how close |a| is to 1 g: dropping the large ones biases that
    // average (BROAD's fast translation, up to 10 g, shows it: 16 deg RMSE with
    // weighting, 0.7 without). Only a sample beyond any accelerometer's range is
    // garbage and skipped, and so is one whose gyro is beyond any range: the whole
    // read is broken then (a glitch on the bus, a spike).
    // The samples are summed here and low-passed at the correction's pace (50 Hz): the
    // low-pass is seconds long, so the mean of four samples loses nothing, and the
    // sum costs three additions where the rotation to earth axes costs fifteen
    // multiplications and additions.
    if (gyro_ok && accel_plausible(accel_m_s2)) {
        gyro_sum_rad_s_ += gyro_rad_s;
        accel_sum_m_s2_ += accel_m_s2;
        accel_sum_of_sums_ += accel_sum_m_s2_;  // sum of (samples from this one on) a_j
        ++window_samples_;
        last_accel_m_s2_ = accel_m_s2;
    } else {
        status_ |= kStatusAccelIgnored;
        rest_corrections_ = 0;  // a broken read is no rest
    }
    // The roll/pitch error (Premerlani & Bizard eq. 27) moves slowly once low-passed:
    // it is worked out every kCorrectionDivider steps and applied at every step in
    // between (below, on a step without an integration).
    if (++correction_phase_ >= kCorrectionDivider) {
        correction_phase_ = 0;
        gravity_due_ = true;
    }

    // Gyro integration, multi-rate (Savage, "Strapdown Inertial Navigation Integration
    // Algorithm Design", part 1): the corrected rates are summed at every step, and
    // every kIntegrationSteps steps the summed rotation vector turns the matrix, with
    // the two-sample coning term (2/3) A x B of its two halves A and B (Savage's
    // two-sample coning algorithm: the rotation vector of a rotation whose axis moved
    // within the interval). The
    // error against a 200 Hz update on BROAD's fast rotations: README, Performance.
    if (gyro_ok) {
        Vector3f rate_rad_s = gyro_rad_s - offset_rad_s_;
        if (yaw_pending_) rate_rad_s += omega_yaw_rad_s_;  // a mag correction is applied once
        last_rate_rad_s_ = rate_rad_s;
        turn_sum_rad_s_ += rate_rad_s;
    }
    yaw_pending_ = false;
    ++pending_steps_;
    if (pending_steps_ == kIntegrationSteps / 2) {
        first_half_rad_s_ = turn_sum_rad_s_;
        turn_sum_rad_s_ = Vector3f();
    }
    // One heavy part a step at most: the integration when due (or before an output
    // line, line_due, with two or more steps waiting), else the gravity correction
    // when due (a step later costs nothing: it follows a 3 s low-pass).
    heavy_ = true;
    if (pending_steps_ >= kIntegrationSteps || (line_due && pending_steps_ >= 2)) {
        integrate();
    } else if (gravity_due_) {
        correct_gravity(startup_left, hold_integrator);
    } else {
        heavy_ = false;
    }
    if (steps_ < 0xFFFFFFFFu) ++steps_;
}

// Rest detection and the gyro bias at rest (after VQF, Laidig & Seel 2023, sec. 3.4):
// the board is still when, for rest_min_s, the gyro and the accelerometer stay close to
// their recent means (deviations, so that any bias passes the test). There the gyro
// reads its bias alone, on every axis, the vertical one too, which neither gravity nor
// the compass can measure well: the bias estimate moves to the mean gyro reading with
// rest_bias_s. The MPU6000's rate noise, 0.005 deg/s/sqrt(Hz), averages to ~0.004 deg/s
// over the 0.5 s mean; a hand-held board's tremor is below 2 deg/s and 0.5 m/s^2.
void Dcm::detect_rest(const Vector3f& gyro_mean, const Vector3f& accel_mean, bool whole_window) {
    status_ &= (uint8_t)~kStatusAtRest;
    // A steady turn passes the deviation test too. The compass tells: at rest the field
    // stays put in body axes, in a turn it turns (correct_heading resets the rest when
    // it moves by kRestFieldMove_uT). Without a compass delivering, the mean must be
    // within the tremor bound of the bias estimate instead (VQF's rule, its 2 deg/s
    // bias clip): a larger vertical bias is then not told from a slow turn.
    const bool compass_watching = steps_since_mag_ < kRestCompassSteps && !(status_ & kStatusNoHeading);
    const bool still = (gyro_mean - rest_gyro_mean_rad_s_).length_squared() < rest_gyro_dev2_ &&
                       (compass_watching || (rest_gyro_mean_rad_s_ - bias_rad_s_).length_squared() < rest_gyro_dev2_) &&
                       (accel_mean - rest_accel_mean_m_s2_).length_squared() < rest_accel_dev2_;
    rest_gyro_mean_rad_s_ += (gyro_mean - rest_gyro_mean_rad_s_) * rest_alpha_;
    rest_accel_mean_m_s2_ += (accel_mean - rest_accel_mean_m_s2_) * rest_alpha_;
    if (!still || !whole_window) {
        rest_corrections_ = 0;
        return;
    }
    if (rest_corrections_ < rest_min_corrections_) {
        ++rest_corrections_;
        return;
    }
    status_ |= kStatusAtRest;
    bias_rad_s_ += (rest_gyro_mean_rad_s_ - bias_rad_s_) * rest_bias_alpha_;
    clamp_bias();
}

// The gravity correction: the accel window low-passed in earth axes, the rest test,
// and the roll/pitch error (correct_tilt).
void Dcm::correct_gravity(float startup_left, bool hold_integrator) {
    profile::begin(profile::kGravity);
    gravity_due_ = false;
    if (window_samples_ > 0) {
        const float inv_n = window_samples_ <= kMaxWindow ? kInverse[window_samples_ - 1] : 1.0f / (float)window_samples_;
        const Vector3f gyro_mean = gyro_sum_rad_s_ * inv_n;
        const Vector3f accel_mean = accel_sum_m_s2_ * inv_n;
        // Sample j of the window meets the matrix of the step before it, R_(j-1) =
        // R (I - [phi_j x]), phi_j = w dt (steps from j-1 to R's time). R is behind this
        // step's sample by the steps not yet integrated (this one among them), so the
        // steps are (n - j + 1) - pending, and sum_j phi_j x a_j is
        // w dt x (sum_j (n - j + 1) a_j - pending sum_j a_j): the first sum is the sum
        // of the running sums, three additions a step. (Weighting each sample, not the
        // mean, matters under a 10 g shake while turning: BROAD 16, 1.99 -> 1.69 deg.)
        const Vector3f turn_per_step = (gyro_mean - offset_rad_s_) * settings_.step_s;
        const Vector3f weighted = accel_sum_of_sums_ - accel_sum_m_s2_ * (float)pending_steps_;
        const float alpha = accel_alpha_ + (kStartupAccelAlpha - accel_alpha_) * startup_left;
        accel_lp_ef_ += (r_ * (accel_mean - turn_per_step.cross(weighted) * inv_n) - accel_lp_ef_) * alpha;
        detect_rest(gyro_mean, accel_mean, window_samples_ >= kCorrectionDivider);
    }
    gyro_sum_rad_s_ = Vector3f();
    accel_sum_m_s2_ = Vector3f();
    accel_sum_of_sums_ = Vector3f();
    window_samples_ = 0;
    correct_tilt(startup_left, hold_integrator);
    offset_rad_s_ = bias_rad_s_ - correction_rad_s_;
    profile::end(profile::kGravity);
}

// R <- R exp([theta x]) with theta the summed turn and its coning term (eq. 17, exact
// to the series' order). For a row r and a = |theta|, Rodrigues' formula is
//   r exp([theta x]) = cos(a) [r + (tan(a)/a)(r x theta) + k theta (r . theta)],
//   k = (1 - cos a) / (a^2 cos a),
// and the factor cos(a) is a length, which renormalisation takes out. The series below
// (tan(a)/a = 1 + a^2/3 + 2a^4/15 + 17a^6/315, k = 1/2 + 5a^2/24 + 61a^4/720) leave
// below 1e-6 rad an update up to a = 0.5 rad (1 430 deg/s at 50 Hz); the terms after
// a^2 are what a 50 Hz update needs (0.24 deg an update at 0.5 rad without them). The
// paper's first-order R (I + [theta x]) is not a rotation: renormalising it shrinks
// each row's component along the axis by a^2/2 an update. Row c is not integrated:
// renormalisation rebuilds it as a x b.
void Dcm::integrate() {
    profile::begin(profile::kIntegration);
    const float dt = settings_.step_s;
    const Vector3f first = first_half_rad_s_ * dt;
    const Vector3f second = turn_sum_rad_s_ * dt;
    const Vector3f theta = first + second + first.cross(second) * (2.0f / 3.0f);
    first_half_rad_s_ = Vector3f();
    turn_sum_rad_s_ = Vector3f();
    pending_steps_ = 0;
    const float a2 = theta.length_squared();
    const float tan_ratio = 1.0f + a2 * (1.0f / 3.0f + a2 * (2.0f / 15.0f + a2 * (17.0f / 315.0f)));
    const float k = 0.5f + a2 * (5.0f / 24.0f + a2 * (61.0f / 720.0f));
    const Vector3f stretched = theta * tan_ratio;
    const Vector3f k_theta = theta * k;
    r_.a += r_.a.cross(stretched) + theta * r_.a.dot(k_theta);
    r_.b += r_.b.cross(stretched) + theta * r_.b.dot(k_theta);
    profile::end(profile::kIntegration);
    profile::begin(profile::kRenormalisation);
    // One pass leaves ~(X.Y)^2: a second one, needed only at high rates (an update of
    // more than ~3 deg), keeps the matrix orthonormal to 1e-5 up to the gyro's range.
    float skew = 0.0f;
    bool ok = renormalise(skew);
    if (ok && (skew > 2e-3f || skew < -2e-3f)) ok = renormalise(skew);
    if (!ok) recover();
    profile::end(profile::kRenormalisation);
}

Vector3f Dcm::pending_turn_rad() const { return (first_half_rad_s_ + turn_sum_rad_s_) * settings_.step_s; }

void Dcm::correct_tilt(float startup_left, bool hold_integrator) {
    // Earth-frame error: measured down (-lp/|lp|) x earth down (0, 0, 1).
    const float lp2 = accel_lp_ef_.length_squared();
    if (!(lp2 > 0.25f * kGravity_m_s2 * kGravity_m_s2)) {
        correction_rad_s_ = Vector3f();
        return;
    }
    const float inv_lp = 1.0f / sqrtf(lp2);
    const float error_n = -accel_lp_ef_.y * inv_lp;
    const float error_e = accel_lp_ef_.x * inv_lp;
    // In body axes: R^T (error_n, error_e, 0).
    const Vector3f error = r_.a * error_n + r_.b * error_e;
    const float kp = settings_.kp_rp_1_s + (settings_.kp_startup_1_s - settings_.kp_rp_1_s) * startup_left;
    correction_rad_s_ = error * kp;
    if (!hold_integrator) {
        bias_rad_s_ -= error * (settings_.ki_rp_1_s2 * correction_dt_);
        clamp_bias();
    }
    // The correction turns the estimated earth frame by kp dt error_ef over the
    // next kCorrectionDivider steps: the low-pass state, kept in that frame, turns
    // with it ((e_n, e_e, 0) x lp, scaled).
    const float turn = kp * correction_dt_;
    const Vector3f lp = accel_lp_ef_;
    accel_lp_ef_ += Vector3f(error_e * lp.z, -error_n * lp.z, error_n * lp.y - error_e * lp.x) * turn;
}

void Dcm::correct_heading(const Vector3f& mag_field) {
    uint16_t interval_steps = steps_since_mag_;
    steps_since_mag_ = 0;
    status_ |= kStatusMagIgnored;
    const float norm2 = mag_field.length_squared();
    if (!(norm2 > 0.0f) || !linalg::is_finite(norm2)) return;
    last_mag_field_ = mag_field;
    // The rest test's witness: a field that moved in body axes since the rest began
    // means the board turns (or a magnet moved): no rest.
    if ((mag_field - rest_field_uT_).length_squared() > kRestFieldMove_uT * kRestFieldMove_uT) {
        rest_field_uT_ = mag_field;
        rest_corrections_ = 0;
    }
    if (!initialised()) return;
    if (status_ & kStatusNoHeading) {
        // The first field sample after a start without one: take its heading as is.
        init(last_accel_m_s2_, mag_field);
        return;
    }

    // The sample is older than the gyro-propagated attitude (the chip's averaging
    // and the wait for the next step): turn it forward by the rotation since, as a
    // fixed earth vector seen from the body moves, dm/dt = m x w.
    // The matrix itself is behind the last sample by the turn not yet integrated: the
    // field is brought back by that much (a fixed earth vector seen from the body
    // after a turn p reads v - p x v = v + v x p, so before it v x -p).
    const Vector3f field_now =
        mag_field + mag_field.cross(last_rate_rad_s_ * settings_.mag_latency_s - pending_turn_rad());
    // Tilt compensation: the field in earth axes; its horizontal part points to
    // magnetic north when the heading is right (eq. 31-33 in vector form).
    const Vector3f field_ef = r_ * field_now;
    const float horizontal2 = field_ef.x * field_ef.x + field_ef.y * field_ef.y;
    if (!(horizontal2 > 0.01f * norm2)) return;  // field within ~6 deg of vertical: no heading
    const float norm = sqrtf(norm2);
    const float down_component = field_ef.z / norm;
    const float inv_horizontal = 1.0f / sqrtf(horizontal2);
    const float sin_error = field_ef.y * inv_horizontal;

    // Disturbance rejection (as VQF does): a field whose strength or dip differs
    // from the learned earth field is a magnet or iron nearby, not north, and is not
    // used; the heading then runs on the gyro. A different field that stays the same
    // for mag_recover_s is a new environment (the board was moved): it becomes the
    // reference, and its heading is taken at once. A magnet fixed to a rotating
    // board never looks the same twice, so it never gets in.
    bool forgotten = !(mag_ref_norm_ > 0.0f);  // reset_mag_reference(): adopt this one
    if (forgotten && !mag_take_heading_) {
        learn_field(norm, down_component);  // the strength and dip only; the heading as usual
        mag_take_heading_ = true;
        forgotten = false;
    }
    if (forgotten || !field_matches(norm, down_component, mag_ref_norm_, mag_ref_down_, 1.0f)) {
        // Only a field that stays the same while the board turns is shown to be fixed
        // in the earth frame: at rest any disturbance (a magnet on the desk, one fixed to
        // the board) is steady too. VQF's rule: a mean rate of 20 deg/s over the window.
        if (field_matches(norm, down_component, mag_candidate_norm_, mag_candidate_down_, 0.5f)) {
            mag_steady_steps_ += interval_steps;
            mag_steady_turn_rad_ += sqrtf(last_rate_rad_s_.length_squared()) * settings_.step_s * (float)interval_steps;
        } else {
            mag_steady_steps_ = 0;
            mag_steady_turn_rad_ = 0.0f;
        }
        mag_candidate_norm_ += 0.2f * (norm - mag_candidate_norm_);
        mag_candidate_down_ += 0.2f * (down_component - mag_candidate_down_);
        if (!forgotten && ((float)mag_steady_steps_ < mag_recover_steps_ ||
                           mag_steady_turn_rad_ < mag_new_min_turn_rad_)) return;
        // A new steady field: learn it and take its heading at once, R <- Rz(-error) R
        // (the rotation that puts the field's horizontal part on north).
        learn_field(norm, down_component);
        mag_steady_steps_ = 0;
        mag_steady_turn_rad_ = 0.0f;
        const float cos_error = field_ef.x * inv_horizontal;
        const Vector3f north = r_.a * cos_error + r_.b * sin_error;
        r_.b = r_.b * cos_error - r_.a * sin_error;
        r_.a = north;
        status_ &= (uint8_t)~kStatusMagIgnored;
        return;
    }
    mag_steady_steps_ = 0;
    mag_steady_turn_rad_ = 0.0f;
    mag_candidate_norm_ = norm;
    mag_candidate_down_ = down_component;
    status_ &= (uint8_t)~kStatusMagIgnored;
    // Track slow changes of the local field (temperature, location): ~1.3 s at 75 Hz.
    mag_ref_norm_ += 0.01f * (norm - mag_ref_norm_);
    mag_ref_down_ += 0.01f * (down_component - mag_ref_down_);

    // sin of the heading error, saturated to +-1 beyond 90 deg so it stays monotonic.
    const float heading_error = field_ef.x >= 0.0f ? sin_error : (sin_error >= 0.0f ? 1.0f : -1.0f);
    // The correction is a rotation about earth down by -error: in body axes that
    // is the third row of R. It stands for the whole interval since the last sample
    // and is applied in the next step, so its rate is scaled by interval / step.
    if (interval_steps > kMaxMagIntervalSteps) interval_steps = kMaxMagIntervalSteps;
    const float steps = (float)interval_steps;
    const Vector3f error = r_.c * -heading_error;
    const bool starting = steps_ < startup_steps_;
    omega_yaw_rad_s_ = error * ((starting ? settings_.kp_startup_1_s : settings_.kp_yaw_1_s) * steps);
    yaw_pending_ = true;
    if (!rotating_fast_ && !starting) {
        bias_rad_s_ -= error * (settings_.ki_yaw_1_s2 * settings_.step_s * steps);
        clamp_bias();
        offset_rad_s_ = bias_rad_s_ - correction_rad_s_;
    }
}

EulerQ24 Dcm::euler_now_q24() const {
    // R carried forward by the lead and any turn not yet integrated (at most one step
    // when the update was told a line is due), in fixed point.
    const Vector3f theta_rad = last_rate_rad_s_ * settings_.output_lead_s + pending_turn_rad();
    return euler_carried_q24(r_, linalg::fixed_from_float(theta_rad.x, 26), linalg::fixed_from_float(theta_rad.y, 26),
                             linalg::fixed_from_float(theta_rad.z, 26));
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
    float* axis[3] = {&bias_rad_s_.x, &bias_rad_s_.y, &bias_rad_s_.z};
    for (uint8_t i = 0; i < 3; ++i) *axis[i] = linalg::constrain(*axis[i], -limit, limit);
}

// Orthonormalisation (eq. 18-21): share the X.Y error between the two rows, bring
// each to unit length, and make Z their cross product (unit to within the square
// of the remaining error, so it needs no scaling of its own).
bool Dcm::renormalise(float& skew) {
    skew = r_.a.dot(r_.b);
    const float half_error = 0.5f * skew;
    const Vector3f x = r_.a - r_.b * half_error;
    const Vector3f y = r_.b - r_.a * half_error;
    if (!rescale(x, r_.a) || !rescale(y, r_.b)) return false;
    r_.c = r_.a.cross(r_.b);
    return true;
}

// Near unit length the first-order Taylor factor (3 - r.r)/2 replaces a square root
// and a division; its residual is 3/8 (r.r - 1)^2, below 2e-6 in this window.
bool Dcm::rescale(const Vector3f& row, Vector3f& out) {
    const float length2 = row.length_squared();
    if (length2 > 0.998f && length2 < 1.002f) {
        out = row * (1.5f - 0.5f * length2);
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
