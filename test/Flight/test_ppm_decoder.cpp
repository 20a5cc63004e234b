// SPDX-License-Identifier: GPL-3.0-or-later
// The PPM decoder (lib/Flight/Ppm): captures of rising edges in, frames out; the timer's
// wrap, short and implausible frames, a glitch, captures lost.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "Ppm.h"

using flight::PpmDecoder;

namespace {

// Timer5 counts 0.5 us ticks from 0 to its TOP, 39999 (a 20 ms period), and wraps: the
// captures the interrupt stores wrap there (the board's fact, not the decoder's constant).
constexpr uint32_t kTimerTicks = 40000;

// Rising-edge captures of one PPM frame (Timer5 ticks, wrapping at 40000) from `t` on,
// then the sync gap to a 22.5 ms frame; returns the next frame's start.
uint32_t ppm_frame(const std::vector<uint16_t>& widths_us, uint32_t t_ticks, std::vector<uint16_t>& captures) {
    uint32_t t = t_ticks;
    captures.push_back((uint16_t)(t % kTimerTicks));
    for (uint16_t w : widths_us) {
        t += 2u * w;
        captures.push_back((uint16_t)(t % kTimerTicks));
    }
    return t_ticks + 45000u;  // 22.5 ms
}

// Feeds frames; returns how many were accepted, the last accepted in `last`.
int feed_all(PpmDecoder& d, const std::vector<uint16_t>& captures, std::vector<uint16_t>* last = nullptr) {
    int accepted = 0;
    for (uint16_t c : captures)
        if (d.feed(c)) {
            ++accepted;
            if (last) last->assign(d.frame_us(), d.frame_us() + flight::kChannels);
        }
    return accepted;
}

const std::vector<uint16_t> kFrame = {1100, 1200, 1300, 1400, 1500, 1600, 1700, 1900};

}  // namespace

TEST(PpmDecoder, GoodFramesAcceptedFromTheSecondWholeOne) {
    PpmDecoder d;
    std::vector<uint16_t> caps, last;
    uint32_t t = 12345;
    for (int i = 0; i < 5; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));  // the edge after the last sync gap
    // A frame closes at the next frame's first edge. Frame 1 opens at the first edge (a
    // receiver switched on) but follows no whole frame; 2, 3, 4, 5 are accepted.
    EXPECT_EQ(feed_all(d, caps, &last), 4);
    EXPECT_EQ(last, kFrame);
}

TEST(PpmDecoder, SwitchedOnMidFrameTheThirdFrameIsTheFirstAccepted) {
    // The board starts while the receiver runs: its first edge is one inside a frame (the
    // 2nd to the 9th). That frame's few widths and the next whole frame (after no whole
    // one) are rejected; frames 3 and 4 accepted.
    for (int skipped = 1; skipped < 9; ++skipped) {
        PpmDecoder d;
        std::vector<uint16_t> caps, last;
        uint32_t t = 777;
        for (int i = 0; i < 4; ++i) t = ppm_frame(kFrame, t, caps);
        caps.push_back((uint16_t)(t % kTimerTicks));
        caps.erase(caps.begin(), caps.begin() + skipped);
        EXPECT_EQ(feed_all(d, caps, &last), 2) << skipped;
        EXPECT_EQ(last, kFrame);
    }
}

TEST(PpmDecoder, WidthsExactThroughTheTimerWrap) {
    PpmDecoder d;
    std::vector<uint16_t> caps, last;
    uint32_t t = 39000;  // the timer wraps inside the first frames
    const std::vector<uint16_t> odd = {800, 2200, 1501, 999, 1000, 2000, 1234, 1777};
    for (int i = 0; i < 6; ++i) t = ppm_frame(odd, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    EXPECT_EQ(feed_all(d, caps, &last), 5);
    EXPECT_EQ(last, odd);
}

TEST(PpmDecoder, ShortFrameAndImplausibleWidthsRejected) {
    std::vector<uint16_t> caps;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    // A 7-channel frame, then a good one (rejected too: it follows an unstable count),
    // then good ones again.
    t = ppm_frame(std::vector<uint16_t>(kFrame.begin(), kFrame.end() - 1), t, caps);
    t = ppm_frame(kFrame, t, caps);
    t = ppm_frame(kFrame, t, caps);
    // A width of 700 us and one of 2300 us: each frame rejected.
    std::vector<uint16_t> low = kFrame, high = kFrame;
    low[2] = 700;
    high[5] = 2300;
    t = ppm_frame(low, t, caps);
    t = ppm_frame(high, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    // Accepted: frames 2 and 3 (each after a whole one), not 4 (7 widths), not 5 (after
    // 7), 6, not 7 (700 us), not 8 (2300 us).
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps), 3);
}

