// SPDX-License-Identifier: GPL-3.0-or-later
#include "RcLink.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace sim {

namespace {

std::string trim(const std::string& s) {
    size_t a = 0, b = s.size();
    while (a < b && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
    while (b > a && (s[b - 1] == ' ' || s[b - 1] == '\t' || s[b - 1] == '\r')) --b;
    return s.substr(a, b - a);
}

std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> fields;
    size_t start = 0;
    for (;;) {
        const size_t comma = line.find(',', start);
        fields.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
        if (comma == std::string::npos) return fields;
        start = comma + 1;
    }
}

bool parse_number(const std::string& text, double& value) {
    if (text.empty()) return false;
    char* end = nullptr;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size() && std::isfinite(value);
}

bool width_ok(double w) { return w >= RcScript::kMinWidth_us && w <= RcScript::kMaxWidth_us; }

}  // namespace

// The out-of-class definitions C++14 needs for constants passed by reference (std::max).
constexpr double RcScript::kMinWidth_us;
constexpr double RcScript::kMaxWidth_us;
constexpr double PpmEncoder::kFrame_us;
constexpr double PpmEncoder::kPrePulse_us;
constexpr double PpmEncoder::kMinSync_us;

bool RcScript::load(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error_ = "cannot read the rc file '" + path + "'";
        return false;
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse(ss.str(), path);
}

bool RcScript::parse(const std::string& text, const std::string& name) {
    rows_.clear();
    std::istringstream in(text);
    std::string line;
    int line_no = 0;
    bool header_seen = false;
    auto fail = [&](const std::string& why) {
        char where[32];
        std::snprintf(where, sizeof where, ":%d: ", line_no);
        error_ = "rc file " + name + where + why;
        rows_.clear();
        return false;
    };
    while (std::getline(in, line)) {
        ++line_no;
        if (trim(line).empty()) continue;
        const std::vector<std::string> fields = split(line);
        if (!header_seen) {
            static const char* const kHeader[] = {"t", "ch1", "ch2", "ch3", "ch4", "ch5", "ch6", "ch7", "ch8"};
            bool ok = fields.size() == 1 + kRcChannels;
            for (size_t i = 0; ok && i < fields.size(); ++i) ok = fields[i] == kHeader[i];
            if (!ok) return fail("the header must be t,ch1,ch2,ch3,ch4,ch5,ch6,ch7,ch8");
            header_seen = true;
            continue;
        }
        if (fields.size() != 1 + kRcChannels) return fail("a row has a time and 8 channels (9 fields)");
        RcRow row;
        if (!parse_number(fields[0], row.t_s) || row.t_s < 0.0) return fail("the time must be a number >= 0 s");
        if (!rows_.empty() && row.t_s <= rows_.back().t_s) return fail("times must increase from row to row");
        int empty = 0;
        for (int c = 0; c < kRcChannels; ++c) empty += fields[1 + c].empty() ? 1 : 0;
        if (empty == kRcChannels) {
            row.signal = false;
        } else if (empty != 0) {
            return fail("a row has all 8 channels or none (a dead receiver)");
        } else {
            row.signal = true;
            for (int c = 0; c < kRcChannels; ++c) {
                if (!parse_number(fields[1 + c], row.width_us[c]) || !width_ok(row.width_us[c])) {
                    char why[96];
                    std::snprintf(why, sizeof why, "ch%d must be a width from %.0f to %.0f us", c + 1, kMinWidth_us,
                                  kMaxWidth_us);
                    return fail(why);
                }
            }
        }
        rows_.push_back(row);
    }
    if (!header_seen) return fail("empty: the header t,ch1,...,ch8 is missing");
    return true;
}

bool RcScript::push(const RcRow& row) {
    if (!std::isfinite(row.t_s) || row.t_s < 0.0) return false;
    if (!rows_.empty() && row.t_s < rows_.back().t_s) return false;
    if (row.signal)
        for (double w : row.width_us)
            if (!width_ok(w)) return false;
    if (!rows_.empty() && row.t_s == rows_.back().t_s) {
        rows_.back() = row;  // the latest word for that instant
        return true;
    }
    rows_.push_back(row);
    return true;
}

void RcScript::drop_before(double t_s) {
    size_t keep_from = 0;
    while (keep_from + 1 < rows_.size() && rows_[keep_from + 1].t_s <= t_s) ++keep_from;
    rows_.erase(rows_.begin(), rows_.begin() + (long)keep_from);
}

