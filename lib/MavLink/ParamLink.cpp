// SPDX-License-Identifier: GPL-3.0-or-later
#include "ParamLink.h"

#include <string.h>

namespace mav {

uint8_t param_type(params::Type t) {
    switch (t) {
        case params::Type::Int16:
        case params::Type::UInt16: return kParamTypeInt16;
        case params::Type::UInt8:
        case params::Type::Bit: return kParamTypeInt8;
        default: return kParamTypeReal32;
    }
}

uint8_t pack_param_value(Packer& packer, uint8_t out[kMaxFrame], const settings::Settings& s, uint16_t index,
                         uint16_t count) {
    params::Info in;
    if (!params::info(index, in)) return 0;
    return packer.param_value(out, in.name, params::get(s, index), param_type(in.type), count, index);
}

int16_t requested_index(const ParamRequest& r) {
    if (r.index >= 0) return r.index < (int16_t)params::count() ? r.index : (int16_t)-1;
    return params::find(r.name);
}

int16_t apply_param_set(settings::Settings& s, const ParamSet& p, bool& changed) {
    changed = false;
    const int16_t index = params::find(p.name);
    if (index < 0) return -1;
    const float before = params::get(s, (uint16_t)index);
    if (params::set(s, (uint16_t)index, p.value)) changed = params::get(s, (uint16_t)index) != before;
    return index;
}

void ParamReplies::request_all() {
    count_ = (uint8_t)params::count();
    next_of_list_ = 0;
}

void ParamReplies::request_one(uint16_t index) {
    count_ = (uint8_t)params::count();
    if (single_count_ < kSingles) singles_[single_count_++] = (uint8_t)index;
}

bool ParamReplies::peek(uint16_t& index) const {
    if (single_count_ > 0) {
        index = singles_[0];
        return true;
    }
    if (next_of_list_ == kNone) return false;
    index = next_of_list_;
    return true;
}

void ParamReplies::pop() {
    if (single_count_ > 0) {
        memmove(singles_, singles_ + 1, --single_count_);
        return;
    }
    if (next_of_list_ == kNone) return;
    ++next_of_list_;
    if (next_of_list_ >= count_) next_of_list_ = kNone;
}

}  // namespace mav
