// SPDX-License-Identifier: GPL-3.0-or-later
// build/apm25sim: the firmware ELF on a simulated APM 2.5 (simavr ATmega2560 at 16 MHz,
// MPU6000 and MS5611 on SPI, HMC5883L on I2C, a u-blox GPS on UART1), sensors fed from a
// trajectory file or a physics backend. The command
// line and output are the contract in ../shared/SIM.md; --help lists the extensions.
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "Board.h"
#include "FaultSpec.h"
#include "Geodesy.h"
#include "Mpxv7002dpModel.h"
#include "PhysicsLink.h"
#include "RcLink.h"
#include "Rotation.h"
#include "SerialLink.h"
#include "Trajectory.h"

namespace {

const char* const kUsage =
    "usage: apm25sim --elf FILE.elf (--trajectory FILE.csv[.gz] | --physics json[:HOST[:PORT]])\n"
    "                [--seconds S] [--stamp]\n"
    "                [--fault SPEC ...] [--input FILE] [--input-at S] [--eeprom FILE]\n"
    "                [--eeprom-cuts T1:T2:STEP] [--mission FILE.waypoints] [--profile FILE]\n"
    "                [--rc FILE] [--servo-log FILE] [--serial tcp:PORT] [--speed X]\n"
    "                [--physics-rate HZ] [--physics-timeout S] [--physics-log FILE]\n"
    "                [--earth-field N,E,D] [--verbose]\n"
    "                [--gps ublox|nmea|none] [--gps-baud B] [--gps-fix-after S] [--gps-latency S]\n"
    "                [--baro ms5611|none] [--baro-noise HPA] [--baro-temp C] [--home LAT,LON,ALT_M]\n"
    "                [--seed N] [--orientation R] [--battery SPEC] [--battery-log FILE]\n"
    "\n"
    "Runs the firmware as an ATmega2560 at 16 MHz on the APM 2.5: MPU6000 on SPI (CS pin 53 = PB0,\n"
    "INT on PE6), HMC5883L on I2C at 0x1E (DRDY on pin 31 = PC6), MS5611 on SPI (CS pin 40 = PG1),\n"
    "a u-blox GPS on UART1 (RXD1 PD2, TXD1 PD3: the GPS port). The sensors read the trajectory\n"
    "(held at its last sample after its end), or the physics backend's state (--physics). stdout:\n"
    "exactly the bytes the firmware sends on UART0.\n"
    "\n"
    "  --seconds S      stop after S simulated seconds (default: the trajectory's length; with\n"
    "                   --serial or --physics, until SIGINT or SIGTERM)\n"
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
    "  --eeprom-cuts T1:T2:STEP  with --eeprom FILE: also write the chip as a power cut at\n"
    "                   T1, T1+STEP, ... (<= T2, simulated seconds) leaves it (what --seconds\n"
    "                   at that time writes) to FILE.cut0, FILE.cut1, ...: one run for many cuts\n"
    "  --mission FILE   a mission (QGC WPL 110: Mission Planner's .waypoints, seq 0 home and not\n"
    "                   stored) written into the EEPROM's mission area before the run, on top of\n"
    "                   --eeprom's bytes or an erased chip, as the MAVLink upload would (lib/Mission's\n"
    "                   from_item and MissionStore): AUTO flies it. A command or frame the firmware\n"
    "                   refuses, or a line that does not parse, is an error naming its line\n"
    "  --profile FILE   cycle counts of the sections the firmware marks: section id 1..63 written\n"
    "                   to GPIOR0 at its start and to GPIOR1 at its end. CSV\n"
    "                   section,count,avg_cycles,min_cycles,max_cycles,total_cycles and a last row\n"
    "                   run,1,C,C,C,C with C = cycles from the first start to the last end of section 6;\n"
    "                   then stack_used,1,U,U,U,U and stack_free,1,F,F,F,F: of the RAM above .data\n"
    "                   and .bss, the bytes still holding the firmware's start-up paint (0xC5, from\n"
    "                   the bottom up: F) and the rest (U, the stack at its deepest)\n"
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
    "  --physics json[:HOST[:PORT]]  instead of a trajectory, a flight dynamics backend that\n"
    "                   speaks ArduPilot's SITL JSON interface (ArduPilot's libraries/SITL/examples/\n"
    "                   JSON/readme.md; default 127.0.0.1:9002), apm25sim on ArduPilot's side.\n"
    "                   Each physics frame it sends the UDP servo packet (uint16 magic 18458,\n"
    "                   uint16 frame_rate, uint32 frame_count from 0, uint16 pwm[16], little-endian)\n"
    "                   with pwm 1-8 = OUT1-OUT8 as measured on their pins, rounded to the us\n"
    "                   (0 before the first pulse and when none came for 60 ms), pwm 9-16 = 0;\n"
    "                   then waits for the JSON reply (timestamp, imu.gyro, imu.accel_body,\n"
    "                   position, velocity, quaternion or attitude; optional rc, airspeed,\n"
    "                   velocity_wind) and runs the board to its timestamp (less the first\n"
    "                   reply's) with the sensors on that state: the MPU6000 on the gyro and the\n"
    "                   specific force, the HMC5883L on the earth field turned by the attitude,\n"
    "                   linear in between frames. Lock-step: time moves only with the backend's\n"
    "                   frames, so a run is deterministic. rc_1..rc_8 drive the PPM on ICP5 (an\n"
    "                   rc with none of them, or all 0, is a dead receiver; --rc, if given,\n"
    "                   drives it instead). A frame unanswered for 1 s is sent again (same\n"
    "                   frame_count, said on stderr); a reply whose timestamp is not after the\n"
    "                   last state taken, or one waiting before a frame is sent, answers an\n"
    "                   earlier send (a frame sent again and answered twice, late): dropped\n"
    "                   and counted (the summary on stderr at the end: frames, sent again,\n"
    "                   replies dropped). airspeed, when sent, is the pitot's: the APM 2.5's\n"
    "                   MPXV7002DP on A0 (ADC0), 2.5 V + 1 V/kPa of 1/2 1.225 v^2, held\n"
    "                   within 0.5..4.5 V; position and velocity (NED metres and m/s from\n"
    "                   --home) drive the GPS and the barometer; wind is read, not used. Runs\n"
    "                   until SIGINT/SIGTERM unless --seconds. Exit status 4 when the backend\n"
    "                   stops answering, answers something that is not a state, or gives no\n"
    "                   state newer than the last for --physics-timeout s (its time stands\n"
    "                   still or went back). With --serial\n"
    "                   a ground station watches the flying board, in real time by default\n"
    "                   (lock-step and --speed pacing together: the slower of the two sets it)\n"
    "  --physics-rate HZ  the frame_rate asked of the backend, 400..10000 (default 1000)\n"
    "  --physics-log FILE  every state the sensors read, as a trajectory file (the header\n"
    "                   t,gx,...,qz,movement,n,e,d; the backend's true attitude and position):\n"
    "                   replay, score and the peers run on a flight as on any recording, and\n"
    "                   apm25sim --trajectory flies it again with the GPS and the barometer\n"
    "  --physics-timeout S  give up on a silent backend, or one whose replies are all stale,\n"
    "                   after S s (default 30)\n"
    "  --earth-field N,E,D  the earth field for --physics, uT NED (default 20,0,45)\n"
    "  --verbose        print the sensor models' protocol counters on stderr at the end\n"
    "  --gps KIND       the module on the GPS port (UART1): ublox (default), a u-blox 6 (NEO-6M)\n"
    "                   that starts factory-new: NMEA (GGA, GLL, GSA, GSV, RMC, VTG) at 1 Hz at\n"
    "                   9600 baud 8N1, taking UBX and NMEA in; it answers $PUBX,41 (port\n"
    "                   protocols and baud), $PUBX,40 (NMEA rates), CFG-PRT, CFG-MSG, CFG-RATE,\n"
    "                   CFG-NAV5, CFG-SBAS, CFG-CFG (ACK-ACK / ACK-NAK; polls answered), MON-VER and\n"
    "                   NAV polls, and sends NAV-POSLLH, NAV-STATUS, NAV-DOP, NAV-SOL, NAV-VELNED\n"
    "                   at the measurement rate and message rates configured (u-blox 6 protocol\n"
    "                   specification; bad checksums ignored and counted). nmea: a module that\n"
    "                   only speaks NMEA at 1 Hz and ignores everything it receives. none: nothing\n"
    "                   on the GPS port. Position: the trajectory's n,e,d columns or the backend's\n"
    "                   position (else still at --home), reported 0.2 s late with a slow ~1 m\n"
    "                   random walk (Gauss-Markov, 30 s) and 0.1 m/s velocity noise, 10 satellites,\n"
    "                   hDOP 0.9. The line is 8N1 at each end's own baud: the module's bytes reach\n"
    "                   UART1 RX (only while RXEN1 is set) as a UART at the firmware's UBRR1 /\n"
    "                   U2X1 samples them, so a mismatch delivers other bytes with framing\n"
    "                   errors, or nothing; likewise the firmware's bytes to the module, which\n"
    "                   drops characters with a bad stop bit. docs/simulator.md has the details\n"
    "  --gps-baud B     the module's baud at power-up (default 9600: factory-new)\n"
    "  --gps-fix-after S  the first 3D fix: the first epoch leaving at or after S simulated\n"
    "                   seconds (default 3); before it gpsFix 0 and NMEA status V\n"
    "  --gps-latency S  measurement to output (default 0.2): what arrives is the truth S\n"
    "                   seconds earlier, stamped (iTOW) with the time it was true\n"
    "  --baro KIND      ms5611 (default): the MS5611 behind pin 40 on the SPI bus, answering only\n"
    "                   while pin 40 is low: RESET 0x1E, PROM 0xA0-0xAE (the datasheet's example\n"
    "                   coefficients, AN520's CRC-4), CONVERT D1 0x40-0x48 / D2 0x50-0x58 taking\n"
    "                   the datasheet's maximum time for the OSR, ADC READ 0x00 (0 before the\n"
    "                   conversion ends); D1 and D2 the datasheet's compensation inverted at the\n"
    "                   standard atmosphere's pressure for the height. none: nobody behind pin 40\n"
    "  --baro-noise HPA  1-sigma pressure noise per conversion (default 0.1 hPa)\n"
    "  --baro-temp C    the chip's temperature (default: the standard atmosphere's at the height)\n"
    "  --home LAT,LON,ALT_M  the origin of the positions: degrees, metres above mean sea level\n"
    "                   (default 7.135045,-73.119421,1028: the thesis' field)\n"
    "  --seed N         the GPS and barometer models' noise (default 1; the same seed, the same\n"
    "                   run)\n"
    "  --orientation R  the board mounted in the airframe at ArduPilot's rotation R (0..37, the\n"
    "                   firmware's AHRS_ORIENTATION; MAVLink's MAV_SENSOR_ORIENTATION gives each one's\n"
    "                   roll, pitch, yaw): the trajectory's (or the backend's) values are the\n"
    "                   airframe's, and the MPU6000 and the HMC5883L, on the board, read them turned\n"
    "                   by M^T with M = Rz(yaw) Ry(pitch) Rx(roll) (default 0: as the arrow says)\n"
    "  --battery SPEC   a LiPo pack behind a 3DR power module on the APM 2.5's A13 (pack volts /\n"
    "                   10.1) and A12 (amps / 17 A/V): KEY=VALUE,... of cells (3), mah (2200),\n"
    "                   charge (1: full, 0..1 at the start), r_ohm (0.04: the pack's internal\n"
    "                   resistance), amps (a fixed current; else from the throttle on OUT3:\n"
    "                   idle_a + (max_a - idle_a) x t^1.5, t = (width - 1000 us) / 1000 us in 0..1,\n"
    "                   idle_a without a pulse), max_a (30), idle_a (0.5), volt_mult (10.1),\n"
    "                   amp_per_volt (17), amp_offset (0 V); '' for the defaults. A cell's\n"
    "                   open-circuit voltage follows a LiPo curve (4.20 V full, 3.27 V empty),\n"
    "                   less current x r_ohm; the charge falls with the current. Without it A12\n"
    "                   and A13 read 0 V. docs/simulator.md has the curve\n"
    "  --battery-log FILE  the pack's truth at 10 Hz: CSV t,volts,amps,mah,charge\n"
    "\n"
    "Bus check: the barometer chip select (pin 40 = PG1, PORTG bit 1) must be high whenever the\n"
    "MPU6000 chip select (pin 53) is low, checked when pin 53 goes low and at every SPI byte.\n"
    "A violation is printed on stderr and the exit status is 3.\n"
    "Timing: an SPI byte takes 8 SCK periods at the divider SPCR/SPSR set; an I2C bit takes\n"
    "16 + 2*TWBR*4^TWPS CPU cycles; an EEPROM byte write keeps EEPE set for 3.4 ms\n"
    "(simavr 1.6's fixed times corrected).\n"
    "Exit status: 0 run completed, 1 usage or file error, 2 the core crashed, 3 bus violation,\n"
    "4 the physics backend failed.\n"
    "\n";

bool read_file(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    std::ostringstream ss;
    ss << in.rdbuf();
    out = ss.str();
    return true;
}

// The backend's `rc` as the receiver's next row (only when it changes; the --rc file, when
// given, drives the receiver instead). False with `error` when `rc` is malformed.
bool take_backend_rc(const sim::PhysicsState& state, double t_s, bool from_backend, sim::RcScript& rc,
                     sim::Board* board, std::string& error) {
    if (!from_backend || !state.has_rc) return true;
    sim::RcRow row;
    if (!sim::physics_rc_row(state, t_s, row, error)) return false;
    const sim::RcRow* last = rc.rows().empty() ? nullptr : &rc.rows().back();
    bool same = last && last->signal == row.signal;
    for (int c = 0; same && row.signal && c < sim::kRcChannels; ++c) same = last->width_us[c] == row.width_us[c];
    if (same) return true;
    rc.push(row);
    if (rc.rows().size() > 4096) rc.drop_before(t_s - 1.0);  // a backend whose sticks move every frame
    if (board) board->rc_changed();
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    sim::BoardOptions options;
    std::string battery_log_path;
    std::string trajectory_path, input_path, profile_path, rc_path, servo_log_path, serial_spec, physics_spec,
        physics_log_path;
    double speed = -1.0;
    sim::PhysicsOptions physics;
    double earth_field_uT[3] = {sim::kEarthFieldNed_uT[0], sim::kEarthFieldNed_uT[1], sim::kEarthFieldNed_uT[2]};
    std::vector<std::string> faults;
    sim::GeodeticPoint home{sim::kHomeLat_deg, sim::kHomeLon_deg, sim::kHomeAlt_m};
    double seconds = -1.0;
    bool verbose = false;
    double mount_rpy_deg[3] = {0.0, 0.0, 0.0};  // --orientation
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
        } else if (arg == "--mission") {
            options.mission_path = value("--mission");
        } else if (arg == "--eeprom") {
            options.eeprom_path = value("--eeprom");
        } else if (arg == "--eeprom-cuts") {
            const char* spec = value("--eeprom-cuts");
            if (std::sscanf(spec, "%lf:%lf:%lf", &options.eeprom_cuts_from_s, &options.eeprom_cuts_to_s,
                            &options.eeprom_cuts_step_s) != 3 ||
                !(options.eeprom_cuts_step_s > 0.0) || !(options.eeprom_cuts_to_s >= options.eeprom_cuts_from_s)) {
                std::fprintf(stderr, "apm25sim: --eeprom-cuts wants T1:T2:STEP with T1 <= T2, STEP > 0, not '%s'\n",
                             spec);
                return 1;
            }
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
        } else if (arg == "--physics") {
            physics_spec = value("--physics");
            std::string error;
            if (!sim::parse_physics_spec(physics_spec, physics, error)) {
                std::fprintf(stderr, "apm25sim: %s\n", error.c_str());
                return 1;
            }
        } else if (arg == "--physics-rate") {
            const char* text = value("--physics-rate");
            char* end = nullptr;
            const long hz = std::strtol(text, &end, 10);
            if (*end != '\0' || hz < 400 || hz > 10000) {
                std::fprintf(stderr, "apm25sim: --physics-rate '%s': a whole number of Hz, 400..10000\n", text);
                return 1;
            }
            physics.frame_rate_hz = (int)hz;
        } else if (arg == "--physics-log") {
            physics_log_path = value("--physics-log");
        } else if (arg == "--physics-timeout") {
            const char* text = value("--physics-timeout");
            char* end = nullptr;
            physics.give_up_s = std::strtod(text, &end);
            if (*end != '\0' || !(physics.give_up_s >= 1.0) || physics.give_up_s > 86400.0) {
                std::fprintf(stderr, "apm25sim: --physics-timeout '%s': seconds, 1..86400\n", text);
                return 1;
            }
        } else if (arg == "--earth-field") {
            const char* text = value("--earth-field");
            char tail = 0;
            if (std::sscanf(text, "%lf,%lf,%lf%c", &earth_field_uT[0], &earth_field_uT[1], &earth_field_uT[2], &tail) != 3 ||
                !std::isfinite(earth_field_uT[0] + earth_field_uT[1] + earth_field_uT[2]) ||
                std::fabs(earth_field_uT[0]) + std::fabs(earth_field_uT[1]) + std::fabs(earth_field_uT[2]) > 1000.0) {
                std::fprintf(stderr, "apm25sim: --earth-field '%s': N,E,D in uT (e.g. 20,0,45)\n", text);
                return 1;
            }
        } else if (arg == "--verbose") {
            verbose = true;
        } else if (arg == "--gps") {
            const std::string kind = value("--gps");
            if (kind == "ublox") {
                options.gps.kind = sim::GpsKind::kUblox;
                options.gps_attached = true;
            } else if (kind == "nmea") {
                options.gps.kind = sim::GpsKind::kNmea;
                options.gps_attached = true;
            } else if (kind == "none") {
                options.gps_attached = false;
            } else {
                std::fprintf(stderr, "apm25sim: --gps '%s': ublox, nmea or none\n", kind.c_str());
                return 1;
            }
        } else if (arg == "--gps-baud") {
            const char* text = value("--gps-baud");
            char* end = nullptr;
            const long baud = std::strtol(text, &end, 10);
            if (*end != '\0' || (baud != 4800 && baud != 9600 && baud != 19200 && baud != 38400 && baud != 57600 &&
                                  baud != 115200)) {
                std::fprintf(stderr, "apm25sim: --gps-baud '%s': 4800, 9600, 19200, 38400, 57600 or 115200\n", text);
                return 1;
            }
            options.gps.baud = (uint32_t)baud;
        } else if (arg == "--gps-fix-after" || arg == "--gps-latency") {
            const char* text = value(arg.c_str());
            char* end = nullptr;
            const double v = std::strtod(text, &end);
            if (*end != '\0' || !(v >= 0.0) || v > 1e6 || (arg == "--gps-latency" && v > 5.0)) {
                std::fprintf(stderr, "apm25sim: %s '%s': seconds >= 0%s\n", arg.c_str(), text,
                             arg == "--gps-latency" ? ", at most 5" : "");
                return 1;
            }
            (arg == "--gps-fix-after" ? options.gps.first_fix_s : options.gps.latency_s) = v;
        } else if (arg == "--baro") {
            const std::string kind = value("--baro");
            if (kind != "ms5611" && kind != "none") {
                std::fprintf(stderr, "apm25sim: --baro '%s': ms5611 or none\n", kind.c_str());
                return 1;
            }
            options.baro_attached = kind == "ms5611";
        } else if (arg == "--baro-noise") {
            const char* text = value("--baro-noise");
            char* end = nullptr;
            const double hpa = std::strtod(text, &end);
            if (*end != '\0' || !(hpa >= 0.0) || hpa > 100.0) {
                std::fprintf(stderr, "apm25sim: --baro-noise '%s': hPa, 0..100\n", text);
                return 1;
            }
            options.baro.noise_pa = hpa * 100.0;
        } else if (arg == "--baro-temp") {
            const char* text = value("--baro-temp");
            char* end = nullptr;
            const double c = std::strtod(text, &end);
            if (*end != '\0' || !(c >= -40.0 && c <= 85.0)) {
                std::fprintf(stderr, "apm25sim: --baro-temp '%s': degC, -40..85 (the chip's range)\n", text);
                return 1;
            }
            options.baro.fixed_temperature = true;
            options.baro.temperature_c = c;
        } else if (arg == "--battery") {
            std::string error;
            if (!sim::parse_battery_spec(value("--battery"), options.battery, error)) {
                std::fprintf(stderr, "apm25sim: %s\n", error.c_str());
                return 1;
            }
            options.battery_attached = true;
        } else if (arg == "--battery-log") {
            battery_log_path = value("--battery-log");
        } else if (arg == "--home") {
            const char* text = value("--home");
            double lat = 0, lon = 0, alt = 0;
            char tail = 0;
            if (std::sscanf(text, "%lf,%lf,%lf%c", &lat, &lon, &alt, &tail) != 3 || !(std::fabs(lat) <= 85.0) ||
                !(std::fabs(lon) <= 180.0) || !(alt >= -500.0 && alt <= 9000.0)) {
                std::fprintf(stderr,
                             "apm25sim: --home '%s': LAT,LON,ALT_M in degrees (|lat| <= 85) and metres above sea "
                             "level (-500..9000)\n",
                             text);
                return 1;
            }
            home = sim::GeodeticPoint{lat, lon, alt};
        } else if (arg == "--seed") {
            const char* text = value("--seed");
            char* end = nullptr;
            const unsigned long long seed = std::strtoull(text, &end, 10);
            if (*end != '\0' || text[0] == '-' || text[0] == 0) {
                std::fprintf(stderr, "apm25sim: --seed '%s': a whole number >= 0\n", text);
                return 1;
            }
            options.gps.seed = options.baro.seed = (uint64_t)seed;
        } else if (arg == "--orientation") {
            const char* text = value("--orientation");
            char* end = nullptr;
            const long r = std::strtol(text, &end, 10);
            if (*end != '\0' || text[0] == 0 || !sim::board_rotation_rpy((int)r, mount_rpy_deg)) {
                std::fprintf(stderr, "apm25sim: --orientation '%s': a rotation number 0..%d\n", text,
                             sim::kBoardRotations - 1);
                return 1;
            }
        } else {
            std::fprintf(stderr, "apm25sim: unknown argument '%s'\n%s", arg.c_str(), kUsage);
            return 1;
        }
    }
    options.gps.home = options.baro.home = home;
    const bool use_physics = !physics_spec.empty();
    if (options.elf_path.empty() || trajectory_path.empty() == !use_physics) {
        std::fprintf(stderr, "apm25sim: --elf and one of --trajectory or --physics are required\n%s", kUsage);
        return 1;
    }
    sim::Trajectory trajectory;
    if (!use_physics && !trajectory.load(trajectory_path)) {
        std::fprintf(stderr, "apm25sim: %s\n", trajectory.error().c_str());
        return 1;
    }
    // The board's mounting: what its sensors read of the airframe's motion.
    auto mount = [&mount_rpy_deg](sim::TrajectorySample& t) {
        if (mount_rpy_deg[0] == 0.0 && mount_rpy_deg[1] == 0.0 && mount_rpy_deg[2] == 0.0) return;
        sim::airframe_to_board(mount_rpy_deg, t.gyro_rad_s);
        sim::airframe_to_board(mount_rpy_deg, t.accel_m_s2);
        sim::airframe_to_board(mount_rpy_deg, t.mag_uT);
    };
    for (sim::TrajectorySample& t : trajectory.samples()) mount(t);
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
    if (!battery_log_path.empty()) {
        if (!options.battery_attached) {
            std::fprintf(stderr, "apm25sim: --battery-log needs --battery\n");
            return 1;
        }
        options.battery_log = std::fopen(battery_log_path.c_str(), "w");
        if (!options.battery_log) {
            std::fprintf(stderr, "apm25sim: cannot write the battery log '%s'\n", battery_log_path.c_str());
            return 1;
        }
    }
    if (!servo_log_path.empty()) {
        servo_log = std::fopen(servo_log_path.c_str(), "w");
        if (!servo_log) {
            std::fprintf(stderr, "apm25sim: cannot write the servo log '%s'\n", servo_log_path.c_str());
            return 1;
        }
        options.servo_log = servo_log;
    }
    if (options.eeprom_cuts_step_s > 0.0 && options.eeprom_path.empty()) {
        std::fprintf(stderr, "apm25sim: --eeprom-cuts needs --eeprom FILE\n");
        return 1;
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
    }
    if (options.serial || use_physics) {
        // A live board or a flight runs until stopped; the stop is a clean end (EEPROM
        // written back).
        std::signal(SIGINT, [](int) { sim::request_stop(); });
        std::signal(SIGTERM, [](int) { sim::request_stop(); });
        if (seconds < 0.0) seconds = 1e9;
    }
    options.speed = speed >= 0.0 ? speed : (options.serial ? 1.0 : 0.0);
    if (seconds < 0.0) seconds = trajectory.duration_s();

    // --physics: the first state before the board starts (the sensors need one at t = 0).
    sim::PhysicsLink link(physics);
    FILE* physics_log = nullptr;
    sim::PhysicsState first;
    const bool rc_from_backend = use_physics && rc_path.empty();
    if (use_physics) {
        if (!link.open()) {
            std::fprintf(stderr, "apm25sim: %s\n", link.error().c_str());
            return 1;
        }
        link.set_stop_check(sim::stop_requested);
        options.measure_servos = true;
        if (rc_from_backend) options.rc = &rc;
        const uint16_t none[sim::kSitlServoChannels] = {};
        if (!link.exchange(0, none, first)) {
            std::fprintf(stderr, "apm25sim: %s\n", link.error().c_str());
            return link.stopped() ? 0 : 4;
        }
        sim::TrajectorySample s0 = sim::physics_sample(first, 0.0, earth_field_uT);
        mount(s0);
        trajectory.append(s0);
        if (!physics_log_path.empty()) {
            physics_log = std::fopen(physics_log_path.c_str(), "w");
            if (!physics_log) {
                std::fprintf(stderr, "apm25sim: cannot write the physics log '%s'\n", physics_log_path.c_str());
                return 1;
            }
            std::fputs(sim::kTrajectoryHeaderNed, physics_log);
            std::fputs(sim::format_trajectory_row_ned(trajectory[0]).c_str(), physics_log);
        }
        std::string error;
        if (!take_backend_rc(first, 0.0, rc_from_backend, rc, nullptr, error)) {
            std::fprintf(stderr, "apm25sim: the physics backend's answer to frame 0: %s\n", error.c_str());
            return 4;
        }
    }

    sim::Board board(trajectory, options);
    for (const std::string& spec : faults) {
        std::string error;
        if (!sim::apply_fault_spec(spec, board.fault_targets(), error)) {
            std::fprintf(stderr, "apm25sim: %s\n", error.c_str());
            return 1;
        }
    }
    if (!board.init()) {
        std::fprintf(stderr, "apm25sim: %s\n", board.error().c_str());
        return 1;
    }
    if (use_physics && first.has_airspeed) board.set_a0_mV(sim::Mpxv7002dpModel::output_mV(first.airspeed_m_s));
    bool ran = true;
    int physics_status = 0;
    if (!use_physics) {
        ran = board.run(seconds);
    } else {
        // Lock-step: each frame sends the outputs as the pins show them now, then runs the
        // board to the backend's new time on the state it answered.
        double last_t = 0.0;
        for (uint32_t frame = 1; ran && !sim::stop_requested() && board.time_s() < seconds; ++frame) {
            uint16_t pwm[sim::kSitlServoChannels] = {};  // OUT9-16 do not exist: 0
            for (int out = 1; out <= sim::kServoOutputs; ++out) pwm[out - 1] = board.servo_width_now_us(out);
            sim::PhysicsState state;
            std::string error;
            if (!link.exchange(frame, pwm, state)) {
                if (link.stopped()) break;  // a clean end, as any SIGINT/SIGTERM
                error = link.error();
            } else {
                const double t = state.timestamp_s - first.timestamp_s;
                if (!(t > last_t)) {
                    char why[160];
                    std::snprintf(why, sizeof why, "the physics backend's timestamp %.6f s (frame %u) is not after %.6f s",
                                  state.timestamp_s, (unsigned)frame, last_t + first.timestamp_s);
                    error = why;
                } else {
                    sim::TrajectorySample sample = sim::physics_sample(state, t, earth_field_uT);
                    mount(sample);
                    board.append_sample(sample, 1.0);
                    if (state.has_airspeed) board.set_a0_mV(sim::Mpxv7002dpModel::output_mV(state.airspeed_m_s));
                    if (physics_log) std::fputs(sim::format_trajectory_row_ned(sample).c_str(), physics_log);
                    if (take_backend_rc(state, t, rc_from_backend, rc, &board, error)) {
                        ran = board.run(std::min(t, seconds));
                        last_t = t;
                    } else {
                        error = "the physics backend's answer to frame " + std::to_string(frame) + ": " + error;
                    }
                }
            }
            if (!error.empty()) {
                std::fprintf(stderr, "apm25sim: %s; stopping at t=%.6f s\n", error.c_str(), board.time_s());
                physics_status = 4;
                break;
            }
        }
        // The link's summary: a loaded machine shows here as frames sent again and their
        // late answers dropped.
        std::fprintf(stderr, "apm25sim: physics backend at %s:%d: %s\n", physics.host.c_str(), physics.port,
                     link.summary().c_str());
    }
    board.finish_output();
    if (physics_log && std::fclose(physics_log) != 0) {
        std::fprintf(stderr, "apm25sim: cannot write the physics log '%s'\n", physics_log_path.c_str());
        return 1;
    }
    if (options.battery_log && std::fclose(options.battery_log) != 0) {
        std::fprintf(stderr, "apm25sim: cannot write the battery log '%s'\n", battery_log_path.c_str());
        return 1;
    }
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
    if (physics_status) return physics_status;
    if (board.bus_violations() > 0) {
        std::fprintf(stderr, "apm25sim: %u bus violation(s): pin 40 must be high while pin 53 is low\n",
                     board.bus_violations());
        return 3;
    }
    return 0;
}
