// SPDX-License-Identifier: GPL-3.0-or-later
// The GPS receiver on a serial port, as ArduPilot's AP_GPS drove the u-blox on APM2
// (AP_GPS.cpp detect_instance, AP_GPS_UBLOX.cpp send_next_rate_update, AP_GPS_Glitch):
// detection, u-blox configuration, the solution and its faults, as a state machine
// driven by the time and the bytes received. No clock and no serial port of its own:
// the firmware feeds received bytes and calls update() each loop pass, and the Port
// seam sets the baud and sends; the host tests drive it with a fake clock and port.
//
// Detection (GPS_TYPE 1 auto, 2 u-blox, 5 NMEA; 0 none: nothing is ever sent or read):
// each baud of baud_at() in turn for kBaudDwellMs; at each, for auto and u-blox,
// "$PUBX,41,1,0003,0001,38400,0*26" (UART1 speaks UBX in and out at 38400) and the UBX
// CFG-MSG that turns NAV-SOL on are sent. The first valid UBX frame means a u-blox at this baud
// (auto, u-blox); a valid NMEA sentence means an NMEA receiver (NMEA; in auto only once
// kNmeaSettleMs have passed since the probes left, time enough for a u-blox that heard
// them to have left NMEA and this baud). A round and its first baud again with nothing
// heard is said once (Event::kNoGpsFound) and detection goes on.
//
// Configuration of a u-blox, one message per update() when the port has room for it:
// CFG-RATE 200 ms (5 Hz), CFG-MSG rate 1 for NAV-POSLLH, NAV-STATUS, NAV-SOL, NAV-VELNED,
// then CFG-NAV5 polled; when its dynModel is not GPS_NAVFILTER, CFG-NAV5 is written (the
// dynModel alone, mask bit 0) and polled again, until the answer agrees (a poll unanswered
// for kPollMs is sent again). The rates are sent again when the 5 Hz rhythm (successive
// fixes <= kRateGapMs apart) has been missing for kRateLostMs. In auto with an NMEA
// receiver the probes are sent again every kRateLostMs: a u-blox that missed them (a cut
// RX wire mended) then switches to UBX, is lost to NMEA, and is found again.
//
// Faults: a position off the earth (|lat| > 90 deg, |lon| > 180 deg), a ground speed over
// kMaxSpeedCmS or a course outside 0..360 deg is no fix. Nothing valid heard for
// kDataTimeoutMs: the receiver is lost (fix kNoGps) and
// detection starts again at the same baud. A 2D/3D position further from the last good
// one moved on by its velocity than kGlitchRadiusM + kGlitchAccelMss * dt^2 / 2 is a
// glitch (AP_GPS_Glitch's test with its defaults): the fix carries `glitching` and the
// last good position is kept, so that a glitch that lasts is accepted once the
// acceleration allowance covers it.
#pragma once

#include <stdint.h>

#include "GpsFix.h"
#include "NmeaParser.h"
#include "UbxParser.h"

namespace gps {

enum class Type : uint8_t { kNone = 0, kAuto = 1, kUblox = 2, kNmea = 5 };  // GPS_TYPE
enum class Protocol : uint8_t { kNone, kUbx, kNmea };

// The serial port: baud changes and sends (never blocking: room() says what fits).
struct Port {
    void* ctx;
    void (*set_baud)(void* ctx, uint32_t baud);
    uint8_t (*room)(void* ctx);
    void (*write)(void* ctx, const uint8_t* data, uint8_t len);
};

// What changed, as bits (Receiver::take_events).
enum Event : uint8_t {
    kEventFound = 0x01,       // a receiver at baud() speaking protocol()
    kEventConfigured = 0x02,  // the u-blox took every setting
    kEventNoGpsFound = 0x04,  // six bauds (a round and 38400 again) without one (said once)
    kEventLost = 0x08,        // nothing valid for kDataTimeoutMs: detection again
    kEventQuality = 0x10,     // quality() changed
    kEventGlitch = 0x20,      // a glitch began (glitch_m()) ...
    kEventGlitchOver = 0x40,  // ... or ended
};

// The fix as the user is told about it.
enum class Quality : uint8_t { kNoFix, k2D, k3DFewSats, k3D };

struct Config {
    Type type = Type::kAuto;
    uint8_t nav_filter = 8;  // GPS_NAVFILTER: u-blox dynModel (8 airborne < 4 g)
    uint8_t min_sats = 6;    // AHRS_GPS_MINSATS: fewer is "too few satellites"
};

class Receiver {
public:
    static constexpr uint8_t kBaudCount = 5;
    static constexpr uint16_t kBaudDwellMs = 1200;
    static constexpr uint16_t kNmeaSettleMs = 300;
    static constexpr uint16_t kPollMs = 1000;
    static constexpr uint16_t kRateGapMs = 300;
    static constexpr uint16_t kRateLostMs = 15000;
    static constexpr uint16_t kDataTimeoutMs = 4000;
    static constexpr uint16_t kMeasRateMs = 200;
    static constexpr float kGlitchRadiusM = 2.0f;   // AP_GPS_Glitch GPSGLITCH_RADIUS 200 cm
    static constexpr float kGlitchAccelMss = 10.0f;  // GPSGLITCH_ACCEL 1000 cm/s/s
    static constexpr uint32_t kMaxSpeedCmS = 50000;  // 500 m/s: a faster "fix" is no fix
    static uint32_t baud_at(uint8_t index);  // kBauds[index]: 38400, 57600, 9600, 115200, 4800

