#include "Console.h"

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

bool equals(const char* a, const char* b) {
    while (*a != '\0' && *a == *b) { ++a; ++b; }
    return *a == *b;
}

Command make(CommandId id) { return Command{id, Error::None, 0, fmt::OutputMode::Plot}; }
Command fail(Error e) { return Command{CommandId::Error, e, 0, fmt::OutputMode::Plot}; }

}  // namespace

bool parse_centi(const char* s, int32_t& out) {
    bool neg = false;
    if (*s == '+' || *s == '-') neg = (*s++ == '-');
    int32_t whole = 0;
    uint8_t int_digits = 0, frac_digits = 0;
    int32_t frac = 0;      // hundredths
    bool round_up = false;
    while (*s >= '0' && *s <= '9') {
        if (++int_digits > 7) return false;
        whole = whole * 10 + (*s++ - '0');
    }
    if (*s == '.') {
        ++s;
        while (*s >= '0' && *s <= '9') {
            if (frac_digits < 2) frac = frac * 10 + (*s - '0');
            else if (frac_digits == 2) round_up = (*s >= '5');
            if (frac_digits < 255) ++frac_digits;
            ++s;
        }
    }
    if (*s != '\0' || (int_digits == 0 && frac_digits == 0)) return false;
    if (frac_digits == 1) frac *= 10;
    int32_t v = whole * 100 + frac + (round_up ? 1 : 0);
    out = neg ? -v : v;
    return true;
}

Command parse_line(const char* line) {
    char copy[kLineCapacity + 1];
    const char* w[3] = {nullptr, nullptr, nullptr};
    const uint8_t n = split(line, copy, w);
    if (n == 0) return make(CommandId::None);
    if (n > 3) return fail(Error::ExtraArgument);
    const char* cmd = w[0];

    // Commands without arguments.
    struct Plain { const char* name; CommandId id; };
    static const Plain kPlain[] = {
        {"help", CommandId::Help}, {"status", CommandId::Status},
        {"save", CommandId::Save}, {"defaults", CommandId::Defaults},
    };
    for (const Plain& p : kPlain) {
        if (equals(cmd, p.name)) return n == 1 ? make(p.id) : fail(Error::ExtraArgument);
    }
    if (equals(cmd, "?")) return n == 1 ? make(CommandId::Help) : fail(Error::ExtraArgument);

    if (equals(cmd, "rate") || equals(cmd, "decl") || equals(cmd, "mode") || equals(cmd, "cal")) {
        if (n < 2) return fail(Error::MissingArgument);
        if (n > 2) return fail(Error::ExtraArgument);
    } else {
        return fail(Error::Unknown);
    }
    const char* arg = w[1];
    if (equals(cmd, "rate")) {
        int32_t c;
        if (!parse_centi(arg, c)) return fail(Error::BadNumber);
        if (c % 100 != 0 || c < settings::kRateMinHz * 100 || c > settings::kRateMaxHz * 100)
            return fail(Error::RateRange);
        Command r = make(CommandId::Rate);
        r.value = c / 100;
        return r;
    }
    if (equals(cmd, "decl")) {
        int32_t c;
        if (!parse_centi(arg, c)) return fail(Error::BadNumber);
        if (c < settings::kDeclMinCentideg || c > settings::kDeclMaxCentideg) return fail(Error::DeclRange);
        Command r = make(CommandId::Decl);
        r.value = c;
        return r;
    }
    if (equals(cmd, "mode")) {
        Command r = make(CommandId::Mode);
        if (equals(arg, "plot")) r.mode = fmt::OutputMode::Plot;
        else if (equals(arg, "csv")) r.mode = fmt::OutputMode::Csv;
        else if (equals(arg, "quiet")) r.mode = fmt::OutputMode::Quiet;
        else return fail(Error::BadMode);
        return r;
    }
    // cal
    if (equals(arg, "gyro")) return make(CommandId::CalGyro);
    if (equals(arg, "mag")) return make(CommandId::CalMag);
    return fail(Error::BadCalTarget);
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
        case fmt::OutputMode::Plot: break;
    }
    return TXT("plot");
}

void print_error(const Command& c, const text::Sink* out) {
    Writer w(out);
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
        case Error::BadMode: w.str(TXT("mode must be plot, csv or quiet")); break;
        case Error::BadCalTarget: w.str(TXT("cal gyro or cal mag")); break;
        case Error::None: w.str(TXT("internal")); break;
    }
    w.str(TXT("; nothing changed")).end();
}

void print_help(const text::Sink* out) {
    Writer(out).str(TXT(
        "# rate <Hz>: output rate 1..100\n"
        "# decl <deg>: declination -180..180, east +\n"
        "# mode plot|csv|quiet: output format\n"
        "# status: health, load, bias, temperature, uptime\n"
        "# cal gyro: gyro bias (keep still 1 s)\n"
        "# cal mag: compass (turn every way for 30 s)\n"
        "# save | defaults: store settings / back to defaults\n"));
}

bool apply_setting(const Command& c, settings::Settings& s, const text::Sink* out) {
    Writer w(out);
    switch (c.id) {
        case CommandId::Rate:
            s.rate_hz = (uint8_t)c.value;
            w.str(TXT("# rate ")).i32(c.value).str(TXT(" Hz")).end();
            return true;
        case CommandId::Decl: {
            s.declination_centideg = (int16_t)c.value;
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
            w.str(TXT("# defaults: rate 50 Hz, decl 0.00, mode plot, no compass cal (save to keep)")).end();
            return true;
        default:
            return false;
    }
}

}  // namespace console
