// SPDX-License-Identifier: GPL-3.0-or-later
// apm25-attitude: roll, pitch and heading from the ArduPilot Mega 2.5's own sensors,
// printed on the serial port (115200 baud) 50 times a second, `roll:-1.23 pitch:4.56
// yaw:271.80`, or spoken in MAVLink to a ground station; and, with a receiver and servos,
// it flies (README "Flying"). This sketch is the table of contents:
//   setup()      brings the board up on a fixed timeline (below);
//   loop()       runs the task table (Tasks.cpp): on each MPU6000 sample (200 Hz) the
//                sample tasks (compass, estimator, airspeed, output line, control ...),
//                between samples the loop tasks (console, ground station, EEPROM ...).
// The parts: Vehicle (the objects), Board (pins, buses, LEDs), Imu and Compass (the
// sensors), AirspeedInput, OutputLine, ConsoleLink, GcsLink and Port (the serial port's
// two languages), FlightIo (receiver, control, servos), SettingsStore (EEPROM),
// LoopLoad. The estimator is lib/Pipeline and lib/DCM, which the host replay tool runs
// too. Your own code goes in user.ino.
#include <SPI.h>
#include <Wire.h>  // unused itself: makes the IDE and PlatformIO build Wire's twi.c (Board.cpp)

#include "AirspeedInput.h"
#include "Board.h"
#include "Console.h"
#include "ConsoleLink.h"
#include "GpsPort.h"
#include "MissionLink.h"
#include "SerialText.h"
#include "Tasks.h"
#include "UserCode.h"
#include "Vehicle.h"
#include "Version.h"

using namespace vehicle;

// The set-up runs on a fixed timeline (pipeline::kMpuStartMs ...): the same instants of
// a trajectory are sampled here and in the host replay tool. Its times count from reset;
// millis() counts from pipeline::kBootMs after it (StartTime.cpp).
static_assert(pipeline::kBootMs < pipeline::kMpuStartMs, "millis() starts before the first stage");
static void wait_until_ms(uint16_t ms_since_reset) {
    while (millis() < (uint16_t)(ms_since_reset - pipeline::kBootMs)) serial_text::pump();
}

void setup() {
    board::init_pins();  // every chip select high before any SPI traffic
    board::set_leds(true, false, false);
    serial_text::begin();
    say(TXT("# apm25-attitude " APM25_VERSION_TEXT ": APM 2.5, 200 Hz loop\n"
            "# " TXT_MPU " 200 Hz, DLPF 42 Hz, 2000 deg/s, 16 g; " TXT_HMC " 75 Hz, 8-sample average, 1.3 Ga"));
    store.load(pipe.settings());
    mission_link::begin();
    pipe.refresh_board_frame();  // AHRS_ORIENTATION, AHRS_TRIM_*, INS_ACC* as loaded, before the samples
    flight_io.begin();  // the outputs from here on (the loaded settings' end points), the receiver
    airspeed_input::begin();
    console_link::print_settings_line();
    if (pipe.settings().flags & settings::kFlagUpgraded) {
        pipe.settings().flags = (uint8_t)(pipe.settings().flags & ~settings::kFlagUpgraded);
        say(TXT("# settings: a version 2 record: flight settings at their defaults (save to keep)"));
    }

    board::spi_begin();
    wait_until_ms(pipeline::kMpuStartMs);
    imu.start(millis());
    board::wake_on_data_ready();  // the loop idles between samples

    board::wire_begin();
    if (board::sda_low()) board::i2c_recover();
    wait_until_ms(pipeline::kMagStartMs);
    compass.start(true, millis());
    say(TXT("# type help for commands"));
    if (pipe.settings().mode == fmt::OutputMode::Csv) text::Writer(out).str(console::csv_header());
    serial_text::flush();  // the banner out before the 200 Hz loop starts: no missed sample
    user_setup();
    wait_until_ms(pipeline::kLoopStartMs);
    gps_port::begin();  // from here the loop task parses what arrives
    tasks::loop_starts();
}

void loop() { tasks::loop_pass(); }
