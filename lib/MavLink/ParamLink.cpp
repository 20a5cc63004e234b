// SPDX-License-Identifier: GPL-3.0-or-later
#include "ParamLink.h"


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
    params::set(s, (uint16_t)index, p.value, &changed);
    return index;
}

void ParamReplies::request_all() {
    count_ = (uint8_t)params::count();
    next_of_list_ = 0;
}

void ParamReplies::request_one(uint16_t index) {
    count_ = (uint8_t)params::count();
    if (index >= kMaxParams) return;
    const uint8_t bit = (uint8_t)(1u << (index & 7u));
    if ((pending_[index >> 3] & bit) != 0u) return;
    pending_[index >> 3] = (uint8_t)(pending_[index >> 3] | bit);
    ++singles_;
}

// Whole bytes at once: request_one() for each (params::count() each time) took 6 ms.
void ParamReplies::request_every_one() {
    count_ = (uint8_t)params::count();
    const uint16_t n = count_ < kMaxParams ? count_ : kMaxParams;
    for (uint8_t byte = 0; byte < kMaxParams / 8; ++byte) {
        const uint16_t first = (uint16_t)(byte * 8u);
        pending_[byte] = first + 8u <= n ? (uint8_t)0xFFu : first < n ? (uint8_t)((1u << (n - first)) - 1u) : (uint8_t)0u;
    }
    singles_ = (uint8_t)n;
}

bool ParamReplies::peek(uint16_t& index) const {
    if (singles_ > 0) {
        for (uint8_t byte = 0; byte < kMaxParams / 8; ++byte) {
            if (pending_[byte] == 0u) continue;
            uint8_t b = 0;
            while ((pending_[byte] & (1u << b)) == 0u) ++b;
            index = (uint16_t)(byte * 8u + b);
            return true;
        }
    }
    if (next_of_list_ == kNone) return false;
    index = next_of_list_;
    return true;
}

void ParamReplies::pop() {
    uint16_t index;
    if (singles_ > 0 && peek(index)) {
        pending_[index >> 3] = (uint8_t)(pending_[index >> 3] & ~(1u << (index & 7u)));
        --singles_;
        return;
    }
    if (next_of_list_ == kNone) return;
    ++next_of_list_;
    if (next_of_list_ >= count_) next_of_list_ = kNone;
}

}  // namespace mav
