// The serial console: one command per line, answered with "# " lines.
//
//   help                 the command list
//   rate <Hz>            output lines per second, whole number 1..100
//   decl <degrees>       magnetic declination, east positive, -180..180 (2 decimals kept)
//   mode plot|csv|quat|raw|mavlink|quiet
//                        output format (csv prints its header "t_ms,roll,pitch,yaw" first;
//                        quat and raw lines: Format.h; mavlink: MAVLink 2, lib/MavLink)
//   status               sensor health, loop load, overruns, gyro bias, temperature, uptime
//   cal gyro             measure the gyro bias again (keep the board still ~1 s)
//   cal mag              hard iron + scale: turn the board every way for 30 s
//   save                 write settings and calibration to EEPROM
//   defaults             back to the defaults (not saved until `save`)
//
// Anything else (unknown words, bad or out-of-range numbers, extra arguments, a line
// over kLineCapacity characters, control or non-ASCII bytes) is answered with
// "# error: ..." and changes nothing. Commands are case-insensitive; '\r', '\n' or
// "\r\n" end a line; backspace (0x08 or 0x7F) deletes the last character.
//
// Pure C++: the firmware feeds received bytes and executes what comes back; the
// commands that only change settings are executed here (apply_setting) so that the
// host tests cover them.
#pragma once

#include <stdint.h>

#include "Format.h"
#include "Settings.h"
#include "Text.h"

namespace console {

constexpr uint8_t kLineCapacity = 40;  // longest accepted line, characters

enum class CommandId : uint8_t {
    None,      // nothing complete yet (or an empty line)
    Error,     // Command::error says what
    Help,
    Rate,      // value = Hz
    Decl,      // value = hundredths of a degree
    Mode,      // mode
    Status,
    CalGyro,
    CalMag,
    Save,
    Defaults,
};

enum class Error : uint8_t {
    None,
    Unknown,          // not a command
    TooLong,          // line over kLineCapacity
    Garbage,          // control or non-ASCII bytes
    MissingArgument,
    ExtraArgument,
    BadNumber,        // not a number of the expected form
    RateRange,        // not 1..100 or not whole
    DeclRange,        // outside -180..180
    BadMode,          // not plot|csv|quat|raw|mavlink|quiet
    BadCalTarget,     // cal without gyro|mag
};

struct Command {
    CommandId id;
    Error error;
    int32_t value;  // Rate: Hz, Decl: hundredths of a degree; Error: further bad lines merged in (CommandQueue)
    fmt::OutputMode mode;
};

// Parses one complete line (NUL-terminated, without the line ending).
Command parse_line(const char* line);

// Parses a decimal number "[+-]digits[.digits]" into hundredths, rounding half away
// from zero on the third decimal. False for anything else (empty, letters, "1e3",
// "nan", two points, more than 7 integer digits).
bool parse_centi(const char* s, int32_t& out);

// Collects bytes into lines and parses them.
class LineReader {
public:
    // Feeds one received byte; returns the command when it ended a line, else None.
    Command feed(uint8_t byte);

private:
    char buf_[kLineCapacity + 1] = {};
    uint8_t len_ = 0;
    bool too_long_ = false;
    bool garbage_ = false;
    bool last_was_cr_ = false;
};

// Writes "# error: <why>\n" for a parse error.
void print_error(const Command& c, const text::Sink* out);
void print_help(const text::Sink* out);

// Executes Rate, Decl, Mode and Defaults on `s` and writes the reply; returns false
// (and touches nothing) for every other command. Defaults keeps nothing: calibration
// too returns to zero bias and unit scale.
bool apply_setting(const Command& c, settings::Settings& s, const text::Sink* out);

// The reply to `defaults`.
void print_defaults(const text::Sink* out);

// "t_ms,roll,pitch,yaw\n": the csv header (after `mode csv` and at start in csv mode).
text::Flash csv_header();

// "plot", "csv", "quiet", "quat", "raw" or "mavlink".
text::Flash mode_name(fmt::OutputMode m);

// The most bytes the reply to c can take: the firmware runs a command only when its
// output queue has that much room (help and status are the long ones: kLongReply;
// status is printed by the firmware and sized by its test; an error with merged ones
// takes two lines).
constexpr uint16_t kShortReply = 96;
constexpr uint16_t kLongReply = 400;
uint16_t reply_bound(const Command& c);

// Parsed commands waiting to run, oldest first. The firmware parses input as soon as it
// arrives (so the UART's small receive ring never overflows) but runs a command only
// when its reply has room to go out: a paste of several lines waits here.
class CommandQueue {
public:
    // A burst of garbage with commands between makes an error line for every ~20 bytes
    // received on average, whose replies (~50 bytes) outrun the UART wherever the
    // garbage lines are short: 96 commands (3 bytes each, 288 bytes of RAM standing for
    // ~4.6 KB of replies, 0.4 s of the UART) hold that backlog for a 20 KB burst of random
    // bytes, so the 64-byte receive ring is always emptied.
    static constexpr uint8_t kCapacity = 96;
    // Past this many, a bad line is merged into the newest item if that is an error (its
    // value counts them) instead of taking a slot: garbage that makes more errors than
    // the UART can answer one by one (a line end every few bytes) never crowds out a
    // command, and replies keep the order of the lines.
    static constexpr uint8_t kErrorSlots = kCapacity - 8;

    bool full() const { return count_ == kCapacity; }
    bool empty() const { return count_ == 0; }
    uint8_t size() const { return count_; }
    // False (nothing stored) when full; an error beyond kErrorSlots is merged (true).
    bool push(const Command& c);
    // The oldest command; call only when not empty.
    Command pop();
    // The oldest command, left in place; call only when not empty.
    Command peek() const { return unpack(items_[head_]); }

private:
    // A queued command in 3 bytes (a Command takes 7): id and error share a byte, and
    // one 16-bit field holds what the command carries (rate in Hz, decl within +-18000
    // centidegrees, the mode, a merged error count <= 0xFFFF), which parse_line and
    // push keep within those ranges: 288 bytes of RAM instead of 672.
    struct Packed {
        uint8_t id_error;
        uint8_t value_lo;
        uint8_t value_hi;
    };
    static Packed pack(const Command& c);
    static Command unpack(const Packed& p);

    Packed items_[kCapacity] = {};
    uint8_t head_ = 0;
    uint8_t count_ = 0;
};

}  // namespace console
