// SPDX-License-Identifier: GPL-3.0-or-later
// The simulator's radio side without simavr (sim/models/RcLink): the --rc script, the PPM
// encoder's edges and the servo pulses measured from pin levels.
#include <gtest/gtest.h>

#include <cmath>

#include "RcLink.h"

namespace {

const char* const kHeader = "t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n";

sim::RcScript parsed(const std::string& body) {
    sim::RcScript script;
    EXPECT_TRUE(script.parse(kHeader + body, "test.csv")) << script.error();
    return script;
}

TEST(RcScript, RowsHoldUntilTheNextAndEmptyChannelsAreADeadReceiver) {
    const sim::RcScript script = parsed(
        "0.5,1100,1200,1300,1400,1500,1600,1700,1800\r\n"
        "\n"
        "12.0,,,,,,,,\n"
        "13, 1500 ,1500,1000,1500,1500,1500,1500,1900.5\n");
    ASSERT_EQ(script.rows().size(), 3u);
    EXPECT_EQ(script.at(0.49), nullptr);  // no signal before the first row
    ASSERT_NE(script.at(0.5), nullptr);
    EXPECT_TRUE(script.at(0.5)->signal);
    EXPECT_EQ(script.at(11.99)->width_us[7], 1800.0);
    EXPECT_FALSE(script.at(12.0)->signal);
    EXPECT_FALSE(script.at(12.99)->signal);
    EXPECT_EQ(script.at(100.0)->width_us[7], 1900.5);
    EXPECT_EQ(script.at(100.0)->width_us[0], 1500.0);
}

TEST(RcScript, BadFilesNameTheLineAndKeepNothing) {
    struct Case {
        const char* text;
        const char* says;
    };
    const Case cases[] = {
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7\n", "header"},
        {"", "header"},
        {"time,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n", "header"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,1500,,,,,,,\n", ":2: "},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,1500,1500,1500,1500,1500,1500,1500\n", "9 fields"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,1500,1500,1500,1500,1500,1500,1500,x\n", "ch8"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,1500,1500,1500,1500,1500,1500,1500,nan\n", "ch8"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,400,1500,1500,1500,1500,1500,1500,1500\n", "ch1"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,1500,1500,1500,1500,1500,1500,3001,1500\n", "ch7"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n2,,,,,,,,\n1,,,,,,,,\n", ":3: times must increase"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n1,,,,,,,,\n1,,,,,,,,\n", "increase"},
        {"t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8\n-1,,,,,,,,\n", ">= 0"},
    };
    for (const Case& c : cases) {
        sim::RcScript script;
        EXPECT_FALSE(script.parse(c.text, "bad.csv")) << c.text;
        EXPECT_NE(script.error().find("bad.csv"), std::string::npos) << script.error();
        EXPECT_NE(script.error().find(c.says), std::string::npos) << c.text << " -> " << script.error();
        EXPECT_TRUE(script.rows().empty());
    }
}

// Collects the encoder's edges up to t_end_s.
std::vector<sim::PpmEdge> edges_until(sim::PpmEncoder& encoder, double t_end_s) {
    std::vector<sim::PpmEdge> edges;
    sim::PpmEdge e;
    while (encoder.next_edge(e)) {
        edges.push_back(e);
        if (e.t_s >= t_end_s) break;
    }
    return edges;
}

TEST(PpmEncoder, AFrameIsNinePrePulsesWithRisingEdgesOneWidthApart) {
    const sim::RcScript script = parsed("1.0,1100,1200,1300,1400,1500,1600,1700,1800\n");
    sim::PpmEncoder encoder(script);
    const std::vector<sim::PpmEdge> edges = edges_until(encoder, 1.05);
    ASSERT_GE(edges.size(), 36u);
    // Frame 1: falling at 1.0, rising 400 us later; the channels between rising edges.
    EXPECT_DOUBLE_EQ(edges[0].t_s, 1.0);
    EXPECT_FALSE(edges[0].high);
    EXPECT_NEAR(edges[1].t_s, 1.0004, 1e-12);
    EXPECT_TRUE(edges[1].high);
    for (int c = 0; c < 8; ++c) {
        const double interval_us = (edges[2 * c + 3].t_s - edges[2 * c + 1].t_s) * 1e6;
        EXPECT_NEAR(interval_us, 1100.0 + 100.0 * c, 1e-6) << c;
        EXPECT_NEAR((edges[2 * c + 3].t_s - edges[2 * c + 2].t_s) * 1e6, 400.0, 1e-6);  // the pre-pulse
    }
    // Levels alternate; the next frame 22.5 ms after the first, the sync over 4 ms.
    for (size_t i = 1; i < edges.size(); ++i) EXPECT_NE(edges[i].high, edges[i - 1].high) << i;
    EXPECT_NEAR(edges[18].t_s, 1.0225, 1e-12);
    EXPECT_GT((edges[19].t_s - edges[17].t_s) * 1e6, 4000.0);
    EXPECT_EQ(encoder.frames(), 3u);
}

TEST(PpmEncoder, WidthsChangeAtAFrameStartAndADeadRowStopsAfterTheFrame) {
    const sim::RcScript script = parsed(
        "0,1500,1500,1500,1500,1500,1500,1500,1500\n"
        "0.03,1000,1500,1500,1500,1500,1500,1500,1500\n"
        "0.05,,,,,,,,\n"
        "0.2,2000,1500,1500,1500,1500,1500,1500,1500\n");
    sim::PpmEncoder encoder(script);
    std::vector<sim::PpmEdge> edges;
    sim::PpmEdge e;
    while (edges.size() < 200 && encoder.next_edge(e)) edges.push_back(e);
    // Frames start at 0, 0.0225 (row 1: 0.03 is mid-frame), 0.045 (row 2, sent whole
    // although the receiver dies at 0.05), then nothing until 0.2.
    ASSERT_EQ(edges.size(), 200u);
    EXPECT_NEAR((edges[18 + 3].t_s - edges[18 + 1].t_s) * 1e6, 1500.0, 1e-6);
    EXPECT_NEAR(edges[36].t_s, 0.045, 1e-12);
    EXPECT_NEAR((edges[36 + 3].t_s - edges[36 + 1].t_s) * 1e6, 1000.0, 1e-6);
    EXPECT_NEAR(edges[53].t_s, 0.045 + (1000.0 + 7 * 1500.0 + 400.0) * 1e-6, 1e-12);  // the frame ends whole
    EXPECT_DOUBLE_EQ(edges[54].t_s, 0.2);
    EXPECT_NEAR((edges[54 + 3].t_s - edges[54 + 1].t_s) * 1e6, 2000.0, 1e-6);
}

TEST(PpmEncoder, NoSignalBeforeTheFirstRowAndPushedRowsRestartIt) {
    sim::RcScript script = parsed("");
    sim::PpmEncoder encoder(script);
    sim::PpmEdge e;
    EXPECT_FALSE(encoder.next_edge(e));
    sim::RcRow row;
    row.t_s = 0.1;
    row.signal = true;
    for (double& w : row.width_us) w = 2200.0;
    ASSERT_TRUE(script.push(row));
    ASSERT_TRUE(encoder.next_edge(e));
    EXPECT_DOUBLE_EQ(e.t_s, 0.1);
    row.t_s = 0.05;
    EXPECT_FALSE(script.push(row));  // back in time
    row.t_s = 0.2;
    row.width_us[3] = 100.0;
    EXPECT_FALSE(script.push(row));  // no 100 us channel
}

// A long flight drops old rows; the encoder keeps going from the rows left.
TEST(PpmEncoder, RowsDroppedBeforeTheFrameDoNotChangeTheSignal) {
    sim::RcScript script = parsed(
        "0,1500,1500,1500,1500,1500,1500,1500,1500\n"
        "0.01,,,,,,,,\n"
        "0.02,,,,,,,,\n"
        "0.05,1200,1500,1500,1500,1500,1500,1500,1500\n");
    sim::PpmEncoder encoder(script);
    std::vector<sim::PpmEdge> edges = edges_until(encoder, 0.0);  // the first frame's first edge
    script.drop_before(0.03);
    ASSERT_EQ(script.rows().size(), 2u);  // 0.02 (in force at 0.03) and 0.05
    EXPECT_FALSE(script.at(0.03)->signal);
    sim::PpmEdge e;
    for (int i = 1; i < 18; ++i) ASSERT_TRUE(encoder.next_edge(e));  // the frame in progress ends whole
    ASSERT_TRUE(encoder.next_edge(e));
    EXPECT_DOUBLE_EQ(e.t_s, 0.05);  // dead until the row at 0.05
}

TEST(PpmEncoder, LongWidthsStretchTheFrameToKeepItsSync) {
    const sim::RcScript script = parsed("0,3000,3000,3000,3000,3000,3000,3000,3000\n");
    sim::PpmEncoder encoder(script);
    const std::vector<sim::PpmEdge> edges = edges_until(encoder, 0.03);
    ASSERT_GE(edges.size(), 20u);
    EXPECT_NEAR(edges[18].t_s, (24000.0 + 4500.0) * 1e-6, 1e-12);
    EXPECT_NEAR((edges[19].t_s - edges[17].t_s) * 1e6, 4500.0, 1e-6);
}

TEST(ServoPulseLog, PulsesComeOutInRisingEdgeOrderOnceFinal) {
    sim::ServoPulseLog log;
    std::vector<sim::ServoPulse> out;
    log.level(2, 0.000, true);
    log.level(1, 0.001, true);
    log.level(1, 0.002, false);  // OUT1 ends first but OUT2 rose before it and is still high
    log.take(out);
    EXPECT_TRUE(out.empty());
    log.level(2, 0.0025, true);  // a repeat: ignored
    log.level(2, 0.003, false);
    log.take(out);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0].output, 2);
    EXPECT_NEAR(out[0].width_us, 3000.0, 1e-6);
    EXPECT_EQ(out[1].output, 1);
    EXPECT_NEAR(out[1].width_us, 1000.0, 1e-6);
    EXPECT_NEAR(log.last_width_us(2), 3000.0, 1e-6);
    EXPECT_EQ(log.last_width_us(3), 0.0);
    EXPECT_EQ(sim::ServoPulseLog::format(out[1]), "0.001000,1,1000.00\n");
    // A pulse still high at the end is dropped; out-of-range outputs are ignored.
    log.level(3, 0.02, true);
    log.level(9, 0.02, true);
    out.clear();
    log.take(out, true);
    EXPECT_TRUE(out.empty());
}

}  // namespace
