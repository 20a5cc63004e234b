// SPDX-License-Identifier: GPL-3.0-or-later
// A u-blox 6 GPS receiver (NEO-6M, firmware 7.03) on the APM 2.5's GPS port (UART1), as
// the u-blox 6 Receiver Description including Protocol Specification (GPS.G6-SW-10018)
// describes it, driven by the trajectory's (or the physics backend's) position and
// velocity. Section names below are that document's.
//
// Host-only, no simavr: the harness hands it the frames the firmware's USART1 sends and
// takes the frames it puts on the line (sim/models/UartLine.h), so the baud rates of both
// ends matter as on the board.
//
// What is modelled:
// - Power-up as a factory-new module ("Default Settings"): UART1 at 9600 baud 8N1, input
//   UBX + NMEA + RTCM, output UBX + NMEA, the NMEA messages GGA, GLL, GSA, GSV, RMC, VTG on
//   (rate 1), every UBX message off; measurement period 1000 ms; two GPTXT lines at boot.
//   Output begins with the first measurement epoch after kBootTime_s.
// - Configuration input ("UBX Protocol", "UBX-CFG"), checked as the receiver does: a UBX
//   frame with a bad checksum, an NMEA sentence with a bad checksum, or anything in a
//   protocol the port does not take in (inProtoMask) is ignored and counted. A message is
//   acted on kAnswerDelay_s (5 ms) after its last byte (the spec: "as soon as possible"):
//   a new baud applies from then, and what the module was sending goes on at it. Every CFG
//   message is answered with ACK-ACK or ACK-NAK (class, id):
//     CFG-PRT  (06 00) poll (0 or 1 byte) -> CFG-PRT for UART1 + ACK; set (20 bytes a port):
//              UART1's baud, inProtoMask, outProtoMask; other ports stored nowhere, ACKed.
//              NAK for a length that is not a multiple of 20, or a baud outside
//              4800..115200 of the standard rates. The new baud applies from the next byte
//              the module starts: the ACK already goes at the new rate.
//     CFG-MSG  (06 01) poll (2) -> CFG-MSG (8: the six I/O targets) + ACK; set (3: UART1,
//              or 8: the six targets, UART1's taken). Rate = 1 message every `rate`
//              measurement epochs, 0 off. Any class and id is stored and ACKed.
//     CFG-RATE (06 08) poll (0) -> CFG-RATE + ACK; set (6): measRate >= 200 ms (the NEO-6's
//              5 Hz), navRate 1 (u-blox 6 cannot change it), timeRef 0 or 1, else NAK.
//     CFG-NAV5 (06 24) poll (0) -> CFG-NAV5 (36) + ACK; set (36): the fields its mask
//              selects; NAK (nothing applied) for a dynModel not in 0, 2..8 or a fixMode
//              not in 1..3. The pDop and pAcc masks decide gpsFixOk.
//     CFG-SBAS (06 16), CFG-CFG (06 09): set ACKed (nothing else happens); SBAS poll answered.
//     CFG-RST  (06 04): no answer, not modelled (counted). Any other CFG id: NAK.
//   MON-VER (0A 04) and the NAV messages below answer a poll (an empty payload) at once.
//   NMEA input ("Proprietary Messages"): $PUBX,41,portId,inProto,outProto,baud,autobaud
//   sets UART1 (portId 1; others ignored) as CFG-PRT does, without an answer;
//   $PUBX,40,msgId,rddc,rus1,rus2,rusb,rspi sets an NMEA message's rate on UART1 (rus1).
// - Output each measurement epoch (CFG-RATE), each message at its CFG-MSG rate, UBX when
//   outProtoMask has UBX, NMEA when it has NMEA, in this order: NAV-POSLLH (01 02, 28 bytes),
//   NAV-STATUS (01 03, 16), NAV-DOP (01 04, 18), NAV-SOL (01 06, 52), NAV-VELNED (01 12, 36),
//   then RMC, VTG, GGA, GSA, GSV, GLL. The UBX messages of one epoch share its iTOW (GPS
//   time of week, ms, a multiple of measRate: epochs are aligned to GPS time), and the
//   NMEA ones its UTC time.
// - Latency: an epoch measured at T leaves the module at T + latency_s (0.2 s by default):
//   what arrives reports the truth latency_s earlier, stamped with T.
// - Errors: position = truth + a first-order Gauss-Markov error per axis (horizontal_sigma_m
//   on N and E, vertical_sigma_m on D, correlation time position_tau_s, seeded): a slow
//   random walk of ~1 m; velocity = truth + white noise velocity_sigma_m_s per axis. With
//   fewer satellites than nominal the errors and DOPs grow by (nominal / numSV)^1.5. hAcc,
//   vAcc, sAcc, pAcc are the model's own error statistics (hAcc the horizontal RMS, sAcc
//   the 3D speed RMS); the heading of motion is held while the ground speed is under
//   0.5 m/s (u-blox 6 freezes the course at low speed), cAcc then 180 deg.
// - Satellites and DOP: 10 satellites used, hDOP 0.90, vDOP 1.40 (pDOP 1.66), tDOP 0.80.
// - First fix at first_fix_s (default 3 s): before it gpsFix 0, flags 0, lat/lon/heights 0,
//   hAcc and vAcc 0xFFFFFFFF, numSV climbing 0..3, NMEA fields empty. The time (WKNSET,
//   TOWSET) is valid from the first fix on. A fix lost later keeps the last position.
// - The line: bytes leave back to back at the module's baud (10 bit times each, 8N1) from a
//   transmit buffer of tx_buffer_bytes; an epoch's message that does not fit is dropped
//   (counted), as a port too slow for its messages does.
// - Faults (UbloxFaults): the windows are in the time the bytes leave the module.
//
// Kind kNmea: a module that only speaks NMEA (GGA, GLL, GSA, GSV, RMC, VTG at 1 Hz at its
// baud) and ignores every byte it receives (UBX, PUBX and NMEA alike, counted).
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <array>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "Geodesy.h"
#include "Noise.h"
#include "TimeWindow.h"
#include "Trajectory.h"
#include "Ubx.h"
#include "UartLine.h"

