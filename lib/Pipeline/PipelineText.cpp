// SPDX-License-Identifier: GPL-3.0-or-later
#include "PipelineText.h"

namespace pipeline_text {

using pipeline::EventKind;
using text::Writer;

namespace {

// The `cal mag` verdict (kMagCalDone).
// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) void write_cal_mag_verdict(Writer& w, const pipeline::AttitudePipeline& pipe, const pipeline::Event& e) {
    using Quality = calib::MagCalibrator::Quality;
    const Quality q = (Quality)e.code;
    if (q == Quality::Ok) {
        // From the calibrator: a result waiting for a ground station's accept is not in use yet.
        const calib::MagCalibrator& m = pipe.mag_calibrator();
        w.str(TXT("# cal mag: offset ")).vec(m.offset_uT()).str(TXT(" uT, scale ")).vec(m.scale())
            .str(TXT(", cross ")).vec(m.cross()).str(TXT(", residual ")).fixed2(e.value)
            .str(TXT(" uT, coverage ")).u32(e.count)
            .str(pipe.mag_cal_state() == pipeline::MagCalState::kWaiting ? TXT("% (accept to use)")
                                                                          : TXT("% (save to keep)")).end();
        return;
    }
    w.str(TXT(TXT_ERROR "cal mag failed: "));
    switch (q) {
        case Quality::TooFewSamples: w.str(TXT("too few samples (")).u32(e.total).chr(')'); break;
        case Quality::ThinCoverage:
            w.str(TXT("not turned every way (coverage ")).u32(e.count).str(TXT("%, need "))
                .u32(calib::kMagMinCoveragePct).str(TXT("%)"));
            break;
        case Quality::FitFailed: w.str(TXT("no ellipsoid fits the samples")); break;
        case Quality::NotEarthField:
            w.str(TXT("field ")).fixed2(e.value).str(TXT(" uT is not the Earth's (magnet near?)"));
            break;
        case Quality::SoftIronTooLarge: w.str(TXT("soft iron beyond 20% (magnet near?)")); break;
        default:
            w.str(TXT("residual ")).fixed2(e.value).str(TXT(" uT, over ")).fixed2(calib::kMagMaxResidual_uT)
                .str(TXT(" (field changed while turning?)"));
            break;
    }
    w.str(TXT("; calibration unchanged")).end();
}

// The level calibration's verdict (kLevelDone).
void write_level_verdict(Writer& w, const pipeline::AttitudePipeline& pipe, const pipeline::Event& e) {
    using pipeline::LevelResult;
    const LevelResult r = (LevelResult)e.code;
    if (r == LevelResult::kOk) {
        const settings::VehicleSettings& v = pipe.settings().vehicle;
        w.str(TXT("# cal level: trim roll ")).fixed2(v.ahrs_trim_x_rad * linalg::kDegPerRad).str(TXT(" pitch "))
            .fixed2(v.ahrs_trim_y_rad * linalg::kDegPerRad).str(TXT(" deg")).end();
        return;
    }
    // Short enough for one STATUSTEXT (50 characters).
    w.str(TXT(TXT_ERROR "cal level: "));
    if (r == LevelResult::kMoved) w.str(TXT("board moved"));
    else if (r == LevelResult::kTooFar) w.str(TXT("over 10 deg off level"));
    else w.str(TXT("never still"));
    w.str(TXT("; trim unchanged")).end();
}

}  // namespace

