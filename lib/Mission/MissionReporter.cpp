// SPDX-License-Identifier: GPL-3.0-or-later
#include "MissionReporter.h"

namespace mission {

bool MissionReporter::request(uint16_t seq, uint8_t count) {
    if (seq == 0 || seq > count) return false;
    asked_ = seq;
    current_ = seq;
    current_news_ = true;  // answered even when it was current already, as ArduPlane
    return true;
}

void MissionReporter::note_current(uint16_t seq) {
    if (seq == current_) return;
    current_ = seq;
    current_news_ = true;
}

void MissionReporter::start(MissionExecutor& ex, const NavState& s) {
    ex.start(s, asked_ != 0u ? asked_ : 1u);
    asked_ = 0;
    reached_count_ = ex.reached_count();
    note_current(ex.current_seq());
}

void MissionReporter::follow(MissionExecutor& ex, const NavState& s) {
    if (ex.reached_count() != reached_count_) {
        reached_count_ = ex.reached_count();
        reached_ = ex.reached_seq();
    } else if (asked_ != 0u) {
        ex.set_current(asked_, s);
        asked_ = 0;
    }
    note_current(ex.current_seq());
}

bool MissionReporter::take_reached(uint16_t& seq) {
    if (reached_ == 0u) return false;
    seq = reached_;
    reached_ = 0;
    return true;
}

bool MissionReporter::take_current() {
    const bool was = current_news_;
    current_news_ = false;
    return was;
}

}  // namespace mission
