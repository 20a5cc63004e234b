// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: the console's input path (lib/Console) on arbitrary bytes, as a
// serial line would deliver them: LineReader -> parse_line -> print_error /
// apply_setting into a string sink, plus parse_line and parse_centi on the raw input.
// Built by mk/fuzz.mk with clang -fsanitize=fuzzer,address,undefined: a crash, an
// out-of-bounds access, undefined behaviour or a broken invariant below aborts.
//
// Invariants checked (what the console promises in Console.h):
// - the settings stay valid (settings::is_valid) whatever commands arrive;
// - a command that is not a setting changes nothing;
// - every reply is whole "# ..." lines of printable ASCII;
// - parse_centi accepts only "[+-]digits[.digits]" with 1..7 integer digits and
//   gives the hundredths a slow reference computes.
#include <stddef.h>
#include <stdint.h>

#include <cstdlib>
#include <cstring>
#include <string>

#include "FuzzAssert.h"
#include "Console.h"
#include "Settings.h"

namespace {

void append(void* ctx, const char* data, uint8_t len) { static_cast<std::string*>(ctx)->append(data, len); }

bool same(const settings::Settings& a, const settings::Settings& b) {
    uint8_t ra[settings::kRecordSize], rb[settings::kRecordSize];
    settings::encode(a, ra);
    settings::encode(b, rb);
    return std::memcmp(ra, rb, sizeof ra) == 0;
}

// Whole lines, each "# " then printable ASCII; the csv header is the one exception.
void check_reply(const std::string& out) {
    size_t start = 0;
    while (start < out.size()) {
        const size_t nl = out.find('\n', start);
        fuzz_assert(nl != std::string::npos);
        const std::string line = out.substr(start, nl - start);
        fuzz_assert(line.rfind("# ", 0) == 0 || line == "t_ms,roll,pitch,yaw");
        for (char c : line) fuzz_assert(c >= 0x20 && c <= 0x7E);
        start = nl + 1;
    }
}

// parse_centi's contract computed the slow way: the grammar, then hundredths rounded
// half away from zero on the third decimal.
bool reference_centi(const char* s, int32_t& out) {
    bool neg = false;
    if (*s == '+' || *s == '-') neg = (*s++ == '-');
    int64_t whole = 0;
    int digits = 0, frac_digits = 0;
    int64_t frac = 0;
    int third = 0;
    while (*s >= '0' && *s <= '9') {
        whole = whole * 10 + (*s++ - '0');
        if (++digits > 7) return false;
    }
    if (*s == '.') {
        ++s;
        while (*s >= '0' && *s <= '9') {
            if (frac_digits < 2) frac = frac * 10 + (*s - '0');
            else if (frac_digits == 2) third = *s - '0';
            ++frac_digits;
            ++s;
        }
    }
    if (*s != '\0' || (digits == 0 && frac_digits == 0)) return false;
    if (frac_digits == 1) frac *= 10;
    const int64_t v = whole * 100 + frac + (third >= 5 ? 1 : 0);
    out = (int32_t)(neg ? -v : v);
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // 1. The bytes as a serial stream.
    console::LineReader reader;
    settings::Settings s = settings::defaults();
    std::string out;
    const text::Sink sink{&out, append};
    for (size_t i = 0; i < size; ++i) {
        const console::Command c = reader.feed(data[i]);
        if (c.id == console::CommandId::None) continue;  // mid-line: nothing to check
        const settings::Settings before = s;
        if (c.id == console::CommandId::Error) {
            fuzz_assert(c.error != console::Error::None);
            console::print_error(c, &sink);
        } else if (c.id == console::CommandId::Help) {
            console::print_help(&sink);
        } else if (!console::apply_setting(c, s, &sink)) {
            fuzz_assert(same(before, s));
        }
        fuzz_assert(settings::is_valid(s));
    }
    check_reply(out);

    // 2. The bytes as one line (any length, any content up to the first NUL).
    std::string line(reinterpret_cast<const char*>(data), size);
    line = line.c_str();
    const console::Command c = console::parse_line(line.c_str());
    if (c.id == console::CommandId::Rate) fuzz_assert(c.value >= settings::kRateMinHz && c.value <= settings::kRateMaxHz);
    if (c.id == console::CommandId::Decl)
        fuzz_assert(c.value >= settings::kDeclMinCentideg && c.value <= settings::kDeclMaxCentideg);

    // 3. parse_centi against the reference.
    int32_t got = 0, want = 0;
    const bool ok = console::parse_centi(line.c_str(), got);
    fuzz_assert(ok == reference_centi(line.c_str(), want));
    if (ok) fuzz_assert(got == want);
    return 0;
}
