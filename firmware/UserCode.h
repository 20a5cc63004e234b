// SPDX-License-Identifier: GPL-3.0-or-later
// Hooks for your own code, defined in user.ino (the sketch's second file). The
// firmware calls them; they run in the same loop as the estimator, so keep each call
// short: the next MPU6000 sample is due 5 ms after the previous one.
#pragma once

#include "Pipeline.h"

// Once, at the end of setup(): start your own devices (Serial2 for a radio, servos, ...;
// UART1, the GPS port, is the firmware's: GpsPort.h).
void user_setup();
// Every loop() iteration: after each interrupt (a sample, a serial byte, a receiver
// edge), and at least every 1.024 ms (timer0's tick) while the loop idles between samples.
void user_loop();
// After every estimator step (200 Hz), while the attitude is being estimated:
// pipe.estimator() is the DCM (its rotation matrix), pipe.angles() the Euler angles
// (an Euler extraction and float conversions: call it at the rate you need, not every
// step).
void user_attitude_step(const pipeline::AttitudePipeline& pipe);
