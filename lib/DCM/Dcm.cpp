// SPDX-License-Identifier: GPL-3.0-or-later
#include "Dcm.h"

#include "Fixed.h"
#include "Profile.h"

#include <math.h>

namespace dcm {

using linalg::Matrix3f;
using linalg::Vector3f;
using linalg::Vector3l;

Dcm::Dcm(const DcmSettings& settings) : settings_(&settings) { k_.from_settings(settings); }

void Dcm::set_gyro_bias_rad_s(const Vector3f& bias) {
    bias_.set_estimate_rad_s(bias, k_);
    update_offset();
}

Vector3f Dcm::gyro_bias_rad_s() const { return bias_.estimate_rad_s(k_); }

Vector3f Dcm::last_mag_field() const { return field_uT_of(last_field_q5_); }


void Dcm::set_sensor_bias_rad_s(const Vector3f& bias) {
    bias_.set_sensor_rad_s(bias, k_);
    update_offset();
}

// The state held in the sensors' units is carried over to the new scales.
void Dcm::set_sample_scales(float gyro_rad_s_per_count, float accel_m_s2_per_count) {
    const float gyro_ratio = k_.gyro_rad_s_per_count / gyro_rad_s_per_count, accel_ratio = k_.accel_m_s2_per_count / accel_m_s2_per_count;
    if (gyro_ratio != 1.0f) {
        bias_.rescale(gyro_ratio);
    }
    gravity_.rescale(gyro_ratio, accel_ratio);
    rest_.rescale(gyro_ratio, accel_ratio);
    k_.set_scales(*settings_, gyro_rad_s_per_count, accel_m_s2_per_count);
    update_offset();
}

// What each step subtracts from the gyro, in the integer units of the turn sums
// (counts * 2^kTurnFraction).
void Dcm::update_offset() {
    offset_units_ = bias_.offset_units(gravity_.correction_units());
}


// Each axis within the range of any accelerometer (16 g): three comparisons where
// |a|^2 would cost five float operations. NaN fails them too.
bool Dcm::accel_plausible(const Vector3f& a) const {
    const float m = settings_->accel_max_g * kGravity_m_s2;
    return a.x < m && a.x > -m && a.y < m && a.y > -m && a.z < m && a.z > -m;
}

// TRIAD (Shuster & Oh 1981, as in the thesis): the rows of R are the earth axes
// in body coordinates, so they are built directly from the two observations.
bool Dcm::init(const Vector3f& accel_m_s2, const Vector3f& mag_field, bool gravity_is_mean) {
    if (!accel_m_s2.is_finite()) return false;
    const Vector3f down = (-accel_m_s2).normalized();  // specific force points up
    if (down.is_zero()) return false;
    last_accel_ = linalg::fixed_from_vector(accel_m_s2 * (k_.accel_units_per_m_s2 * (1.0f / (float)kTurnScale)), 0);  // for a rebuild

    // North: the field's component perpendicular to down. Without a usable field,
    // the body x axis projected on the horizontal (yaw 0), or body y at pitch 90.
    Vector3f north;
    // (d x m) x d = m - d (d . m) for a unit d: one dot product, not two cross products.
    const float field_down = mag_field.is_finite() ? down.dot(mag_field) : 0.0f;
    if (mag_field.is_finite()) north = (mag_field - down * field_down).normalized();
    if (north.is_zero()) {
        status_ |= kStatusNoHeading;
        north = (down.cross(Vector3f(1.0f, 0.0f, 0.0f))).cross(down).normalized();
        if (north.is_zero()) north = (down.cross(Vector3f(0.0f, 1.0f, 0.0f))).cross(down).normalized();
    } else {
        status_ &= (uint8_t)~kStatusNoHeading;
        const Vector3f kept(linalg::constrain(mag_field.x, -kMaxField_uT, kMaxField_uT),
                            linalg::constrain(mag_field.y, -kMaxField_uT, kMaxField_uT),
                            linalg::constrain(mag_field.z, -kMaxField_uT, kMaxField_uT));
        last_field_q5_ = linalg::Vector3i((int16_t)linalg::fixed_from_float(kept.x, kFieldQ),
                                          (int16_t)linalg::fixed_from_float(kept.y, kFieldQ),
                                          (int16_t)linalg::fixed_from_float(kept.z, kFieldQ));
        const float norm = mag_field.length();
        heading_.learn_field(norm, field_down / norm);
    }
    strapdown_.reset(linalg::q30_from_matrix(Matrix3f(north, down.cross(north), down)));
    // The integer factors of the scales, unless set_sample_scales set them (the float
    // form's, whose scales are the defaults: the Pipeline sets its own before the start).
    if (k_.theta_factor_q30 == 0) k_.derive_from_scales(*settings_);
    const float per_m_s2 = k_.accel_units_per_m_s2;
    gravity_.reset(linalg::fixed_from_float(-kGravity_m_s2 * per_m_s2, 0));
    update_offset();
    heading_.restart();
    rest_.reset(linalg::fixed_from_vector(accel_m_s2 * per_m_s2, 0));
    steps_ = 0;
    start_from_mean_ = gravity_is_mean;
    gps_.stop();  // no pair across a start
    course_taken_ = false;
    status_ |= kStatusInitialised;
    return true;
}



Vector3l Dcm::gyro_turn_q30(const Vector3l& counts, uint16_t steps) const {
    // In the turn sums' units, less the bias at every step. Within 1 024 steps in
    // integers: beyond 2^22 counts (128 steps at full scale) the turn is far beyond the
    // saturation, and within, no product overflows. A longer interval (the first sample
    // after a compass outage) in float: the bias times 65 535 steps would overflow, and
    // a still board's counts are then its bias times steps, which the clamp would cut.
    constexpr int32_t kMaxCounts = 1L << 22;
    const Vector3l bias = bias_.sensor_units() + bias_.units();
    const int32_t* c = &counts.x;
    const int32_t* b = &bias.x;
    int32_t units[3];
    for (uint8_t i = 0; i < 3; ++i) {
        if (steps > 1024u) {
            const float limit = (float)(1L << 30);  // beyond any saturation below
            const float u = (float)c[i] * (float)kTurnScale - (float)b[i] * (float)steps;
            units[i] = (int32_t)linalg::constrain(u, -limit, limit);
            continue;
        }
        const int32_t sum = c[i] > kMaxCounts ? kMaxCounts : (c[i] < -kMaxCounts ? -kMaxCounts : c[i]);
        units[i] = in_turn_units(sum) - b[i] * (int32_t)steps;
    }
    // Saturated at twice an integration's limit (1.5 rad: still within Q30's 2).
    if (k_.theta_factor_q30 == 0) {  // scales beyond the integer factor
        const float limit = 2.0f * (float)kMaxTurnAxisQ26 / 67108864.0f;
        const Vector3f t = Vector3l(units[0], units[1], units[2]).scaled(k_.turn_rad_per_unit());
        return linalg::fixed_from_vector(Vector3f(linalg::constrain(t.x, -limit, limit), linalg::constrain(t.y, -limit, limit),
                                                  linalg::constrain(t.z, -limit, limit)),
                                         linalg::kQ30);
    }
    const int32_t limit = 2 * k_.theta_units_limit;
    int32_t q30[3];
    for (uint8_t i = 0; i < 3; ++i) {
        const int32_t u = units[i] > limit ? limit : (units[i] < -limit ? -limit : units[i]);
        q30[i] = linalg::mul_q30(k_.theta_factor_q30, u) * 16;
    }
    return Vector3l(q30[0], q30[1], q30[2]);
}



// The float form: the sample in SI units, held in the integer units of the step
// (kFloatGyroScale, kFloatAccelScale), after the checks a float sample needs.
void Dcm::update(const Vector3f& gyro_rad_s, const Vector3f& accel_m_s2, bool line_due) {
    if (k_.gyro_rad_s_per_count != kFloatGyroScale || k_.accel_m_s2_per_count != kFloatAccelScale)
        set_sample_scales(kFloatGyroScale, kFloatAccelScale);
    // NaN and infinity fail these comparisons too: such samples are rejected.
    const bool gyro_ok = gyro_rad_s.length_squared() < kMaxCredibleRate_rad_s * kMaxCredibleRate_rad_s;
    const bool accel_ok = accel_plausible(accel_m_s2);
    const Vector3l gyro = gyro_ok ? linalg::fixed_from_vector(gyro_rad_s * (1.0f / kFloatGyroScale), 0) : Vector3l();
    const Vector3l accel = accel_ok ? linalg::fixed_from_vector(accel_m_s2 * (1.0f / kFloatAccelScale), 0) : Vector3l();
    if (!initialised()) {
        init(accel_m_s2, last_mag_field());
        return;
    }
    step(gyro, accel, gyro_ok, accel_ok, line_due);
}

void Dcm::update(const linalg::Vector3i& gyro_counts, const linalg::Vector3i& accel_counts, bool gyro_valid,
                 bool accel_valid, bool line_due) {
    const Vector3l gyro{gyro_counts.x, gyro_counts.y, gyro_counts.z};
    const Vector3l accel{accel_counts.x, accel_counts.y, accel_counts.z};
    if (!initialised()) {
        init(accel.scaled(k_.accel_m_s2_per_count), last_mag_field());
        return;
    }
    step(gyro, accel, gyro_valid, accel_valid, line_due);
}


// The step as ArduPilot's AP_AHRS_DCM::update() reads: the sample into the sums, then
// at most one heavy part (HeavySchedule). The heading has its own call, when a field
// sample arrives (correct_heading).
void Dcm::step(const Vector3l& gyro, const Vector3l& accel, bool gyro_ok, bool accel_ok, bool line_due) {
    const HeavyPart heavy = next_heavy_part(line_due);
    take_sample(gyro, accel, gyro_ok, accel_ok);     // the checks; into the gravity window and the turn
    heavy_ = HeavySchedule::blocks(heavy);
    if (heavy == HeavyPart::kIntegration) {
        strapdown_.integrate(k_);                    // matrix_update: R <- R exp([theta x])
    } else if (heavy == HeavyPart::kGravity) {
        correct_gravity();                           // drift_correction's roll/pitch, the rest test, the bias
    } else if (heavy == HeavyPart::kRenormalisation) {
        if (!strapdown_.renormalise()) recover();    // normalize, check_matrix's rebuild
    }
    if (steps_ < 0xFFFFu) ++steps_;
}

// The sample's checks (status), then into the gravity window and the strapdown's turn.
void Dcm::take_sample(const Vector3l& gyro, const Vector3l& accel, bool gyro_ok, bool accel_ok) {
    status_ &= (uint8_t)~(kStatusAccelIgnored | kStatusBiasHeld | kStatusGyroRejected);
    heading_.count_step();
    if (!gyro_ok) {
        status_ |= kStatusGyroRejected;
        bias_.hold_for_broken_sample();  // no bias learning on a broken gyro read
    }
    if (bias_.integrator_held(steps_ < k_.startup_steps, start_from_mean_)) status_ |= kStatusBiasHeld;

    // Gravity. The specific force is low-passed in the (estimated) earth frame, as
    // VQF does: there a linear acceleration averages out over the filter's time,
    // since velocity stays bounded, while in body axes it does not. Samples are
    // not weighted by how close |a| is to 1 g: a translation's acceleration averages
    // out only as a whole, and dropping or shrinking its large samples (a fast shake's
    // peaks, up to 10 g) leaves the rest of it in the average as tilt. Only a sample
    // beyond any accelerometer's range is garbage and skipped, and so is one whose gyro
    // is beyond any range: the whole read is broken then (a glitch on the bus, a spike).
    // The samples are summed here, in integers, and low-passed at the correction's pace
    // (50 Hz): the low-pass is seconds long, so the mean of four samples loses nothing.
    if (gyro_ok && accel_ok) {
        gravity_.add(gyro, accel);
        last_accel_ = accel;
    } else {
        status_ |= kStatusAccelIgnored;
        rest_.interrupt();  // a broken read is no rest
    }
    // The roll/pitch error (Premerlani & Bizard eq. 27) moves slowly once low-passed:
    // it is worked out every kCorrectionDivider steps and applied at every step in
    // between (below, on a step without an integration).
    schedule_.count_step();

    // Gyro integration, multi-rate (Savage, "Strapdown Inertial Navigation Integration
    // Algorithm Design", part 1): the corrected rates are summed at every step, and
    // every kIntegrationSteps steps the summed rotation vector turns the matrix, with
    // the two-sample coning term (2/3) A x B of its two halves A and B (Savage's
    // two-sample coning algorithm: the rotation vector of a rotation whose axis moved
    // within the interval). The sums are integers: counts * 2^kTurnFraction less the
    // offset in the same units (the bias to 1/256 of a count). The error against a
    // 200 Hz update on fast rotations: docs/performance.md.
    if (gyro_ok) {
        last_gyro_ = gyro;
        strapdown_.add_turn(Vector3l(in_turn_units(gyro.x) - offset_units_.x, in_turn_units(gyro.y) - offset_units_.y,
                                     in_turn_units(gyro.z) - offset_units_.z));
    }
    strapdown_.end_step();
}

// Rest detection (RestDetector) and, at rest, the bias estimate from the rest mean.
// A steady turn passes the deviation test too: the compass tells (correct_heading
// watches the field) while one delivers.
void Dcm::detect_rest(const WindowMeans& window, const Vector3l& mean_off_bias) {
    status_ &= (uint8_t)~kStatusAtRest;
    const bool compass_watching = heading_.sample_recent() && !(status_ & kStatusNoHeading);
    if (!rest_.update(window.gyro, window.accel, mean_off_bias, window.whole, compass_watching, k_)) return;
    status_ |= kStatusAtRest;
    trace().bias_before(bias_, k_);
    bias_.learn_at_rest(rest_.gyro_mean(), k_);
    trace().bias_after(BiasSource::kRest, bias_, k_);
}

// What the gravity correction reads: R, the turn not yet integrated, the offsets, and
// where the start-up ramp is. The start-up's fast gain (kp_startup) pulls in a start
// from one sample, whatever the moment's acceleration put in it. A start from a mean
// (the still calibration's, a never-still window's: Pipeline) is as good as gravity
// gets; a fast gain would only follow the accelerations since (a gust's 2-3 m/s^2 at
// 5/s: degrees of tilt within 0.3 s, 2.5 times as much heading through the dip). The
// low-pass's start-up ramp stays: a bias nothing measured turns the estimate from the
// first step, and inside the loop a 3 s low-pass makes its answer slow and ringing
// (second order, damping 1 / (2 sqrt(kp tau)): 0.29 at 3 s, 1 at 0.25 s).
FIXED_INLINE GravityContext Dcm::gravity_context() {
    const bool starting = steps_ < k_.startup_steps;
    const float startup_left = starting ? 1.0f - (float)steps_ * k_.inv_startup_steps : 0.0f;
    const float tilt_startup_left = start_from_mean_ ? 0.0f : startup_left;
    return GravityContext{*settings_, k_, strapdown_.r(), strapdown_.pending_steps(), offset_units_,
                          bias_.sensor_units(), starting, startup_left, tilt_startup_left, trace()};
}

// The gravity correction (drift_correction's roll and pitch): the bias integrator's
// holds, the turn's acceleration off the window, the window into the earth-frame
// low-pass and the rest test, and the roll/pitch error (GravityCorrection).
FIXED_OWN_FRAME void Dcm::correct_gravity() {
    profile::begin(profile::kGravity);
    schedule_.gravity_done();
    const GravityContext context = gravity_context();
    // The bias integrator's holds (GyroBias): the turn that lasts, the rest test's mean
    // rate less the estimate; a rejected gyro sample in the window; the start-up.
    const Vector3l mean_off_bias = rest_.gyro_mean() - bias_.units();  // the rest mean's turn (units)
    bias_.judge_rotation(mean_off_bias, (status_ & kStatusGyroRejected) != 0, k_);
    const bool hold_integrator = bias_.integrator_held(context.starting, start_from_mean_);
    // In flight, the turn's centripetal acceleration off the window first (Centripetal.h),
    // unless the GPS's acceleration comes off it (GpsAid.h: the turn's is in it).
    const bool gps_aiding = gps_.aiding();
    const bool turn = turn_ != nullptr && turn_->active() && !gps_aiding;
    if (turn) gravity_.subtract_turn(*turn_, context);
    // The window into the earth-frame low-pass (or, GPS-aided, into the GPS's sums: its
    // observations feed the low-pass), its means into the rest test.
    WindowMeans window;
    if (gravity_.low_pass_window(context, window, !gps_aiding)) {
        detect_rest(window, mean_off_bias);
        // The GPS's sums take the specific force as measured (its acceleration comes off
        // at the pair): before its aiding starts, the turn's term goes back, in earth axes.
        if (turn && gps_.receiving()) window.accel_ef += earth_of_counts(turn_->term());
        gps_.add_window(window.accel_ef);
    }
    // The low-pass's direction against earth down: the roll/pitch correction, and its
    // integral into the bias unless held.
    gravity_.correct_tilt(context, hold_integrator, bias_);
    update_offset();
    profile::end(profile::kGravity);
}


// A vector in accel counts in body axes, in earth axes and accel units (counts * 2^8),
// by R in 16 bits (Q14: 6e-5 of it).
Vector3l Dcm::earth_of_counts(const linalg::Vector3i& counts) const {
    using linalg::mul_q14;
    using linalg::q14_of;
    const linalg::Matrix3q30& r = strapdown_.r();
    const Vector3l u((int32_t)counts.x * 256, (int32_t)counts.y * 256, (int32_t)counts.z * 256);
    return Vector3l(mul_q14(q14_of(r.a.x), u.x) + mul_q14(q14_of(r.a.y), u.y) + mul_q14(q14_of(r.a.z), u.z),
                    mul_q14(q14_of(r.b.x), u.x) + mul_q14(q14_of(r.b.y), u.y) + mul_q14(q14_of(r.b.z), u.z),
                    mul_q14(q14_of(r.c.x), u.x) + mul_q14(q14_of(r.c.y), u.y) + mul_q14(q14_of(r.c.z), u.z));
}

// A GPS velocity (GpsAid.h): a completed pair's observation into the low-pass, with the
// factor of its interval against gps_lowpass_s (5 Hz, in float): 1 - exp(-I / tau) as
// I / (tau + I / 2) (the bilinear form: within 1e-3 of it at I / tau = 0.2, no exp).
void Dcm::on_gps_velocity(const Vector3f& vel_ned_m_s, float interval_s, float gain) {
    if (!initialised() || steps_ < k_.startup_steps) {
        gps_.stop();
        return;
    }
    Vector3l observation;
    if (!gps_.on_velocity(vel_ned_m_s, interval_s, gain, k_.accel_units_per_m_s2,
                          observation))
        return;
    const float alpha = interval_s / (settings_->gps_lowpass_s + 0.5f * interval_s);
    gravity_.low_pass_observation(observation, linalg::fixed_from_float(alpha, linalg::kQ30));
}

// The GPS course as the heading reference (AP_AHRS_DCM without a compass): the error
// sin(yaw - course), yaw's cosine and sine from R's first column (cos(pitch) cos(yaw),
// cos(pitch) sin(yaw)), corrected at kp_yaw as a compass's mean is (Heading.h); the
// first one after a start without a heading at once.
void Dcm::correct_heading_from_course(float course_rad, uint16_t interval_steps) {
    if (!initialised()) return;
    const float north = linalg::float_from_fixed(strapdown_.r().a.x, linalg::kQ30);
    const float east = linalg::float_from_fixed(strapdown_.r().b.x, linalg::kQ30);
    const float horizontal2 = north * north + east * east;
    if (!(horizontal2 > 0.01f)) return;  // the nose within ~6 deg of vertical: no yaw to correct
    const float inv = linalg::inverse_sqrt(horizontal2);
    const float cos_course = cosf(course_rad), sin_course = sinf(course_rad);
    const float cos_error = (north * cos_course + east * sin_course) * inv;
    const float sin_error = (east * cos_course - north * sin_course) * inv;
    if ((status_ & kStatusNoHeading) && !course_taken_) {
        course_taken_ = true;
        turn_heading_at_once(strapdown_.r(), cos_error, sin_error);
        return;
    }
    // Saturated at +-1 beyond 90 deg, so it stays monotonic (as the compass's).
    const float heading_error = cos_error >= 0.0f ? sin_error : (sin_error >= 0.0f ? 1.0f : -1.0f);
    const uint16_t steps = interval_steps < kGpsMaxCourseSteps ? interval_steps : kGpsMaxCourseSteps;
    turn_heading(strapdown_, heading_error, settings_->kp_yaw_1_s, (float)steps, k_);
}

Vector3l Dcm::pending_turn_units() const { return strapdown_.pending_units(); }

FIXED_COLD Vector3f Dcm::pending_turn_rad() const { return pending_turn_units().scaled(k_.turn_rad_per_unit()); }

FIXED_INLINE Vector3l Dcm::last_rate_units() const {
    return Vector3l(in_turn_units(last_gyro_.x) - offset_units_.x, in_turn_units(last_gyro_.y) - offset_units_.y,
                    in_turn_units(last_gyro_.z) - offset_units_.z);
}

FIXED_COLD Vector3f Dcm::last_rate_rad_s() const { return last_rate_units().scaled(k_.gyro_rad_s_per_count * (1.0f / (float)kTurnScale)); }


void Dcm::correct_heading(const Vector3f& mag_field, uint8_t age_steps) {
    linalg::Vector3i field;
    if (!field_q5_of(mag_field, field)) {  // beyond any compass: garbage
        heading_.take_interval();
        status_ |= kStatusMagIgnored;
        return;
    }
    correct_heading(field, age_steps);
}

// The sample's checks, the rest test's witness and the start's heading; then the
// heading correction (HeadingCorrection).
void Dcm::correct_heading(const linalg::Vector3i& field, uint8_t age_steps) {
    const uint16_t since_last = heading_.take_interval();
    const uint32_t sample_norm2 = field_norm2(field);  // uT^2 * 2^(2 kFieldQ - kNorm2Shift)
    if (sample_norm2 == 0) {
        status_ |= kStatusMagIgnored;
        return;
    }
    last_field_q5_ = field;
    // The rest test's witness: a field that moved in body axes since the rest began
    // means the board turns (or a magnet moved): no rest.
    rest_.watch_field(field);
    if (!initialised()) return;
    if (status_ & kStatusNoHeading) {
        // The first field sample after a start without one: take its heading as is.
        init(last_accel_.scaled(k_.accel_m_s2_per_count), last_mag_field());
        return;
    }
    // The sample into the heading's mean; a complete mean corrects the heading. (Each call
    // has its own context: the 75 Hz part's stays in registers.)
    if (!heading_.add_sample(field, sample_norm2, since_last, age_steps, heading_context())) return;
    const HeadingResult result = heading_.correct(heading_context());
    if (result.field_used)
        status_ &= (uint8_t)~kStatusMagIgnored;
    else
        status_ |= kStatusMagIgnored;
    if (result.bias_learned) update_offset();
}

EulerQ24 Dcm::euler_now_q24(const int16_t (*trim_q14)[3]) const {
    // R carried forward by the lead and any turn not yet integrated (at most one step
    // when the update was told a line is due), in fixed point.
    int32_t theta_q26[3];
    if (k_.theta_q26_per_unit_q15 == 0) {  // scales beyond the integer path's factors: in float
        const Vector3f theta_rad = last_rate_rad_s() * settings_->output_lead_s + pending_turn_rad();
        theta_q26[0] = linalg::fixed_from_float(theta_rad.x, 26);
        theta_q26[1] = linalg::fixed_from_float(theta_rad.y, 26);
        theta_q26[2] = linalg::fixed_from_float(theta_rad.z, 26);
    } else {
        // From the integer sums: theta = (pending + rate * lead / dt) in the turn sums' units,
        // times the radians per unit, each factor Q15 (16x16 multiplies, no float).
        const Vector3l rate = last_rate_units(), pending = pending_turn_units();
        const uint16_t lead = k_.lead_steps_q15, k = k_.theta_q26_per_unit_q15;
        theta_q26[0] = scale_q15(pending.x + scale_q15(rate.x, lead), k);
        theta_q26[1] = scale_q15(pending.y + scale_q15(rate.y, lead), k);
        theta_q26[2] = scale_q15(pending.z + scale_q15(rate.z, lead), k);
    }
    // The level trim, when there is one (AHRS_TRIM: the airframe's angles, not the board's).
    if (trim_q14 != nullptr)
        return euler_carried_trimmed_q24(strapdown_.r(), theta_q26[0], theta_q26[1], theta_q26[2], trim_q14);
    return euler_carried_q24(strapdown_.r(), theta_q26[0], theta_q26[1], theta_q26[2]);
}

// A matrix that renormalisation cannot save (NaN, or rows far from unit length)
// is rebuilt from the last good gravity and field, as at start-up; the bias
// estimate survives. ArduPilot's check_matrix() does the same.
void Dcm::recover() {
    ++recoveries_;
    status_ |= kStatusRecovered;
    if (!init(last_accel_.scaled(k_.accel_m_s2_per_count), last_mag_field())) strapdown_.reset(linalg::q30_from_matrix(Matrix3f::identity()));
}

}  // namespace dcm