namespace sim {

enum class GpsKind { kUblox, kNmea };

struct UbloxOptions {
    GpsKind kind = GpsKind::kUblox;
    GeodeticPoint home{kHomeLat_deg, kHomeLon_deg, kHomeAlt_m};
    uint32_t baud = 9600;             // at power-up
    double first_fix_s = 3.0;         // simulated time of the first 3D fix
    double latency_s = 0.2;           // measurement to output
    uint64_t seed = 1;
    double horizontal_sigma_m = 0.7;  // per axis, N and E: a horizontal RMS of ~1 m
    double vertical_sigma_m = 1.5;
    double position_tau_s = 30.0;
    double velocity_sigma_m_s = 0.1;  // per axis
    int satellites = 10;              // used in the solution, nominal
    size_t tx_buffer_bytes = 4096;
};

struct UbloxFaults {
    TimeWindows no_fix;        // the fix is lost: gpsFix 0, numSV 2; the module talks on
    TimeWindows silent;        // no byte reaches the line (the module works on unseen)
    TimeWindows deaf;          // every byte from the firmware is ignored
    TimeWindows garbage;       // random bytes on the line among the module's
    ValueWindows glitch;       // the reported position jumps `value` metres north
    ValueWindows satellites;   // numSV = value: < 3 no fix, 3 a 2D fix, >= 4 3D, worse DOP
};

// Events and protocol errors, counted (tests assert on them).
struct UbloxCounters {
    uint32_t epochs = 0;                // measurement epochs output
    uint32_t ubx_messages_out = 0;
    uint32_t nmea_sentences_out = 0;
    uint32_t tx_dropped_messages = 0;   // did not fit the transmit buffer
    uint32_t bytes_out = 0;             // bytes put on the line by the module
    uint32_t bytes_silenced = 0;        // module bytes a `silent` fault kept off the line
    uint32_t garbage_bytes = 0;
    uint32_t bytes_in = 0;              // characters received with a good stop bit
    uint32_t framing_errors_in = 0;     // characters received with a low stop bit (dropped)
    uint32_t ignored_deaf = 0;          // bytes a `deaf` fault dropped
    uint32_t ignored_nmea_only = 0;     // bytes a kNmea module ignored
    uint32_t ignored_protocol = 0;      // a message in a protocol the port does not take in
    uint32_t acks = 0;
    uint32_t naks = 0;
    uint32_t polls = 0;                 // polls answered
    uint32_t pubx41 = 0;
    uint32_t pubx40 = 0;
    uint32_t port_changes = 0;          // UART1's baud or protocols set (PUBX,41, CFG-PRT)
    uint32_t not_modelled = 0;          // CFG-RST, other ports, unknown PUBX
};

class UbloxModel {
public:
    static constexpr double kBootTime_s = 0.5;        // no output before the first epoch after this
    static constexpr double kAnswerDelay_s = 0.005;   // a message is acted on this long after its last byte
    static constexpr double kCourseHoldSpeed_m_s = 0.5;