TEST(PpmDecoder, GlitchSplittingAPulseCostsTheFrameNotAWrongWidth) {
    std::vector<uint16_t> caps, last;
    uint32_t t = 500;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    // A spurious edge 300 us into channel 4: two short widths, nine in all.
    const size_t start = caps.size();
    t = ppm_frame(kFrame, t, caps);
    const uint16_t glitch = (uint16_t)((caps[start + 3] + 600u) % kTimerTicks);
    caps.insert(caps.begin() + (long)start + 4, glitch);
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    PpmDecoder d;
    int n = 0;
    for (uint16_t c : caps)
        if (d.feed(c)) {
            ++n;
            EXPECT_EQ(std::vector<uint16_t>(d.frame_us(), d.frame_us() + 8), kFrame);
        }
    // Accepted: frames 2 and 3, not the glitched 4, not 5 (after a 9-count), 6, 7.
    EXPECT_EQ(n, 4);
}

TEST(PpmDecoder, ResetDropsTheFrameInProgress) {
    std::vector<uint16_t> caps;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    t = ppm_frame(kFrame, t, caps);
    PpmDecoder d;
    // Three frames and the fourth's first 5 edges: frames 2 and 3 accepted (3 at the 4th's
    // first edge).
    EXPECT_EQ(feed_all(d, std::vector<uint16_t>(caps.begin(), caps.begin() + 27 + 5)), 2);
    d.reset();  // captures lost mid-frame: the next edge is the fourth frame's eighth
    std::vector<uint16_t> more(caps.begin() + 27 + 7, caps.end());
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, more);
    more.push_back((uint16_t)(t % kTimerTicks));
    // The fourth's rest (one width) and the fifth (after it) rejected; 6 and 7 accepted.
    EXPECT_EQ(feed_all(d, more), 2);
}

namespace {

// Captures from widths in timer ticks (0.5 us), each frame's sync gap given in ticks too.
uint32_t ppm_ticks(const std::vector<uint32_t>& widths_ticks, uint32_t gap_ticks, uint32_t t_ticks,
                   std::vector<uint16_t>& captures) {
    uint32_t t = t_ticks;
    captures.push_back((uint16_t)(t % kTimerTicks));
    for (uint32_t w : widths_ticks) {
        t += w;
        captures.push_back((uint16_t)(t % kTimerTicks));
    }
    return t + gap_ticks;
}

}  // namespace

TEST(PpmDecoder, WidthsRoundedToTheNearestMicrosecondAcrossTheWrap) {
    // Odd tick counts are half microseconds: rounded up. The frames start just before the
    // timer wraps, so that widths straddle it.
    const std::vector<uint32_t> ticks = {2999, 3000, 3001, 3002, 1601, 4399, 4400, 2001};
    const std::vector<uint16_t> us = {1500, 1500, 1501, 1501, 801, 2200, 2200, 1001};
    for (uint32_t start : {39990u, 39000u, 35000u, 100u}) {
        std::vector<uint16_t> caps, last;
        uint32_t t = start;
        for (int i = 0; i < 6; ++i) t = ppm_ticks(ticks, 9001 + (uint32_t)i * 997, t, caps);
        caps.push_back((uint16_t)(t % kTimerTicks));
        PpmDecoder d;
        EXPECT_EQ(feed_all(d, caps, &last), 5) << start;
        EXPECT_EQ(last, us) << start;
    }
}

TEST(PpmDecoder, ASyncGapIsOver3000us) {
    const std::vector<uint32_t> widths(8, 2000);  // 1000 us each
    // A gap of 3000.5 us (6001 ticks) rounds to 3001 and closes the frame ...
    for (uint32_t gap : {6001u, 6002u, 30000u}) {
        std::vector<uint16_t> caps;
        uint32_t t = 7;
        for (int i = 0; i < 5; ++i) t = ppm_ticks(widths, gap, t, caps);
        caps.push_back((uint16_t)(t % kTimerTicks));
        PpmDecoder d;
        EXPECT_EQ(feed_all(d, caps), 4) << gap;
    }
    // ... 3000 us does not: it is a width, and too long for one.
    for (uint32_t gap : {5999u, 6000u}) {
        std::vector<uint16_t> caps;
        uint32_t t = 7;
        for (int i = 0; i < 5; ++i) t = ppm_ticks(widths, i == 0 ? 30000u : gap, t, caps);
        caps.push_back((uint16_t)(t % kTimerTicks));
        PpmDecoder d;
        EXPECT_EQ(feed_all(d, caps), 0) << gap;
    }
}

