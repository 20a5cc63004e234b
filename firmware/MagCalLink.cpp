// SPDX-License-Identifier: GPL-3.0-or-later
#include "MagCalLink.h"

#include "ArduinoCore.h"
#include "GcsLink.h"
#include "Params.h"
#include "Port.h"
#include "SerialText.h"
#include "Vehicle.h"

namespace mag_cal_link {

using pipeline::MagCalState;
using vehicle::pipe;

constexpr uint16_t kProgressPeriodMs = 500;  // MAG_CAL_PROGRESS at 2 Hz
// One byte for the three flags (RAM).
static struct {
    bool start_pending : 1;  // START acknowledged: the run starts in the task's next run
    bool reporting : 1;      // a run the ground station started: PROGRESS, then REPORT
    bool autosave : 1;
} link = {false, false, false};
static uint16_t progress_ms = 0;  // millis()'s low half at the last PROGRESS

bool handles(uint16_t command) {
    return command == mav::kCmdDoStartMagCal || command == mav::kCmdDoAcceptMagCal ||
           command == mav::kCmdDoCancelMagCal;
}

// The run itself starts in the gcs_position task, not in the request: its "# cal mag: ..." line (a
// STATUSTEXT packed) and the ACK would not fit one request's budget together.
mav::Result start(bool save) {
    if (pipe.phase() != pipeline::Phase::Running || pipe.gyro_calibrating()) return mav::Result::TemporarilyRejected;
    if (!vehicle::compass.ok()) return mav::Result::Failed;
    link.start_pending = true;
    link.reporting = true;
    link.autosave = save;
    return mav::Result::Accepted;
}

// param1 the compasses: 0 all, else a mask that must hold compass 0 (the only one).
mav::Result command(const mav::CommandLong& c) {
    const float* p = c.param;
    if (p[0] != 0.0f && ((uint8_t)p[0] & 1u) == 0u) return mav::Result::Failed;
    if (c.command == mav::kCmdDoStartMagCal) return start(p[2] != 0.0f);  // retry, delay, reboot: not done
    if (c.command == mav::kCmdDoAcceptMagCal) {
        if (pipe.accept_mag_calibration()) {
            gcs_link::save_soon();
            gcs_link::announce_calibration(gcs_link::Calibrated::kCompass);
            return mav::Result::Accepted;
        }
        // Already in use (autosaved, or accepted before: MAVProxy accepts every report): nothing to do.
        return pipe.mag_cal_state() == MagCalState::kApplied ? mav::Result::Accepted : mav::Result::Failed;
    }
    pipe.cancel_mag_calibration();
    link.start_pending = link.reporting = false;
    return mav::Result::Accepted;
}

bool due() {
    if (!link.reporting || !port::mavlink_mode() ||
        serial_text::room() < mav::kMaxFrame + gcs_link::output_line_bytes())
        return false;
    const MagCalState m = pipe.mag_cal_state();
    const bool running = m == MagCalState::kCollecting || m == MagCalState::kFitting;
    return link.start_pending || !running || (uint16_t)((uint16_t)millis() - progress_ms) >= kProgressPeriodMs;
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) void send() {
    if (link.start_pending) {
        link.start_pending = false;
        pipe.start_mag_calibration(!link.autosave);
        link.reporting = pipe.mag_cal_state() == MagCalState::kCollecting;  // else the compass went (said)
        progress_ms = (uint16_t)(millis() - kProgressPeriodMs);     // the first PROGRESS in the next pass
        return;
    }
    uint8_t frame[mav::kMaxFrame];
    const MagCalState m = pipe.mag_cal_state();
    const calib::MagCalibrator& cal = pipe.mag_calibrator();
    uint8_t n;
    if (m == MagCalState::kCollecting || m == MagCalState::kFitting) {
        progress_ms = (uint16_t)millis();
        linalg::Vector3f dir = pipe.field_uT();
        const float len = dir.length();
        dir = len > 0.0f ? dir * (1.0f / len) : linalg::Vector3f();
        n = port::mavlink.mag_cal_progress(frame, m == MagCalState::kCollecting ? mav::MagCalStatus::RunningStepOne
                                                                                : mav::MagCalStatus::RunningStepTwo,
                                           1u, pipe.mag_cal_progress_pct(), cal.cells_seen(), dir);
    } else {
        link.reporting = false;
        if (m == MagCalState::kNone) return;  // stopped by other means: nothing to report
        const bool good = m != MagCalState::kFailed;
        // A good fit's terms (waiting or in use); after a failure the calibration in use, which stays.
        const calib::Calibration& now = pipe.settings().cal;
        mav::MagCalReport r;
        r.status = good ? mav::MagCalStatus::Success : mav::MagCalStatus::Failed;
        r.autosaved = good && link.autosave;
        r.fitness_mgauss = cal.residual_uT() * params::kMilliGaussPerMicroTesla;
        const linalg::Vector3f ofs_uT = good ? cal.offset_uT() : now.mag_offset_uT;
        r.ofs_mgauss = linalg::Vector3f(params::compass_ofs_mgauss(ofs_uT.x), params::compass_ofs_mgauss(ofs_uT.y),
                                        params::compass_ofs_mgauss(ofs_uT.z));
        r.diag = good ? cal.scale() : now.mag_scale;
        r.offdiag = good ? cal.cross() : now.mag_cross;
        n = port::mavlink.mag_cal_report(frame, r);
        if (r.autosaved) gcs_link::save_soon();
    }
    port::send_frame(frame, n);
}

void parameter_changed(uint16_t index) {
    if (params::is_compass_calibration(index)) pipe.take_mag_calibration();
}

}  // namespace mag_cal_link