    UbloxModel(const Trajectory& trajectory, const UbloxOptions& options);  // copies (own cursor)
    Trajectory& trajectory() { return trajectory_; }
    const UbloxOptions& options() const { return options_; }

    // Runs the module to simulated time t_s (never backwards).
    void advance_to(double t_s);
    double time_s() const { return time_s_; }
    // The next instant something happens: a character received, an epoch, an output, a
    // byte starting on the line (infinity when nothing is scheduled).
    double next_event_s() const;

    // Module -> firmware: the next frame that has started on the line by time_s().
    bool pop_frame(UartFrame& frame);
    // Firmware -> module: a frame the firmware's USART puts on the line (at its start).
    void line_in(const UartFrame& frame);

    // The port and message configuration now.
    uint32_t baud() const { return baud_; }
    uint16_t in_proto() const { return in_proto_; }
    uint16_t out_proto() const { return out_proto_; }
    uint16_t meas_rate_ms() const { return meas_rate_ms_; }
    uint8_t message_rate(uint8_t cls, uint8_t id) const;
    uint8_t dyn_model() const { return nav5_[2]; }

    // GPS time: ms since the GPS epoch (1980-01-06) at simulated time t_s.
    uint64_t gps_ms(double t_s) const;
    static uint32_t itow_ms(uint64_t gps_ms) { return (uint32_t)(gps_ms % kWeek_ms); }
    static uint16_t gps_week(uint64_t gps_ms) { return (uint16_t)(gps_ms / kWeek_ms); }
    static constexpr uint64_t kWeek_ms = 604800000ull;
    static constexpr int kLeapSeconds = 16;  // GPS - UTC from July 2012 to June 2015
    // The simulated start: GPS week 1760, Thursday 2013-10-03 15:00:00.37 UTC.
    static constexpr uint64_t kStartGps_ms = 1760ull * kWeek_ms + 399616370ull;

    UbloxFaults& faults() { return faults_; }
    const UbloxCounters& counters() const { return counters_; }
    const ubx::StreamParser::Counters& parser_counters() const { return parser_.counters(); }

private:
    struct Solution {
        double meas_s = 0.0;   // the measurement instant (simulated time)
        uint64_t gps_ms = 0;   // its GPS time
        double truth_ned_m[3] = {0, 0, 0};
        double truth_vel_m_s[3] = {0, 0, 0};
        double pos_error_m[3] = {0, 0, 0};   // before the satellite scaling
        double vel_error_m_s[3] = {0, 0, 0};
        double out_s = 0.0;    // when it leaves the module
    };
    // What an epoch reports once the faults at its output time are applied.
    struct Report {
        uint32_t itow = 0;
        uint16_t week = 0;
        uint8_t fix = 0;         // 0 none, 2 2D, 3 3D
        bool fix_ok = false;
        bool time_valid = false;
        int num_sv = 0;
        double hdop = 99.99, vdop = 99.99, pdop = 99.99, tdop = 99.99, gdop = 99.99;
        bool have_position = false;  // a position to report (the current or the last fix)
        GeodeticPoint position;
        double vel_ned_m_s[3] = {0, 0, 0};
        double heading_deg = 0.0;
        double h_acc_m = 0.0, v_acc_m = 0.0, s_acc_m_s = 0.0, c_acc_deg = 180.0;
        double ecef_m[3] = {0, 0, 0};
        double ecef_vel_m_s[3] = {0, 0, 0};
        uint32_t ttff_ms = 0;
        uint32_t msss = 0;
        uint64_t gps_ms = 0;
    };
    struct TxByte {
        uint8_t byte;
        bool noise;  // a `garbage` byte, not the module's
    };