TEST(PpmDecoder, WidthsJustOutsideThePlausibleOnesCostTheirFrameOnly) {
    for (uint16_t bad : {799, 2201, 0, 3000}) {
        std::vector<uint16_t> caps, last;
        uint32_t t = 0;
        for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
        std::vector<uint16_t> odd = kFrame;
        odd[6] = bad;
        t = ppm_frame(odd, t, caps);
        for (int i = 0; i < 2; ++i) t = ppm_frame(kFrame, t, caps);
        caps.push_back((uint16_t)(t % kTimerTicks));
        // Accepted: frames 2 and 3, not 4, then 5 (a whole count before it) and 6.
        PpmDecoder d;
        EXPECT_EQ(feed_all(d, caps, &last), 4) << bad;
        EXPECT_EQ(last, kFrame);
    }
    // The ends themselves are plausible.
    std::vector<uint16_t> caps, last;
    const std::vector<uint16_t> ends = {800, 2200, 800, 2200, 800, 2200, 800, 2200};
    uint32_t t = 0;
    for (int i = 0; i < 4; ++i) t = ppm_frame(ends, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps, &last), 3);
    EXPECT_EQ(last, ends);
}

TEST(PpmDecoder, ALongRunWithoutASyncGapThenFramesAgain) {
    // Three frames (the second and third accepted), then edges 1 ms apart (a stuck encoder: the count
    // saturates), then frames: the second whole one after the run is accepted.
    std::vector<uint16_t> caps, last;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    for (int i = 0; i < 300; ++i, t += 2000u) caps.push_back((uint16_t)(t % kTimerTicks));
    t += 8000u;  // a sync gap
    for (int i = 0; i < 4; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps, &last), 2 + 3);
    EXPECT_EQ(last, kFrame);
}

TEST(PpmDecoder, ResetRightAfterASyncGapStartsAsFromPowerUp) {
    std::vector<uint16_t> caps;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));  // closes frame 3: the count is 0 again
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps), 2);
    d.reset();
    // The next edge starts afresh: the first frame follows no whole frame, the second and
    // third are accepted.
    std::vector<uint16_t> more;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, more);
    more.push_back((uint16_t)(t % kTimerTicks));
    EXPECT_EQ(feed_all(d, more), 2);
}

TEST(PpmDecoder, ASyncGapAcrossTheWrapFromMidPeriod) {
    // 20 ms frames whose last edge is at 10 ms of the timer's period (20000 ticks) and whose
    // sync gap of 11.5 ms ends at 1.5 ms of the next period: widths of 1062.5 us.
    const std::vector<uint32_t> widths(8, 2125);
    std::vector<uint16_t> caps, last;
    uint32_t t = 3000;
    for (int i = 0; i < 5; ++i) t = ppm_ticks(widths, 23000, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps, &last), 4);
    EXPECT_EQ(last, std::vector<uint16_t>(8, 1063));
}

TEST(PpmDecoder, ASplitPulseCostsItsFrameAndTheNextWhateverTheTiming) {
    // A frame of nine widths (channel 4 split in two), its last one 1000 us, the next frame
    // starting 2000 ticks into the timer's period: then two whole frames after the next are
    // accepted.
    std::vector<uint16_t> caps, last;
    uint32_t t = 0;
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    const std::vector<uint32_t> split = {2200, 2400, 2600, 600, 2200, 3000, 3200, 3400, 2000};
    uint32_t sum = 0;
    for (uint32_t w : split) sum += w;
    uint32_t gap = (kTimerTicks + 3000u - (t + sum) % kTimerTicks) % kTimerTicks;
    if (gap < 8000u) gap += kTimerTicks;
    t = ppm_ticks(split, gap, t, caps);
    ASSERT_EQ(t % kTimerTicks, 3000u);
    for (int i = 0; i < 3; ++i) t = ppm_frame(kFrame, t, caps);
    caps.push_back((uint16_t)(t % kTimerTicks));
    // Accepted: frames 2 and 3, not the split one, not the one after it, then both others.
    PpmDecoder d;
    EXPECT_EQ(feed_all(d, caps, &last), 2 + 2);
    EXPECT_EQ(last, kFrame);
}