const RcRow* RcScript::at(double t_s) const {
    // Last row with t <= t_s.
    auto it = std::upper_bound(rows_.begin(), rows_.end(), t_s,
                               [](double t, const RcRow& r) { return t < r.t_s; });
    return it == rows_.begin() ? nullptr : &*(it - 1);
}

// --- PPM ----------------------------------------------------------------------------

bool PpmEncoder::start_frame() {
    // The first instant >= resume_s_ at which a live row is in force.
    double start_s = resume_s_;
    const RcRow* row = script_.at(start_s);
    if (!row || !row->signal) {
        const std::vector<RcRow>& rows = script_.rows();
        auto next = std::upper_bound(rows.begin(), rows.end(), start_s,
                                     [](double t, const RcRow& r) { return t < r.t_s; });
        while (next != rows.end() && !next->signal) ++next;
        row = next == rows.end() ? nullptr : &*next;
        if (!row) return false;
        start_s = row->t_s;
    }
    double sum_us = 0.0;
    for (int c = 0; c < kRcChannels; ++c) {
        widths_us_[c] = row->width_us[c];
        sum_us += row->width_us[c];
    }
    frame_start_s_ = start_s;
    frame_length_s_ = std::max(kFrame_us, sum_us + kMinSync_us) * 1e-6;
    edge_index_ = 0;
    in_frame_ = true;
    ++frames_;
    return true;
}

bool PpmEncoder::next_edge(PpmEdge& edge) {
    if (!in_frame_ && !start_frame()) return false;
    // Falling edge k (k = 0..8) at the sum of the first k widths; rising 400 us later.
    const int k = edge_index_ / 2;
    double offset_us = 0.0;
    for (int c = 0; c < k; ++c) offset_us += widths_us_[c];
    const bool rising = (edge_index_ % 2) == 1;
    if (rising) offset_us += kPrePulse_us;
    edge.t_s = frame_start_s_ + offset_us * 1e-6;
    edge.high = rising;
    if (++edge_index_ == 2 * (kRcChannels + 1)) {
        in_frame_ = false;
        resume_s_ = frame_start_s_ + frame_length_s_;
    }
    return true;
}

// --- servo pulses -------------------------------------------------------------------

void ServoPulseLog::level(int output, double t_s, bool high) {
    if (output < 1 || output > kServoOutputs) return;
    const int i = output - 1;
    if (high == high_[i]) return;
    high_[i] = high;
    if (high) {
        rise_s_[i] = t_s;
        return;
    }
    ServoPulse p;
    p.rise_s = rise_s_[i];
    p.output = output;
    p.width_us = (t_s - rise_s_[i]) * 1e6;
    last_width_us_[i] = p.width_us;
    last_end_s_[i] = t_s;
    ended_.push_back(p);
}

void ServoPulseLog::take(std::vector<ServoPulse>& out, bool all) {
    // A pulse is final once no output still high rose before it (that one would be
    // written first).
    double horizon_s = 1e300;
    if (!all)
        for (int i = 0; i < kServoOutputs; ++i)
            if (high_[i]) horizon_s = std::min(horizon_s, rise_s_[i]);
    std::stable_sort(ended_.begin(), ended_.end(), [](const ServoPulse& a, const ServoPulse& b) {
        return a.rise_s < b.rise_s || (a.rise_s == b.rise_s && a.output < b.output);
    });
    size_t n = 0;
    while (n < ended_.size() && (all || ended_[n].rise_s < horizon_s)) out.push_back(ended_[n++]);
    ended_.erase(ended_.begin(), ended_.begin() + (long)n);
}

double ServoPulseLog::last_width_us(int output) const {
    return output >= 1 && output <= kServoOutputs ? last_width_us_[output - 1] : 0.0;
}

uint16_t ServoPulseLog::width_now_us(int output, double t_s, double stale_s) const {
    if (output < 1 || output > kServoOutputs) return 0;
    const int i = output - 1;
    if (last_width_us_[i] <= 0.0 || t_s - last_end_s_[i] > stale_s) return 0;
    const double w = std::round(last_width_us_[i]);
    return (uint16_t)std::min(w, 65535.0);
}

std::string ServoPulseLog::format(const ServoPulse& pulse) {
    char row[64];
    std::snprintf(row, sizeof row, "%.6f,%d,%.2f\n", pulse.rise_s, pulse.output, pulse.width_us);
    return row;
}

}  // namespace sim
