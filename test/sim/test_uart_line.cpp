// SPDX-License-Identifier: GPL-3.0-or-later
// The serial line between two UARTs at their own baud rates (sim/models/UartLine.h).
#include <gtest/gtest.h>

#include <vector>

#include "UartLine.h"

namespace {

std::vector<sim::UartChar> send_and_decode(const std::vector<uint8_t>& bytes, double tx_baud, double rx_baud,
                                           double gap_bits = 0.0) {
    sim::UartReceiver rx(1.0 / rx_baud);
    double t = 0.001;
    for (uint8_t b : bytes) {
        sim::UartFrame f;
        f.start_s = t;
        f.bit_s = 1.0 / tx_baud;
        f.byte = b;
        rx.push(f);
        t = f.end_s() + gap_bits / tx_baud;
    }
    std::vector<sim::UartChar> out;
    rx.decode(t + 1.0, out);
    return out;
}

TEST(UartLine, EqualBaudsDeliverEveryByteAtItsFramesStart) {
    std::vector<uint8_t> bytes;
    for (int i = 0; i < 256; ++i) bytes.push_back((uint8_t)i);
    const std::vector<sim::UartChar> out = send_and_decode(bytes, 38400, 38400);
    ASSERT_EQ(out.size(), bytes.size());
    for (size_t i = 0; i < out.size(); ++i) {
        EXPECT_EQ(out[i].byte, bytes[i]);
        EXPECT_TRUE(out[i].framing_ok);
        EXPECT_NEAR(out[i].edge_s, 0.001 + i * 10.0 / 38400, 1e-9);
        EXPECT_EQ(out[i].ready_s, out[i].edge_s);  // known once the frame starts
    }
}

TEST(UartLine, WithinTheToleranceEveryByteStillDecodes) {
    std::vector<uint8_t> bytes;
    for (int i = 0; i < 256; ++i) bytes.push_back((uint8_t)(i * 37 + 11));
    // Arduino's 115200 (117647, +2.1 %) and 57600 (58824, +2.1 %), and a 4 % slow sender.
    for (double rx : {117647.0, 112000.0, 110600.0}) {
        const std::vector<sim::UartChar> out = send_and_decode(bytes, 115200, rx);
        ASSERT_EQ(out.size(), bytes.size()) << rx;
        for (size_t i = 0; i < out.size(); ++i) {
            EXPECT_EQ(out[i].byte, bytes[i]) << rx;
            EXPECT_TRUE(out[i].framing_ok) << rx;
        }
    }
}

TEST(UartLine, BitLevelDecodingMatchesTheFastPath) {
    // At 3 % off the fast path does not apply: each bit is sampled, with the same result.
    std::vector<uint8_t> bytes;
    for (int i = 0; i < 256; ++i) bytes.push_back((uint8_t)i);
    const std::vector<sim::UartChar> out = send_and_decode(bytes, 9600, 9600 * 1.06, 1.0);
    ASSERT_EQ(out.size(), bytes.size());
    for (size_t i = 0; i < out.size(); ++i) {
        EXPECT_EQ(out[i].byte, bytes[i]);
        EXPECT_GT(out[i].ready_s, out[i].edge_s);  // needs the samples
    }
}

TEST(UartLine, AFourTimesFasterReceiverSeesGarbage) {
    const std::vector<uint8_t> text = {'$', 'G', 'P', 'G', 'G', 'A', ',', '1', '2', '3'};
    const std::vector<sim::UartChar> out = send_and_decode(text, 9600, 38400);
    ASSERT_GT(out.size(), text.size());  // several characters a frame
    int framing = 0;
    for (const sim::UartChar& c : out) framing += c.framing_ok ? 0 : 1;
    EXPECT_GT(framing, 0);
    bool all_text = true;
    for (size_t i = 0; i < text.size() && i < out.size(); ++i) all_text = all_text && out[i].byte == text[i];
    EXPECT_FALSE(all_text);
}

TEST(UartLine, AFourTimesSlowerReceiverSeesFewCharacters) {
    const std::vector<uint8_t> text(40, 0x55);
    const std::vector<sim::UartChar> out = send_and_decode(text, 38400, 9600);
    EXPECT_LT(out.size(), text.size() / 2);
}

TEST(UartLine, AFramesStartIsFoundAfterALowStopBitAndIdleLine) {
    // A receiver at 4x the sender's bit time reads the 0x00 frame as a long low: framing
    // error; then the idle line and a good frame at the right baud decode again.
    sim::UartReceiver rx(1.0 / 9600);
    sim::UartFrame f;
    f.start_s = 0.0;
    f.bit_s = 1.0 / 2400;
    f.byte = 0x00;
    rx.push(f);
    sim::UartFrame g;
    g.start_s = 0.02;
    g.bit_s = 1.0 / 9600;
    g.byte = 'A';
    rx.push(g);
    std::vector<sim::UartChar> out;
    rx.decode(1.0, out);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_FALSE(out[0].framing_ok);
    EXPECT_EQ(out[0].byte, 0x00);
    EXPECT_EQ(out[1].byte, 'A');
    EXPECT_TRUE(out[1].framing_ok);
}

TEST(UartLine, UsartBitTimeFromUbrr) {
    EXPECT_NEAR(1.0 / sim::usart_bit_s(16000000, 103, false), 9615.4, 0.1);   // Arduino 9600
    EXPECT_NEAR(1.0 / sim::usart_bit_s(16000000, 51, true), 38461.5, 0.1);    // Arduino 38400 (U2X)
    EXPECT_NEAR(1.0 / sim::usart_bit_s(16000000, 0, false), 1000000.0, 0.1);  // UBRR at reset
}

}  // namespace
