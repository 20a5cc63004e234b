// SPDX-License-Identifier: GPL-3.0-or-later
// The u-blox model (sim/models/UbloxModel.h) as a driver sees it down the line: what a
// factory-new module says, how it answers configuration, the UBX messages' layout per
// the u-blox 6 protocol specification, latency and noise, the faults.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "sim_models_support.h"

namespace {

using simtest::GpsBench;
using simtest::LineMessage;

constexpr double kDegToRad = M_PI / 180.0;

sim::Trajectory at_rest(double seconds) {
    const double still[3] = {0, 0, 0};
    return simtest::moving_trajectory(seconds, still);
}

std::vector<uint8_t> cfg_msg(uint8_t cls, uint8_t id, uint8_t rate) { return simtest::ubx_frame(0x06, 0x01, {cls, id, rate}); }

std::vector<uint8_t> cfg_rate(uint16_t ms) {
    return simtest::ubx_frame(0x06, 0x08, {(uint8_t)ms, (uint8_t)(ms >> 8), 1, 0, 1, 0});
}

const char* const kPubx41 = "$PUBX,41,1,0003,0001,38400,0*26\r\n";

// As ArduPilot configured the module on APM2: PUBX,41 at 9600, then at 38400 the five
// NAV messages at rate 1 and a 200 ms measurement period, from `t_s` on.
void configure_for_ubx(GpsBench& bench, double t_s) {
    bench.run_to(t_s);
    bench.send(t_s, simtest::bytes_of(kPubx41));
    bench.run_to(t_s + 0.1);
    bench.set_firmware_baud(38400);
    std::vector<uint8_t> config;
    for (uint8_t id : {0x02, 0x03, 0x04, 0x06, 0x12}) {
        const std::vector<uint8_t> m = cfg_msg(0x01, id, 1);
        config.insert(config.end(), m.begin(), m.end());
    }
    const std::vector<uint8_t> rate = cfg_rate(200);
    config.insert(config.end(), rate.begin(), rate.end());
    bench.send(t_s + 0.1, config);
}

std::vector<LineMessage> ubx_of(const std::vector<LineMessage>& all, uint8_t cls, uint8_t id) {
    std::vector<LineMessage> out;
    for (const LineMessage& m : all)
        if (m.ubx && m.cls == cls && m.id == id) out.push_back(m);
    return out;
}

std::string nmea_type(const LineMessage& m) { return m.sentence.size() > 6 ? m.sentence.substr(1, 5) : ""; }

// North and east of the origin from lat/lon in 1e-7 degrees, by the WGS-84 radii at the
// origin (written here, not taken from sim/models/Geodesy).
void north_east(int32_t lat_e7, int32_t lon_e7, double& north, double& east) {
    const double a = 6378137.0, f = 1.0 / 298.257223563, e2 = f * (2 - f);
    const double lat0 = sim::kHomeLat_deg * kDegToRad;
    const double w = 1.0 - e2 * std::sin(lat0) * std::sin(lat0);
    const double h = sim::kHomeAlt_m + sim::kGeoidSeparation_m;
    north = (lat_e7 * 1e-7 - sim::kHomeLat_deg) * kDegToRad * (a * (1 - e2) / (w * std::sqrt(w)) + h);
    east = (lon_e7 * 1e-7 - sim::kHomeLon_deg) * kDegToRad * (a / std::sqrt(w) + h) * std::cos(lat0);
}

TEST(UbloxModel, FactoryNewSpeaksNmeaAt9600OnceASecond) {
    GpsBench bench(at_rest(10), sim::UbloxOptions(), 9600);
    bench.run_to(6.0);
    ASSERT_FALSE(bench.frames.empty());
    for (const sim::UartFrame& f : bench.frames) ASSERT_NEAR(f.bit_s, 1.0 / 9600, 1e-12);
    std::map<std::string, int> count;
    for (const LineMessage& m : bench.messages()) {
        ASSERT_FALSE(m.ubx) << "a factory-new module sends no UBX";
        EXPECT_TRUE(m.checksum_ok) << m.sentence;
        ++count[nmea_type(m)];
    }
    for (const char* type : {"GPRMC", "GPVTG", "GPGGA", "GPGSA", "GPGLL"}) EXPECT_GE(count[type], 5) << type;
    EXPECT_GE(count["GPGSV"], 5);
    EXPECT_EQ(count["GPTXT"], 3);  // the boot banner
    for (const sim::UartChar& c : bench.received) EXPECT_TRUE(c.framing_ok);
    // Before the first fix (3 s) RMC says V; after it A, with the field's position.
    bool void_seen = false, fix_seen = false;
    for (const LineMessage& m : bench.messages()) {
        if (nmea_type(m) != "GPRMC") continue;
        if (m.first_s < 3.0) {
            EXPECT_NE(m.sentence.find(",V,"), std::string::npos) << m.sentence;
            void_seen = true;
        } else if (m.first_s > 3.3) {
            EXPECT_NE(m.sentence.find(",A,0708."), std::string::npos) << m.sentence;  // 7 deg 08.1 min N
            EXPECT_NE(m.sentence.find(",N,07307."), std::string::npos) << m.sentence; // 73 deg 07.2 min W
            EXPECT_NE(m.sentence.find(",W,"), std::string::npos) << m.sentence;
            EXPECT_NE(m.sentence.find(",031013,"), std::string::npos) << m.sentence;  // 3 Oct 2013
            fix_seen = true;
        }
    }
    EXPECT_TRUE(void_seen);
    EXPECT_TRUE(fix_seen);
}

TEST(UbloxModel, Pubx41SwitchesToUbxAt38400) {
    GpsBench bench(at_rest(10), sim::UbloxOptions(), 9600);
    configure_for_ubx(bench, 1.2);
    bench.run_to(8.0);
    EXPECT_EQ(bench.gps.baud(), 38400u);
    EXPECT_EQ(bench.gps.in_proto(), 0x0003);
    EXPECT_EQ(bench.gps.out_proto(), 0x0001);
    EXPECT_EQ(bench.gps.counters().pubx41, 1u);
    // After the switch: only UBX, every frame at 38400, every character whole.
    bool after = false;
    for (const sim::UartFrame& f : bench.frames) {
        if (f.start_s > 1.3) {
            ASSERT_NEAR(f.bit_s, 1.0 / 38400, 1e-12);
            after = true;
        }
    }
    EXPECT_TRUE(after);
    const std::vector<LineMessage> late = bench.messages_between(1.35, 8.0);
    ASSERT_FALSE(late.empty());
    for (const LineMessage& m : late) EXPECT_TRUE(m.ubx) << m.sentence;
}

TEST(UbloxModel, CfgMsgAndCfgRateAreAcked) {
    GpsBench bench(at_rest(10), sim::UbloxOptions(), 9600);
    configure_for_ubx(bench, 1.2);
    bench.run_to(2.0);
    const std::vector<LineMessage> acks = ubx_of(bench.messages(), 0x05, 0x01);
    ASSERT_EQ(acks.size(), 6u);  // five CFG-MSG, one CFG-RATE
    for (size_t i = 0; i < acks.size(); ++i) {
        EXPECT_TRUE(acks[i].checksum_ok);
        ASSERT_EQ(acks[i].payload.size(), 2u);
        EXPECT_EQ(acks[i].payload[0], 0x06);
        EXPECT_EQ(acks[i].payload[1], i < 5 ? 0x01 : 0x08);
    }
    EXPECT_TRUE(ubx_of(bench.messages(), 0x05, 0x00).empty());
    EXPECT_EQ(bench.gps.meas_rate_ms(), 200);
    EXPECT_EQ(bench.gps.message_rate(0x01, 0x06), 1);
}

TEST(UbloxModel, BadChecksumIsIgnoredAndCounted) {
    GpsBench bench(at_rest(5), sim::UbloxOptions(), 9600);
    bench.run_to(1.0);
    std::vector<uint8_t> bad = cfg_msg(0x01, 0x06, 1);
    bad.back() ^= 0x01;
    bench.send(1.0, bad);
    bench.send(1.1, simtest::bytes_of("$PUBX,41,1,0003,0001,38400,0*27\r\n"));
    bench.run_to(2.5);
    EXPECT_EQ(bench.gps.parser_counters().ubx_bad_checksum, 1u);
    EXPECT_EQ(bench.gps.parser_counters().nmea_bad_checksum, 1u);
    EXPECT_EQ(bench.gps.message_rate(0x01, 0x06), 0);
    EXPECT_EQ(bench.gps.baud(), 9600u);
    EXPECT_EQ(bench.gps.counters().acks + bench.gps.counters().naks, 0u);
    EXPECT_TRUE(ubx_of(bench.messages(), 0x05, 0x01).empty());
}

TEST(UbloxModel, BadConfigurationIsNaked) {
    GpsBench bench(at_rest(5), sim::UbloxOptions(), 9600);
    bench.run_to(1.0);
    bench.send(1.0, cfg_rate(100));                                    // faster than a NEO-6's 5 Hz
    bench.send(1.0, simtest::ubx_frame(0x06, 0x01, {0x01, 0x06}));      // a CFG-MSG poll: answered
    bench.send(1.0, simtest::ubx_frame(0x06, 0x77, {}));                // no such CFG message
    std::vector<uint8_t> nav5(36, 0);
    nav5[0] = 0x01;  // mask: dynModel only
    nav5[2] = 1;     // dynModel 1 does not exist
    bench.send(1.0, simtest::ubx_frame(0x06, 0x24, nav5));
    bench.run_to(2.0);
    const std::vector<LineMessage> all = bench.messages();
    const std::vector<LineMessage> naks = ubx_of(all, 0x05, 0x00);
    ASSERT_EQ(naks.size(), 3u);
    EXPECT_EQ(naks[0].payload[1], 0x08);
    EXPECT_EQ(naks[1].payload[1], 0x77);
    EXPECT_EQ(naks[2].payload[1], 0x24);
    const std::vector<LineMessage> polled = ubx_of(all, 0x06, 0x01);
    ASSERT_EQ(polled.size(), 1u);
    ASSERT_EQ(polled[0].payload.size(), 8u);
    EXPECT_EQ(polled[0].payload[3], 0);  // NAV-SOL off on UART1
    EXPECT_EQ(bench.gps.meas_rate_ms(), 1000);
    EXPECT_EQ(bench.gps.dyn_model(), 0);
}

TEST(UbloxModel, CfgPrtPollThenSetAnswersAtTheNewBaud) {
    GpsBench bench(at_rest(5), sim::UbloxOptions(), 9600);
    bench.run_to(1.0);
    bench.send(1.0, simtest::ubx_frame(0x06, 0x00, {0x01}));
    bench.run_to(1.5);
    const std::vector<LineMessage> polled = ubx_of(bench.messages(), 0x06, 0x00);
    ASSERT_EQ(polled.size(), 1u);
    ASSERT_EQ(polled[0].payload.size(), 20u);
    EXPECT_EQ(polled[0].payload[0], 1);                    // UART1
    EXPECT_EQ(simtest::le32(polled[0].payload, 4) & 0x3EC0, 0x08C0u);  // 8N1
    EXPECT_EQ(simtest::le32(polled[0].payload, 8), 9600u);
    EXPECT_EQ(simtest::le16(polled[0].payload, 12), 0x0007);  // in: UBX + NMEA + RTCM
    EXPECT_EQ(simtest::le16(polled[0].payload, 14), 0x0003);  // out: UBX + NMEA
    // Set 57600, UBX in and out: the ACK already comes at 57600, 5 ms after the message;
    // the firmware switches as soon as its last byte is out.
    std::vector<uint8_t> set = polled[0].payload;
    set[8] = (uint8_t)57600;
    set[9] = (uint8_t)(57600 >> 8);
    set[10] = (uint8_t)(57600 >> 16);
    set[12] = 0x01;
    set[14] = 0x01;
    bench.send(1.5, simtest::ubx_frame(0x06, 0x00, set));
    const double switched_s = bench.tx_free_s;
    bench.run_to(switched_s + 0.0005);
    bench.set_firmware_baud(57600);
    bench.run_to(2.0);
    EXPECT_EQ(bench.gps.baud(), 57600u);
    const std::vector<LineMessage> acks = ubx_of(bench.messages_between(1.5, 2.0), 0x05, 0x01);
    ASSERT_EQ(acks.size(), 1u);
    EXPECT_EQ(acks[0].payload[1], 0x00);
    int after = 0;
    for (const sim::UartFrame& f : bench.frames) {
        if (f.start_s <= switched_s) continue;
        EXPECT_NEAR(f.bit_s, 1.0 / 57600, 1e-12);
        ++after;
    }
    EXPECT_GE(after, 10);
    // An impossible baud: NAK, nothing changed.
    set[8] = 0x39;
    set[9] = 0x30;
    set[10] = 0;  // 12345
    bench.send(2.0, simtest::ubx_frame(0x06, 0x00, set));
    bench.run_to(2.3);
    EXPECT_EQ(ubx_of(bench.messages_between(2.0, 2.3), 0x05, 0x00).size(), 1u);
    EXPECT_EQ(bench.gps.baud(), 57600u);
}

TEST(UbloxModel, Nav5PollAndSetAsArduPilotDoes) {
    GpsBench bench(at_rest(5), sim::UbloxOptions(), 9600);
    bench.run_to(1.0);
    bench.send(1.0, simtest::ubx_frame(0x06, 0x24, {}));
    bench.run_to(1.5);
    std::vector<LineMessage> polls = ubx_of(bench.messages(), 0x06, 0x24);
    ASSERT_EQ(polls.size(), 1u);
    ASSERT_EQ(polls[0].payload.size(), 36u);
    EXPECT_EQ(polls[0].payload[2], 0);  // portable
    std::vector<uint8_t> set = polls[0].payload;
    set[0] = 0x01;
    set[1] = 0x00;
    set[2] = 8;  // airborne < 4 g
    bench.send(1.5, simtest::ubx_frame(0x06, 0x24, set));
    bench.send(1.6, simtest::ubx_frame(0x06, 0x24, {}));
    bench.run_to(2.5);
    EXPECT_EQ(bench.gps.dyn_model(), 8);
    polls = ubx_of(bench.messages(), 0x06, 0x24);
    ASSERT_EQ(polls.size(), 2u);
    EXPECT_EQ(polls[1].payload[2], 8);
    EXPECT_EQ(polls[1].payload[3], 3);  // fixMode untouched (not in the mask)
    EXPECT_EQ(ubx_of(bench.messages(), 0x05, 0x01).size(), 3u);
}

TEST(UbloxModel, NavMessagesHaveTheSpecsLayoutAndShareTheEpochsItow) {
    GpsBench bench(at_rest(12), sim::UbloxOptions(), 9600);
    configure_for_ubx(bench, 1.2);
    bench.run_to(10.0);
    const std::vector<LineMessage> all = bench.messages_between(4.0, 10.0);
    const std::map<uint8_t, size_t> lengths = {{0x02, 28}, {0x03, 16}, {0x04, 18}, {0x06, 52}, {0x12, 36}};
    std::map<uint32_t, std::set<uint8_t>> by_itow;
    std::map<uint32_t, double> first_seen;
    for (const LineMessage& m : all) {
        ASSERT_TRUE(m.ubx);
        ASSERT_TRUE(m.checksum_ok);
        ASSERT_EQ(m.cls, 0x01);
        ASSERT_EQ(lengths.count(m.id), 1u) << (int)m.id;
        ASSERT_EQ(m.payload.size(), lengths.at(m.id)) << (int)m.id;
        const uint32_t itow = simtest::le32(m.payload, 0);
        EXPECT_EQ(itow % 200, 0u);
        by_itow[itow].insert(m.id);
        if (!first_seen.count(itow)) first_seen[itow] = m.first_s;
    }
    // Five messages an epoch, epochs 200 ms apart: 5 Hz.
    ASSERT_GE(by_itow.size(), 28u);
    uint32_t previous = 0;
    for (const auto& e : by_itow) {
        if (e.first == by_itow.begin()->first || e.first == by_itow.rbegin()->first) {
            previous = e.first;
            continue;  // the ends may be cut by the window
        }
        EXPECT_EQ(e.second.size(), 5u) << e.first;
        EXPECT_EQ(e.first - previous, 200u);
        previous = e.first;
    }
    // A 3D fix: NAV-STATUS gpsFix 3, flags gpsFixOk | WKNSET | TOWSET, NAV-SOL numSV 10,
    // week 1760; NAV-DOP hDOP 0.90.
    const LineMessage status = ubx_of(all, 0x01, 0x03).back();
    EXPECT_EQ(status.payload[4], 3);
    EXPECT_EQ(status.payload[5], 0x0D);
    // ttff: the time tag of the first fixed epoch, the first to leave at or after 3 s.
    EXPECT_GE(simtest::le32(status.payload, 8), 2800u);
    EXPECT_LT(simtest::le32(status.payload, 8), 3000u);
    const LineMessage sol = ubx_of(all, 0x01, 0x06).back();
    EXPECT_EQ(simtest::le16(sol.payload, 8), 1760);
    EXPECT_EQ(sol.payload[10], 3);
    EXPECT_EQ(sol.payload[11] & 0x01, 0x01);
    EXPECT_EQ(sol.payload[47], 10);
    EXPECT_EQ(simtest::le16(sol.payload, 44), 166);  // pDOP 1.66
    const LineMessage dop = ubx_of(all, 0x01, 0x04).back();
    EXPECT_EQ(simtest::le16(dop.payload, 12), 90);  // hDOP
    // NAV-SOL's ECEF position is NAV-POSLLH's point on the WGS-84 ellipsoid.
    const LineMessage pos = ubx_of(all, 0x01, 0x02).back();
    const double lat = simtest::le32s(pos.payload, 8) * 1e-7 * kDegToRad;
    const double lon = simtest::le32s(pos.payload, 4) * 1e-7 * kDegToRad;
    const double h = simtest::le32s(pos.payload, 12) * 1e-3;
    const double e2 = (1.0 / 298.257223563) * (2 - 1.0 / 298.257223563);
    const double n = 6378137.0 / std::sqrt(1 - e2 * std::sin(lat) * std::sin(lat));
    EXPECT_NEAR(simtest::le32s(sol.payload, 12) * 0.01, (n + h) * std::cos(lat) * std::cos(lon), 0.2);
    EXPECT_NEAR(simtest::le32s(sol.payload, 16) * 0.01, (n + h) * std::cos(lat) * std::sin(lon), 0.2);
    EXPECT_NEAR(simtest::le32s(sol.payload, 20) * 0.01, (n * (1 - e2) + h) * std::sin(lat), 0.2);
    // height above the ellipsoid = hMSL + the model's geoid separation
    EXPECT_EQ(simtest::le32s(pos.payload, 12) - simtest::le32s(pos.payload, 16), 10000);
}

TEST(UbloxModel, ReportsTheTruthOfItsLatencyEarlierWithinNoise) {
    // 12 m/s north, 5 m/s east, climbing 2 m/s.
    const double vel[3] = {12.0, 5.0, -2.0};
    sim::UbloxOptions options;
    options.first_fix_s = 1.0;
    GpsBench bench(simtest::moving_trajectory(40, vel), options, 9600);
    configure_for_ubx(bench, 1.2);
    bench.run_to(40.0);
    const std::vector<LineMessage> all = bench.messages_between(3.0, 40.0);
    const std::vector<LineMessage> pos = ubx_of(all, 0x01, 0x02), velned = ubx_of(all, 0x01, 0x12);
    ASSERT_GT(pos.size(), 150u);
    ASSERT_EQ(pos.size(), velned.size());
    double sum_n = 0, sum_e = 0, sum_d = 0, sum_n2 = 0, sum_e2 = 0, sum_v2 = 0;
    int n = 0;
    for (size_t i = 0; i < pos.size(); ++i) {
        // iTOW = the GPS time of the measurement; the frame leaves 0.2 s later.
        const uint32_t itow = simtest::le32(pos[i].payload, 0);
        const double meas_s = (double)(itow - sim::UbloxModel::itow_ms(sim::UbloxModel::kStartGps_ms)) / 1000.0;
        EXPECT_NEAR(pos[i].first_s - meas_s, 0.2, 0.05) << i;
        EXPECT_EQ(simtest::le32(velned[i].payload, 0), itow);
        double north, east;
        north_east(simtest::le32s(pos[i].payload, 8), simtest::le32s(pos[i].payload, 4), north, east);
        const double up = simtest::le32s(pos[i].payload, 16) * 1e-3 - sim::kHomeAlt_m;
        const double dn = north - vel[0] * meas_s, de = east - vel[1] * meas_s, du = up + vel[2] * meas_s;
        // Against the truth at arrival instead, the error would be ~2.4 m north.
        EXPECT_LT(std::fabs(dn), 3.5) << i;
        EXPECT_LT(std::fabs(de), 3.5) << i;
        EXPECT_LT(std::fabs(du), 7.0) << i;
        sum_n += dn, sum_e += de, sum_d += du, sum_n2 += dn * dn, sum_e2 += de * de;
        for (int k = 0; k < 3; ++k) {
            const double v = simtest::le32s(velned[i].payload, 4 + 4 * k) * 0.01 - vel[k];
            sum_v2 += v * v;
        }
        ++n;
        // gSpeed and heading from the velocity.
        EXPECT_NEAR(simtest::le32(velned[i].payload, 20) * 0.01, 13.0, 0.5);
        EXPECT_NEAR(simtest::le32s(velned[i].payload, 24) * 1e-5, std::atan2(5.0, 12.0) / kDegToRad, 2.0);
    }
    // The horizontal RMS near 1 m, the velocity's 0.1 m/s a component.
    const double rms_h = std::sqrt((sum_n2 + sum_e2) / n);
    EXPECT_GT(rms_h, 0.2);
    EXPECT_LT(rms_h, 2.5);
    EXPECT_NEAR(std::sqrt(sum_v2 / (3 * n)), 0.1, 0.03);
    // A slow walk: consecutive errors 0.2 s apart differ by centimetres, not metres.
    (void)sum_n, (void)sum_e, (void)sum_d;
}

TEST(UbloxModel, PositionErrorIsASlowRandomWalkWithTheConfiguredSpread) {
    sim::UbloxOptions options;
    options.first_fix_s = 0.0;
    GpsBench bench(at_rest(400), options, 9600);
    configure_for_ubx(bench, 1.0);
    bench.run_to(400.0, 0.002);
    const std::vector<LineMessage> pos = ubx_of(bench.messages_between(2.0, 400.0), 0x01, 0x02);
    ASSERT_GT(pos.size(), 1900u);
    double sum2 = 0, step2 = 0, prev_n = 0;
    for (size_t i = 0; i < pos.size(); ++i) {
        double north, east;
        north_east(simtest::le32s(pos[i].payload, 8), simtest::le32s(pos[i].payload, 4), north, east);
        sum2 += north * north;
        if (i > 0) step2 += (north - prev_n) * (north - prev_n);
        prev_n = north;
    }
    const double sigma = std::sqrt(sum2 / pos.size());
    EXPECT_GT(sigma, 0.35);  // 0.7 m configured; 400 s is ~13 correlation times
    EXPECT_LT(sigma, 1.2);
    // Gauss-Markov, tau 30 s, 0.2 s steps: a step's RMS is 0.7 sqrt(2 (1 - e^-0.2/30)) = 8 cm.
    EXPECT_NEAR(std::sqrt(step2 / (pos.size() - 1)), 0.081, 0.025);
}

TEST(UbloxModel, NoFixUntilTheConfiguredTime) {
    sim::UbloxOptions options;
    options.first_fix_s = 5.0;
    GpsBench bench(at_rest(8), options, 9600);
    configure_for_ubx(bench, 1.2);
    bench.run_to(8.0);
    for (const LineMessage& m : ubx_of(bench.messages(), 0x01, 0x03)) {
        const bool fixed = m.payload[4] == 3;
        EXPECT_EQ(fixed, m.first_s >= 5.0) << m.first_s;
        EXPECT_EQ(m.payload[5], fixed ? 0x0D : 0x00) << m.first_s;
    }
    for (const LineMessage& m : ubx_of(bench.messages(), 0x01, 0x02)) {
        if (m.first_s >= 5.0) continue;
        EXPECT_EQ(simtest::le32s(m.payload, 8), 0);
        EXPECT_EQ(simtest::le32(m.payload, 20), 0xFFFFFFFFu);
    }
}

TEST(UbloxModel, BaudMismatchDeliversGarbageNotMessages) {
    // The firmware listens at 38400 to a factory-new module at 9600.
    GpsBench bench(at_rest(6), sim::UbloxOptions(), 38400);
    bench.run_to(5.0);
    ASSERT_FALSE(bench.received.empty());
    int framing = 0;
    for (const sim::UartChar& c : bench.received) framing += c.framing_ok ? 0 : 1;
    EXPECT_GT(framing, (int)bench.received.size() / 4);
    for (const LineMessage& m : bench.messages()) EXPECT_FALSE(m.checksum_ok) << m.sentence;
    // And it sends PUBX,41 at 38400: the module does not understand it.
    bench.send(5.0, simtest::bytes_of(kPubx41));
    bench.run_to(6.0);
    EXPECT_EQ(bench.gps.baud(), 9600u);
    EXPECT_EQ(bench.gps.counters().pubx41, 0u);
    EXPECT_GT(bench.gps.counters().framing_errors_in + bench.gps.parser_counters().bytes_outside, 0u);
}

TEST(UbloxModel, ArduinoBaudErrorsStillDecode) {
    // 115200 from UBRR 16 with U2X is 117647 baud (+2.1 %): within a UART's tolerance.
    sim::UbloxOptions options;
    options.baud = 115200;
    GpsBench bench(at_rest(4), options, 1.0 / sim::usart_bit_s(16000000, 16, true));
    bench.run_to(3.5);
    ASSERT_FALSE(bench.messages().empty());
    for (const LineMessage& m : bench.messages()) EXPECT_TRUE(m.checksum_ok) << m.sentence;
    for (const sim::UartChar& c : bench.received) EXPECT_TRUE(c.framing_ok);
}

TEST(UbloxModel, NmeaOnlyModuleIgnoresUbxAndPubx) {
    sim::UbloxOptions options;
    options.kind = sim::GpsKind::kNmea;
    GpsBench bench(at_rest(6), options, 9600);
    configure_for_ubx(bench, 1.2);
    bench.set_firmware_baud(9600);
    bench.run_to(5.0);
    EXPECT_EQ(bench.gps.baud(), 9600u);
    EXPECT_GT(bench.gps.counters().ignored_nmea_only, 30u);
    for (const LineMessage& m : bench.messages()) {
        EXPECT_FALSE(m.ubx);
        EXPECT_TRUE(m.checksum_ok);
        EXPECT_NE(nmea_type(m), "GPTXT");
    }
}

TEST(UbloxModel, FaultsShowOnTheLine) {
    sim::UbloxOptions options;
    options.first_fix_s = 1.0;
    GpsBench bench(at_rest(20), options, 9600);
    sim::UbloxFaults& f = bench.gps.faults();
    f.no_fix.add(sim::TimeWindow::between(4.0, 5.0));
    f.glitch.add(sim::TimeWindow::between(6.0, 7.0), 50.0);
    f.satellites.add(sim::TimeWindow::between(8.0, 9.0), 4.0);
    f.silent.add(sim::TimeWindow::between(10.0, 11.0));
    f.deaf.add(sim::TimeWindow::between(12.0, 13.0));
    f.garbage.add(sim::TimeWindow::between(14.0, 15.0));
    configure_for_ubx(bench, 1.2);
    bench.send(12.2, cfg_msg(0x01, 0x30, 1));  // unheard: no ACK
    bench.run_to(16.0);
    for (const LineMessage& m : ubx_of(bench.messages_between(2.0, 14.0), 0x01, 0x06)) {
        const uint8_t fix = m.payload[10], sats = m.payload[47];
        const uint16_t pdop = simtest::le16(m.payload, 44);
        if (m.first_s >= 4.0 && m.first_s < 5.0) {
            EXPECT_EQ(fix, 0) << m.first_s;
            EXPECT_EQ(m.payload[11] & 0x01, 0);
        } else if (m.first_s >= 8.0 && m.first_s < 9.0) {
            EXPECT_EQ(sats, 4);
            EXPECT_EQ(fix, 3);
            EXPECT_GT(pdop, 400);  // (10/4)^1.5 x 1.66
        } else {
            EXPECT_EQ(fix, 3) << m.first_s;
            EXPECT_EQ(sats, 10);
        }
    }
    for (const LineMessage& m : ubx_of(bench.messages_between(2.0, 9.0), 0x01, 0x02)) {
        double north, east;
        north_east(simtest::le32s(m.payload, 8), simtest::le32s(m.payload, 4), north, east);
        if (m.first_s >= 6.0 && m.first_s < 7.0) {
            EXPECT_NEAR(north, 50.0, 4.0) << m.first_s;
        } else if (m.first_s < 8.0) {
            EXPECT_NEAR(north, 0.0, 4.0) << m.first_s;
        }
    }
    // Silent: nothing on the line from 10 to 11 s.
    for (const sim::UartFrame& fr : bench.frames) EXPECT_FALSE(fr.start_s >= 10.0 && fr.start_s < 11.0) << fr.start_s;
    EXPECT_GT(bench.gps.counters().bytes_silenced, 100u);
    // Deaf: the CFG-MSG at 12.2 s unanswered.
    EXPECT_TRUE(ubx_of(bench.messages_between(12.0, 14.0), 0x05, 0x01).empty());
    EXPECT_GT(bench.gps.counters().ignored_deaf, 0u);
    EXPECT_EQ(bench.gps.message_rate(0x01, 0x30), 0);
    // Garbage: extra bytes, some messages broken, the module's still there after.
    EXPECT_GT(bench.gps.counters().garbage_bytes, 50u);
    int broken = 0;
    for (const LineMessage& m : bench.messages_between(14.0, 15.0)) broken += m.checksum_ok ? 0 : 1;
    EXPECT_GT(bench.messages_between(15.2, 16.0).size(), 5u);
    for (const LineMessage& m : bench.messages_between(15.2, 16.0)) EXPECT_TRUE(m.checksum_ok);
    (void)broken;
}

TEST(UbloxModel, SameSeedSameBytes) {
    const double vel[3] = {3.0, -1.0, 0.0};
    auto run = [&](uint64_t seed) {
        sim::UbloxOptions options;
        options.seed = seed;
        GpsBench bench(simtest::moving_trajectory(8, vel), options, 9600);
        configure_for_ubx(bench, 1.2);
        bench.run_to(8.0);
        std::vector<uint8_t> bytes;
        for (const sim::UartChar& c : bench.received) bytes.push_back(c.byte);
        return bytes;
    };
    EXPECT_EQ(run(7), run(7));
    EXPECT_NE(run(7), run(8));
}

TEST(UbloxModel, TxBufferOverflowDropsWholeMessages) {
    // At 9600 every NMEA and UBX message at 5 Hz is ~3.5 kB/s: the port cannot keep up.
    GpsBench bench(at_rest(30), sim::UbloxOptions(), 9600);
    bench.run_to(1.0);
    std::vector<uint8_t> config;
    for (uint8_t id : {0x02, 0x03, 0x04, 0x06, 0x12}) {
        const std::vector<uint8_t> m = cfg_msg(0x01, id, 1);
        config.insert(config.end(), m.begin(), m.end());
    }
    const std::vector<uint8_t> rate = cfg_rate(200);
    config.insert(config.end(), rate.begin(), rate.end());
    bench.send(1.0, config);
    bench.run_to(30.0, 0.002);
    EXPECT_GT(bench.gps.counters().tx_dropped_messages, 0u);
    for (const LineMessage& m : bench.messages()) EXPECT_TRUE(m.checksum_ok);
}

}  // namespace
