// SPDX-License-Identifier: GPL-3.0-or-later
// A user's second sketch file, as README.md ("Your own code") describes it: a device on
// Serial2 (UART2; the firmware's GPS port owns UART1), a message on Serial, the I2C clock set again, and an SPI device whose
// interrupt the SPI library must mask during transactions. The sketch test puts this
// in place of firmware/user.ino, builds the sketch with arduino-builder and runs it in
// apm25sim: it must link (the Arduino core's Serial, SPI and Wire are shared, not
// replaced) and the angles must still flow.

static uint32_t user_steps = 0;

void user_setup() {
    Serial2.begin(57600);                               // a telemetry radio on UART2
    Wire.setClock(400000);                              // a second I2C device at 400 kHz
    SPI.usingInterrupt(digitalPinToInterrupt(18));      // an SPI device with its INT on pin 18
    Serial.print("# user code: Serial2 at 57600 baud\n");
}

void user_loop() {
    while (Serial2.available() > 0) Serial2.read();     // drain the radio (nothing connected here)
}

void user_attitude_step(const pipeline::AttitudePipeline& pipe) {
    if (pipe.estimator().initialised()) ++user_steps;   // where a 200 Hz control law would run
}