void write_event(void* out, const pipeline::AttitudePipeline& pipe, const pipeline::Event& e) {
    Writer w(static_cast<const text::Sink*>(out));
    switch (e.kind) {
        case EventKind::kGyroCalStart: w.str(TXT("# calibrating gyro: keep the board still")); break;
        case EventKind::kGyroCalAgain: w.str(TXT("# cal gyro: keep the board still for 1 s")); break;
        case EventKind::kGyroCalMoved:
            w.str(TXT("# calibrating gyro: board moved"));
            if (e.count != 0) w.chr(' ').u32(e.count).str(TXT(" more times"));
            w.str(TXT(", retrying"));
            break;
        case EventKind::kGyroCalTimeout:
            w.str(TXT(TXT_ERROR "cal gyro: board never still for 1 s; bias unchanged"));
            break;
        case EventKind::kGyroBias:
            w.str(TXT("# gyro bias: ")).vec(pipe.settings().cal.gyro_bias_rad_s, linalg::kDegPerRad).str(TXT(" deg/s"));
            break;
        case EventKind::kNotStill:
            w.str(TXT(TXT_WARN "board not still: starting with ")).str(e.code ? TXT("the saved") : TXT("zero"))
                .str(TXT(" gyro bias, measuring on"));
            break;
        case EventKind::kGyroBiasRefused:
            w.str(TXT(TXT_WARN "gyro calibration in motion (a steady turn?): ")).fixed2(e.value)
                .str(TXT(" deg/s off the bias in use, not taken; keeping ")).str(e.code ? TXT("the saved") : TXT("zero"))
                .str(TXT(" gyro bias"));
            break;
        case EventKind::kSpike:
            w.str(TXT(TXT_WARN TXT_MPU " spike: "));
            if (e.count == 0) w.str(TXT("previous sample used instead ("));
            else w.u32(e.count).str(TXT(" more samples replaced ("));
            w.u32(e.total).str(TXT(" so far)"));
            break;
        case EventKind::kGyroSaturated:
        case EventKind::kAccelSaturated: {
            const bool gyro = e.kind == EventKind::kGyroSaturated;
            w.str(TXT(TXT_WARN TXT_MPU)).str(gyro ? TXT(" gyro saturated") : TXT(" accel saturated"));
            if (e.count != 0) w.str(TXT(": ")).u32(e.count).str(TXT(" more samples"));
            else w.str(gyro ? TXT(" (beyond 2000 deg/s)") : TXT(" (beyond 16 g)"));
            break;
        }
        case EventKind::kMagNotEarth:
            w.str(TXT(TXT_WARN TXT_HMC " field "));
            if (e.count == 0) w.fixed2(e.value).str(TXT(" uT is not the Earth's (10..200): sample dropped"));
            else w.str(TXT("not the Earth's: ")).u32(e.count).str(TXT(" more samples dropped"));
            break;
        case EventKind::kMagCalStart: w.str(TXT("# cal mag: turn the board every way for 30 s")); break;
        case EventKind::kMagCalNoCompass: w.str(TXT(TXT_ERROR "cal mag: " TXT_HMC " absent")); break;
        case EventKind::kMagCalProgress:
            w.str(TXT("# cal mag: ")).u32(e.count).str(TXT(" s left, keep turning (")).u32(e.total)
                .str(TXT(" samples)"));
            break;
        case EventKind::kMagCalDone: write_cal_mag_verdict(w, pipe, e); return;
        case EventKind::kLevelStart: w.str(TXT("# cal level: keep the airframe level and still for 1 s")); break;
        case EventKind::kLevelDone: write_level_verdict(w, pipe, e); return;
        case EventKind::kAccelCalAsk: {
            // ArduPilot's words (AP_AccelCal): MAVProxy's accelcal waits for "Place ".
            const char* p = TXT("level\0on its LEFT side\0on its RIGHT side\0nose DOWN\0nose UP\0on its BACK\0").p;
            for (uint8_t k = 1; k < e.code; ++k)
                while (text::flash_byte(p++) != 0u) {}
            w.str(TXT("# Place vehicle ")).str(text::flash(p)).str(TXT(" and press any key"));
            break;
        }
        case EventKind::kAccelCalRefused:
            w.str(TXT(TXT_ERROR "cal accel: ")).str(e.value == 0.0f ? TXT("board moved") : TXT("not in that position"));
            break;
        case EventKind::kAccelCalDone:
            if (e.code == (uint8_t)calib::AccelFit::Quality::Ok) {
                w.str(TXT("# Calibration successful"));
                break;
            }
            w.str(TXT(TXT_ERROR "Calibration FAILED: ")).str(e.code == (uint8_t)calib::AccelFit::Quality::OutOfRange
                                                               ? TXT("offsets or scales out of range")
                                                               : TXT("positions do not fit"));
            break;
        case EventKind::kOrientation:
            w.str(TXT("# AHRS_ORIENTATION ")).u32(e.code).str(TXT(": estimator restarted, calibrating gyro: keep the board still"));
            break;
        default: return;
    }
    w.end();
}

void write_bias_status(const text::Sink* out, const pipeline::AttitudePipeline& pipe) {
    Writer(out).str(TXT("# gyro bias ")).vec(pipe.gyro_bias_rad_s(), linalg::kDegPerRad)
        .str(TXT(" deg/s, temperature ")).fixed2(pipe.temperature_c()).str(TXT(" C")).end();
}

void write_compass_status(const text::Sink* out, const pipeline::AttitudePipeline& pipe) {
    const settings::Settings& s = pipe.settings();
    Writer(out).str(TXT("# compass: cal "))
        .str((s.flags & settings::kFlagMagCalibrated) ? TXT("yes") : TXT("none"))
        .str(TXT(", learned offset ")).vec(s.cal.mag_learned_uT).str(TXT(" uT ("))
        .u32(pipe.offset_learner().updates()).str(TXT(" updates)")).end();
}

}  // namespace pipeline_text