    void measure(double t_s);
    void output(const Solution& s);
    Report report(const Solution& s, double out_s);
    void queue_message(const std::vector<uint8_t>& bytes, bool is_ubx, double t_s);
    void start_byte(double t_s);
    void inject_garbage(double t_s);
    void receive_char(const UartChar& c, double t_s);
    void act_on(const ubx::StreamParser::Message& m, double t_s);
    void handle_ubx(const ubx::StreamParser::Message& m, double t_s);
    void handle_nmea(const std::string& sentence, double t_s);
    void handle_cfg(const ubx::StreamParser::Message& m, double t_s);
    void ack(uint8_t cls, uint8_t id, bool ok, double t_s);
    void send_ubx(uint8_t cls, uint8_t id, const std::vector<uint8_t>& payload, double t_s);
    bool set_port(uint32_t baud, uint16_t in_proto, uint16_t out_proto);
    // The next epoch: the first multiple of the period at (inclusive) or after a GPS time.
    void schedule_next_measurement(uint64_t after_gps_ms, bool inclusive);

    std::vector<uint8_t> nav_payload(uint8_t id, const Report& r) const;
    std::vector<std::string> nmea_sentences(uint8_t id, const Report& r) const;
    std::vector<uint8_t> cfg_prt_payload() const;
    std::vector<uint8_t> cfg_msg_payload(uint8_t cls, uint8_t id) const;

    Trajectory trajectory_;
    UbloxOptions options_;
    LocalFrame frame_;
    UbloxFaults faults_;
    UbloxCounters counters_;
    NoiseSource noise_;
    NoiseSource garbage_noise_;
    GaussMarkov pos_error_[3];

    double time_s_ = 0.0;
    // Port (UART1) and messages.
    uint32_t baud_;
    uint16_t in_proto_ = ubx::kProtoUbx | ubx::kProtoNmea | ubx::kProtoRtcm;
    uint16_t out_proto_ = ubx::kProtoUbx | ubx::kProtoNmea;
    std::map<uint16_t, std::array<uint8_t, 6>> rates_;  // class << 8 | id -> rate per I/O target
    uint16_t meas_rate_ms_ = 1000;
    uint16_t time_ref_ = 1;
    uint8_t nav5_[ubx::kLenCfgNav5];
    uint8_t sbas_[ubx::kLenCfgSbas];

    // Epochs.
    double next_measurement_s_;
    uint64_t epoch_count_ = 0;
    std::deque<Solution> pending_;  // measured, waiting for their output time
    Report last_report_;             // for polls
    bool have_report_ = false;
    bool first_fix_done_ = false;
    double first_fix_at_s_ = 0.0;
    GeodeticPoint last_fix_position_;
    double last_heading_deg_ = 0.0;
    bool boot_text_sent_ = false;

    // The line out.
    std::deque<TxByte> tx_;
    size_t tx_module_bytes_ = 0;  // module bytes in tx_ (the buffer's fill)
    double line_free_s_ = 0.0;
    std::deque<UartFrame> wire_;
    double next_garbage_s_ = 0.0;

    // The line in.
    UartReceiver rx_;
    std::deque<UartChar> rx_pending_;  // decoded, processed at their stop-bit sample
    struct Inbox {
        double at_s;
        ubx::StreamParser::Message message;
    };
    std::deque<Inbox> inbox_;          // whole messages, acted on at at_s
    std::vector<UartChar> rx_scratch_;
    ubx::StreamParser parser_;
};

}  // namespace sim
