// SPDX-License-Identifier: GPL-3.0-or-later
// build/apm25sim: the firmware ELF on a simulated APM 2.5 (simavr ATmega2560 at 16 MHz,
// MPU6000 on SPI, HMC5883L on I2C), sensors fed from a trajectory file. The command
// line and output are the contract in ../shared/SIM.md; --help lists the extensions.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "Board.h"
#include "FaultSpec.h"
#include "RcLink.h"
#include "SerialLink.h"
#include "Trajectory.h"

namespace {

const char* const kUsage =
    "usage: apm25sim --elf FILE.elf --trajectory FILE.csv[.gz] [--seconds S] [--stamp]\n"
    "                [--fault SPEC ...] [--input FILE] [--input-at S] [--eeprom FILE] [--profile FILE]\n"
    "                [--rc FILE] [--servo-log FILE] [--serial tcp:PORT] [--speed X] [--verbose]\n"
    "\n"
    "Runs the firmware as an ATmega2560 at 16 MHz on the APM 2.5: MPU6000 on SPI (CS pin 53 = PB0,\n"
    "INT on PE6), HMC5883L on I2C at 0x1E (DRDY on pin 31 = PC6). The sensors read the trajectory\n"
    "(held at its last sample after its end). stdout: exactly the bytes the firmware sends on UART0.\n"
    "\n"
    "  --seconds S      stop after S simulated seconds (default: the trajectory's length)\n"
    "  --stamp          prefix each line with the simulated time (s) its newline left the UART\n"
    "  --fault SPEC     inject a fault (repeatable; grammar below)\n"
    "  --input FILE     type FILE's bytes into UART0 RX, one character per 10 bit times at the\n"
    "                   baud rate the firmware set (87 us at 115200), starting at the firmware's\n"
    "                   first angle line (first line not beginning with '#') or at t = 2.5 s,\n"
    "                   whichever comes first; a character waits while simavr's receive\n"
    "                   FIFO is full (XOFF: simavr lags the line by the interrupt latency)\n"
    "  --input-at S     start the input at exactly S simulated seconds instead\n"
    "  --eeprom FILE    the ATmega2560's 4096-byte EEPROM: start from FILE's bytes (a missing\n"
    "                   file, or the bytes beyond its end, read as erased 0xFF; a longer file is\n"
    "                   an error) and write all 4096 bytes back to FILE when the run ends (also\n"
    "                   after a crash), so settings saved survive the next run as a power cycle;\n"
    "                   the run's end is a power cut: an EEPROM write in progress stays partial\n"
    "  --profile FILE   cycle counts of the sections the firmware marks: section id 1..15 written\n"
    "                   to GPIOR0 at its start and to GPIOR1 at its end. CSV\n"
    "                   section,count,avg_cycles,min_cycles,max_cycles,total_cycles and a last row\n"
    "                   run,1,C,C,C,C with C = cycles from the first start to the last end of section 6\n"
    "  --rc FILE        the receiver: CSV header t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8 (s, us), rows\n"
    "                   in increasing time, widths 500-3000 us; a row holds from its time until\n"
    "                   the next; a row with every channel empty (12.0,,,,,,,,) is a dead\n"
    "                   receiver: no PPM until the next full row; before the first row, no\n"
    "                   signal. Sent as the APM 2.5's PPM encoder does on ICP5 = PL1 (pin 48):\n"
    "                   8 channels in a 22.5 ms frame (longer only if the widths leave less\n"
    "                   than 4.5 ms of sync), each a 400 us low pre-pulse then high, so the\n"
    "                   rising edges (ArduPilot's ICES5 capture) are one width apart; the line\n"
    "                   idles high. A frame takes the widths in force at its start and is sent\n"
    "                   whole; a full row after a dead one starts a frame at its time\n"
    "  --servo-log FILE one row per pulse on OUT1-OUT8, CSV header t,out,width_us: the rising\n"
    "                   edge's time (s, 6 decimals), the output 1-8, the width (us, 2 decimals),\n"
    "                   in rising-edge order; measured from the pins OUT1 OC1B/PB6, OUT2\n"
    "                   OC1A/PB5, OUT3 OC4C/PH5, OUT4 OC4B/PH4, OUT5 OC4A/PH3, OUT6 OC3C/PE5,\n"
    "                   OUT7 OC3B/PE4, OUT8 OC3A/PE3 (the timer drives a pin its COM bits\n"
    "                   connect, else PORT does); edges are stamped at the instruction\n"
    "                   boundary (within 0.3 us); a pulse still high at the end is not written.\n"
    "                   Fast PWM (mode 14, TOP = ICRn) sets the pin at BOTTOM and clears it\n"
    "                   at the match, so OCRn = 2 x width reads width + 0.5 us, as on the chip\n"
    "  --serial tcp:PORT  also serve UART0 on TCP 127.0.0.1:PORT (loopback only), as ArduPilot's\n"
    "                   SITL serves 5760: MAVProxy (--master=tcp:127.0.0.1:PORT), QGroundControl and\n"
    "                   Mission Planner connect as to a board. One client at a time; another may\n"
    "                   connect after it leaves. The client's bytes go to UART0 RX at once (a\n"
    "                   --input file first waits for its start, and the client's bytes after it),\n"
    "                   one character time apart, waiting while simavr's RX FIFO is full; TX\n"
    "                   bytes go to the client (dropped while none is connected). stdout still\n"
    "                   carries every TX byte. PORT 0: the system picks one. stderr says\n"
    "                   'apm25sim: serving UART0 on tcp:127.0.0.1:PORT' once listening, and when a\n"
    "                   client comes or goes. Runs until SIGINT or SIGTERM (EEPROM saved, exit 0)\n"
    "                   unless --seconds is given; real time unless --speed says otherwise\n"
    "  --speed X        pace simulated time at X simulated seconds per wall second (1 = real time,\n"
    "                   the default with --serial; 0 = as fast as the host runs, the default\n"
    "                   otherwise); a slower host runs behind, never ahead\n"
    "  --verbose        print the sensor models' protocol counters on stderr at the end\n"
    "\n"
    "Bus check: the barometer chip select (pin 40 = PG1, PORTG bit 1) must be high whenever the\n"
    "MPU6000 chip select (pin 53) is low, checked when pin 53 goes low and at every SPI byte.\n"
    "A violation is printed on stderr and the exit status is 3.\n"
    "Timing: an SPI byte takes 8 SCK periods at the divider SPCR/SPSR set; an I2C bit takes\n"
    "16 + 2*TWBR*4^TWPS CPU cycles; an EEPROM byte write keeps EEPE set for 3.4 ms\n"
    "(simavr 1.6's fixed times corrected).\n"
    "Exit status: 0 run completed, 1 usage or file error, 2 the core crashed, 3 bus violation.\n"
    "\n";

bool read_file(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    std::ostringstream ss;
    ss << in.rdbuf();
    out = ss.str();
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    sim::BoardOptions options;
    std::string trajectory_path, input_path, profile_path, rc_path, servo_log_path, serial_spec;
    double speed = -1.0;
    std::vector<std::string> faults;
    double seconds = -1.0;
    bool verbose = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&](const char* name) -> const char* {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "apm25sim: %s needs a value\n", name);
                std::exit(1);
            }
            return argv[++i];
        };
        if (arg == "--help" || arg == "-h") {
            std::fputs(kUsage, stdout);
            std::fputs(sim::kFaultHelp, stdout);
            return 0;
        } else if (arg == "--elf") {
            options.elf_path = value("--elf");
        } else if (arg == "--trajectory") {
            trajectory_path = value("--trajectory");
        } else if (arg == "--seconds") {
            seconds = std::atof(value("--seconds"));
        } else if (arg == "--stamp") {
            options.stamp = true;
        } else if (arg == "--fault") {
            faults.push_back(value("--fault"));
        } else if (arg == "--input") {
            input_path = value("--input");
        } else if (arg == "--input-at") {
            options.input_start_s = std::atof(value("--input-at"));
            options.input_start_fixed = true;
        } else if (arg == "--eeprom") {
            options.eeprom_path = value("--eeprom");
        } else if (arg == "--profile") {
            profile_path = value("--profile");
        } else if (arg == "--rc") {
            rc_path = value("--rc");
        } else if (arg == "--servo-log") {
            servo_log_path = value("--servo-log");
        } else if (arg == "--serial") {
            serial_spec = value("--serial");
        } else if (arg == "--speed") {
            char* end = nullptr;
            const char* text = value("--speed");
            speed = std::strtod(text, &end);
            if (*end != '\0' || !(speed >= 0.0) || speed > 1e6) {
                std::fprintf(stderr, "apm25sim: --speed '%s': a number >= 0 (1 = real time)\n", text);
                return 1;
            }
        } else if (arg == "--verbose") {
            verbose = true;
        } else {
            std::fprintf(stderr, "apm25sim: unknown argument '%s'\n%s", arg.c_str(), kUsage);
            return 1;
        }
    }
    if (options.elf_path.empty() || trajectory_path.empty()) {
        std::fprintf(stderr, "apm25sim: --elf and --trajectory are required\n%s", kUsage);
        return 1;
    }
    sim::Trajectory trajectory;
    if (!trajectory.load(trajectory_path)) {
        std::fprintf(stderr, "apm25sim: %s\n", trajectory.error().c_str());
        return 1;
    }
    if (!input_path.empty() && !read_file(input_path, options.input)) {
        std::fprintf(stderr, "apm25sim: cannot read the input file '%s'\n", input_path.c_str());
        return 1;
    }
    sim::RcScript rc;
    if (!rc_path.empty()) {
        if (!rc.load(rc_path)) {
            std::fprintf(stderr, "apm25sim: %s\n", rc.error().c_str());
            return 1;
        }
        options.rc = &rc;
    }
    FILE* servo_log = nullptr;
    if (!servo_log_path.empty()) {
        servo_log = std::fopen(servo_log_path.c_str(), "w");
        if (!servo_log) {
            std::fprintf(stderr, "apm25sim: cannot write the servo log '%s'\n", servo_log_path.c_str());
            return 1;
        }
        options.servo_log = servo_log;
    }
    options.profile = !profile_path.empty();
    sim::TcpSerial serial;
    if (!serial_spec.empty()) {
        int port = 0;
        std::string error;
        if (!sim::parse_serial_spec(serial_spec, port, error)) {
            std::fprintf(stderr, "apm25sim: %s\n", error.c_str());
            return 1;
        }
        if (!serial.listen(port)) {
            std::fprintf(stderr, "apm25sim: %s\n", serial.error().c_str());
            return 1;
        }
        options.serial = &serial;
        std::fprintf(stderr, "apm25sim: serving UART0 on tcp:127.0.0.1:%d\n", serial.port());
        // A live board runs until stopped; the stop is a clean end (EEPROM written back).
        std::signal(SIGINT, [](int) { sim::request_stop(); });
        std::signal(SIGTERM, [](int) { sim::request_stop(); });
        if (seconds < 0.0) seconds = 1e9;
    }
    options.speed = speed >= 0.0 ? speed : (options.serial ? 1.0 : 0.0);
    if (seconds < 0.0) seconds = trajectory.duration_s();

    sim::Board board(trajectory, options);
    for (const std::string& spec : faults) {
        std::string error;
        if (!sim::apply_fault_spec(spec, board.mpu(), board.mag(), board.bus_faults(), error)) {
            std::fprintf(stderr, "apm25sim: %s\n", error.c_str());
            return 1;
        }
    }
    if (!board.init()) {
        std::fprintf(stderr, "apm25sim: %s\n", board.error().c_str());
        return 1;
    }
    const bool ran = board.run(seconds);
    board.finish_output();
    if (servo_log && std::fclose(servo_log) != 0) {
        std::fprintf(stderr, "apm25sim: cannot write the servo log '%s'\n", servo_log_path.c_str());
        return 1;
    }
    if (!board.save_eeprom()) {
        std::fprintf(stderr, "apm25sim: cannot write the EEPROM file '%s'\n", options.eeprom_path.c_str());
        return 1;
    }
    if (!ran) std::fprintf(stderr, "apm25sim: %s\n", board.error().c_str());
    if (verbose) board.print_counters(stderr);
    if (options.profile && !board.write_profile(profile_path)) {
        std::fprintf(stderr, "apm25sim: cannot write the profile '%s'\n", profile_path.c_str());
        return 1;
    }
    if (!ran) return 2;
    if (board.bus_violations() > 0) {
        std::fprintf(stderr, "apm25sim: %u bus violation(s): pin 40 must be high while pin 53 is low\n",
                     board.bus_violations());
        return 3;
    }
    return 0;
}
