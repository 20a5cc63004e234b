// SPDX-License-Identifier: GPL-3.0-or-later
// Your code beside the attitude firmware: this file is yours to extend.
//
// The firmware uses Serial (115200 baud, its text goes through SerialText.h so it
// never blocks), SPI (the MPU6000, chip select 53; the MS5611 barometer's chip select,
// pin 40, is held high) and Wire (the HMC5883L at 0x1E, 400 kHz). All three are the
// Arduino core's own: use them here as in any sketch, and add any Arduino library
// (an MS5611 driver on this SPI bus, a radio on Serial2, servo outputs, ...). The GPS
// port (UART1) is the firmware's (GpsPort.h: gps_port::fix() is the latest fix): do
// not use Serial1, whose interrupts would clash with the firmware's at link time.
// Print whole lines with Serial.print/println; start lines that are not angle data
// with "# " so that the ground tools can tell them apart.
//
// Example (see README.md, "Your own code"):
//   void user_setup() { Serial2.begin(57600); }          // a telemetry radio on UART2
//   void user_attitude_step(const pipeline::AttitudePipeline& pipe) {
//       const linalg::Matrix3f& r = pipe.estimator().matrix();  // body -> earth
//       ...  // a control law at 200 Hz
//   }

void user_setup() {}

void user_loop() {}

void user_attitude_step(const pipeline::AttitudePipeline&) {}
