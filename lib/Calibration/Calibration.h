// SPDX-License-Identifier: GPL-3.0-or-later
// Sensor calibration: the values applied to every sample (SensorCalibration.h) and the
// procedures that measure them, one file each: the gyro bias at rest (GyroCalibrator.h),
// the magnetometer's hard and soft iron from a least-squares ellipsoid fit on the samples
// of a rotation, `cal mag` (MagCalibrator.h), and its hard iron learned in motion
// (OffsetLearner.h). Include this for all of them, or the one you need.
#pragma once

#include "GyroCalibrator.h"
#include "MagCalibrator.h"
#include "OffsetLearner.h"
#include "SensorCalibration.h"