    // The port is kept by reference: it outlives the receiver.
    // constexpr: a static receiver needs no start-up code.
    explicit constexpr Receiver(const Port& port) : port_(&port), ubx_(work_), nmea_(work_) {}

    // Starts (or restarts with new settings) detection; Type::kNone: stays silent.
    void begin(const Config& config, uint32_t now_ms);
    // One received byte.
    void feed(uint8_t byte, uint32_t now_ms);
    // Each loop pass: time-outs, baud changes, the next message to send.
    void update(uint32_t now_ms);
    // The events since the last call (Event bits).
    uint8_t take_events() {
        const uint8_t e = events_;
        events_ = 0;
        return e;
    }

    const Fix& fix() const { return fix_; }
    // Incremented on each new solution (fix() changed), also when the receiver is lost.
    uint16_t fix_count() const { return fix_count_; }
    Quality quality() const { return quality_; }
    bool found() const { return state_ == State::kConfiguring || state_ == State::kRunning; }
    bool configured() const { return state_ == State::kRunning; }
    Protocol protocol() const { return protocol_; }
    uint32_t baud() const { return baud_at(baud_index_); }
    float glitch_m() const { return glitch_m_; }
    const UbxParser::Counters& ubx_counters() const { return ubx_.counters(); }
    const NmeaParser::Counters& nmea_counters() const { return nmea_.counters(); }
    const Config& config() const { return config_; }

private:
    enum class State : uint8_t { kOff, kDetecting, kConfiguring, kRunning };
    // The configuration's steps, in order (kWaitNav5: the poll's answer awaited).
    enum Step : uint8_t { kStepRate, kStepPosllh, kStepStatus, kStepSol, kStepVelned, kStepPollNav5, kStepWaitNav5,
                          kStepWriteNav5 };

    void start_baud(uint8_t index, uint32_t now_ms);
    void found_at(Protocol p, uint32_t now_ms);
    bool send_probes();
    bool send_step();
    void new_solution(const Fix& f, uint32_t now_ms);
    void check_glitch(uint32_t now_ms);
    bool send_frame(uint8_t cls, uint8_t id, const uint8_t* payload, uint8_t len);

    const Port* port_;
    Config config_;
    Fix work_;  // the parsers' solution being assembled (only one parser runs once found)
    UbxParser ubx_;
    NmeaParser nmea_;
    Fix fix_;
    State state_ = State::kOff;
    Protocol protocol_ = Protocol::kNone;
    Quality quality_ = Quality::kNoFix;
    uint8_t baud_index_ = 0;
    uint8_t bauds_tried_ = 0;      // since detection started (saturates past kBaudCount + 1)
    uint8_t probe_step_ = 0;       // probes sent at this baud (2: both)
    uint8_t step_ = 0;             // Step
    uint8_t events_ = 0;
    bool no_gps_said_ = false;
    bool glitching_ = false;
    bool have_good_ = false;       // a last good position for the glitch test
    uint16_t fix_count_ = 0;
    uint32_t state_ms_ = 0;        // baud started / poll sent / NMEA probes sent
    uint32_t probes_ms_ = 0;       // both probes left (detection)
    uint32_t last_data_ms_ = 0;    // a valid frame or sentence
    uint32_t rate_ok_ms_ = 0;      // the 5 Hz rhythm last seen
    uint32_t last_itow_ms_ = 0;
    uint32_t good_ms_ = 0;         // the last good position's time ...
    int32_t good_lat_e7_ = 0, good_lon_e7_ = 0;  // ... and place
    float good_vel_n_m_s_ = 0.0f, good_vel_e_m_s_ = 0.0f;
    float glitch_m_ = 0.0f;
};

// The probes sent at each baud (AP_GPS's _initialisation_blob for the u-blox on APM2).
extern const char kPubx41[];  // "$PUBX,41,1,0003,0001,38400,0*26\r\n"

}  // namespace gps
