// SPDX-License-Identifier: GPL-3.0-or-later
#include "Console.h"

#include "Modes.h"
#include "Params.h"

#include <string.h>

namespace console {

using text::Writer;

namespace {

char lower(char c) { return (c >= 'A' && c <= 'Z') ? (char)(c - 'A' + 'a') : c; }
bool is_space(char c) { return c == ' ' || c == '\t'; }

// Splits `line` into at most 3 words (pointers into a lower-cased copy); returns the
// word count, or 4 if there were more.
uint8_t split(const char* line, char copy[kLineCapacity + 1], const char* words[3]) {
    uint8_t n = 0, i = 0;
    for (; line[i] != '\0' && i < kLineCapacity; ++i) copy[i] = lower(line[i]);
    copy[i] = '\0';
    char* p = copy;
    while (true) {
        while (is_space(*p)) ++p;
        if (*p == '\0') return n;
        if (n == 3) return 4;
        words[n++] = p;
        while (*p != '\0' && !is_space(*p)) ++p;
        if (*p == '\0') return n;
        *p++ = '\0';
    }
}

// Index of `word` in `names` (TXT words, each NUL-terminated, an empty word last), or -1.
int8_t find_word(const char* word, text::Flash names) {
    const char* p = names.p;
    for (int8_t i = 0; text::flash_byte(p) != 0u; ++i) {
        const char* w = word;
        while (*w != '\0' && (uint8_t)*w == text::flash_byte(p)) { ++w; ++p; }
        if (*w == '\0' && text::flash_byte(p) == 0u) return i;
        while (text::flash_byte(p) != 0u) ++p;
        ++p;
    }
    return -1;
}

Command make(CommandId id) { return Command{id, Error::None, 0, fmt::OutputMode::Plot, 0}; }
Command fail(Error e) { return Command{CommandId::Error, e, 0, fmt::OutputMode::Plot, 0}; }

// A value with four decimals as the float a parameter takes (a division: 1500.0000
// comes back exactly 1500).
float param_value(int32_t scaled) { return (float)scaled / (float)kParamScale; }

// "VALUE": an integer type's whole number, a float's four decimals.
void write_value(Writer& w, params::Type t, float v) {
    int32_t x;
    if (params::is_integer(t)) {
        w.i32((int32_t)v);
    } else if (text::to_fixed(v, 4, x)) {
        char buf[16];
        w.str(buf, text::format_fixed(buf, x, 4));
    } else {
        w.chr('?');
    }
}

// "manual or stabilize or fbwa" (lower case, `sep` between), "0 manual, 2 ..." with the numbers:
// the modes the board has, from lib/Flight/Modes.h.
void write_modes(Writer& w, text::Flash sep, bool numbers) {
    for (uint8_t i = 0; i < flight::kModeCount; ++i) {
        char name[flight::kModeNameMax + 1];
        flight::mode_name(i, name);
        if (i > 0) w.str(sep);
        if (numbers) w.u32(flight::mode_number(i)).chr(' ');
        for (char* p = name; *p != '\0'; ++p) *p = lower(*p);
        w.str(name, (uint8_t)strlen(name));
    }
}

}  // namespace

bool parse_centi(const char* s, int32_t& out) { return parse_fixed(s, 2, 7, out); }

bool parse_fixed(const char* s, uint8_t decimals, uint8_t max_int_digits, int32_t& out) {
    bool neg = false;
    if (*s == '+' || *s == '-') neg = (*s++ == '-');
    int32_t whole = 0;
    uint8_t int_digits = 0, frac_digits = 0;
    int32_t frac = 0;      // in units of the last kept decimal
    bool round_up = false;
    while (*s >= '0' && *s <= '9') {
        if (++int_digits > max_int_digits) return false;
        whole = whole * 10 + (*s++ - '0');
    }
    if (*s == '.') {
        ++s;
        while (*s >= '0' && *s <= '9') {
            if (frac_digits < decimals) frac = frac * 10 + (*s - '0');
            else if (frac_digits == decimals) round_up = (*s >= '5');
            if (frac_digits < 255) ++frac_digits;
            ++s;
        }
    }
    if (*s != '\0' || (int_digits == 0 && frac_digits == 0)) return false;
    int32_t unit = 1;
    for (uint8_t k = 0; k < decimals; ++k) unit *= 10;
    for (uint8_t k = frac_digits; k < decimals; ++k) frac *= 10;
    int32_t v = whole * unit + frac + (round_up ? 1 : 0);
    out = neg ? -v : v;
    return true;
}

// Never inline (cold, between samples): inlined into its callers with the rest, it took
// 508 B more flash together with six others of the kind (docs/performance.md, "Size").
__attribute__((noinline)) Command parse_line(const char* line) {
    char copy[kLineCapacity + 1];
    const char* w[3] = {nullptr, nullptr, nullptr};
    const uint8_t n = split(line, copy, w);
    if (n == 0) return make(CommandId::None);
    if (n > 3) return fail(Error::ExtraArgument);
    const char* cmd = w[0];

    // The command names in flash, those without an argument first; each name's command
    // is its byte in kIds (a TXT string too: an array would be copied to the AVR's SRAM).
    // (rc, servo, params, gps, baro and mission are Show with kShowRc .. kShowMission.)
    const text::Flash kIds = TXT("\x02\x02\x06\x09\x0A\x0C\x0C\x0C\x0C\x0C\x0C\x0B\x0B\x03\x04\x05\x07\x0B\x0E\x0D");
    static_assert((uint8_t)CommandId::Help == 2 && (uint8_t)CommandId::Status == 6 &&
                      (uint8_t)CommandId::Save == 9 && (uint8_t)CommandId::Defaults == 10 &&
                      (uint8_t)CommandId::Rate == 3 && (uint8_t)CommandId::Decl == 4 &&
                      (uint8_t)CommandId::Mode == 5 && (uint8_t)CommandId::CalGyro == 7 &&
                      (uint8_t)CommandId::Flight == 11 && (uint8_t)CommandId::Show == 12 &&
                      (uint8_t)CommandId::Set == 13 && (uint8_t)CommandId::Get == 14,
                  "kIds holds these values");
    constexpr int8_t kFirstShow = 5, kArmWord = 11, kFirstWithArgument = 13;
    const int8_t k = find_word(
        cmd, TXT("help\0?\0status\0save\0defaults\0rc\0servo\0params\0gps\0baro\0mission\0arm\0disarm\0rate\0decl\0mode\0cal\0flight\0get\0set\0"));
    if (k < 0) return fail(Error::Unknown);
    const CommandId id = (CommandId)text::flash_byte(kIds.p + k);
    if (k < kFirstWithArgument) {
        if (n != 1) return fail(Error::ExtraArgument);
        Command r = make(id);
        if (id == CommandId::Show) r.arg = (uint8_t)(k - kFirstShow);
        if (id == CommandId::Flight) r.arg = k == kArmWord ? kArm : kDisarm;
        return r;
    }
    if (n < 2) return fail(Error::MissingArgument);
    if (id == CommandId::Set) {
        if (n < 3) return fail(Error::MissingArgument);
        const int16_t index = params::find(w[1]);
        if (index < 0) return fail(Error::UnknownParam);
        params::Info in;
        params::info((uint16_t)index, in);
        int32_t v;
        if (!parse_fixed(w[2], 4, 5, v)) return fail(Error::BadNumber);
        const float f = param_value(v);
        Command r = make(id);
        r.arg = (uint8_t)index;
        if (!(f >= in.min && f <= in.max) || (params::is_integer(in.type) && v % kParamScale != 0)) {
            r = fail(Error::ParamRange);
            r.arg = (uint8_t)index;
            return r;
        }
        if (params::is_flight_mode((uint16_t)index) && !flight::mode_known((uint8_t)(v / kParamScale))) {
            r = fail(Error::NoSuchMode);
            r.arg = (uint8_t)index;
            return r;
        }
        r.value = v;
        return r;
    }
    if (n > 2) return fail(Error::ExtraArgument);
    const char* arg = w[1];
    Command r = make(id);
    if (id == CommandId::Get) {
        const int16_t index = params::find(arg);
        if (index < 0) return fail(Error::UnknownParam);
        r.arg = (uint8_t)index;
        return r;
    }
    if (id == CommandId::Flight) {
        const int8_t m = flight::mode_by_name(arg);
        if (m < 0) return fail(Error::BadFlightMode);
        r.arg = (uint8_t)m;
        return r;
    }
    if (id == CommandId::Rate || id == CommandId::Decl) {
        int32_t c;
        if (!parse_centi(arg, c)) return fail(Error::BadNumber);
        if (id == CommandId::Rate) {
            if (c % 100 != 0 || c < settings::kRateMinHz * 100 || c > settings::kRateMaxHz * 100)
                return fail(Error::RateRange);
            c /= 100;
        } else if (c < settings::kDeclMinCentideg || c > settings::kDeclMaxCentideg) {
            return fail(Error::DeclRange);
        }
        r.value = c;
        return r;
    }
    if (id == CommandId::Mode) {
        // The names in the order of fmt::OutputMode's values.
        const int8_t m = find_word(arg, TXT("plot\0csv\0quiet\0quat\0raw\0mavlink\0"));
        if (m < 0) return fail(Error::BadMode);
        r.mode = (fmt::OutputMode)m;
        return r;
    }
    // cal
    const int8_t t = find_word(arg, TXT("gyro\0mag\0level\0accel\0"));
    if (t < 0) return fail(Error::BadCalTarget);
    r.id = t == 0 ? CommandId::CalGyro : t == 1 ? CommandId::CalMag : t == 2 ? CommandId::CalLevel : CommandId::CalAccel;
    return r;
}

Command LineReader::feed(uint8_t byte) {
    const bool after_cr = last_was_cr_;
    last_was_cr_ = (byte == '\r');
    if (byte == '\r' || byte == '\n') {
        if (byte == '\n' && after_cr) return make(CommandId::None);  // second half of "\r\n"
        Command c;
        if (garbage_) c = fail(Error::Garbage);  // binary noise: say so even if long
        else if (too_long_) c = fail(Error::TooLong);
        else {
            buf_[len_] = '\0';
            c = parse_line(buf_);
        }
        len_ = 0;
        too_long_ = garbage_ = false;
        return c;
    }
    if (byte == 0x08 || byte == 0x7F) {  // backspace / delete
        if (len_ > 0 && !too_long_) --len_;
        return make(CommandId::None);
    }
    if ((byte < 0x20 && byte != '\t') || byte > 0x7E) {
        garbage_ = true;
        return make(CommandId::None);
    }
    if (len_ >= kLineCapacity) {
        too_long_ = true;
        return make(CommandId::None);
    }
    buf_[len_++] = (char)byte;
    return make(CommandId::None);
}

text::Flash csv_header() { return TXT("t_ms,roll,pitch,yaw\n"); }

text::Flash mode_name(fmt::OutputMode m) {
    switch (m) {
        case fmt::OutputMode::Csv: return TXT("csv");
        case fmt::OutputMode::Quiet: return TXT("quiet");
        case fmt::OutputMode::Quat: return TXT("quat");
        case fmt::OutputMode::Raw: return TXT("raw");
        case fmt::OutputMode::Mavlink: return TXT("mavlink");
        case fmt::OutputMode::Plot: break;
    }
    return TXT("plot");
}

bool print_error(const Command& c, uint8_t part, const text::Sink* out) {
    Writer w(out);
    if (part == 1 && c.value > 0) {
        w.str(TXT(TXT_ERROR)).u32((uint32_t)c.value)
            .str(TXT(" more bad lines (too many to answer one by one); nothing changed")).end();
        return true;
    }
    if (part != 0) return false;
    w.str(TXT(TXT_ERROR));
    switch (c.error) {
        case Error::Unknown: w.str(TXT("unknown command" TXT_HELP)); break;
        case Error::TooLong: w.str(TXT("line over 40 characters")); break;
        case Error::Garbage: w.str(TXT("non-text bytes in line")); break;
        case Error::MissingArgument: w.str(TXT("missing argument" TXT_HELP)); break;
        case Error::ExtraArgument: w.str(TXT("too many arguments" TXT_HELP)); break;
        case Error::BadNumber: w.str(TXT("not a number (e.g. 50 or -2.5)")); break;
        case Error::RateRange: w.str(TXT("rate must be a whole number 1..100 Hz")); break;
        case Error::DeclRange: w.str(TXT("decl must be -180..180 degrees")); break;
        case Error::BadMode: w.str(TXT("mode must be plot, csv, quat, raw, mavlink or quiet")); break;
        case Error::BadCalTarget: w.str(TXT("cal gyro|mag|level|accel")); break;
        case Error::UnknownParam: w.str(TXT("unknown parameter (type params)")); break;
        case Error::BadFlightMode: w.str(TXT("flight ")); write_modes(w, TXT(" or "), false); break;
        case Error::NoSuchMode: {
            params::Info in;
            if (!params::info(c.arg, in)) break;
            w.str(in.name, (uint8_t)strlen(in.name)).str(TXT(" must be a mode of this board: "));
            write_modes(w, TXT(", "), true);
            break;
        }
        case Error::ParamRange: {
            params::Info in;
            if (!params::info(c.arg, in)) break;
            w.str(in.name, (uint8_t)strlen(in.name)).str(TXT(" must be "));
            write_value(w, in.type, in.min);
            w.str(TXT(".."));
            write_value(w, in.type, in.max);
            if (params::is_integer(in.type)) w.str(TXT(", whole"));
            break;
        }
        case Error::None: w.str(TXT("internal")); break;
    }
    w.str(TXT("; nothing changed")).end();
    return true;
}

void print_error(const Command& c, const text::Sink* out) {
    for (uint8_t part = 0; print_error(c, part, out); ++part) {}
}

bool print_help(uint8_t part, const text::Sink* out) {
    // The lines, NUL-separated (an empty one last): one is written per part.
    const char* p = TXT("# rate <Hz>: output rate 1..100\0"
                        "# decl <deg>: declination -180..180, east +\0"
                        "# mode plot|csv|quat|raw|mavlink|quiet: output\0"
                        "# status: health, load, bias, temperature, uptime\0"
                        "# cal gyro: gyro bias (keep still 1 s)\0"
                        "# cal mag: compass (turn every way for 30 s)\0"
                        "# cal level: AHRS_TRIM (airframe level, still 1 s)\0"
                        "# cal accel: 6 positions; again at each one asked\0"
                        "# save | defaults: store settings / back to defaults\0"
                        "# flight manual|stabilize|fbwa: flight mode\0"
                        "# arm | disarm: the throttle (pre-arm checks first)\0"
                        "# rc | servo: receiver / output widths, us\0"
                        "# gps: fix, satellites, position, speed, counters\0"
                        "# baro: pressure, temperature, height, climb\0"
                        "# mission: the stored mission\0"
                        "# params | get NAME | set NAME VALUE: flight settings\0").p;
    for (uint8_t k = 0; k < part && text::flash_byte(p) != 0u; ++k)
        while (text::flash_byte(p++) != 0u) {}
    if (text::flash_byte(p) == 0u) return false;
    Writer(out).str(text::flash(p)).end();
    return true;
}

void print_help(const text::Sink* out) {
    for (uint8_t part = 0; print_help(part, out); ++part) {}
}

void print_defaults(const text::Sink* out) {
    Writer(out).str(TXT("# defaults: rate 50 Hz, decl 0.00, mode plot, no compass cal (save to keep)")).end();
}

bool print_param(uint16_t index, const settings::Settings& s, const text::Sink* out) {
    params::Info in;
    if (!params::info(index, in)) return false;
    Writer w(out);
    w.str(TXT("# ")).str(in.name, (uint8_t)strlen(in.name)).chr(' ');
    write_value(w, in.type, params::get(s, index));
    w.end();
    return true;
}

bool apply_setting(const Command& c, settings::Settings& s, const text::Sink* out) {
    Writer w(out);
    switch (c.id) {
        case CommandId::Get:
            print_param(c.arg, s, out);
            return true;
        case CommandId::Set:
            if (params::set(s, c.arg, param_value(c.value))) {
                print_param(c.arg, s, out);
            } else {
                params::Info in;
                params::info(c.arg, in);
                w.str(TXT(TXT_ERROR)).str(in.name, (uint8_t)strlen(in.name))
                    .str(TXT(": end points must stay MIN <= TRIM <= MAX; nothing changed")).end();
            }
            return true;
        case CommandId::Rate:
            s.rate_hz = (uint8_t)c.value;
            w.str(TXT("# rate ")).i32(c.value).str(TXT(" Hz")).end();
            return true;
        case CommandId::Decl: {
            settings::set_declination_centideg(s, (int16_t)c.value);
            char buf[14];
            w.str(TXT("# decl ")).str(buf, text::format_centi(buf, c.value)).str(TXT(" deg")).end();
            return true;
        }
        case CommandId::Mode:
            s.mode = c.mode;
            w.str(TXT("# mode ")).str(mode_name(c.mode)).end();
            if (c.mode == fmt::OutputMode::Csv) w.str(csv_header());
            return true;
        case CommandId::Defaults:
            s = settings::defaults();
            print_defaults(out);
            return true;
        default:
            return false;
    }
}

static_assert((uint8_t)CommandId::Get < 15 && (uint8_t)Error::NoSuchMode < 16 && flight::kModeCount < kArm &&
                  (uint8_t)fmt::kLastOutputMode < 16,
              "CommandQueue packs the id and the error or mode into 4 bits each, id 15 spare");
static_assert((CommandQueue::kBytes & (CommandQueue::kBytes - 1u)) == 0, "kBytes must be a power of two");

uint8_t CommandQueue::item_bytes(uint8_t first) {
    const uint8_t id = first & 0x0Fu;
    if (id == (uint8_t)CommandId::Rate || id == (uint8_t)CommandId::Get) return 2;
    if (id == (uint8_t)CommandId::Error &&
        ((first >> 4) == (uint8_t)Error::ParamRange || (first >> 4) == (uint8_t)Error::NoSuchMode))
        return 2;
    if (id == (uint8_t)CommandId::Decl || id == kMergedError) return 3;
    if (id == (uint8_t)CommandId::Set) return kMaxItem;
    return 1;
}

Command CommandQueue::decode(uint8_t at) const {
    const uint8_t first = byte(at);
    const uint8_t id = first & 0x0Fu, high = (uint8_t)(first >> 4);
    if (id == kMergedError) {
        Command c = fail((Error)high);
        c.value = word((uint8_t)(at + 1u));  // a count, 0..0xFFFF
        return c;
    }
    Command c = make((CommandId)id);
    c.error = id == (uint8_t)CommandId::Error ? (Error)high : Error::None;
    if (id == (uint8_t)CommandId::Mode) c.mode = (fmt::OutputMode)high;
    if (id == (uint8_t)CommandId::Rate) c.value = byte((uint8_t)(at + 1u));
    if (id == (uint8_t)CommandId::Decl) c.value = (int16_t)word((uint8_t)(at + 1u));
    if (id == (uint8_t)CommandId::Flight || id == (uint8_t)CommandId::Show) c.arg = high;
    if (item_bytes(first) >= 2u && id != (uint8_t)CommandId::Rate && id != (uint8_t)CommandId::Decl)
        c.arg = byte((uint8_t)(at + 1u));  // get, set, a range error: the index
    if (id == (uint8_t)CommandId::Set)
        c.value = (int32_t)((uint32_t)word((uint8_t)(at + 2u)) | ((uint32_t)word((uint8_t)(at + 4u)) << 16));
    return c;
}

bool CommandQueue::push(const Command& c) {
    // Merged only into the newest item, so that replies keep the order of the lines.
    if (c.id == CommandId::Error && count_ > 0 && used_ >= kErrorBytes) {
        const uint8_t first = byte(newest_);
        if ((first & 0x0Fu) == kMergedError) {
            const uint16_t n = word((uint8_t)(newest_ + 1u));
            if (n < 0xFFFFu) put_word((uint8_t)(newest_ + 1u), (uint16_t)(n + 1u));
            return true;
        }
        // A plain error is the last item: its count goes in the two bytes after it.
        if ((first & 0x0Fu) == (uint8_t)CommandId::Error && item_bytes(first) == 1u &&
            (uint8_t)(kBytes - used_) >= 2u) {
            items_[newest_ & kMask] = (uint8_t)(kMergedError | (first & 0xF0u));
            put_word((uint8_t)(newest_ + 1u), 1u);
            used_ = (uint8_t)(used_ + 2u);
            return true;
        }
    }
    const uint8_t high = c.id == CommandId::Mode ? (uint8_t)c.mode
                         : (c.id == CommandId::Flight || c.id == CommandId::Show) ? c.arg
                                                                                  : (uint8_t)c.error;
    const uint8_t first = (uint8_t)((uint8_t)c.id | (uint8_t)(high << 4));
    const uint8_t n = item_bytes(first);
    if ((uint8_t)(kBytes - used_) < n) return false;
    const uint8_t at = (uint8_t)(head_ + used_);
    items_[at & kMask] = first;
    if (c.id == CommandId::Rate) items_[(uint8_t)(at + 1u) & kMask] = (uint8_t)c.value;
    if (c.id == CommandId::Decl) put_word((uint8_t)(at + 1u), (uint16_t)(int16_t)c.value);
    if (n >= 2u && c.id != CommandId::Rate && c.id != CommandId::Decl) items_[(uint8_t)(at + 1u) & kMask] = c.arg;
    if (c.id == CommandId::Set) {
        put_word((uint8_t)(at + 2u), (uint16_t)((uint32_t)c.value & 0xFFFFu));
        put_word((uint8_t)(at + 4u), (uint16_t)((uint32_t)c.value >> 16));
    }
    newest_ = (uint8_t)(at & kMask);
    used_ = (uint8_t)(used_ + n);
    ++count_;
    return true;
}

Command CommandQueue::pop() {
    const Command c = decode(head_);
    const uint8_t n = item_bytes(byte(head_));
    head_ = (uint8_t)((head_ + n) & kMask);
    used_ = (uint8_t)(used_ - n);
    --count_;
    return c;
}

}  // namespace console
